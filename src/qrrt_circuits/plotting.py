"""Figures: the tree drawn along its closed-loop trajectories, obstacles, path, start and goal.

Only this module imports matplotlib's pyplot; planners never plot. In d > 2 the first two axes are
drawn.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .reachability.dynamics import LinearTrackingDynamics
from .world.environment import Environment

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from .planners.result import PlanResult


def _axes(ax: Axes | None) -> Axes:
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(6, 6))
    return ax


def plot_environment(env: Environment, ax: Axes | None = None, color: str = "0.15") -> Axes:
    """Obstacles as filled rectangles inside the workspace outline (first two axes).

    Args:
        env: The ``Environment`` to draw.
        ax: Matplotlib axes to draw on; None (default) for a new 6 x 6 inch figure.
        color: Fill colour of the obstacles (default dark grey ``"0.15"``).

    Returns:
        The axes, with limits set to the workspace and an equal aspect ratio.
    """
    from matplotlib.collections import PolyCollection

    ax = _axes(ax)
    lo, hi = env.boxes[:, 0, :2], env.boxes[:, 1, :2]
    # each box's four corners, counter-clockwise, as one polygon of one collection (no Python
    # object per box: worlds have hundreds of boxes)
    corners = np.stack([lo, np.stack([hi[:, 0], lo[:, 1]], axis=1), hi,
                        np.stack([lo[:, 0], hi[:, 1]], axis=1)], axis=1)
    ax.add_collection(PolyCollection(list(corners), facecolors=color, edgecolors="none"))
    (x0, x1), (y0, y1) = env.bounds[0], env.bounds[1]
    ax.plot([x0, x1, x1, x0, x0], [y0, y0, y1, y1, y0], color="0.3", lw=0.8)
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    return ax


def edge_curves(nodes: np.ndarray, parents: np.ndarray, dynamics: LinearTrackingDynamics | None,
                samples: int = 24) -> np.ndarray:
    """(E, samples, d) points along each edge: the closed-loop trajectory
    x(t) = c + expm(Mt)(p - c) of ``dynamics``, or the straight segment when ``dynamics`` is None
    (a predicate without closed-loop dynamics).

    Each curve starts at the parent p (t = 0) and runs towards the child c, the tracking target;
    with dynamics the times are 0 and ``samples - 1`` geometrically spaced
    times from 1e-3 to the horizon T (DESIGN §2, the paper's §V motion model).

    Args:
        nodes: Float (N+1, d), the tree's nodes (root in row 0).
        parents: Int (N+1,), each node's parent row, -1 for the root.
        dynamics: The ``LinearTrackingDynamics`` the edges follow, or None for straight segments.
        samples: Points per edge (default 24).

    Returns:
        Float array (E, samples, d), one curve per node with a parent (E = number of edges).

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits.plotting import edge_curves
        >>> nodes = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 2.0]])
        >>> curves = edge_curves(nodes, np.array([-1, 0, 1]), None, samples=3)
        >>> curves.shape, curves[1].tolist()
        ((2, 3, 2), [[1.0, 0.0], [1.0, 1.0], [1.0, 2.0]])
    """
    children = np.flatnonzero(parents >= 0)
    if children.size == 0:
        return np.zeros((0, samples, nodes.shape[1]))
    errors = nodes[parents[children]] - nodes[children]  # (E, d)
    if dynamics is None:
        weights = np.linspace(1.0, 0.0, samples)
        return nodes[children][:, None, :] + weights[None, :, None] * errors[:, None, :]
    times = np.concatenate([[0.0], np.geomspace(1e-3, dynamics.horizon, samples - 1)])
    phis = dynamics.propagators(times)  # (S, d, d)
    return nodes[children][:, None, :] + np.einsum("sij,ej->esi", phis, errors)


def plan_dynamics(result: PlanResult) -> LinearTrackingDynamics | None:
    """The dynamics a plan's predicate followed, from ``result.settings["dynamics"]`` (None: the
    predicate describes none, and edges are drawn straight).

    Args:
        result: A ``PlanResult``.

    Returns:
        The ``LinearTrackingDynamics`` rebuilt from its recorded description, or None.
    """
    description = result.settings.get("dynamics")
    return None if description is None else LinearTrackingDynamics.from_description(description)


def plot_edges(env: Environment, nodes: np.ndarray, parents: np.ndarray,
               dynamics: LinearTrackingDynamics | None, ax: Axes | None = None,
               edge_color: str = "tab:blue") -> Axes:
    """Obstacles, the tree's edges along their motion (see ``edge_curves``), nodes and the root.

    Args:
        env: The ``Environment`` (obstacles and workspace).
        nodes: Float (N+1, d), the tree's nodes (root in row 0).
        parents: Int (N+1,), each node's parent row, -1 for the root.
        dynamics: The ``LinearTrackingDynamics`` the edges follow, or None for straight segments.
        ax: Matplotlib axes to draw on; None (default) for a new figure.
        edge_color: Colour of the edges and nodes (default ``"tab:blue"``).

    Returns:
        The axes.
    """
    from matplotlib.collections import LineCollection

    ax = plot_environment(env, ax)
    curves = edge_curves(nodes, parents, dynamics)
    ax.add_collection(LineCollection(list(curves[:, :, :2]), colors=edge_color, linewidths=0.7, alpha=0.8))
    ax.plot(nodes[1:, 0], nodes[1:, 1], ".", color=edge_color, ms=2.5)
    ax.plot(*nodes[0, :2], "o", color="tab:green", ms=8, label="start")
    return ax


def plot_tree(env: Environment, result: PlanResult, ax: Axes | None = None,
              dynamics: LinearTrackingDynamics | None = None, edge_color: str = "tab:blue",
              path_color: str = "tab:red", title: str | None = None) -> Axes:
    """Obstacles, tree edges along the motion the plan's predicate used (``dynamics`` overrides
    what ``result.settings`` records), the path, the start and the goal ball.

    Args:
        env: The ``Environment`` the plan ran in.
        result: The ``PlanResult`` to draw.
        ax: Matplotlib axes to draw on; None (default) for a new figure.
        dynamics: The motion to draw the edges along; None (default) for the one recorded in
            ``result.settings`` (``plan_dynamics``).
        edge_color: Colour of the tree (default ``"tab:blue"``).
        path_color: Colour of the path and the goal ball (default ``"tab:red"``).
        title: The axes' title; None (default) for the planner, nodes, oracle calls and status.

    Returns:
        The axes.
    """
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Circle

    dynamics = plan_dynamics(result) if dynamics is None else dynamics
    ax = plot_edges(env, result.nodes, result.parents, dynamics, ax, edge_color)
    if result.path is not None:
        index = [result.goal_node]
        while result.parents[index[-1]] >= 0:
            index.append(int(result.parents[index[-1]]))
        path_parents = np.full(len(result.nodes), -1)
        for child, parent in zip(index[:-1], index[1:], strict=True):
            path_parents[child] = parent
        path_curves = edge_curves(result.nodes, path_parents, dynamics)
        ax.add_collection(LineCollection(list(path_curves[:, :, :2]), colors=path_color, linewidths=2.0))
    goal = result.settings.get("goal")
    if goal is not None:
        ax.add_patch(Circle(goal[:2], result.settings.get("goal_radius", 0.75), fill=False,
                            color=path_color, lw=2, label="goal"))
    metrics = result.metrics
    ax.set_title(title or f"{result.planner}: {metrics.nodes} nodes, {metrics.oracle_calls} oracle "
                          f"calls ({result.status})", fontsize=10)
    return ax
