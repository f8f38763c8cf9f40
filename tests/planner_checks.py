"""Independent re-checks of planner output used by the planner tests."""

from __future__ import annotations

import numpy as np
from reference import dense_trajectory, diagonal_edge_hits, penetration_and_clearance


def assert_tree_edges_valid(env, dynamics, result, resolution=0.01, spacing=0.004):
    """Every edge of the tree re-checked by the dense trajectory check: no edge may penetrate an
    obstacle (or leave the workspace) by more than the resolution."""
    nodes, parents = result.nodes, result.parents
    assert parents[0] == -1
    assert np.all(parents[1:] >= 0) and np.all(parents[1:] < len(parents))
    ancestors = np.where(np.arange(len(parents)) == 0, 0, parents)  # a tree rooted at 0: every chain ends
    for _ in range(int(np.ceil(np.log2(len(parents) + 1))) + 1):  # there (pointer doubling; a rewired
        ancestors = ancestors[ancestors]  # q-RRT* node may have a parent of a higher index)
    assert np.all(ancestors == 0), "a node whose chain of parents never reaches the root (a cycle)"
    assert env.is_free(nodes).all()
    closed = dynamics.closed_loop
    if np.allclose(closed, np.diag(np.diag(closed))):
        # exact interval check: no contact at all, with any obstacle, along the whole edge
        rates = np.diag(closed)
        for child in range(1, len(nodes)):
            assert not diagonal_edge_hits(nodes[parents[child]], nodes[child], rates,
                                          dynamics.horizon, env.bounds, env.boxes), \
                f"edge {parents[child]} -> {child} touches an obstacle"
        return
    for child in range(1, len(nodes)):
        points = dense_trajectory(dynamics.A, dynamics.B, dynamics.K, nodes[parents[child]],
                                  nodes[child], dynamics.horizon, spacing=spacing)
        depth, _ = penetration_and_clearance(points, env.bounds, env.boxes)
        assert depth <= resolution, f"edge {parents[child]} -> {child} penetrates by {depth}"


def assert_path_valid(result):
    if result.status == "reached":
        goal = np.asarray(result.settings["goal"])
        assert np.linalg.norm(result.path[-1] - goal) <= result.settings["goal_radius"] + 1e-12
        assert np.array_equal(result.path[0], result.nodes[0])
        index = result.goal_node
        chain = []
        while index >= 0:
            chain.append(index)
            index = result.parents[index]
        assert np.array_equal(result.path, result.nodes[chain[::-1]])
    else:
        assert result.path is None


def posed(world, start=None, goal=None, goal_radius=None, **parts):
    """The problem a test plans: an ``Environment`` with a start, a goal point (with its radius) or
    ``Goal``, and optional parts (``predicate``, ``space``, ``dynamics``, ``resolution``); or a
    ``Problem`` with the given start, goal or radius replaced (the rest kept)."""
    import qrrt_circuits as qc

    if isinstance(world, qc.Environment):
        return qc.Problem.build(world, start, goal, goal_radius, **parts)
    problem = world
    changes = dict(parts)
    if start is not None:
        changes["start"] = start
    if goal is not None:
        changes["goal"] = goal if isinstance(goal, qc.Goal) else qc.GoalBall(
            goal, goal_radius if goal_radius is not None else problem.goal.radius)
    elif goal_radius is not None:
        return problem.replace(**changes).with_goal_radius(goal_radius) if changes else \
            problem.with_goal_radius(goal_radius)
    return problem.replace(**changes) if changes else problem
