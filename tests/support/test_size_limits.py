"""Every size argument of the public API (iterations, qubits, boxes, samples, nodes, shots,
workers, trials): values just above the largest accepted one are refused before any allocation
(the traced peak stays under ``ALLOCATION_BYTES``), with a ``ValueError`` that names the argument.

The largest accepted value of each is its documented limit; a property test draws values from
just above it up to 2^62."""

from __future__ import annotations

import tracemalloc
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import qrrt_circuits as qc
from qrrt_circuits.coherent import FixedPointFormat, SampledMotion, coherent_phase_oracle
from qrrt_circuits.coherent.costs import scaling_instance
from qrrt_circuits.coherent.grover import coherent_grover_circuit
from qrrt_circuits.coherent.motion import MAX_TIME_SAMPLES
from qrrt_circuits.coherent.number_format import MAX_BITS
from qrrt_circuits.experiments.runner import MAX_TRIALS, run_experiment
from qrrt_circuits.planners.options import MAX_WORKERS
from qrrt_circuits.problems.families import maze
from qrrt_circuits.problems.scenarios import MAX_CORRIDOR_CLUTTER, MAX_WORLD_BOXES
from qrrt_circuits.search.oracles import CircuitOracle, LookupOracle
from qrrt_circuits.search.requests import MAX_ITERATIONS, MAX_SHOTS

#: a refusal may allocate its message and the checks' small objects, not the work it refuses
ALLOCATION_BYTES = 1 << 20

_ORACLE = LookupOracle(np.array([0, 1, 0, 0], dtype=bool))
_STATEVECTOR = qc.StatevectorBackend()


def _small_circuit_oracle() -> tuple[CircuitOracle, int]:
    """A 3-qubit circuit oracle of 203 gates (100 pairs of X that cancel) and the most iterations
    of it that fit ``MAX_GROVER_GATES`` (fewer than ``MAX_ITERATIONS``: the product binds)."""
    from qiskit import QuantumCircuit

    from qrrt_circuits.search.oracles import MAX_GROVER_GATES

    flip = QuantumCircuit(3)
    flip.x(1)
    flip.ccz(0, 1, 2)
    flip.x(1)
    for _ in range(100):
        flip.x(0)
        flip.x(0)
    oracle = CircuitOracle(flip, 3)
    assert MAX_GROVER_GATES // oracle.iteration_gates() < MAX_ITERATIONS
    return oracle, MAX_GROVER_GATES // oracle.iteration_gates()


_CIRCUIT_ORACLE, _MOST_CIRCUIT_ITERATIONS = _small_circuit_oracle()
_COHERENT_CIRCUIT = coherent_phase_oracle(*scaling_instance(4, 0, parent_bits=0, bits=4, time_samples=2))
_PROBLEM = qc.paper_clutter(0)

#: (what, the argument named, the largest accepted value, the call with a value)
SIZES: list[tuple[str, str, int, Callable[[int], Any]]] = [
    ("search iterations", "iterations", MAX_ITERATIONS,
     lambda k: _STATEVECTOR.search(_ORACLE, iterations=k, shots=1, seed=0)),
    ("search shots", "shots", MAX_SHOTS, lambda shots: _STATEVECTOR.search(_ORACLE, iterations=1, shots=shots, seed=0)),
    ("circuit oracle iterations", "iterations", _MOST_CIRCUIT_ITERATIONS,
     lambda k: _CIRCUIT_ORACLE.check_grover_size(k)),
    ("coherent Grover iterations", "iterations", 10_000,
     lambda k: coherent_grover_circuit(_COHERENT_CIRCUIT, 4, k)),
    ("database qubits", "num_qubits", int(_STATEVECTOR.max_qubits),
     lambda n: qc.QRRT(num_qubits=n, backend=_STATEVECTOR)),
    ("workers", "workers", MAX_WORKERS, lambda p: qc.PQRRT(workers=p)),
    ("world boxes", "num_boxes", MAX_WORLD_BOXES, lambda b: qc.paper_clutter(0, num_boxes=b)),
    ("annealing boxes", "num_boxes", MAX_WORLD_BOXES,
     lambda b: __import__("qrrt_circuits.problems.scenarios", fromlist=["x"]).annealing_field(0, num_boxes=b)),
    ("corridor clutter", "clutter", MAX_CORRIDOR_CLUTTER,
     lambda c: __import__("qrrt_circuits.problems.scenarios", fromlist=["x"]).narrow_corridor(0, clutter=c)),
    ("coherent scaling boxes", "boxes", 100_000, lambda b: scaling_instance(10, b)),
    ("motion time samples", "time_samples", MAX_TIME_SAMPLES, lambda k: SampledMotion.straight_line(2, k, 1)),
    ("fixed-point bits", "bits", MAX_BITS, lambda b: FixedPointFormat(b, 0.0, 16.0)),
    ("time-sampled check samples", "time_samples", 1_000_000,
     lambda k: qc.TimeSampledCheck(qc.paper_clutter(0).env, time_samples=k)),
    ("maze cells", "cells", 32, lambda c: maze(cells=c)),
    ("experiment trials", "trials", MAX_TRIALS, lambda t: run_experiment("heatmaps", out="/nonexistent", trials=t)),
]


def _refusal(call: Callable[[int], Any], value: int) -> tuple[BaseException | None, int]:
    """What ``call(value)`` raised (None if nothing) and the traced peak of allocations while it ran."""
    tracemalloc.start()
    try:
        call(value)
        error = None
    except (ValueError, TypeError) as exc:
        error = exc
    finally:
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    return error, peak


@pytest.mark.parametrize(("what", "name", "largest", "call"), SIZES, ids=[row[0] for row in SIZES])
@settings(max_examples=8, deadline=None)
@given(above=st.one_of(st.just(1), st.integers(min_value=1, max_value=2**62)))
def test_sizes_above_the_largest_accepted_are_refused_before_any_allocation(what, name, largest, call, above):
    error, peak = _refusal(call, largest + above)
    assert isinstance(error, ValueError), f"{what}: {largest + above} accepted"
    assert name in str(error), f"{what}: the message does not name {name}: {error}"
    assert peak < ALLOCATION_BYTES, f"{what}: {peak} bytes allocated before the refusal"


#: the cheap ones, whose largest accepted value is built to show that it is accepted
ACCEPTED = ["search iterations", "circuit oracle iterations", "database qubits", "workers", "motion time samples",
            "fixed-point bits"]


@pytest.mark.parametrize(("what", "name", "largest", "call"), [row for row in SIZES if row[0] in ACCEPTED],
                         ids=ACCEPTED)
def test_the_largest_value_is_accepted(what, name, largest, call):
    call(largest)


@pytest.mark.parametrize("planner", [qc.RRT(seed=0), qc.QRRT(num_qubits=6, seed=0, backend=_STATEVECTOR)],
                         ids=["RRT", "QRRT"])
@settings(max_examples=6, deadline=None)
@given(limit=st.integers(min_value=10**12, max_value=2**62))
def test_node_and_round_limits_beyond_memory_are_refused_before_the_plan_allocates(planner, limit):
    """max_nodes and max_rounds whose tree and history cannot fit: refused by the plan's memory
    check before the first round, naming the limit to lower."""
    error, peak = _refusal(lambda value: planner.plan(_PROBLEM, max_nodes=value, max_rounds=value), limit)
    assert isinstance(error, ValueError) and ("max_rounds" in str(error) or "max_nodes" in str(error)), error
    assert peak < ALLOCATION_BYTES, f"{peak} bytes allocated before the refusal"
