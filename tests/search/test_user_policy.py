"""A policy the library has never seen runs through the same round as the built-ins."""

import numpy as np
import pytest

import qrrt_circuits as qc
from qrrt_circuits.search.policies import PolicyState
from qrrt_circuits.search.problem import SearchOutcome


class TwoIterations(qc.IterationPolicy):
    """A user's policy: k = 2 on every database, written from scratch (no built-in subclassed)."""

    name = "user-two"

    def start(self, num_items):
        return TwoIterationsState(self, num_items)

    def describe(self):
        return "user: k = 2"

    def _iterations(self, num_items, tree_nodes, num_marked):
        return 2


class TwoIterationsState(PolicyState):
    def run(self, problem, workers, tree_nodes):
        measured = problem.search(2, workers, problem.shared_seed())
        return tuple(SearchOutcome(int(i) if problem.verify(int(i)) else None, 2, 1,
                                   ((2, problem.verify(int(i))),)) for i in measured)


@pytest.mark.parametrize("workers, shared", [(1, True), (4, True), (3, False)])
def test_a_users_policy_plans_as_the_builtin_with_the_same_behaviour(workers, shared):
    env = qc.paper_clutter(seed=2)
    plans = []
    for policy in (qc.FixedIterations(2), TwoIterations()):
        planner = qc.PQRRT(backend=qc.StatevectorBackend(), num_qubits=6, workers=workers,
                           shared_database=shared, search_policy=policy, seed=5)
        plans.append(planner.plan(env, max_nodes=30))
    builtin, user = plans
    assert np.array_equal(builtin.nodes, user.nodes) and np.array_equal(builtin.parents, user.parents)
    assert builtin.metrics.oracle_calls == user.metrics.oracle_calls
    assert builtin.metrics.critical_path_oracle_calls == user.metrics.critical_path_oracle_calls
    assert builtin.metrics.nodes >= 1
