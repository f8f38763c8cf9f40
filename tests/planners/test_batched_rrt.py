"""RRT / ParallelRRT rounds tested ahead in batches are exactly the rounds tested one at a time.

The reference is the same planner with an executor: one task per worker per round, nothing tested
ahead (B = 1). Trees, counters, history and status must agree bit for bit; only ``wasted_checks``
(tests made ahead and dropped) differ. Every planner runs the one round loop of ``Planner._run``.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from planner_fingerprints import HISTORY_KEYS, METRIC_KEYS

import qrrt_circuits as qc
from qrrt_circuits._support.randomness import RandomStreams, Stream
from qrrt_circuits.planners.base import Planner
from qrrt_circuits.planners.classical import MAX_BATCH_ROUNDS, batch_rounds
from qrrt_circuits.planners.extension_samples import ExtensionSamples


def _sequential(planner, executor):
    planner.executor = executor
    return planner


def _same(batched, sequential):
    assert np.array_equal(batched.nodes, sequential.nodes)
    assert np.array_equal(batched.parents, sequential.parents)
    for key in METRIC_KEYS:
        assert batched.metrics[key] == sequential.metrics[key], key
    for key in HISTORY_KEYS:
        assert np.array_equal(batched.history[key], sequential.history[key]), key
    assert batched.status == sequential.status and batched.goal_node == sequential.goal_node
    assert sequential.metrics.wasted_checks == 0


@pytest.fixture(scope="module")
def executor():
    with ThreadPoolExecutor(2) as pool:
        yield pool


BUDGETS = ({"max_nodes": 40}, {"max_oracle_calls": 73}, {"max_rounds": 31}, {"stall_rounds": 3, "max_nodes": 60},
           {"max_critical_path_calls": 50, "max_nodes": 30})


@pytest.mark.parametrize("seed", range(24))
def test_batched_rrt_equals_sequential_rrt(seed, executor):
    env = qc.paper_clutter(seed=seed % 6)
    budgets = BUDGETS[seed % len(BUDGETS)]
    options = {"goal_bias": 0.15} if seed % 4 == 1 else {}
    if seed % 4 == 2:
        options["oracle_errors"] = qc.OracleErrorModel(false_positive=0.2, false_negative=0.1)
    batched = qc.RRT(seed=seed, **options).plan(env, **budgets)
    sequential = _sequential(qc.RRT(seed=seed, **options), executor).plan(env, **budgets)
    _same(batched, sequential)
    if "max_oracle_calls" in budgets and not batched.reached and not options:
        assert batched.metrics.oracle_calls == budgets["max_oracle_calls"]  # stops exactly there


@pytest.mark.parametrize("seed", range(8))
def test_batched_parallel_rrt_equals_sequential(seed, executor):
    env = qc.paper_clutter(seed=seed % 3)
    workers = (2, 3, 8)[seed % 3]
    budgets = BUDGETS[seed % len(BUDGETS)]
    options = {"oracle_errors": qc.OracleErrorModel(false_positive=0.1, false_negative=0.1)} if seed % 4 == 3 else {}
    batched = qc.ParallelRRT(workers=workers, seed=seed, **options).plan(env, **budgets)
    sequential = _sequential(qc.ParallelRRT(workers=workers, seed=seed, **options), executor).plan(env, **budgets)
    _same(batched, sequential)


def test_wasted_checks_are_the_tests_of_rounds_that_never_ran():
    env = qc.paper_clutter(seed=3)
    result = qc.RRT(seed=3).plan(env, max_nodes=50)
    metrics = result.metrics
    assert metrics.oracle_calls == metrics.rounds == metrics.verification_calls
    assert metrics.wasted_checks > 0
    predicate = qc.ExactCheck(env.env)  # counts every pair it evaluates
    again = qc.RRT(seed=3).plan(env.replace(predicate=predicate), max_nodes=50)
    assert predicate.evaluations == again.metrics.oracle_calls + again.metrics.wasted_checks
    assert again.metrics.wasted_checks == metrics.wasted_checks


def test_batch_size_follows_the_success_rate():
    assert batch_rounds(0, 0) == 2
    assert batch_rounds(9, 98) == 10
    assert batch_rounds(99, 98) == 1
    assert batch_rounds(0, 10**6) == MAX_BATCH_ROUNDS


@pytest.mark.parametrize("workers", [1, 4])
def test_without_look_ahead_the_predicate_is_asked_once_per_oracle_call(clutter, workers):
    """look_ahead=False: the same plan, no wasted checks, and the predicate sees exactly the
    counted oracle calls (for a user's expensive check)."""
    class Counting:
        dim, name = 2, "counting"

        def __init__(self):
            self.inner, self.pairs = qc.ExactCheck(clutter.env), 0

        def reachable(self, parents, children):
            self.pairs += len(np.atleast_2d(children))
            return self.inner.reachable(parents, children)

        def describe(self):
            return self.inner.describe()

    batched, single = Counting(), Counting()
    ahead = qc.ParallelRRT(workers=workers, seed=4).plan(clutter.replace(predicate=batched), max_nodes=20)
    once = qc.ParallelRRT(workers=workers, seed=4, look_ahead=False).plan(clutter.replace(predicate=single),
                                                                          max_nodes=20)
    assert np.array_equal(ahead.nodes, once.nodes) and ahead.metrics.oracle_calls == once.metrics.oracle_calls
    assert once.metrics.wasted_checks == 0 and single.pairs == once.metrics.oracle_calls
    assert batched.pairs == ahead.metrics.oracle_calls + ahead.metrics.wasted_checks > single.pairs
    with pytest.raises(TypeError, match="look_ahead"):
        qc.RRT(look_ahead="no")


def test_every_planner_runs_the_one_round_loop():
    for planner in (qc.RRT, qc.ParallelRRT, qc.QRRT, qc.PQRRT):
        assert planner._run is Planner._run, planner.__name__


@pytest.mark.parametrize("goal_bias", [0.0, 0.3])
def test_extension_samples_drawn_in_batches_are_those_drawn_one_by_one(clutter, goal_bias):
    """``ExtensionSamples.next`` (the classical planners' candidates): batches of any sizes give
    the samples drawn one at a time, the biased ones in the goal from the goal stream."""
    goal = qc.GoalBall(np.array([9.0, 9.0]), 1.5)
    batched = ExtensionSamples(RandomStreams.from_seed(12), clutter.env, goal, goal_bias)
    single = ExtensionSamples(RandomStreams.from_seed(12), clutter.env, goal, goal_bias)
    samples = np.concatenate([batched.next(size) for size in (1, 7, 0, 30, 2)])
    one_by_one = np.concatenate([single.next(1) for _ in range(40)])
    assert samples.shape == (40, 2) and np.array_equal(samples, one_by_one)
    in_goal = np.linalg.norm(samples - goal.centre, axis=1) <= 1.5
    points = RandomStreams.from_seed(12).sequence(Stream.EXTENSION_SAMPLES).random((40, 2 + (goal_bias > 0)))
    uniform = clutter.env.box_points(points[:, :2])
    biased = points[:, 2] < goal_bias if goal_bias else np.zeros(40, dtype=bool)
    assert np.array_equal(samples[~biased], uniform[~biased])  # (the unbiased ones: the stream's doubles)
    assert np.all(in_goal[biased]) and (biased.any() == bool(goal_bias))
    assert not np.array_equal(RandomStreams.from_seed(13).sequence(Stream.EXTENSION_SAMPLES).random(3), points[0, :3])


@pytest.mark.parametrize("family", ["se2-gap", "narrow-passage-4d", "open-space", "maze"])
def test_batched_rrt_equals_sequential_on_the_problem_families(family, executor):
    """Tests made ahead stay in use while no node added since is as near to their sample as their
    parent (SE(2)'s scan and the Euclidean grid): the same plan as testing each round on its own."""
    from qrrt_circuits.experiments.problems import build_problem

    problem = build_problem(family, 1)
    batched = qc.RRT(seed=5, goal_bias=0.05).plan(problem, max_oracle_calls=600)
    sequential = _sequential(qc.RRT(seed=5, goal_bias=0.05), executor).plan(problem, max_oracle_calls=600)
    _same(batched, sequential)
    assert batched.metrics.wasted_checks < batched.metrics.oracle_calls  # most tests made ahead were used


def test_rounds_ready_stop_where_a_check_before_each_round_would():
    from qrrt_circuits.planners.termination import MaxOracleCalls, MaxRounds, Progress, Stall, rounds_that_start

    now = Progress(10, 4, 3, 6, 2, 0.0)
    growth = Progress(3, 1, 0, 1, 1, 0.0)
    assert rounds_that_start(MaxOracleCalls(20), now, growth, 10) == 4  # rounds from 10, 13, 16, 19 calls
    assert rounds_that_start(MaxRounds(8) | Stall(100), now, growth, 10) == 2
    assert rounds_that_start(Stall(5), now, growth, 10) == 3
    assert rounds_that_start(MaxOracleCalls(10**6), now, growth, 7) == 7
