"""Figure helpers shared by the experiments (matplotlib with the Agg backend; only figures are
drawn here, never in the algorithms)."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def new_figure(rows: int = 1, cols: int = 1, size: tuple[float, float] | None = None):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(rows, cols, figsize=size or (5.0 * cols, 4.2 * rows), squeeze=False)
    return fig, axes


def save(fig, path: Path) -> Path:
    import matplotlib.pyplot as plt

    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def node_heatmap(ax, env, points: np.ndarray, title: str, bins: int = 50, goal=None, radius=None):
    """2-D histogram of node positions over the workspace with the obstacles drawn on top."""
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
        ax.add_patch(Circle(goal[:2], radius, fill=False, color="tab:red", lw=2, zorder=4))
    ax.set_title(title, fontsize=9)
