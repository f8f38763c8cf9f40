"""Figure helpers shared by the experiments (matplotlib with the Agg backend; only figures are
drawn here, never in the algorithms)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .._support.output_files import write_result_file

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure
    from matplotlib.image import AxesImage

    from ..world.environment import Environment


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


def node_heatmap(ax: Axes, env: Environment, points: np.ndarray, title: str, bins: int = 50,
                 goal: np.ndarray | None = None, radius: float | None = None,
                 norm: Normalize | None = None) -> AxesImage | None:
    """2-D histogram of node positions over the workspace with the obstacles drawn on top.

    Args:
        ax: The axes to draw on.
        env: The world (its bounds, obstacles and start).
        points: (N, >=2) node positions; the first two coordinates are binned.
        title: The axes' title.
        bins: Histogram bins per axis.
        goal: The goal's centre, drawn as a circle of ``radius`` when given.
        radius: The goal's radius (required with ``goal``).
        norm: The colour scale shared by several panels (the caller draws their one colour bar),
            or None (default) for this panel's own logarithmic scale and colour bar.

    Returns:
        The histogram's image (for a shared colour bar), or None without points.

    Raises:
        ValueError: If ``goal`` is given without ``radius``.
    """
    from matplotlib.colors import LogNorm
    from matplotlib.patches import Circle

    from ..plotting import plot_environment

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
    if env.start is not None:
        ax.plot(*env.start[:2], "o", color="tab:green", ms=6, zorder=4)
    if goal is not None:
        if radius is None:
            raise ValueError("node_heatmap: a goal needs its radius")
        centre: Any = goal[:2]  # an array; matplotlib takes any (x, y) sequence
        ax.add_patch(Circle(centre, radius, fill=False, color="tab:red", lw=2, zorder=4))
    ax.set_title(title, fontsize=9)
    return image
