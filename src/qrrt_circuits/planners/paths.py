"""Path length and shortcut simplification: what a planner's path costs, before and after the
cheapest post-processing every motion-planning study reports (OMPL's ``PathSimplifier`` does more:
random shortcuts, smoothing and vertex reduction).

``shortcut(path, predicate)`` is the deterministic greedy shortcut: from the first state, jump to
the farthest later state of the path that ``predicate`` can reach from it in one motion, and repeat
from there. Every motion of the result is a motion the predicate accepted, and the result is never
longer in the space's metric than the path it came from when the metric obeys the triangle
inequality (each jump replaces a chain of motions by one). Its checks are made through the
predicate and counted by it; they are post-processing, not part of a plan's oracle calls.
"""

from __future__ import annotations

import numpy as np

from ..reachability.predicate import ReachabilityPredicate
from ..world.spaces import RealVectorSpace, StateSpace

__all__ = ["path_length", "shortcut"]


def path_length(path: np.ndarray, space: StateSpace | None = None) -> float:
    """The sum of the space's distances between consecutive states of ``path``.

    Args:
        path: Float (L, d), L >= 1.
        space: The state space (default Euclidean ``RealVectorSpace``).

    Returns:
        The length (0 for a single state).
    """
    path = np.atleast_2d(np.asarray(path, dtype=float))
    if path.shape[0] < 2:
        return 0.0
    space = RealVectorSpace(path.shape[1]) if space is None else space
    return float(np.sum(space.distance(path[:-1], path[1:])))


def shortcut(path: np.ndarray, predicate: ReachabilityPredicate) -> np.ndarray:
    """The greedy shortcut of ``path`` (module docstring): at most L - 1 batched calls of
    ``predicate.reachable``, each on the states after the current one.

    Args:
        path: Float (L, d), every consecutive motion one the predicate accepts.
        predicate: The motion check.

    Returns:
        Float (L', d), L' <= L: the first and last states of ``path`` and a subsequence between.
    """
    path = np.atleast_2d(np.asarray(path, dtype=float))
    kept, current, last = [0], 0, path.shape[0] - 1
    while current < last:
        later = path[current + 1:]
        ok = np.asarray(predicate.reachable(np.repeat(path[current][None], len(later), axis=0), later), dtype=bool)
        reachable = np.flatnonzero(ok)
        current = current + 1 + int(reachable[-1]) if reachable.size else current + 1
        kept.append(current)
    return path[kept]
