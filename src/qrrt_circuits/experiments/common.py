"""Helpers shared by the experiment modules: planners by name, growth curves, figures."""

from __future__ import annotations

import functools
import json
from pathlib import Path

import numpy as np

from .. import planners, scenarios
from ..search import AerBackend, StatevectorBackend
from ..search.schedules import IterationPolicy

PLANNER_KINDS = ("RRT", "ParallelRRT", "QRRT", "PQRRT", "PQRRT-unshared")

BACKEND_LABEL = {
    "aer": "Aer statevector simulator (gate-level circuits)",
    "statevector": "exact statevector (ideal; same statistics as Aer)",
}


def make_backend(name: str):
    if name == "aer":
        return AerBackend(max_parallel_threads=1)
    if name == "statevector":
        return StatevectorBackend()
    raise ValueError(f"backend must be 'aer' or 'statevector', got {name!r}")


def make_planner(kind: str, env, seed: int, backend: str = "aer", workers: int = 8,
                 num_qubits: int = 8, iterations: IterationPolicy | None = None, **options):
    """One of PLANNER_KINDS with the experiments' defaults (8 workers, 2^8 database)."""
    if kind == "RRT":
        return planners.RRT(env, seed=seed, **options)
    if kind == "ParallelRRT":
        return planners.ParallelRRT(env, workers=workers, seed=seed, **options)
    quantum = {"backend": make_backend(backend), "num_qubits": num_qubits, "iterations": iterations,
               "seed": seed, **options}
    if kind == "QRRT":
        return planners.QRRT(env, **quantum)
    if kind == "PQRRT":
        return planners.PQRRT(env, workers=workers, shared_database=True, **quantum)
    if kind == "PQRRT-unshared":
        return planners.PQRRT(env, workers=workers, shared_database=False, **quantum)
    raise ValueError(f"planner must be one of {PLANNER_KINDS}, got {kind!r}")


@functools.lru_cache(maxsize=16)
def _cached_world(name: str, seed: int, options: tuple):
    return scenarios.SCENARIOS[name](seed=seed, **dict(options))


def world(name: str, seed: int, **options):
    """The scenario (cached per process: environments are immutable)."""
    return _cached_world(name, int(seed) % (2**31), tuple(sorted(options.items())))


def growth_curve(result) -> list[list[int]]:
    """[[nodes, oracle_calls, critical_path_calls], ...] at every round that added a node."""
    history = result.history
    curve = []
    last = 0
    for nodes, calls, critical in zip(history["nodes"], history["oracle_calls"],
                                      history["critical_path"], strict=True):
        if nodes > last:
            curve.append([int(nodes), int(calls), int(critical)])
            last = nodes
    return curve


def cut_at(result, budget: int, on: str = "oracle_calls") -> tuple[int, int]:
    """(nodes, calls) of the same run stopped by ``max_oracle_calls=budget``: rounds start only
    while calls < budget, so the run ends after the first round that reaches the budget.
    ``on="critical_path"`` cuts on critical-path calls instead."""
    calls = result.history[on]
    nodes = result.history["nodes"]
    if len(calls) == 0:
        return 0, 0
    reached = np.flatnonzero(calls >= budget)
    index = int(reached[0]) if reached.size else len(calls) - 1
    return int(nodes[index]), int(calls[index])


def dumps(value) -> str:
    return json.dumps(value, separators=(",", ":"))


def loads(text):
    return json.loads(text) if isinstance(text, str) else text


def rounded(points: np.ndarray, digits: int = 3) -> list:
    return np.round(np.asarray(points, dtype=float), digits).tolist()


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
