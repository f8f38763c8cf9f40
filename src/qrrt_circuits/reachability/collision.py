"""Exact-up-to-resolution collision checking of closed-loop trajectories against boxes.

Each trajectory x(t) = c + Phi(t) e (e = p - c) is cut into chords [x(t_j), x(t_k)]. On a chord
of duration h the curve stays within delta = h^2/8 * |e| * a of the chord (a bounds |M^2 Phi(t)|),
so testing the chord exactly (slab test) against every box padded by delta on each side can never
miss a collision: a trajectory that touches an obstacle is always rejected. Chords are chosen
greedily so that delta <= resolution. A free trajectory is rejected only when a chord meets a box
padded by delta on every axis: the chord then lies within delta * sqrt(d) (Euclidean, at a corner)
of the box and the curve within delta of the chord, so the curve passes within
(1 + sqrt(d)) * resolution of the obstacle (0.0241 in 2-D at the default 0.01), or within
2 * resolution of the workspace boundary (a per-axis test). That is the documented bound on false
rejections (``false_rejection_bound``). A bound of ``resolution`` alone does not hold: free
trajectories with clearances between ``resolution`` and (1 + sqrt(d)) * ``resolution`` can be
rejected.

Boxes are found through a uniform grid (``GridIndex``), so the cost of a chord follows the boxes
near it, not all boxes. The inner loop is compiled with numba.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit


@dataclass(frozen=True, eq=False)
class GridIndex:
    """Uniform grid over the workspace; cell i lists the boxes overlapping it (CSR arrays).

    Cells are numbered row-major over ``shape``; the boxes of cell i are
    ``cell_items[cell_start[i]:cell_start[i + 1]]``, in index order.

    Args:
        origin: Float (d,), the workspace's lower corner.
        cell_size: Float (d,), a cell's side on each axis.
        shape: Int64 (d,), cells per axis.
        cell_start: Int64 (num_cells + 1,), CSR offsets.
        cell_items: Int64 (total,), box indices per cell.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits.reachability.collision import GridIndex
        >>> boxes = np.array([[[0.5, 0.5], [1.5, 1.5]], [[2.5, 2.5], [3.5, 3.5]]])
        >>> grid = GridIndex.build(np.array([[0.0, 4.0], [0.0, 4.0]]), boxes)
        >>> grid.shape.tolist(), grid.cell_start.tolist(), grid.cell_items.tolist()
        ([2, 2], [0, 1, 1, 1, 2], [0, 1])
    """

    origin: np.ndarray
    cell_size: np.ndarray
    shape: np.ndarray
    cell_start: np.ndarray
    cell_items: np.ndarray

    @classmethod
    def build(
        cls, bounds: np.ndarray, boxes: np.ndarray, max_cells: int = 1 << 20
    ) -> GridIndex:
        """Index ``boxes`` on a grid of about one box per cell, cells no smaller than a typical box.

        Args:
            bounds: Float (d, 2), the workspace.
            boxes: Float (k, 2, d), lower and upper corners.
            max_cells: The most cells (default 2^20); cells are enlarged until they fit.

        Returns:
            The ``GridIndex``.
        """
        d = bounds.shape[0]
        extent = bounds[:, 1] - bounds[:, 0]
        count = max(len(boxes), 1)
        if len(boxes):
            typical = float(np.median(np.max(boxes[:, 1] - boxes[:, 0], axis=1)))
        else:
            typical = float(np.max(extent))
        # about one box per cell, but never cells much smaller than a box
        edge = max((float(np.prod(extent)) / count) ** (1.0 / d), typical, 1e-9)
        shape = np.maximum(np.ceil(extent / edge).astype(np.int64), 1)
        while int(np.prod(shape)) > max_cells:
            edge *= 1.25
            shape = np.maximum(np.ceil(extent / edge).astype(np.int64), 1)
        cell_size = extent / shape
        strides = np.ones(d, dtype=np.int64)
        for axis in range(d - 2, -1, -1):
            strides[axis] = strides[axis + 1] * shape[axis + 1]
        num_cells = int(np.prod(shape))
        cells, items = _box_cells(bounds, boxes, cell_size, shape, strides)
        order = np.lexsort((items, cells))  # by cell, boxes in index order within a cell
        cell_start = np.zeros(num_cells + 1, dtype=np.int64)
        np.cumsum(np.bincount(cells, minlength=num_cells), out=cell_start[1:])
        cell_items = np.ascontiguousarray(items[order])
        return cls(bounds[:, 0].copy(), cell_size, shape, cell_start, cell_items)


def _box_cells(bounds: np.ndarray, boxes: np.ndarray, cell_size: np.ndarray, shape: np.ndarray,
               strides: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(cell, box) for every grid cell every box overlaps, vectorized over the boxes (no Python
    loop per box)."""
    if len(boxes) == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    lo = np.clip(np.floor((boxes[:, 0] - bounds[:, 0]) / cell_size).astype(np.int64), 0, shape - 1)
    hi = np.clip(np.floor((boxes[:, 1] - bounds[:, 0]) / cell_size).astype(np.int64), 0, shape - 1)
    span = hi - lo + 1
    counts = np.prod(span, axis=1)
    items = np.repeat(np.arange(len(boxes), dtype=np.int64), counts)
    remainder = np.arange(int(counts.sum()), dtype=np.int64) - np.repeat(np.cumsum(counts) - counts, counts)
    cells = np.zeros_like(items)
    for axis in range(bounds.shape[0] - 1, -1, -1):  # unravel the index within each box's cell range
        axis_span = span[items, axis]
        cells += (lo[items, axis] + remainder % axis_span) * strides[axis]
        remainder //= axis_span
    return cells, items


@njit(cache=True, nogil=True)
def _segment_hits_box(p: np.ndarray, q: np.ndarray, lo: np.ndarray, hi: np.ndarray, pad: float) -> bool:
    """Closed slab test: does segment p->q meet the box [lo - pad, hi + pad]?"""
    t0 = 0.0
    t1 = 1.0
    for axis in range(p.shape[0]):
        a = lo[axis] - pad
        b = hi[axis] + pad
        direction = q[axis] - p[axis]
        if abs(direction) < 1e-300:
            if p[axis] < a or p[axis] > b:
                return False
        else:
            ta = (a - p[axis]) / direction
            tb = (b - p[axis]) / direction
            if ta > tb:
                ta, tb = tb, ta
            if ta > t0:
                t0 = ta
            if tb < t1:
                t1 = tb
            if t0 > t1:
                return False
    return True


@njit(cache=True, nogil=True)
def _segment_free(p: np.ndarray, q: np.ndarray, pad: float, bounds: np.ndarray, lower: np.ndarray,
                  upper: np.ndarray, origin: np.ndarray, cell_size: np.ndarray, shape: np.ndarray,
                  cell_start: np.ndarray, cell_items: np.ndarray, stamp: np.ndarray, stamp_id: int,
                  lo_cell: np.ndarray, hi_cell: np.ndarray, cursor: np.ndarray) -> bool:
    d = p.shape[0]
    for axis in range(d):
        if min(p[axis], q[axis]) - pad < bounds[axis, 0] or max(p[axis], q[axis]) + pad > bounds[axis, 1]:
            return False
    for axis in range(d):
        a = int(np.floor((min(p[axis], q[axis]) - pad - origin[axis]) / cell_size[axis]))
        b = int(np.floor((max(p[axis], q[axis]) + pad - origin[axis]) / cell_size[axis]))
        lo_cell[axis] = min(max(a, 0), shape[axis] - 1)
        hi_cell[axis] = min(max(b, 0), shape[axis] - 1)
        cursor[axis] = lo_cell[axis]
    while True:
        cell = 0
        for axis in range(d):
            cell = cell * shape[axis] + cursor[axis]
        for item in range(cell_start[cell], cell_start[cell + 1]):
            box = cell_items[item]
            if stamp[box] != stamp_id:
                stamp[box] = stamp_id
                if _segment_hits_box(p, q, lower[box], upper[box], pad):
                    return False
        axis = d - 1
        while axis >= 0:
            cursor[axis] += 1
            if cursor[axis] <= hi_cell[axis]:
                break
            cursor[axis] = lo_cell[axis]
            axis -= 1
        if axis < 0:
            return True


@njit(cache=True, nogil=True)
def trajectories_free(parents: np.ndarray, children: np.ndarray, times: np.ndarray, phis: np.ndarray,
                      curvature: np.ndarray, resolution: float, bounds: np.ndarray, lower: np.ndarray,
                      upper: np.ndarray, origin: np.ndarray, cell_size: np.ndarray, shape: np.ndarray,
                      cell_start: np.ndarray, cell_items: np.ndarray, out: np.ndarray) -> np.ndarray:
    """out[i] = trajectory parents[i] -> children[i] stays in bounds and misses every box.

    Compiled (numba). Chords are merged greedily while their error bound ``h^2/8 |e| a`` stays below
    ``resolution``; each is tested against the boxes padded by that bound (module docstring),
    and the last chord to the child c itself unpadded.

    Args:
        parents: Float (M, d), the start points p.
        children: Float (M, d), the targets c.
        times: Float (S + 1,), increasing times t_0 = 0 .. T.
        phis: Float (S + 1, d, d), expm(M t_j).
        curvature: Float (S,), a bound on ``|M^2 Phi(t)|`` over each interval.
        resolution: The largest chord error bound (> 0).
        bounds: Float (d, 2), the workspace.
        lower: Float (k, d), the boxes' lower corners.
        upper: Float (k, d), the boxes' upper corners.
        origin: ``GridIndex.origin``.
        cell_size: ``GridIndex.cell_size``.
        shape: ``GridIndex.shape``.
        cell_start: ``GridIndex.cell_start``.
        cell_items: ``GridIndex.cell_items``.
        out: Bool (M,), written in place.

    Returns:
        ``out``.
    """
    d = parents.shape[1]
    num_intervals = times.shape[0] - 1
    stamp = np.full(lower.shape[0], -1, dtype=np.int64)
    stamp_id = 0
    lo_cell = np.zeros(d, dtype=np.int64)
    hi_cell = np.zeros(d, dtype=np.int64)
    cursor = np.zeros(d, dtype=np.int64)
    e = np.zeros(d)
    p = np.zeros(d)
    q = np.zeros(d)
    for i in range(parents.shape[0]):
        norm = 0.0
        for axis in range(d):
            e[axis] = parents[i, axis] - children[i, axis]
            norm += e[axis] * e[axis]
        norm = np.sqrt(norm)
        for axis in range(d):
            p[axis] = parents[i, axis]
        free = True
        j = 0
        while j < num_intervals:
            # merge intervals j..k-1 while the chord error bound stays below the resolution
            k = j + 1
            amax = curvature[j]
            while k < num_intervals:
                a_next = max(amax, curvature[k])
                h = times[k + 1] - times[j]
                if h * h * 0.125 * norm * a_next > resolution:
                    break
                amax = a_next
                k += 1
            h = times[k] - times[j]
            pad = h * h * 0.125 * norm * amax
            for axis in range(d):
                acc = children[i, axis]
                for col in range(d):
                    acc += phis[k, axis, col] * e[col]
                q[axis] = acc
            stamp_id += 1
            if not _segment_free(p, q, pad, bounds, lower, upper, origin, cell_size, shape,
                                 cell_start, cell_items, stamp, stamp_id, lo_cell, hi_cell,
                                 cursor):
                free = False
                break
            for axis in range(d):
                p[axis] = q[axis]
            j = k
        if free:
            # x(T) is within |expm(M T) e| of c; the node added is c itself, so check that chord too
            for axis in range(d):
                q[axis] = children[i, axis]
            stamp_id += 1
            free = _segment_free(p, q, 0.0, bounds, lower, upper, origin, cell_size, shape,
                                 cell_start, cell_items, stamp, stamp_id, lo_cell, hi_cell, cursor)
        out[i] = free
    return out


@njit(cache=True, nogil=True)
def points_free(points: np.ndarray, bounds: np.ndarray, lower: np.ndarray, upper: np.ndarray, origin: np.ndarray,
                cell_size: np.ndarray, shape: np.ndarray, cell_start: np.ndarray, cell_items: np.ndarray,
                out: np.ndarray) -> np.ndarray:
    """out[i] = points[i] lies in the closed bounds and outside every closed box.

    Compiled (numba); only the boxes listed in the point's grid cell are tested.

    Args:
        points: Float (M, d).
        bounds: Float (d, 2), the workspace.
        lower: Float (k, d), the boxes' lower corners.
        upper: Float (k, d), the boxes' upper corners.
        origin: ``GridIndex.origin``.
        cell_size: ``GridIndex.cell_size``.
        shape: ``GridIndex.shape``.
        cell_start: ``GridIndex.cell_start``.
        cell_items: ``GridIndex.cell_items``.
        out: Bool (M,), written in place.

    Returns:
        ``out``.
    """
    d = points.shape[1]
    for i in range(points.shape[0]):
        free = True
        cell = 0
        for axis in range(d):
            x = points[i, axis]
            if x < bounds[axis, 0] or x > bounds[axis, 1]:
                free = False
                break
            c = int(np.floor((x - origin[axis]) / cell_size[axis]))
            c = min(max(c, 0), shape[axis] - 1)
            cell = cell * shape[axis] + c
        if free:
            for item in range(cell_start[cell], cell_start[cell + 1]):
                box = cell_items[item]
                inside = True
                for axis in range(d):
                    if points[i, axis] < lower[box, axis] or points[i, axis] > upper[box, axis]:
                        inside = False
                        break
                if inside:
                    free = False
                    break
        out[i] = free
    return out
