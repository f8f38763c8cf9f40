"""Independent, slow reference checks used by the tests (no code shared with the oracle)."""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm


def dense_trajectory(A, B, K, parent, child, horizon=5.0, spacing=0.002):
    """Points of x(t) = c + expm((A-BK) t)(p - c) with consecutive points at most ``spacing``
    apart (time steps refined until they are)."""
    closed = np.asarray(A) - np.asarray(B) @ np.asarray(K)
    parent = np.asarray(parent, float)
    child = np.asarray(child, float)
    times = np.linspace(0.0, horizon, 2001)
    for _ in range(12):
        points = child + np.einsum("tij,j->ti", expm(times[:, None, None] * closed), parent - child)
        steps = np.linalg.norm(np.diff(points, axis=0), axis=1)
        if steps.max() <= spacing:
            return np.vstack([points, child])
        refine = np.flatnonzero(steps > spacing)
        extra = []
        for i in refine:
            pieces = int(np.ceil(steps[i] / spacing)) + 1
            extra.append(np.linspace(times[i], times[i + 1], pieces + 1)[1:-1])
        times = np.unique(np.concatenate([times, *extra]))
    raise RuntimeError("could not refine the trajectory")


def penetration_and_clearance(points, bounds, boxes):
    """(deepest penetration into any box or out of bounds, smallest distance to any obstacle or
    to the boundary) over ``points``; penetration <= 0 means no contact."""
    low, high = bounds[:, 0], bounds[:, 1]
    outside = np.max(np.maximum(low - points, points - high))
    to_bounds = np.min(np.minimum(points - low, high - points))
    deepest = outside
    clearance = to_bounds
    span_lo = points.min(axis=0) - 1.0
    span_hi = points.max(axis=0) + 1.0
    near = np.all((boxes[:, 1] >= span_lo) & (boxes[:, 0] <= span_hi), axis=1)
    for lo, hi in boxes[near]:
        inside_depth = np.min(np.minimum(points - lo, hi - points), axis=1)
        deepest = max(deepest, float(inside_depth.max()))
        gap = np.maximum(np.maximum(lo - points, points - hi), 0.0)
        clearance = min(clearance, float(np.linalg.norm(gap, axis=1).min()))
    return deepest, clearance


def diagonal_edge_hits(parent, child, rates, horizon, bounds, boxes, shrink=1e-9):
    """Exact test for a diagonal closed loop M = diag(rates), rates < 0: does
    x(t) = c + exp(M t)(p - c), t in [0, T], or the final point c meet any box shrunk by
    ``shrink`` (or leave the bounds)? Each coordinate is monotone, so the times a coordinate spends
    inside a box's slab form one interval, found with logarithms; the curve meets the box iff the
    intervals of all axes overlap. No sampling."""
    p = np.asarray(parent, float)
    c = np.asarray(child, float)
    e = p - c
    lo_all = np.minimum(p, c)
    hi_all = np.maximum(p, c)
    if np.any(lo_all < bounds[:, 0]) or np.any(hi_all > bounds[:, 1]):
        return True
    near = np.all((boxes[:, 1] - shrink >= lo_all) & (boxes[:, 0] + shrink <= hi_all), axis=1)
    for lo, hi in boxes[near]:
        lo = lo + shrink
        hi = hi - shrink
        if np.all((c >= lo) & (c <= hi)):
            return True
        t_start, t_end = 0.0, horizon
        for axis in range(len(p)):
            if e[axis] == 0.0:
                if not (lo[axis] <= c[axis] <= hi[axis]):
                    t_start, t_end = 1.0, 0.0
                    break
                continue
            s_a = (lo[axis] - c[axis]) / e[axis]
            s_b = (hi[axis] - c[axis]) / e[axis]
            s_lo, s_hi = min(s_a, s_b), max(s_a, s_b)  # exp(rate t) must lie in [s_lo, s_hi]
            if s_hi <= 0.0:
                t_start, t_end = 1.0, 0.0
                break
            t_lo = np.log(min(s_hi, 1.0)) / rates[axis] if s_hi < 1.0 else 0.0
            t_hi = np.log(s_lo) / rates[axis] if s_lo > 0.0 else np.inf
            if s_lo > 1.0:
                t_start, t_end = 1.0, 0.0
                break
            t_start, t_end = max(t_start, t_lo), min(t_end, t_hi)
            if t_start > t_end:
                break
        if t_start <= t_end:
            return True
    return False
