"""Goals (OMPL's ``Goal``): a ball, one exact state, any region; goal-biased draws; bad goals refused."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import make_backend
from planner_checks import posed

import qrrt_circuits as qc
from qrrt_circuits.problems.goals import first_satisfying, sample_goal


@pytest.fixture(scope="module")
def open_world():
    wall = qc.Environment(np.array([[0.0, 10.0], [0.0, 10.0]]), np.array([[[4.0, 0.0], [6.0, 6.0]]]), name="wall")
    return qc.Problem.build(wall, [1, 1], [9, 1], 0.5)


class RightEdge:
    """Every state with x >= 9: a region with volume, drawn from uniformly."""

    dim = 2

    def is_satisfied(self, points):
        return np.atleast_2d(points)[:, 0] >= 9.0

    def sample(self, count, rng):
        return np.column_stack([rng.uniform(9.0, 10.0, count), rng.uniform(0.0, 10.0, count)])

    def describe(self):
        return {"kind": "x >= 9"}


def _planners(env, **kwargs):
    return {"RRT": qc.RRT(seed=1, **kwargs),
            "QRRT": qc.QRRT(backend=make_backend("statevector", 1), num_qubits=5, seed=1, **kwargs),
            "PQRRT": qc.PQRRT(backend=make_backend("aer", 1), num_qubits=5, workers=3, seed=1, **kwargs)}


def test_a_ball_goal_is_the_environments_goal(open_world):
    for name, planner in _planners(open_world).items():
        by_point = planner.plan(open_world, max_oracle_calls=3000)
        by_goal = _planners(open_world)[name].plan(posed(open_world, goal=qc.GoalBall([9, 1], 0.5)),
                                                   max_oracle_calls=3000)
        assert np.array_equal(by_point.nodes, by_goal.nodes), name
        assert by_goal.settings["goal"] == [9.0, 1.0] and by_goal.settings["goal_radius"] == 0.5
        assert by_goal.settings["goal_region"] == {"kind": "ball", "centre": [9.0, 1.0], "radius": 0.5}


@pytest.mark.parametrize("name", ["RRT", "QRRT", "PQRRT"])
def test_an_exact_goal_state_is_reached_exactly_through_goal_bias(open_world, name):
    """OMPL's GoalState: no volume, reached when a goal-biased draw (the state itself) is verified;
    with a range the tree approaches it step by step. 20 seeds, every one within the budget."""
    target = qc.GoalState([9.0, 1.0])
    reached = 0
    options = {"goal_bias": 0.1, "max_extension": 3.0}
    for seed in range(20):
        if name == "RRT":
            planner = qc.RRT(seed=seed, **options)
        elif name == "QRRT":
            planner = qc.QRRT(backend=make_backend("statevector", seed), num_qubits=4, seed=seed,
                              **options)
        else:
            planner = qc.PQRRT(backend=make_backend("statevector", seed), num_qubits=4, workers=2,
                               seed=seed, **options)
        result = planner.plan(posed(open_world, goal=target), max_oracle_calls=4000)
        if result.reached:
            reached += 1
            assert np.array_equal(result.path[-1], [9.0, 1.0])
    assert reached == 20


def test_a_region_goal_with_its_own_sampler(open_world):
    for name, planner in _planners(open_world, goal_bias=0.05).items():
        result = planner.plan(posed(open_world, goal=RightEdge()), max_oracle_calls=5000)
        assert result.reached and result.path[-1][0] >= 9.0, name
        assert result.settings["goal"] is None and result.settings["goal_region"] == {"kind": "x >= 9"}
        assert not RightEdge().is_satisfied(result.nodes[:result.goal_node]).any()  # the first one ends it


def test_a_start_inside_the_goal_is_reached_at_once(open_world):
    result = qc.RRT(seed=0).plan(posed(open_world, start=[9.5, 5], goal=RightEdge()), max_rounds=5)
    assert result.reached and result.metrics.rounds == 0


def test_goal_helpers_check_what_user_goals_return():
    assert first_satisfying(RightEdge(), np.array([[1.0, 1.0], [9.5, 2.0], [9.9, 0.0]])) == 1
    assert first_satisfying(RightEdge(), np.array([[1.0, 1.0]])) == -1

    class Miscounting(RightEdge):
        def is_satisfied(self, points):
            return np.ones(1, dtype=bool)

        def sample(self, count, rng):
            return np.zeros((count, 3))

    with pytest.raises(ValueError, match="is_satisfied must return 2 booleans for 2 points"):
        first_satisfying(Miscounting(), np.zeros((2, 2)))
    with pytest.raises(ValueError, match=r"sample must return shape \(4, 2\), got \(4, 3\)"):
        sample_goal(Miscounting(), 4, np.random.default_rng(0))
    state = qc.GoalState([1.0, 2.0], threshold=0.0)
    assert state.is_satisfied(np.array([[1.0, 2.0], [1.0, 2.0 + 1e-12]])).tolist() == [True, False]
    assert np.array_equal(state.sample(3, np.random.default_rng(0)), [[1.0, 2.0]] * 3)


class NoSampler:
    dim = 2

    def is_satisfied(self, points):
        return np.zeros(len(np.atleast_2d(points)), dtype=bool)

    def describe(self):
        return {}


@pytest.mark.parametrize(("make", "goal", "extra", "error", "message"), [
    (lambda env: qc.RRT(seed=0), qc.GoalState([9, 1]), {}, ValueError,
     r"goal_bias = 0, but the goal GoalState\(state=\[9.0, 1.0\], threshold=1e-09\) has no volume"),
    (lambda env: qc.RRT(seed=0, goal_bias=0.1), NoSampler(), {}, TypeError,
     "goal_bias = 0.1 draws candidates in the goal, but NoSampler has no sample"),
    (lambda env: qc.RRT(seed=0), qc.GoalBall([9, 1], 0.5), {"goal_radius": 1.0}, ValueError,
     "goal_radius is given with a goal point, not with a Goal object"),
    (lambda env: qc.RRT(seed=0), qc.GoalBall([12, 1], 0.5), {}, ValueError,
     r"goal \[12.0, 1.0\] is out of bounds"),
    (lambda env: qc.RRT(seed=0, goal_bias=0.1), qc.GoalState([5, 3]), {}, ValueError,
     r"goal \[5.0, 3.0\] is in collision with an obstacle"),
    (lambda env: qc.RRT(seed=0), qc.GoalBall([1, 1, 1], 0.5), {}, ValueError,
     "dimension mismatch: the goal has d = 3, the environment has d = 2"),
    (lambda env: qc.RRT(seed=0), "somewhere", {"goal_radius": 0.5}, ValueError,
     "goal must be 2 numbers, got 'somewhere'"),
])
def test_bad_goals_are_refused_before_planning(open_world, make, goal, extra, error, message):
    with pytest.raises(error, match=message):
        make(open_world).plan(qc.Problem.build(open_world.env, [1, 1], goal, **extra), max_rounds=3)


@pytest.mark.parametrize(("args", "message"), [
    (([1, 1], 0.0), "goal_radius must be a finite number > 0.0"),
    (([1, 1], float("nan")), "goal_radius must be a finite number"),
    (([np.nan, 1], 1.0), "goal must be d >= 1 finite numbers"),
])
def test_bad_goal_balls_are_refused(args, message):
    with pytest.raises(ValueError, match=message):
        qc.GoalBall(*args)


def test_a_negative_goal_state_threshold_is_refused():
    with pytest.raises(ValueError, match="threshold must be a finite number >= 0.0"):
        qc.GoalState([1, 1], threshold=-1.0)
