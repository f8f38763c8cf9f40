"""Small seeded instances of the coherent oracle for the tests: worlds, databases and motions."""

from __future__ import annotations

import numpy as np

from qrrt_circuits import Environment, LinearTrackingDynamics
from qrrt_circuits.coherent import FixedPointFormat, LatticeDatabase, SampledMotion

SIDE = 10.0


def random_instance(seed: int, dim: int = 2, max_bits: int = 5, max_cell_bits: int = 3, max_boxes: int = 3,
                    max_nodes: int = 4) -> tuple[Environment, LatticeDatabase, SampledMotion]:
    """A random world (bounds inside [0, 10), up to ``max_boxes`` boxes), a lattice database of up to
    ``max_nodes`` nodes (sometimes a spare parent bit, so some parent indices are not nodes), and a
    motion: a straight line, the paper's dynamics (d = 2) or a random stable closed loop (with
    off-diagonal terms)."""
    rng = np.random.default_rng([0xC0DE, seed, dim])
    bits = int(rng.integers(2, max_bits + 1))
    cell_bits = int(rng.integers(1, min(bits, max_cell_bits) + 1))
    fmt = FixedPointFormat(bits, 0.0, SIDE)
    count = int(rng.integers(0, max_boxes + 1))
    low = rng.uniform(0, SIDE * 0.8, (count, dim))
    high = np.minimum(low + rng.uniform(0.2, 4, (count, dim)), SIDE - 0.01)
    bounds = np.stack([rng.uniform(0, 2, dim), rng.uniform(SIDE - 3, SIDE - 0.01, dim)], axis=1)
    env = Environment(bounds, np.stack([low, high], axis=1).reshape(count, 2, dim))
    nodes = rng.uniform(0, SIDE - 1e-9, (int(rng.integers(1, max_nodes + 1)), dim))
    parent_bits = max(len(nodes) - 1, 0).bit_length() + int(rng.integers(0, 2))
    database = LatticeDatabase(fmt, cell_bits, nodes, parent_bits=parent_bits)
    fraction_bits, samples = int(rng.integers(0, 5)), int(rng.integers(2, 5))
    kind = int(rng.integers(0, 3))
    if kind == 0:
        return env, database, SampledMotion.straight_line(dim, samples, fraction_bits)
    if kind == 1 and dim == 2:
        dynamics = LinearTrackingDynamics.paper(horizon=float(rng.uniform(0.1, 2.0)))
    else:
        a = rng.normal(size=(dim, dim))
        gain = a + 2.0 * np.eye(dim) + 0.3 * rng.normal(size=(dim, dim))
        if np.max(np.linalg.eigvals(a - gain).real) >= 0:
            gain = a + 3.0 * np.eye(dim)
        dynamics = LinearTrackingDynamics(a, np.eye(dim), gain, horizon=1.0)
    return env, database, SampledMotion.from_dynamics(dynamics, samples, fraction_bits)


def wall_instance() -> tuple[Environment, LatticeDatabase, SampledMotion]:
    """A wall x in [6, 9], y <= 9 in [0, 15]^2; 4 x 4 cells of a 4-bit grid; one node at (2, 2);
    straight lines of 3 samples (exact with f = 1). n = 4 index qubits, 10 qubits in all."""
    env = Environment([[0, 15], [0, 15]], [[[6, 0], [9, 9]]])
    database = LatticeDatabase(FixedPointFormat(4, 0.0, 16.0), 2, np.array([[2.0, 2.0]]))
    return env, database, SampledMotion.straight_line(2, 3, 1)


def grover_instance(nodes: int = 2) -> tuple[Environment, LatticeDatabase, SampledMotion]:
    """The wall world with ``nodes`` tree nodes (a parent field of 1 bit for 2): n = 5."""
    env = Environment([[0, 15], [0, 15]], [[[6, 0], [9, 9]]])
    points = np.array([[2.0, 2.0], [12.0, 3.0], [3.0, 13.0], [13.0, 13.0]])[:nodes]
    database = LatticeDatabase(FixedPointFormat(4, 0.0, 16.0), 2, points)
    return env, database, SampledMotion.straight_line(2, 3, 1)
