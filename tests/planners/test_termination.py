"""Termination conditions alone and combined, on planners and on progress snapshots; the status
names the condition that ended the plan."""

import dataclasses
import math

import numpy as np
import pytest
from planner_checks import posed

import qrrt_circuits as qc
from qrrt_circuits._support import available_memory as probe
from qrrt_circuits.planners.termination import (
    DEFAULT_MAX_NODES,
    Progress,
    from_budgets,
    with_defaults,
    with_round_limit,
)
from qrrt_circuits.world.environment import Environment

WALLED_GOAL = np.array([[[14, 14], [18, 14.5]], [[14, 17.5], [18, 18]], [[14, 14], [14.5, 18]],
                        [[17.5, 14], [18, 18]]], dtype=float)


@pytest.fixture(scope="module")
def walled():
    """The goal (16, 16) is walled in: no plan reaches it, so only a condition ends a plan."""
    return Environment(np.array([[0, 20], [0, 20]]), WALLED_GOAL)


@pytest.fixture(scope="module")
def boxed_in():
    """The start (5, 5) sits in a 0.02-wide pocket inside a 2 x 2 block: no trajectory leaves it."""
    gap = 0.01
    boxes = [[[4, 4], [6, 5 - gap]], [[4, 5 + gap], [6, 6]], [[4, 5 - gap], [5 - gap, 5 + gap]],
             [[5 + gap, 5 - gap], [6, 5 + gap]]]
    return Environment(np.array([[0, 20], [0, 20]]), np.array(boxes, dtype=float))


def _walled_from(walled, start):
    """The walled world's problem from ``start`` toward the walled-in goal (16, 16)."""
    return posed(walled, start=start, goal=[16, 16], goal_radius=0.5)


def _boxed(boxed_in):
    """The boxed-in world's problem from (5, 5), inside the pocket."""
    return posed(boxed_in, start=[5, 5], goal=[15, 15], goal_radius=0.5)


def _applicable(name, options):
    """The options the registry's planner ``name`` takes."""
    from qrrt_circuits.registry import PLANNERS

    takes = PLANNERS.resolve(name).options()
    return {key: value for key, value in options.items() if key in takes}


def progress(**values):
    base = {"oracle_calls": 0, "critical_path_oracle_calls": 0, "nodes": 0, "rounds": 0,
            "rounds_without_new_node": 0, "elapsed_s": 0.0}
    return Progress(**(base | values))


@pytest.mark.parametrize("condition, field, status", [
    (qc.MaxOracleCalls(10), "oracle_calls", "max_oracle_calls"),
    (qc.MaxCriticalPathCalls(10), "critical_path_oracle_calls", "max_critical_path_calls"),
    (qc.MaxNodes(10), "nodes", "max_nodes"),
    (qc.MaxRounds(10), "rounds", "max_rounds"),
    (qc.Stall(10), "rounds_without_new_node", "stalled"),
])
def test_each_limit_fires_exactly_at_its_limit(condition, field, status):
    assert condition.ended_by(progress(**{field: 9})) is None
    assert condition.ended_by(progress(**{field: 10})) == status
    assert condition.ended_by(progress(**{field: 11})) == status


def test_wall_time_condition_on_progress_and_on_a_plan(walled):
    condition = qc.MaxWallTime(0.5)
    assert condition.ended_by(progress(elapsed_s=0.49)) is None
    assert condition.ended_by(progress(elapsed_s=0.5)) == "max_time_s"
    # a limit far below one round's time ends the plan before its first round
    result = qc.RRT(seed=0).plan(_walled_from(walled, [1, 1]), max_time_s=1e-12)
    assert result.status == "max_time_s" and result.metrics.rounds == 0


def test_combined_conditions_name_the_first_that_fires():
    combined = qc.MaxNodes(5) | qc.MaxRounds(7) | qc.Stall(3)
    assert isinstance(combined, qc.AnyOf) and len(combined.conditions) == 3  # flattened
    assert combined.ended_by(progress(nodes=4, rounds=6, rounds_without_new_node=2)) is None
    assert combined.ended_by(progress(nodes=5, rounds=7)) == "max_nodes"  # order decides ties
    assert combined.ended_by(progress(nodes=1, rounds=7)) == "max_rounds"
    assert combined.ended_by(progress(rounds_without_new_node=3)) == "stalled"
    assert combined.describe() == {"max_nodes": 5, "max_rounds": 7, "stall_rounds": 3}
    assert combined.limits_rounds and not (qc.MaxNodes(5) | qc.Stall(3)).limits_rounds


@pytest.mark.parametrize("budget", [400, 401])
def test_oracle_call_budget_on_a_plan(budget, walled):
    for planner in (qc.RRT(seed=0), qc.QRRT(backend=qc.StatevectorBackend(0), seed=0,
                                                     search_policy=qc.FixedIterations(2))):
        result = planner.plan(_walled_from(walled, [2, 2]), max_oracle_calls=budget)
        calls = result.history["oracle_calls"]
        assert result.status == "max_oracle_calls"
        # the plan stops after the first round that reaches the budget, and not before
        assert calls[-1] >= budget and (len(calls) == 1 or calls[-2] < budget)


def test_critical_path_budget_stops_parallel_workers_on_their_own_time(walled):
    """Pq-RRT with p = 8 workers and k = 2: each round costs 8 x 3 calls but 3 on the critical path,
    so a critical-path budget of 40 ends the plan after ceil(40 / 3) = 14 rounds."""
    k, p, budget = 2, 8, 40
    result = qc.PQRRT(backend=qc.StatevectorBackend(0), workers=p, search_policy=qc.FixedIterations(k),
                      seed=1).plan(_walled_from(walled, [2, 2]), max_critical_path_calls=budget)
    rounds = math.ceil(budget / (k + 1))
    assert result.status == "max_critical_path_calls"
    assert result.metrics.rounds == rounds
    assert result.metrics.critical_path_oracle_calls == rounds * (k + 1)
    assert result.metrics.oracle_calls == rounds * p * (k + 1)


def test_max_nodes_and_rounds_on_a_plan(clutter):
    result = qc.ParallelRRT(workers=4, seed=3).plan(clutter, max_nodes=12)
    assert result.status == "max_nodes" and 12 <= result.metrics.nodes < 12 + 4
    assert result.history["nodes"][-2] < 12
    result = qc.RRT(seed=3).plan(clutter, max_rounds=25)
    assert result.status == "max_rounds" and result.metrics.rounds == 25


@pytest.mark.parametrize("planner_name", ["rrt", "prrt", "qrrt", "pqrrt", "pqrrt-unshared"])
def test_stall_ends_a_plan_that_cannot_add_nodes(planner_name, boxed_in):
    from qrrt_circuits.registry import PLANNERS

    options = {"seed": 0, "workers": 3, "num_qubits": 5, "backend": qc.StatevectorBackend(0)}
    planner = PLANNERS.create(planner_name, **_applicable(planner_name, options))
    result = planner.plan(_boxed(boxed_in), stall_rounds=9, max_nodes=50)
    assert result.status == qc.PlanStatus.STALLED
    assert result.metrics.nodes == 0 and result.metrics.rounds == 9


def test_stall_counts_consecutive_rounds_only(clutter):
    """Stall counts rounds since the last new node, not all empty rounds."""
    result = qc.RRT(seed=5).plan(clutter, max_nodes=30, stall_rounds=10_000)
    empty = int(np.sum(np.diff(np.concatenate([[0], result.history["nodes"]])) == 0))
    assert result.status == "max_nodes" and empty > 10  # many empty rounds, never 10 000 in a row


def test_termination_argument_combines_with_the_shorthands(walled):
    result = qc.RRT(seed=0).plan(_walled_from(walled, [1, 1]), termination=qc.MaxRounds(30), max_oracle_calls=12)
    assert result.status == "max_oracle_calls" and result.metrics.rounds == 12
    assert result.settings["termination"] == {"max_rounds": 30, "max_oracle_calls": 12,
                                              "max_nodes": DEFAULT_MAX_NODES}  # budgets: no stall limit
    assert not result.safety_limit and "ended by a limit you set" in result.status_text
    with pytest.raises(TypeError, match="termination must be a TerminationCondition"):
        qc.RRT().plan(_walled_from(walled, [1, 1]), termination=30)


def test_a_round_limit_is_always_in_force():
    from qrrt_circuits.planners import termination

    assert with_round_limit(None) == qc.MaxRounds(termination.DEFAULT_MAX_ROUNDS)
    nodes_only = with_round_limit(qc.MaxNodes(5))
    assert nodes_only.describe() == {"max_nodes": 5, "max_rounds": termination.DEFAULT_MAX_ROUNDS}
    assert with_round_limit(qc.MaxRounds(3)) == qc.MaxRounds(3)
    assert from_budgets() is None


def test_start_inside_the_goal_ball_is_reached_at_once(clutter):
    start = clutter.start
    result = qc.RRT(seed=0).plan(posed(clutter, start=start, goal=start, goal_radius=0.5), max_rounds=10)
    assert result.status == "reached" and result.metrics.rounds == 0 and result.goal_node == 0
    assert np.array_equal(result.path, start[None])


@pytest.mark.parametrize("kwargs, error, message", [
    ({"max_nodes": 0}, ValueError, r"max_nodes must be an integer >= 1, got 0"),
    ({"max_rounds": 2.5}, TypeError, r"max_rounds must be an integer >= 1, got 2.5"),
    ({"max_critical_path_calls": -1}, ValueError, "max_critical_path_calls must be an integer >= 1"),
    ({"stall_rounds": 0}, ValueError, "stall_rounds must be an integer >= 1"),
    ({"max_time_s": float("nan")}, ValueError, "max_time_s must be a finite number > 0"),
    ({"max_time_s": True}, TypeError, "max_time_s must be a real number"),
])
def test_bad_limits_are_refused_before_any_work(kwargs, error, message, clutter):
    problem = clutter.replace(predicate=qc.ExactCheck(clutter.env))
    with pytest.raises(error, match=message):
        qc.RRT(seed=0).plan(problem, **kwargs)
    assert problem.predicate.evaluations == 0


def test_default_stall_ends_a_plan_given_only_a_node_budget(monkeypatch, boxed_in):
    """A plan with only max_nodes that can add no node ends as "stalled" after the default stall
    limit (0.1 looped forever here)."""
    from qrrt_circuits.planners import termination

    monkeypatch.setattr(termination, "DEFAULT_STALL_ROUNDS", 25)
    result = qc.RRT(seed=0).plan(_boxed(boxed_in), max_nodes=5)
    assert result.status == "stalled" and result.metrics.rounds == 25
    assert result.to_dict()["safety_limit"] is True
    assert with_defaults(qc.Stall(3)) == (qc.Stall(3) | qc.MaxRounds(termination.DEFAULT_MAX_ROUNDS)
                                          | qc.MaxNodes(termination.DEFAULT_MAX_NODES))
    assert result.safety_limit and "safety limit" in result.status_text and "stall_rounds=25" in result.status_text
    # a budget ends the plan itself: no stall limit beside it
    assert with_defaults(qc.MaxRounds(3)) == qc.MaxRounds(3) | qc.MaxNodes(termination.DEFAULT_MAX_NODES)
    complete = qc.MaxRounds(3) | qc.MaxNodes(4) | qc.Stall(2)
    assert with_defaults(complete) == complete


def _tiled(cells: int = 317, gap: float = 0.004) -> tuple[Environment, np.ndarray, np.ndarray]:
    """A 20 x 20 world tiled by cells^2 (about 10^5) boxes with gaps of ``gap`` between them: every
    motion is rejected (the gaps are narrower than the check's margin). Start and goal sit on gap
    crossings, so both are free."""
    pitch = 20.0 / cells
    index = np.arange(cells)
    x, y = (a.ravel() for a in np.meshgrid(index, index, indexing="ij"))
    lower = np.stack([x * pitch + gap / 2, y * pitch + gap / 2], axis=1)
    upper = np.stack([(x + 1) * pitch - gap / 2, (y + 1) * pitch - gap / 2], axis=1)
    env = Environment(np.array([[0.0, 20.0], [0.0, 20.0]]), np.stack([lower, upper], axis=1))
    return env, np.array([100 * pitch, 100 * pitch]), np.array([250 * pitch, 250 * pitch])


@pytest.mark.parametrize("planner_name", ["rrt", "prrt", "qrrt", "pqrrt-unshared"])
def test_a_world_of_1e5_boxes_where_nothing_can_be_added_stalls(planner_name):
    from qrrt_circuits.registry import PLANNERS

    env, start, goal = _tiled()
    assert env.num_boxes > 100_000 and env.is_free(start) and env.is_free(goal)
    options = {"seed": 0, "workers": 2, "num_qubits": 4, "backend": qc.StatevectorBackend(0)}
    planner = PLANNERS.create(planner_name, **_applicable(planner_name, options))
    result = planner.plan(posed(env, start=start, goal=goal, goal_radius=0.5), max_nodes=3, stall_rounds=4)
    assert result.status == "stalled" and result.metrics.nodes == 0 and result.metrics.rounds == 4


def test_grid_index_of_1e5_boxes_lists_every_box_it_overlaps():
    """The vectorized index build: every box appears in exactly the cells it overlaps."""
    env, _, _ = _tiled(60)
    index = env.grid_index
    counts = np.bincount(index.cell_items, minlength=env.num_boxes)
    lo = np.floor((env.boxes[:, 0] - index.origin) / index.cell_size).clip(0, index.shape - 1)
    hi = np.floor((env.boxes[:, 1] - index.origin) / index.cell_size).clip(0, index.shape - 1)
    assert np.array_equal(counts, np.prod(hi - lo + 1, axis=1).astype(int))
    probes = np.random.default_rng(0).uniform(0, 20, (2000, 2))
    inside = np.any(np.all((probes[:, None] >= env.boxes[None, :, 0]) & (probes[:, None] <= env.boxes[None, :, 1]),
                           axis=2), axis=1)
    assert np.array_equal(env.is_free(probes), ~inside)


@pytest.mark.parametrize("planner_name", ["rrt", "prrt", "qrrt", "pqrrt"])
@pytest.mark.parametrize("start", [[0.0, 5.0], [20.0, 7.5], [3.0, 0.0], [0.0, 20.0]])
def test_a_start_on_the_boundary_is_refused_before_any_work(planner_name, start, walled):
    """The exact check rejects every motion from a point on the workspace boundary (issue 10,
    defect 1: the plan looped until the stall limit)."""
    from qrrt_circuits.registry import PLANNERS

    options = {"seed": 0, "workers": 2, "num_qubits": 4, "backend": qc.StatevectorBackend(0)}
    planner = PLANNERS.create(planner_name, **_applicable(planner_name, options))
    with pytest.raises(ValueError, match=r"start \[.*\] lies on the workspace boundary .*rejects every motion"):
        planner.plan(posed(walled, start=start, goal=[10, 10], goal_radius=0.5), max_nodes=5)


def test_boundary_refusal_follows_the_predicate_and_the_goal():
    env = qc.paper_clutter(seed=0)
    with pytest.raises(ValueError, match=r"start \[0.0, 5.0\] lies on the workspace boundary"):
        qc.RRT(seed=0).plan(posed(env, start=[0.0, 5.0]), max_nodes=5)  # the reproduction
    # the time-sampled check tests points only: a boundary start can leave it, so it is not refused
    sampled = posed(env, start=[0.0, 5.0], predicate=qc.TimeSampledCheck(env.env))
    assert qc.RRT(seed=0).plan(sampled, max_nodes=2).status == "max_nodes"
    # a boundary start inside the goal ball is reached at once, not refused
    assert qc.RRT(seed=0).plan(posed(env, start=[0.0, 5.0], goal=[0.2, 5.0], goal_radius=0.5)).status == "reached"
    with pytest.raises(ValueError, match=r"start \[2.0, 5.0\] is in collision with an obstacle"):
        qc.RRT(seed=0).plan(posed(env, start=[2.0, 5.0]), max_nodes=5)


@pytest.mark.parametrize("planner_name", ["rrt", "qrrt"])
def test_a_start_just_inside_the_boundary_margin_ends_stalled(planner_name, walled):
    """Off the boundary but inside its margin, leaving is possible in principle (a close enough
    child passes) but not decidable: the stall limit ends the plan."""
    from qrrt_circuits.registry import PLANNERS

    options = {"seed": 0, "num_qubits": 4, "backend": qc.StatevectorBackend(0)}
    planner = PLANNERS.create(planner_name, **_applicable(planner_name, options))
    result = planner.plan(posed(walled, start=[1e-7, 5.0], goal=[10, 10], goal_radius=0.5), max_nodes=5,
                          stall_rounds=20)
    assert result.status == "stalled" and result.metrics.nodes == 0


def test_a_node_limit_is_always_in_force(walled, monkeypatch):
    """Without a node limit of the caller's, DEFAULT_MAX_NODES ends a plan that keeps growing (8
    workers fill the world outside the walled goal): the status says max_nodes and the tree
    overshoots by fewer than p nodes; a caller's own node limit replaces the default."""
    from qrrt_circuits.planners import termination

    monkeypatch.setattr(termination, "DEFAULT_MAX_NODES", 40)
    result = qc.ParallelRRT(workers=8, seed=0).plan(_walled_from(walled, [1, 1]))
    assert result.status == "max_nodes" and 40 <= result.metrics.nodes < 40 + 8
    assert result.settings["termination"]["max_nodes"] == 40
    own = qc.ParallelRRT(workers=8, seed=0).plan(_walled_from(walled, [1, 1]), max_nodes=60)
    assert own.status == "max_nodes" and 60 <= own.metrics.nodes < 68
    assert own.settings["termination"]["max_nodes"] == 60


def test_node_and_round_limits_of_composed_conditions():
    condition = qc.MaxNodes(50) | qc.MaxRounds(100) | qc.MaxNodes(20) | qc.Stall(5)
    assert condition.node_limit == 20 and condition.round_limit == 100
    assert qc.Stall(5).node_limit is None and qc.Stall(5).round_limit is None
    assert (qc.MaxOracleCalls(5) | qc.Stall(3)).node_limit is None
    defaults = with_defaults(None)
    assert defaults.node_limit == DEFAULT_MAX_NODES and defaults.round_limit == 20000
    assert with_defaults(qc.MaxNodes(7)).node_limit == 7


def test_limits_whose_tree_or_history_exceed_memory_are_refused_before_any_work(walled, monkeypatch):
    """A round limit of 10^9 would let a plan that cannot grow keep about 240 GiB of round history
    (RRT's rounds take microseconds, so it would get there); a node limit of 10^9 the same of tree.
    Both are refused before the first round, naming the limit and the largest value that fits."""

    monkeypatch.setattr(probe, "available_memory", lambda: (1 << 30, probe.MACHINE_SOURCE))
    planner = qc.RRT(seed=0)
    with pytest.raises(ValueError, match=r"max_rounds = 1000000000: .* the largest max_rounds that fits is about"):
        planner.plan(_walled_from(walled, [1, 1]), max_rounds=10**9,
                     stall_rounds=10**9)
    with pytest.raises(ValueError, match=r"max_nodes = 1000000000: .* the largest max_nodes that fits is about"):
        qc.ParallelRRT(workers=4096, seed=0).plan(_walled_from(walled, [1, 1]), max_nodes=10**9)
    assert planner.plan(_walled_from(walled, [1, 1]), max_rounds=50,
                        stall_rounds=50).metrics.rounds == 50


@pytest.mark.parametrize("dim", [2, 4])
def test_check_plan_fits_names_the_largest_limit_that_fits(dim):
    """The largest value the message names fits, and one more than it does not."""
    import re

    from qrrt_circuits._support.memory import check_plan_fits, plan_bytes

    available = 1 << 30
    for limit_name, call in (("max_nodes", lambda v: check_plan_fits(v, 4096, 20000, dim, available)),
                             ("max_rounds", lambda v: check_plan_fits(1000, 1, v, dim, available))):
        with pytest.raises(ValueError, match=limit_name) as refused:
            call(10**10)
        largest = int(re.search(r"fits is about (\d+)", str(refused.value)).group(1))
        call(largest)
        with pytest.raises(ValueError, match=limit_name):
            call(largest + 1)
    tree, history = plan_bytes(1000, 8, 20000, dim)
    assert tree == 1008 * (96 + 48 * dim) and history == 20000 * 256


def test_a_round_limit_bounds_the_tree_the_memory_check_counts():
    """At most max_rounds * p nodes: a plan of 10 rounds in d = 600 is not refused for the default
    node limit's million nodes (it was: 26.9 GiB), and the message says when the limit to lower is
    the default one, or that no value fits."""
    from qrrt_circuits._support.memory import check_plan_fits, plan_bytes

    assert plan_bytes(10**6, 8, 10, 600) == (81 * (96 + 48 * 600), 10 * 256)
    check_plan_fits(10**6, 1, 10, 600, available=1 << 20)
    with pytest.raises(ValueError, match=r"max_nodes = 1000000 \(the default: the plan was given none\)"):
        check_plan_fits(10**6, 4096, 20000, 600, available=1 << 30, default_nodes=True)
    with pytest.raises(ValueError, match=r"max_rounds = 20000: .* no max_rounds fits"):
        check_plan_fits(10**6, 4096, 20000, 600, available=1000)


class _UserCondition(qc.TerminationCondition):
    """A user's condition that never ends a plan, with any settings note and any node limit."""

    def __init__(self, note=None, node_limit=None):
        self.note, self.limit = note, node_limit

    def ended_by(self, progress):
        return None

    def describe(self):
        return {"user_note": self.note}

    @property
    def node_limit(self):
        return self.limit


class _OwnLimit(_UserCondition):
    """A user's condition reporting any node limit."""

    def __init__(self, value):
        super().__init__(node_limit=value)


@pytest.mark.parametrize("value, error, message", [
    (-5, ValueError, r"_OwnLimit.node_limit must be an integer >= 1, got -5"),
    (0, ValueError, r"_OwnLimit.node_limit must be an integer >= 1"),
    (2.5, TypeError, r"_OwnLimit.node_limit"),
    (True, TypeError, r"_OwnLimit.node_limit"),
    ("100", TypeError, r"_OwnLimit.node_limit"),
    (float("nan"), TypeError, r"_OwnLimit.node_limit"),
])
def test_a_user_condition_with_a_bad_node_limit_is_refused(walled, value, error, message):
    with pytest.raises(error, match=message):
        qc.RRT(seed=0).plan(_walled_from(walled, [1, 1]), termination=_OwnLimit(value), max_rounds=30)
    with pytest.raises(error, match=message):
        qc.RRT(seed=0).plan(_walled_from(walled, [1, 1]), termination=_OwnLimit(value) | qc.Stall(5))


def test_numpy_limits_are_python_ints_and_the_memory_check_sees_them(walled, monkeypatch):
    """MaxRounds(np.int64(2**56)) overflowed the estimate in int64 and passed the check, and its
    settings could not be written as JSON."""
    import json


    limit = qc.MaxRounds(np.int64(2**56))
    assert type(limit.limit) is int
    monkeypatch.setattr(probe, "available_memory", lambda: (1 << 30, probe.MACHINE_SOURCE))
    with pytest.raises(ValueError, match="max_rounds = 72057594037927936"):
        qc.RRT(seed=0).plan(_walled_from(walled, [1, 1]), termination=limit, max_nodes=5)
    with pytest.raises(ValueError, match="max_nodes = 288230376151711744"):
        qc.ParallelRRT(workers=4096, seed=0).plan(_walled_from(walled, [1, 1]),
                                                  termination=qc.MaxNodes(np.int64(2**58)))
    result = qc.RRT(seed=0).plan(_walled_from(walled, [1, 1]), termination=qc.MaxRounds(np.int64(7)))
    assert result.metrics.rounds == 7 and json.dumps(result.settings["termination"])


def test_settings_record_the_limit_that_applies():
    """Where two parts set the same limit, the smaller ends the plan and is the one recorded."""
    assert (qc.MaxNodes(10) | qc.MaxNodes(20)).describe() == {"max_nodes": 10}
    assert (qc.MaxRounds(20000) | qc.MaxRounds(10) | qc.Stall(3)).describe() == {"max_rounds": 10, "stall_rounds": 3}


def test_with_defaults_names_a_bad_default():
    with pytest.raises(ValueError, match="default_max_nodes must be an integer >= 1"):
        with_defaults(None, default_max_nodes=0)


def test_describe_merges_user_settings_without_comparing_them(walled):
    """Only this module's limits take the smaller value; a user's keys keep the last value (a
    minimum over None or dicts raised after the plan had run)."""
    for first, last in ((None, None), ({"x": 1}, {"x": 2}), ([1], "s")):
        result = qc.RRT(seed=0).plan(_walled_from(walled, [1, 1]), max_rounds=5,
                                     termination=_UserCondition(first) | _UserCondition(last))
        assert result.settings["termination"]["user_note"] == last


def test_a_round_limit_too_large_for_a_float_is_sized_by_the_history_checked_up_front():
    """The history of at most ``HISTORY_ROUNDS_CHECKED_UP_FRONT`` rounds is counted whatever the
    round limit (10^400 here): refused in GiB where that and the tree do not fit, accepted where
    they do."""
    from qrrt_circuits._support.memory import check_plan_fits

    with pytest.raises(ValueError, match=r"max_rounds = 1000+: this plan could need about 1\.2 GiB"):
        check_plan_fits(10**6, 1, 10**400, 2, available=1 << 30)
    check_plan_fits(10**6, 1, 10**400, 2, available=1 << 32)


class _DescribesMaxNodes(_UserCondition):
    """A user's condition that describes the max_nodes key with anything."""

    def describe(self):
        return {"max_nodes": self.note}


@pytest.mark.parametrize("value", [None, float("nan"), "five"])
def test_a_limit_key_keeps_its_finite_number_whatever_a_user_part_describes(value):
    for parts in ((qc.MaxNodes(5), _DescribesMaxNodes(value)), (_DescribesMaxNodes(value), qc.MaxNodes(5))):
        assert qc.AnyOf(parts).describe()["max_nodes"] == 5


class _EveryRound(qc.TerminationCondition):
    """A user's condition that wraps another."""

    def __init__(self, inner):
        self.inner = inner

    def ended_by(self, progress):
        return self.inner.ended_by(progress)

    def describe(self):
        return self.inner.describe()

    @property
    def limits_rounds(self):
        return self.inner.limits_rounds

    @property
    def node_limit(self):
        return self.inner.node_limit


@pytest.mark.parametrize("planner_name", ["rrt", "prrt", "qrrt", "pqrrt", "pqrrt-unshared"])
def test_a_wrapped_condition_ends_a_plan_where_the_condition_does(planner_name, clutter):
    from qrrt_circuits.experiments.planners import make_planner

    statuses = set()
    for seed, condition in enumerate((qc.MaxNodes(23), qc.MaxRounds(41), qc.Stall(2),
                                      qc.MaxNodes(30) | qc.Stall(4) | qc.MaxRounds(90))):
        results = [make_planner(planner_name, seed, "statevector").plan(clutter.with_goal_radius(1e-9), chosen)
                   for chosen in (condition, _EveryRound(condition))]
        fast, every = results
        assert fast.status == every.status
        assert dataclasses.replace(fast.metrics, wall_time_s=0.0) == dataclasses.replace(every.metrics, wall_time_s=0.0)
        assert np.array_equal(fast.nodes, every.nodes)
        assert all(np.array_equal(fast.history[key], every.history[key]) for key in every.history)
        statuses.add(str(fast.status))
    assert statuses >= {"max_nodes", "max_rounds", "stalled"}


def test_an_anyof_subclass_with_its_own_test_is_checked_every_round(clutter):
    class Cancelled(qc.AnyOf):  # a user's composite that also ends the plan at round 7
        def ended_by(self, progress):
            return qc.PlanStatus.MAX_TIME if progress.rounds >= 7 else super().ended_by(progress)

    condition = Cancelled((qc.MaxNodes(500), qc.MaxRounds(1000), qc.Stall(300)))
    result = qc.RRT(seed=0).plan(posed(clutter, goal_radius=1e-9), termination=condition)
    assert result.status == qc.PlanStatus.MAX_TIME and result.metrics.rounds == 7
    nested = qc.RRT(seed=0).plan(posed(clutter, goal_radius=1e-9), termination=Cancelled((qc.MaxNodes(500),)))
    assert nested.status == qc.PlanStatus.MAX_TIME and nested.metrics.rounds == 7  # kept when the defaults are added


def test_rounds_that_add_more_nodes_than_the_planners_bound_end_at_the_node_limit(clutter):
    """A user's policy state that hands back two verified outcomes per worker (against the
    contract) adds two nodes a round: the node limit ends the plan at the first check past it."""
    from qrrt_circuits.search.policies import FixedIterations, PolicyState
    from qrrt_circuits.search.problem import SearchOutcome

    class Greedy(FixedIterations):
        def start(self, num_items):
            return GreedyState(self, num_items)

    class GreedyState(PolicyState):
        def run(self, problem, workers, tree_nodes):
            found = [index for index in range(256) if problem.verify(index)][:2 * workers]
            return tuple(SearchOutcome(index, 0, 1, ((0, True),)) for index in found)

    ends = []
    for condition in (qc.MaxNodes(40), _EveryRound(qc.MaxNodes(40))):
        planner = qc.QRRT(backend=qc.StatevectorBackend(), search_policy=Greedy(0), seed=1)
        result = planner.plan(clutter.with_goal_radius(1e-9), termination=condition)
        ends.append((str(result.status), result.metrics.rounds, result.metrics.nodes))
    assert ends[0] == ends[1] and ends[0][0] == "max_nodes" and ends[0][2] == 40


@pytest.mark.parametrize("planner", ["RRT", "QRRT"])
def test_a_budget_is_never_cut_by_a_safety_limit(monkeypatch, boxed_in, planner):
    """With an oracle-call budget in force, neither the default round limit nor the default stall
    limit ends the plan first: a start that can add no node spends the whole budget."""
    from qrrt_circuits.planners import termination

    monkeypatch.setattr(termination, "DEFAULT_STALL_ROUNDS", 25)
    monkeypatch.setattr(termination, "DEFAULT_MAX_ROUNDS", 40)
    make = {"RRT": lambda: qc.RRT(seed=0),
            "QRRT": lambda: qc.QRRT(backend=qc.StatevectorBackend(seed=0), num_qubits=3, seed=0)}[planner]
    result = make().plan(_boxed(boxed_in), max_oracle_calls=300)
    assert result.status == "max_oracle_calls" and not result.safety_limit
    assert 300 <= result.metrics.oracle_calls and result.metrics.nodes == 0
    assert result.settings["termination"]["max_rounds"] == 301 and "stall_rounds" not in result.settings["termination"]
    timed = make().plan(_boxed(boxed_in), max_critical_path_calls=100)
    assert timed.status == "max_critical_path_calls" and timed.metrics.critical_path_oracle_calls >= 100
    # without a budget the safety limits end it, and say so
    unbounded = make().plan(_boxed(boxed_in), max_nodes=3)
    assert unbounded.status == "stalled" and unbounded.safety_limit and unbounded.metrics.rounds == 25


def test_a_wall_clock_budget_alone_adds_no_round_or_stall_limit():
    from qrrt_circuits.planners import termination

    assert with_defaults(qc.MaxWallTime(1.0)) == qc.MaxWallTime(1.0) | qc.MaxNodes(termination.DEFAULT_MAX_NODES)
    assert with_defaults(qc.MaxOracleCalls(10) | qc.MaxWallTime(1.0)).round_limit == termination.DEFAULT_MAX_ROUNDS
    assert with_defaults(qc.MaxOracleCalls(10 ** 6)).round_limit == 10 ** 6 + 1


def test_a_large_budget_is_not_refused_for_history_it_may_never_need(clutter):
    """An oracle-call budget of 10^8 lets 10^8 rounds run, but the plan's check counts the history
    of at most ``HISTORY_ROUNDS_CHECKED_UP_FRONT`` of them; the plan reaches the goal in a few
    hundred calls."""
    result = qc.RRT(seed=0).plan(clutter, max_oracle_calls=10**8)
    assert result.reached and result.metrics.oracle_calls < 10**4


def test_history_beyond_the_rounds_checked_up_front_is_checked_as_it_grows(walled, monkeypatch):
    """Past the checkpoint, a history whose doubling does not fit ends the plan with one line naming
    the rounds run and the limits to lower (not the whole plan's worst case refused up front)."""
    from qrrt_circuits._support.memory import OutOfMemory
    from qrrt_circuits.planners import run_state

    monkeypatch.setattr(run_state, "HISTORY_ROUNDS_CHECKED_UP_FRONT", 64)
    monkeypatch.setattr(probe, "available_memory", lambda: (10_000, probe.MACHINE_SOURCE))
    with pytest.raises(OutOfMemory, match=r"the plan has run 64 rounds and its round history would need about "
                                          r"16 KiB more .*max_rounds or oracle-call budget"):
        qc.RRT(seed=0).plan(_walled_from(walled, [1, 1]), max_rounds=1000, stall_rounds=1000)
    monkeypatch.setattr(probe, "available_memory", lambda: (1 << 30, probe.MACHINE_SOURCE))
    assert qc.RRT(seed=0).plan(_walled_from(walled, [1, 1]), max_rounds=1000,
                               stall_rounds=1000).metrics.rounds == 1000
