"""OMPL-style success rates: each planner, 20 seeded worlds of paper_clutter, a node budget (never
a time budget). Every edge of every tree is re-checked exactly."""

import pytest
from planner_checks import assert_path_valid, assert_tree_edges_valid

import qrrt_circuits as qc

SEEDS = range(20)
NODE_BUDGET = 3000
GOAL_BIAS = 0.05  # the same for every planner: 5% of samples drawn in the goal ball


def make(name, env, seed):
    backend = qc.StatevectorBackend()
    common = {"seed": seed, "goal_bias": GOAL_BIAS}
    return {
        "RRT": lambda: qc.RRT(**common),
        "ParallelRRT": lambda: qc.ParallelRRT(workers=8, **common),
        "QRRT": lambda: qc.QRRT(backend=backend, **common),
        "PQRRT": lambda: qc.PQRRT(backend=backend, workers=8, **common),
        "PQRRT-unshared": lambda: qc.PQRRT(backend=backend, workers=8, shared_database=False,
                                           **common),
    }[name]()


@pytest.mark.slow
@pytest.mark.parametrize("name", ["RRT", "ParallelRRT", "QRRT", "PQRRT", "PQRRT-unshared"])
def test_reaches_goal_in_95_percent_of_seeds(name):
    dynamics = qc.LinearTrackingDynamics.paper()
    reached = 0
    for seed in SEEDS:
        env = qc.paper_clutter(seed=seed)
        result = make(name, env, seed).plan(env, max_nodes=NODE_BUDGET)
        reached += result.status == "reached"
        assert_path_valid(result)
        assert_tree_edges_valid(env.env, dynamics, result)
    assert reached >= 0.95 * len(SEEDS), f"{name} reached the goal in {reached}/20 worlds"
