"""q-RRT-Connect: the connection search against Lemma 1 on both backends, success over seeded
worlds with an oracle-call budget, every edge of both trees re-checked, the counters of DESIGN §2,
the registry and the command line."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from conftest import BACKENDS, make_backend
from planner_checks import assert_path_valid, assert_tree_edges_valid
from reference import dense_trajectory, penetration_and_clearance
from tolerances import within_binomial

import qrrt_circuits as qc
from qrrt_circuits._support.randomness import RandomStreams
from qrrt_circuits.planners.connect import QRRTConnect, connection_search
from qrrt_circuits.planners.context import WorkerContext
from qrrt_circuits.planners.extension import GrowingTree
from qrrt_circuits.planners.tree import Tree
from qrrt_circuits.probability import success_probability


class Hop:
    """A motion is free when it is at most ``reach`` long (a user predicate)."""

    dim = 2
    name = "hop"

    def __init__(self, reach: float) -> None:
        self.reach = reach

    def reachable(self, parents, children):
        return np.linalg.norm(children - parents, axis=1) <= self.reach

    def describe(self):
        return {"reach": self.reach}


def _trees(backend, connecting: int, candidates: int):
    """A grower with one node at the origin and another tree of ``candidates`` nodes on rings, the
    ``connecting`` nearest within reach 1."""
    env = qc.Environment([[-10, 10], [-10, 10]], [])
    space = qc.RealVectorSpace(2)
    context = WorkerContext(env, Hop(1.0), space, RandomStreams(0), backend=backend, database_size=candidates)
    angles = np.linspace(0.0, 2 * np.pi, candidates, endpoint=False)
    offsets = 0.01 * np.arange(candidates)
    radii = np.where(np.arange(candidates) < connecting, 0.5 + offsets, 3.0 + offsets)
    other_tree = Tree(np.array([9.0, 9.0]))
    other_tree.add_many(np.column_stack([radii * np.cos(angles), radii * np.sin(angles)]),
                        np.zeros(candidates, dtype=np.int64))
    grower = GrowingTree(Tree(np.zeros(2)), None, context, None, None, None)  # (the search reads trees only)
    other = GrowingTree(other_tree, None, context, None, None, None)
    return grower, other


@pytest.mark.parametrize("backend_name", BACKENDS)
@pytest.mark.parametrize(("connecting", "iterations"), [(1, 2), (3, 1), (5, 2)])
def test_connection_search_hits_at_lemma_1_rate(backend_name, connecting, iterations):
    """A connection database of N = 16 candidates (the other tree's 16 nearest of 17), m of them
    connecting: a search of k iterations connects with probability sin^2((2k+1) theta), sin^2 theta
    = m / N (Lemma 1), for k + 1 oracle calls."""
    size, trials = 16, 300
    backend = make_backend(backend_name, 0)
    grower, other = _trees(backend, connecting, size)
    state = qc.FixedIterations(iterations).start(size)
    hits = 0
    for trial in range(trials):
        found = connection_search(grower, other, 0, size, state, round_index=trial)
        assert int(np.count_nonzero(found.truth)) == connecting and found.truth.shape == (size,)
        assert found.outcome.quantum_calls == iterations and found.outcome.verifications == 1
        if found.connected is not None:
            hits += 1
            assert np.linalg.norm(other.tree.nodes[found.connected]) <= 1.0
    p = success_probability(size, connecting, iterations)
    assert within_binomial(hits, trials, p), (hits, trials, p)


def test_connection_database_is_padded_with_unmarked_entries():
    grower, other = _trees(make_backend("statevector", 0), 2, 5)  # 6 nodes: padded to 8
    found = connection_search(grower, other, 0, 16, qc.FixedIterations(1).start(8), round_index=0)
    assert found.truth.shape == (8,) and not found.truth[6:].any() and found.rows.shape == (6,)


def _recheck(env, dynamics, starts, ends):
    for start, end in zip(starts, ends, strict=True):
        points = dense_trajectory(dynamics.A, dynamics.B, dynamics.K, start, end, dynamics.horizon, spacing=0.004)
        depth, _ = penetration_and_clearance(points, env.bounds, env.boxes)
        assert depth <= 0.01


SEEDS = range(10)


def test_success_over_seeded_worlds_with_every_edge_rechecked():
    """OMPL's test style: in 10 seeded clutter worlds with 5000 oracle calls each, q-RRT-Connect
    (n = 6, the statevector) solves at least 9; every edge of the start tree (with the grafted
    path) and of the goal tree (child -> parent) passes the dense reference check."""
    dynamics = qc.LinearTrackingDynamics.paper()
    reached = 0
    for seed in SEEDS:
        problem = qc.paper_clutter(seed=seed)
        result = QRRTConnect(backend=qc.StatevectorBackend(seed=seed), num_qubits=6, seed=seed).plan(
            problem, max_oracle_calls=5000)
        reached += result.reached
        assert_path_valid(result)
        assert_tree_edges_valid(problem.env, dynamics, result)
        nodes, parents = result.second_tree
        assert parents[0] == -1 and np.all(parents[1:] < np.arange(1, len(parents)))
        assert problem.goal.is_satisfied(nodes[:1])[0]
        _recheck(problem.env, dynamics, nodes[1:], nodes[parents[1:]])
        m = result.metrics
        assert m.oracle_calls == m.quantum_oracle_calls + m.verification_calls == result.history["oracle_calls"][-1]
        assert m.critical_path_oracle_calls == m.oracle_calls  # one worker: every call is on the path
        if result.reached:
            assert result.status == "reached" and result.path is not None
    assert reached >= 9, f"q-RRT-Connect reached the goal in {reached}/10 worlds"


@pytest.mark.parametrize("backend_name", BACKENDS)
def test_it_plans_on_both_backends_with_labels(backend_name, clutter):
    result = QRRTConnect(backend=make_backend(backend_name, 1), num_qubits=5, seed=3).plan(clutter,
                                                                                         max_oracle_calls=3000)
    assert result.reached
    assert any("connection oracle" in label for label in result.labels)
    assert result.settings["connect_qubits"] == 5 and result.planner == "QRRTConnect"
    assert "second_tree" in result.to_dict()


def test_bad_options_are_refused_by_name():
    with pytest.raises(ValueError, match="connect_qubits must be"):
        QRRTConnect(connect_qubits=0)
    with pytest.raises(TypeError, match="QRRTConnect does not take workers"):
        QRRTConnect(workers=2)


def test_registry_and_command_line():
    assert qc.registry.PLANNERS.resolve("qrrt-connect").options() >= {"connect_qubits", "num_qubits", "backend"}
    run = subprocess.run([sys.executable, "-m", "qrrt_circuits.cli", "plan", "--planner", "qrrt-connect",
                          "--backend", "statevector", "--qubits", "5", "--connect-qubits", "4",
                          "--max-oracle-calls", "3000"], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert "QRRTConnect on paper_clutter" in run.stdout and "connect_qubits" in run.stdout
