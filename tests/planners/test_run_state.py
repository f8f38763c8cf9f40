"""The plan's bookkeeping: the goal test and node additions one by one or in a batch."""

from __future__ import annotations

import math

import numpy as np

from qrrt_circuits.planners.run_state import RunState
from qrrt_circuits.problems.goals import GoalBall, in_ball
from qrrt_circuits.world.nearest import GridNearest


def first_in_ball(points, centre, radius):
    hits = np.flatnonzero(in_ball(np.asarray(points, dtype=float).reshape(-1, len(centre)), centre, radius))
    return int(hits[0]) if hits.size else -1


def test_the_goal_ball_is_closed_and_the_first_row_inside_wins():
    rng = np.random.default_rng(2)
    centre = np.array([3.0, -1.5])
    for _ in range(200):
        point = centre + rng.normal(size=2) * rng.uniform(0.01, 10)
        radius = math.sqrt(sum((x - c) ** 2 for x, c in zip(point, centre, strict=True)))  # the same formula
        assert first_in_ball(point[None], centre, radius) == 0  # on the boundary: inside
        assert first_in_ball(point[None], centre, float(np.nextafter(radius, 0))) == -1
    far, near = centre + [5.0, 0.0], centre + [0.5, 0.0]
    assert first_in_ball(np.array([far, near, near]), centre, 1.0) == 1
    assert first_in_ball(np.array([far, far]), centre, 1.0) == -1
    assert first_in_ball(np.empty((0, 2)), centre, 1.0) == -1


def test_add_nodes_in_a_batch_sets_the_goal_node_as_add_node_one_by_one():
    rng = np.random.default_rng(4)
    goal = np.array([8.0, 8.0])
    for _ in range(30):
        points = rng.uniform(0, 10, (12, 2))
        parents = rng.integers(0, 3, 12)
        single = RunState(np.array([1.0, 1.0]), GoalBall(goal, 2.5), GridNearest(2))
        batch = RunState(np.array([1.0, 1.0]), GoalBall(goal, 2.5), GridNearest(2))
        for point, parent in zip(points, parents, strict=True):
            single.add_node(point, int(parent))
        batch.add_nodes(points[:5], parents[:5])
        batch.add_nodes(points[5:5], parents[5:5])  # nothing to add
        batch.add_nodes(points[5:], parents[5:])
        assert single.goal_node == batch.goal_node
        inside = [i + 1 for i, p in enumerate(points) if np.hypot(*(p - goal)) <= 2.5]
        assert single.goal_node == (inside[0] if inside else None)
        assert np.array_equal(single.tree.nodes, batch.tree.nodes)
        for state in (single, batch):  # the structure holds the tree's nodes, at the same indices
            assert np.array_equal(state.neighbors.points, state.tree.nodes)
    root_in_the_ball = RunState(goal + [0.0, 2.5], GoalBall(goal, 2.5), GridNearest(2))
    assert root_in_the_ball.goal_node == 0  # a root in the ball is the goal node
