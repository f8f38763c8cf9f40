"""Figure helpers shared by the experiments (matplotlib with the Agg backend; only figures are
drawn here, never in the algorithms)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .._support.output_files import write_result_file

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure
    from matplotlib.image import AxesImage

    from ..problems.problem import Problem
    from ..reachability.dynamics import LinearTrackingDynamics
    from ..world.environment import Environment
    from .base import PaperComparison


def new_figure(rows: int = 1, cols: int = 1, size: tuple[float, float] | None = None) -> tuple[Figure, Any]:
    """A figure with a grid of axes (Agg backend).

    Args:
        rows: Rows of axes.
        cols: Columns of axes.
        size: The figure size in inches; by default 5.0 x 4.2 per axes.

    Returns:
        ``(figure, axes)`` with ``axes`` a (rows, cols) numpy array of ``Axes`` (never squeezed).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(rows, cols, figsize=size or (5.0 * cols, 4.2 * rows), squeeze=False)
    return fig, axes


def save(fig: Figure, path: Path, tight: bool = True) -> Path:
    """Lay out ``fig`` (``tight_layout``), write it to ``path`` (110 dpi) and close it.

    The file is replaced whole (``output_files.write_result_file``): a failed write (a full disk)
    leaves the old figure, or none, never part of one.

    Args:
        fig: The figure.
        path: Where to write it (the format follows the suffix).
        tight: Whether to run ``tight_layout`` first (default True); False for a figure whose
            axes were placed by hand (``tight_layout`` draws every tick label to measure it).

    Returns:
        ``path``.
    """
    import matplotlib.pyplot as plt

    if tight:
        fig.tight_layout()
    try:
        write_result_file(path, lambda handle: fig.savefig(handle, dpi=110, format=path.suffix.lstrip(".")),
                        binary=True)
    finally:
        plt.close(fig)
    return path


def heatmap_counts(env: Environment, points: np.ndarray, bins: int = 50) -> np.ndarray:
    """Node counts per cell of a ``bins`` x ``bins`` grid over the workspace's first two axes.

    Args:
        env: The world (its bounds).
        points: (N, >=2) node positions; the first two coordinates are binned.
        bins: Cells per axis.

    Returns:
        Float array (bins, bins): counts, indexed [x cell, y cell].
    """
    (x0, x1), (y0, y1) = env.bounds[0], env.bounds[1]
    if not len(points):
        return np.zeros((bins, bins))
    counts, _, _ = np.histogram2d(points[:, 0], points[:, 1], bins=bins, range=[[x0, x1], [y0, y1]])
    return counts


def node_heatmap(ax: Axes, problem: Problem, points: np.ndarray, title: str, bins: int = 50,
                 norm: Normalize | None = None) -> AxesImage | None:
    """2-D histogram of node positions over the workspace with the obstacles, the start and a ball
    goal drawn on top.

    Args:
        ax: The axes to draw on.
        problem: The problem (its world's bounds and obstacles, its start and goal).
        points: (N, >=2) node positions; the first two coordinates are binned.
        title: The axes' title.
        bins: Histogram bins per axis.
        norm: The colour scale shared by several panels (the caller draws their one colour bar),
            or None (default) for this panel's own logarithmic scale and colour bar.

    Returns:
        The histogram's image (for a shared colour bar), or None without points.
    """
    from matplotlib.colors import LogNorm
    from matplotlib.patches import Circle

    from ..plotting import plot_environment
    from ..problems.goals import ball_of

    env = problem.env
    (x0, x1), (y0, y1) = env.bounds[0], env.bounds[1]
    image = None
    if len(points):
        counts = heatmap_counts(env, points, bins)
        masked = np.ma.masked_equal(counts.T, 0)
        own_scale = norm is None
        if norm is None:
            norm = LogNorm(vmin=1, vmax=max(counts.max(), 2))
        image = ax.imshow(masked, origin="lower", extent=(x0, x1, y0, y1), cmap="plasma",
                          norm=norm, interpolation="nearest", zorder=3)
        if own_scale:
            ax.figure.colorbar(image, ax=ax, fraction=0.046, pad=0.03, label="nodes")
    plot_environment(env, ax, color="0.35")
    ax.plot(*problem.start[:2], "o", color="tab:green", ms=6, zorder=4)
    ball = ball_of(problem.goal)
    if ball is not None:
        centre: Any = ball[0][:2]  # an array; matplotlib takes any (x, y) sequence
        ax.add_patch(Circle(centre, ball[1], fill=False, color="tab:red", lw=2, zorder=4))
    ax.set_title(title, fontsize=9)
    return image


def tree_on_world(ax: Axes, env: Environment, nodes: np.ndarray, parents: np.ndarray,
                  dynamics: LinearTrackingDynamics | None, title: str, color: str = "tab:blue") -> None:
    """A tree over the whole workspace: obstacles in light grey, the edges along their motion in
    ``color``, the root in green; the extent is the world's bounds, so panels of one figure share it.

    Args:
        ax: The axes to draw on.
        env: The world (its bounds and obstacles).
        nodes: Float (N+1, d), the tree's nodes (root in row 0).
        parents: Int (N+1,), each node's parent row, -1 for the root.
        dynamics: The motion the edges follow (``plotting.edge_curves``), or None for straight edges.
        title: The axes' title.
        color: Colour of the edges and nodes.
    """
    from matplotlib.collections import LineCollection

    from ..plotting import edge_curves, plot_environment

    plot_environment(env, ax, color="0.78")
    curves = edge_curves(nodes, parents, dynamics)
    ax.add_collection(LineCollection(list(curves[:, :, :2]), colors=color, linewidths=1.3, zorder=3))
    ax.plot(nodes[1:, 0], nodes[1:, 1], ".", color=color, ms=4, zorder=4)
    ax.plot(*nodes[0, :2], "o", color="tab:green", ms=7, zorder=5)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_title(title, fontsize=10)


def with_intervals(ax: Axes, x: Any, values: Any, intervals: Any, **style: Any) -> Any:
    """Points with 95 % intervals as error bars (``Axes.errorbar``, caps of 3 points).

    Args:
        ax: The axes to draw on.
        x: The abscissae.
        values: The points' values, one per abscissa.
        intervals: ``[low, high]`` per point; a side that lies past its value (an interval that
            excludes a rounded value) is drawn with length 0.
        **style: Passed to ``errorbar`` (``color``, ``fmt``, ``label``, ``ms``, ...).

    Returns:
        The ``ErrorbarContainer``.
    """
    values = np.asarray(values, dtype=float)
    spans = np.asarray(intervals, dtype=float).reshape(-1, 2)
    below = np.clip(values - spans[:, 0], 0.0, None)
    above = np.clip(spans[:, 1] - values, 0.0, None)
    style.setdefault("capsize", 3)
    return ax.errorbar(x, values, yerr=[below, above], **style)


def dodge(count: int, width: float = 0.6) -> np.ndarray:
    """Offsets that set ``count`` series side by side around each category's position.

    Args:
        count: Series per category.
        width: The span of the offsets (less than 1 keeps categories apart).

    Returns:
        (count,) offsets, centred on 0.
    """
    if count <= 1:
        return np.zeros(max(count, 0))
    return np.linspace(-width / 2, width / 2, count)


def wrapped(label: str) -> str:
    """A tick label over lines instead of one long line (``-`` and spaces break it).

    Args:
        label: A name such as ``"authors-octave"`` or ``"samples-200"``.

    Returns:
        The label with each ``-`` or space replaced by a line break.
    """
    return label.replace("-", "\n").replace(" ", "\n")


def paper_comparison_figure(panels: Sequence[Sequence[tuple[str, PaperComparison]]], path: Path) -> Path:
    """The paper's numbers beside several runs' (one panel per experiment): the paper's as black
    diamonds, each run's as a point with its 95 % interval, side by side per number.

    Args:
        panels: Per experiment, ``(run label, comparison)`` for each run, in the order drawn; the
            numbers drawn and the paper's values are the first run's, matched by label in the
            others (a number another run lacks is left out of that run).
        path: Where to write the figure.

    Returns:
        ``path``.

    Raises:
        ValueError: Without panels.
    """
    if not panels:
        raise ValueError("a comparison with the paper needs at least one experiment")
    cols = min(len(panels), 2)
    rows = -(-len(panels) // cols)
    fig, axes = new_figure(rows, cols, (6.2 * cols, 4.4 * rows + 0.5))
    colors = ("tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:brown")
    for index, runs in enumerate(panels):
        ax = axes[index // cols, index % cols]
        first = runs[0][1]
        labels = [number.label for number in first.numbers]
        x = np.arange(len(labels), dtype=float)
        offsets = dodge(len(runs) + 1, 0.5)
        ax.plot(x + offsets[0], [number.paper for number in first.numbers], "D", color="black", ms=7,
                label="paper")
        for run, (label, comparison) in enumerate(runs):
            by_label = {number.label: number for number in comparison.numbers}
            kept = [i for i, name in enumerate(labels) if name in by_label]
            numbers = [by_label[labels[i]] for i in kept]
            with_intervals(ax, x[kept] + offsets[run + 1], [n.ours for n in numbers],
                           [n.interval for n in numbers], fmt="o", ms=6, color=colors[run % len(colors)],
                           label=f"{label} (95 % interval)")
        ax.set_xticks(x, labels, fontsize=8)
        ax.set_xlim(-0.6, len(labels) - 0.4)
        ax.set_ylim(bottom=0)
        ax.set_ylabel(first.quantity, fontsize=9)
        ax.set_title(first.title, fontsize=10)
        ax.grid(alpha=0.3, axis="y")
    for index in range(len(panels), rows * cols):
        axes[index // cols, index % cols].set_visible(False)
    handles, names = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, names, loc="upper center", ncol=len(names), fontsize=9, frameon=False)
    fig.tight_layout(rect=(0, 0, 1, 1 - 0.45 / fig.get_figheight()))
    return save(fig, path, tight=False)
