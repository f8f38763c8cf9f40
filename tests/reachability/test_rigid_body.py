"""The SE(2) rigid-body check: exact state overlap, a sound motion check, planning through a gap."""

from __future__ import annotations

import math

import numpy as np
import pytest

import qrrt_circuits as qc
from qrrt_circuits.reachability.rigid_body import RigidBodyCheck, se2_world
from qrrt_circuits.world.spaces import SE2Space

WORKSPACE = np.array([[0.0, 10.0], [0.0, 10.0]])
#: a wall x in [4.8, 5.2] with a gap y in [4.4, 5.6]
WALL = np.array([[[4.8, 0.0], [5.2, 4.4]], [[4.8, 5.6], [5.2, 10.0]]])


def corners(x, y, theta, a, b):
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[x + c * u - s * v, y + s * u + c * v] for u, v in ((a, b), (-a, b), (-a, -b), (a, -b))])


def polygons_overlap(p, q):
    """Separating axes of two convex polygons (every edge normal of both), touching = overlap."""
    for poly in (p, q):
        for i in range(len(poly)):
            edge = poly[(i + 1) % len(poly)] - poly[i]
            axis = np.array([-edge[1], edge[0]])
            if np.max(p @ axis) < np.min(q @ axis) or np.max(q @ axis) < np.min(p @ axis):
                return False
    return True


def reference_free(state, a, b, boxes, workspace):
    body = corners(*state, a, b)
    if np.any(body < workspace[:, 0]) or np.any(body > workspace[:, 1]):
        return False
    for low, high in boxes:
        box = np.array([[low[0], low[1]], [high[0], low[1]], [high[0], high[1]], [low[0], high[1]]])
        if polygons_overlap(body, box):
            return False
    return True


def test_state_validity_is_the_exact_polygon_overlap():
    rng = np.random.default_rng(0)
    check = RigidBodyCheck(WORKSPACE, WALL, (0.6, 0.2))
    states = np.column_stack([rng.uniform(0, 10, 3000), rng.uniform(0, 10, 3000), rng.uniform(-math.pi, math.pi, 3000)])
    answers = check.is_valid(states)
    expected = [reference_free(s, 0.6, 0.2, WALL, WORKSPACE) for s in states]
    assert answers.tolist() == expected
    assert 0.2 < answers.mean() < 0.95


def test_the_motion_check_is_sound_and_rejects_only_near_contacts():
    """Accepted motions are free at a 100x finer step with the true rectangle; a rejected motion
    collides there, or comes within the resolution (the rectangle grown by it collides)."""
    rng = np.random.default_rng(1)
    a, b, resolution = 0.6, 0.2, 0.05
    check = RigidBodyCheck(WORKSPACE, WALL, (a, b), resolution)
    space = SE2Space()
    parents = np.column_stack([rng.uniform(3, 7, 400), rng.uniform(3, 7, 400), rng.uniform(-math.pi, math.pi, 400)])
    children = parents + rng.normal(scale=[1.0, 1.0, 1.0], size=(400, 3))
    children[:, 2] = (children[:, 2] + math.pi) % (2 * math.pi) - math.pi
    answers = check.reachable(parents, children)
    assert 0.1 < answers.mean() < 0.9
    for parent, child, accepted in zip(parents, children, answers, strict=True):
        fine = space.interpolate(np.repeat(parent[None], 401, 0), np.repeat(child[None], 401, 0),
                                 np.linspace(0, 1, 401))
        truly = all(reference_free(s, a, b, WALL, WORKSPACE) for s in fine)
        if accepted:
            assert truly, (parent, child)
        elif truly:  # rejected but free: it must pass within the resolution
            grown = all(reference_free(s, a + resolution, b + resolution, WALL, WORKSPACE) for s in fine)
            assert not grown, (parent, child)


def test_q_rrt_turns_the_body_through_the_gap():
    """The 1.2 x 0.4 body plans through the 1.2-wide gap: 4 of 5 seeds or more reach the goal within
    the budget, every path crosses the wall's x, and every edge re-checks."""
    env, check = se2_world(WORKSPACE, WALL, (0.6, 0.2), resolution=0.05)
    problem = qc.Problem.build(env, [2, 2, math.pi / 2], [8, 8, 0.0], 1.0, predicate=check, space=SE2Space())
    reached = 0
    for seed in range(5):
        planner = qc.QRRT(backend=qc.StatevectorBackend(seed=seed), num_qubits=6, seed=seed, max_extension=1.0,
                          search_policy=qc.Adaptive())
        result = planner.plan(problem, max_oracle_calls=6000)
        assert check.reachable(result.nodes[result.parents[1:]], result.nodes[1:]).all()
        if result.reached:
            reached += 1
            path = result.path
            crossing = [i for i in range(len(path) - 1) if (path[i][0] - 5.0) * (path[i + 1][0] - 5.0) <= 0]
            assert crossing
    assert reached >= 4


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"workspace": [[0, 1]]}, "workspace must be"),
    ({"boxes": [[[1, 1], [0, 0]]]}, "boxes must be finite"),
    ({"half_lengths": (0.0, 1.0)}, r"half_lengths\[0\] must be a finite number > 0.0"),
    ({"half_lengths": 1.0}, r"half_lengths must be \(a, b\)"),
    ({"resolution": -1.0}, "resolution must be a finite number > 0.0"),
])
def test_bad_rigid_bodies_are_refused(kwargs, message):
    arguments = {"workspace": WORKSPACE, "boxes": WALL, "half_lengths": (0.5, 0.2)} | kwargs
    with pytest.raises(ValueError, match=message):
        RigidBodyCheck(**arguments)


def test_a_start_where_the_body_overlaps_the_wall_is_refused():
    env, check = se2_world(WORKSPACE, WALL, (0.6, 0.2))
    with pytest.raises(ValueError, match=r"start \[5.0, 2.0, 0.0\] is not a valid state"):
        qc.Problem.build(env, [5.0, 2.0, 0.0], [8, 8, 0.0], 1.0, predicate=check, space=SE2Space())
