"""Figure helpers shared by the experiments (matplotlib with the Agg backend; only figures are
drawn here, never in the algorithms)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..environment import Environment


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


def save(fig: Figure, path: Path) -> Path:
    """Lay out ``fig``, write it to ``path`` (110 dpi) and close it.

    Args:
        fig: The figure.
        path: Where to write it (the format follows the suffix).

    Returns:
        ``path``.
    """
    import matplotlib.pyplot as plt

    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def node_heatmap(ax: Axes, env: Environment, points: np.ndarray, title: str, bins: int = 50,
                 goal: np.ndarray | None = None, radius: float | None = None) -> None:
    """2-D histogram of node positions over the workspace with the obstacles drawn on top.

    Args:
        ax: The axes to draw on.
        env: The world (its bounds, obstacles and start).
        points: (N, >=2) node positions; the first two coordinates are binned.
        title: The axes' title.
        bins: Histogram bins per axis.
        goal: The goal's centre, drawn as a circle of ``radius`` when given.
        radius: The goal's radius (required with ``goal``).

    Raises:
        ValueError: If ``goal`` is given without ``radius``.
    """
    from matplotlib.colors import LogNorm
    from matplotlib.patches import Circle

    from ..plotting import plot_environment

    (x0, x1), (y0, y1) = env.bounds[0], env.bounds[1]
    if len(points):
        counts, xe, ye = np.histogram2d(points[:, 0], points[:, 1], bins=bins,
                                        range=[[x0, x1], [y0, y1]])
        masked = np.ma.masked_equal(counts.T, 0)
        image = ax.imshow(masked, origin="lower", extent=(x0, x1, y0, y1), cmap="plasma",
                          norm=LogNorm(vmin=1, vmax=max(counts.max(), 2)), interpolation="nearest", zorder=3)
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
