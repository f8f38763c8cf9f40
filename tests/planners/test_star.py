"""q-RRT*: after every round (every rewire) each node's cost is the sum of its edges' lengths to the
root and the tree has no cycle; every edge re-checked; success over seeded worlds with an
oracle-call budget; the best path's cost never rises; the counters of DESIGN §2; registry and
command line."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from conftest import BACKENDS, make_backend
from reference import dense_trajectory, penetration_and_clearance

import qrrt_circuits as qc
from qrrt_circuits.planners.star import QRRTStar, near_count
from qrrt_circuits.problems.families import open_space, straight_line_dynamics


def _root_paths(parents):
    """Each node's chain to the root, failing on a cycle."""
    chains = []
    for node in range(len(parents)):
        chain, seen = [node], {node}
        while parents[chain[-1]] >= 0:
            chain.append(int(parents[chain[-1]]))
            assert chain[-1] not in seen, f"cycle through node {chain[-1]}"
            seen.add(chain[-1])
        chains.append(chain)
    return chains


class CheckedStar(QRRTStar):
    """q-RRT* that checks its invariants after every round: costs are sums along the edges to the
    root, the parents form a tree rooted at 0 (no cycle)."""

    checked_rounds = 0

    def _round(self, state):
        super()._round(state)
        tree, costs = state.tree, np.asarray(state.extra.costs)
        assert costs.shape == (tree.size,)
        steps = np.zeros(tree.size)
        steps[1:] = np.linalg.norm(tree.nodes[1:] - tree.nodes[tree.parents[1:]], axis=1)
        for node, chain in enumerate(_root_paths(tree.parents)):
            assert chain[-1] == 0
            assert abs(costs[node] - steps[chain].sum()) <= 1e-9 * (1 + costs[node])
        type(self).checked_rounds += 1


def _recheck_edges(problem, result):
    dynamics = qc.LinearTrackingDynamics.paper()
    env = problem.env
    for child in range(1, len(result.nodes)):
        parent = result.parents[child]
        points = dense_trajectory(dynamics.A, dynamics.B, dynamics.K, result.nodes[parent], result.nodes[child],
                                  dynamics.horizon, spacing=0.004)
        depth, _ = penetration_and_clearance(points, env.bounds, env.boxes)
        assert depth <= 0.01, f"edge {parent} -> {child} penetrates by {depth}"


def test_costs_are_edge_sums_after_every_rewire_and_no_cycle(clutter):
    CheckedStar.checked_rounds = 0
    result = CheckedStar(backend=qc.StatevectorBackend(seed=0), num_qubits=5, seed=0, goal_bias=0.05).plan(
        clutter, max_oracle_calls=2500)
    assert CheckedStar.checked_rounds == result.metrics.rounds > 50
    assert (result.parents[1:] > np.arange(1, len(result.parents))).any()  # some node was rewired
    _recheck_edges(clutter, result)


SEEDS = range(10)


def test_success_over_seeds_and_the_anytime_cost():
    """OMPL's test style on a small problem (``open-space``: one box in [0, 10]^2): with 1500 oracle
    calls per plan, q-RRT* (n = 6, the statevector, goal bias 0.05) holds a path for at least 9 of 10
    seeds; the best path's cost never rises from round to round and is the length of the returned
    path; every edge passes an independent check.

    Rewiring shortens the path: on each seed both planners solve, q-RRT*'s path is shorter than
    q-RRT's (the same seed, options and budget, no choose-parent or rewire). A sign test: were
    rewiring no better, each such pair would go either way with probability 1/2, and at least 9
    pairs all going q-RRT*'s way would have probability at most 2^-9 (about 0.002)."""
    problem = open_space()
    recheck = qc.ExactCheck(problem.env, straight_line_dynamics(2), resolution=0.005)
    reached = paired = 0
    for seed in SEEDS:
        options = {"num_qubits": 6, "seed": seed, "goal_bias": 0.05}
        result = QRRTStar(backend=qc.StatevectorBackend(seed=seed), **options).plan(problem, max_oracle_calls=1500)
        plain = qc.QRRT(backend=qc.StatevectorBackend(seed=seed), **options).plan(problem, max_oracle_calls=1500)
        reached += result.reached
        costs = result.history["path_cost"]
        assert costs.shape == result.history["oracle_calls"].shape
        finite = costs[np.isfinite(costs)]
        assert np.all(np.diff(finite) <= 1e-9)
        m = result.metrics
        assert m.oracle_calls == m.quantum_oracle_calls + m.verification_calls
        assert recheck.reachable(result.nodes[result.parents[1:]], result.nodes[1:]).all()
        if result.reached:
            chain = _root_paths(result.parents)[result.goal_node][::-1]
            assert np.array_equal(result.path, result.nodes[chain])
            assert problem.goal.is_satisfied(result.path[-1:])[0]
            length = float(np.linalg.norm(np.diff(result.path, axis=0), axis=1).sum())
            assert abs(length - finite[-1]) <= 1e-9 * length
            if plain.reached:
                paired += 1
                plain_length = float(np.linalg.norm(np.diff(plain.path, axis=0), axis=1).sum())
                assert length < plain_length, f"seed {seed}: q-RRT* {length} against q-RRT {plain_length}"
        else:
            assert result.status == "max_oracle_calls" and result.path is None
    assert reached >= 9, f"q-RRT* reached the goal for {reached}/10 seeds"
    assert paired >= 9, f"q-RRT* and q-RRT both reached the goal for {paired}/10 seeds"


@pytest.mark.parametrize("backend_name", BACKENDS)
def test_it_plans_on_both_backends_with_labels(backend_name, clutter):
    result = QRRTStar(backend=make_backend(backend_name, 2), num_qubits=4, seed=1).plan(clutter, max_oracle_calls=600)
    assert any("choose-parent and rewire oracles" in label for label in result.labels)
    assert result.settings["minimum_finding"]["kind"] == "durr-hoyer" and result.planner == "QRRTStar"
    assert result.metrics.databases > result.metrics.rounds  # extension, choose-parent and rewire databases


def test_near_count_is_ompls_k_nearest_rule():
    assert near_count(1.1, 2, 0) == 1
    assert near_count(1.1, 2, 100) == int(np.ceil(1.1 * np.e * 1.5 * np.log(101)))


def test_bad_options_are_refused_by_name():
    with pytest.raises(ValueError, match=r"rewire_factor must be a finite number in \[1.0, 10.0\]"):
        QRRTStar(rewire_factor=0.5)
    with pytest.raises(TypeError, match="QRRTStar does not take connect_qubits"):
        QRRTStar(connect_qubits=3)


def test_registry_and_command_line():
    assert "rewire_factor" in qc.registry.PLANNERS.resolve("qrrt-star").options()
    run = subprocess.run([sys.executable, "-m", "qrrt_circuits.cli", "plan", "--planner", "qrrt-star",
                          "--backend", "statevector", "--qubits", "4", "--rewire-factor", "1.5",
                          "--max-oracle-calls", "400"], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert "QRRTStar on paper_clutter" in run.stdout and "rewire_factor" in run.stdout
