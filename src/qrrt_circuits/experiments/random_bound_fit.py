"""The paper's Fig. 9 estimator, resampled from our trees.

The authors' driver grows each tree to a random node bound (``oracbound = 30*rand()``: the tree
grows while it has fewer nodes than the bound, so it stops at the first round with at least
``ceil(30 u)`` nodes, u uniform in (0, 1)) and plots one (nodes, oracle calls) point per tree; the
figure's slope is a least-squares line through those points. One replicate of that design is far
less precise than a line through every point of every full growth curve (our ``interval_95``), so
whether the paper's number is plausible is asked of that estimator's own sampling distribution:
``random_bound_slopes`` draws it by resampling our trees (with replacement) and a bound per tree.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["calls_at_bounds", "random_bound_slopes"]


def calls_at_bounds(curve: np.ndarray, max_bound: int) -> np.ndarray:
    """(nodes, calls) of a tree stopped at each bound b = 1 .. ``max_bound``: the first point of its
    growth curve with at least b nodes (NaN where the tree never reached b).

    Args:
        curve: (K, >= 2) growth curve, rows (nodes, oracle calls, ...) with nodes increasing
            (``measures.growth_curve``).
        max_bound: The largest bound (the driver's 30).

    Returns:
        (max_bound, 2) array of (nodes, calls).
    """
    curve = np.asarray(curve, dtype=float)
    out = np.full((max_bound, 2), np.nan)
    if curve.size == 0:
        return out
    bounds = np.arange(1, max_bound + 1)
    first = np.searchsorted(curve[:, 0], bounds, side="left")  # first row with nodes >= b
    reached = first < len(curve)
    out[reached] = curve[first[reached], :2]
    return out


def random_bound_slopes(curves: Sequence[np.ndarray], trees: int, resamples: int, rng: np.random.Generator,
                        max_bound: int = 30) -> np.ndarray:
    """Slopes of the paper's estimator over ``resamples`` replicates of its design.

    Each replicate draws ``trees`` of our trees with replacement and, for each, a bound
    b = max(1, ceil(``max_bound`` u)); the tree contributes its (nodes, calls) at b, and the
    replicate's slope is the ordinary least-squares slope through its points (with intercept).

    Args:
        curves: One growth curve per tree of one planner.
        trees: Trees (points) per replicate.
        resamples: Replicates.
        rng: The random generator.
        max_bound: The driver's largest bound.

    Returns:
        (resamples,) slopes; NaN for a replicate whose points share one node count.

    Raises:
        ValueError: If there is no curve, or ``trees`` or ``resamples`` is below 1 (or 2 trees).
    """
    if not curves:
        raise ValueError("random_bound_slopes needs at least one growth curve")
    if trees < 2 or resamples < 1:
        raise ValueError(f"trees must be >= 2 and resamples >= 1, got {trees} and {resamples}")
    table = np.stack([calls_at_bounds(curve, max_bound) for curve in curves])  # (trees, bound, 2)
    which = rng.integers(len(curves), size=(resamples, trees))
    bound = np.maximum(1, np.ceil(max_bound * rng.random((resamples, trees)))).astype(int)
    points = table[which, bound - 1]  # (resamples, trees, 2)
    x, y = points[..., 0], points[..., 1]
    dx = x - np.nanmean(x, axis=1, keepdims=True)
    dy = y - np.nanmean(y, axis=1, keepdims=True)
    spread = np.nansum(dx * dx, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(spread > 0, np.nansum(dx * dy, axis=1) / spread, np.nan)
