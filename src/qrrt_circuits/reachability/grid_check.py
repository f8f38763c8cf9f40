"""The exact motion check of an occupancy grid: straight segments, every cell they touch.

Motion model: a motion from a parent p to a child c is the **straight segment** p -> c, with no
dynamics (OMPL's geometric planning, where a motion validator checks the straight interpolation
between two states). It is not the paper's closed-loop motion (DESIGN §2, ``ExactCheck``); the
check's ``describe()`` therefore has no ``"dynamics"`` key, and ``plotting`` draws its edges
straight.

A segment is reachable iff it lies in the grid's closed bounds and touches no occupied cell.
Cells are closed squares (as ``Environment``'s boxes are closed): a segment that runs along an
occupied cell's edge, or passes through a corner it shares with an occupied cell, touches that
cell and is rejected. With cell coordinates u = (x - ox) / s and v = (y - oy) / s, the cells
touched are found exactly by walking the segment slab by slab along its major axis (the axis of
its larger extent; the column-by-column form of the Amanatides-Woo grid traversal that also
reports the cells touched only at an edge or a corner): in slab k <= u <= k + 1 the segment's v
lies in an interval [v_lo, v_hi], and the cells touched there are the rows j with
j <= v_hi and j + 1 >= v_lo. Each interval is widened by ``EPSILON`` cell widths so that rounding
never drops a touched cell: the check is conservative; it accepts no segment that touches an
occupied cell, and rejects a free one only where it passes within ``EPSILON`` cell widths of an
occupied cell. (The cell coordinates are computed as (x - ox) / s of points in the bounds; the
subtraction's result lies in [0, cols s], so it is rounded by at most 2^-53 cols s whatever the
origin, and u is within 2^-52 cols cells of its exact value, under 1.5e-11 cells for the
``MAX_SIDE`` of ``world.image``. Walking the major axis keeps |dv / du| <= 1, so the computed
crossings are within a few units of rounding of the largest cell coordinate, under 1e-10 cells in
all.) The loop is compiled with numba and batched over M pairs; its cost is the number of cells
touched.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
from numba import njit

from .._support.validation import check_instance, check_real_array
from ..world.environment import Environment
from ..world.image import OccupancyGrid
from .predicate import as_pairs

__all__ = ["EPSILON", "GridCheck", "image_world"]

#: how far (in cell widths) the check widens each touched interval against rounding
EPSILON = 1e-9


@njit(cache=True, nogil=True)
def _span(low: float, high: float, count: int) -> tuple[int, int]:
    """The cells k in [0, count) whose closed [k, k + 1] meets [low - EPSILON, high + EPSILON]."""
    first = max(int(math.ceil(low - EPSILON)) - 1, 0)
    last = min(int(math.floor(high + EPSILON)), count - 1)
    return first, last


@njit(cache=True, nogil=True)
def _walk_free(a0: float, b0: float, a1: float, b1: float, occupied: np.ndarray, swapped: bool) -> bool:
    """Whether the segment (a0, b0) -> (a1, b1) in cell coordinates touches no occupied cell,
    walking slabs of the major axis a (``swapped``: a is v, the rows of ``occupied``)."""
    majors = occupied.shape[0] if swapped else occupied.shape[1]
    minors = occupied.shape[1] if swapped else occupied.shape[0]
    a_low, a_high = min(a0, a1), max(a0, a1)
    b_low, b_high = min(b0, b1), max(b0, b1)
    da = a1 - a0
    db = b1 - b0
    first, last = _span(a_low, a_high, majors)
    for k in range(first, last + 1):
        if da == 0.0:
            low, high = b_low, b_high
        else:
            # the part of the segment in the slab k <= a <= k + 1 (clamped to the segment)
            enter = min(max(float(k), a_low), a_high)
            leave = max(min(float(k + 1), a_high), a_low)
            b_enter = b0 if enter == a0 else (b1 if enter == a1 else b0 + (enter - a0) / da * db)
            b_leave = b0 if leave == a0 else (b1 if leave == a1 else b0 + (leave - a0) / da * db)
            low = max(min(b_enter, b_leave), b_low)
            high = min(max(b_enter, b_leave), b_high)
        j_first, j_last = _span(low, high, minors)
        for j in range(j_first, j_last + 1):
            if occupied[k, j] if swapped else occupied[j, k]:
                return False
    return True


@njit(cache=True, nogil=True)
def segments_free(parents: np.ndarray, children: np.ndarray, occupied: np.ndarray, origin_x: float,
                  origin_y: float, pixel_size: float, bounds: np.ndarray, out: np.ndarray) -> None:
    """``out[m]``: whether the straight segment ``parents[m]`` -> ``children[m]`` lies in the closed
    ``bounds`` (2, 2) and touches no cell of ``occupied`` (uint8 (rows, cols), row 0 the bottom:
    cell (j, i) is [i, i + 1] x [j, j + 1] in cell coordinates ((x - origin_x) / pixel_size,
    (y - origin_y) / pixel_size)); see the module docstring."""
    for m in range(parents.shape[0]):
        x0, y0 = parents[m, 0], parents[m, 1]
        x1, y1 = children[m, 0], children[m, 1]
        inside = (bounds[0, 0] <= x0 <= bounds[0, 1] and bounds[1, 0] <= y0 <= bounds[1, 1]
                  and bounds[0, 0] <= x1 <= bounds[0, 1] and bounds[1, 0] <= y1 <= bounds[1, 1])
        if not inside:
            out[m] = False
            continue
        u0, v0 = (x0 - origin_x) / pixel_size, (y0 - origin_y) / pixel_size
        u1, v1 = (x1 - origin_x) / pixel_size, (y1 - origin_y) / pixel_size
        if abs(u1 - u0) >= abs(v1 - v0):
            out[m] = _walk_free(u0, v0, u1, v1, occupied, False)
        else:
            out[m] = _walk_free(v0, u0, v1, u1, occupied, True)


class GridCheck:
    """The exact straight-segment motion check of an ``OccupancyGrid`` (a ``ReachabilityPredicate``;
    see the module docstring for the motion model, the closed-cell convention and ``EPSILON``).

    ``reachable(parents, children)`` is True iff the straight segment parent -> child lies in the
    grid's closed bounds and touches no occupied cell (corners and edges included). ``is_valid``
    asks the same of the zero-length segment at each point: a point is valid iff it is in bounds
    and every cell whose closed square contains it is free. This is a geometric check, as OMPL's
    motion validators are: the planners' edges are straight segments, not the paper's closed-loop
    trajectories.

    ``evaluations`` counts the pairs checked through this object.

    Args:
        grid: The ``OccupancyGrid``.
        name: The name recorded in results (default ``"grid"``).

    Raises:
        TypeError: ``grid`` not an ``OccupancyGrid``.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits import GridCheck, OccupancyGrid
        >>> free = np.ones((3, 3), dtype=bool)
        >>> free[1, 1] = False  # the centre cell of a 3 x 3 map of unit cells
        >>> check = GridCheck(OccupancyGrid(free, pixel_size=1.0))
        >>> parents = np.array([[0.5, 0.5], [0.5, 0.5], [0.5, 0.5]])
        >>> children = np.array([[2.5, 0.5], [2.5, 2.5], [0.5, 2.5]])
        >>> check.reachable(parents, children).tolist()  # the diagonal crosses the centre
        [True, False, True]
        >>> check.reachable(np.array([[0.0, 1.0]]), np.array([[3.0, 1.0]])).tolist()  # along its edge
        [False]
    """

    dim = 2

    def __init__(self, grid: OccupancyGrid, name: str = "grid") -> None:
        self.grid = check_instance(grid, "grid", OccupancyGrid, "an OccupancyGrid")
        self.name = str(name)
        self.evaluations = 0
        self._occupied = np.ascontiguousarray(~grid.free[::-1], dtype=np.uint8)  # row 0 the bottom
        self._bounds = np.ascontiguousarray(grid.bounds())

    def bounds(self) -> np.ndarray:
        """Float (2, 2): the grid's closed bounds (the planners refuse an environment beyond them)."""
        return self._bounds.copy()

    def describe(self) -> dict:
        """Name, the motion model (straight segments; no ``"dynamics"`` key), ``sound: True``, the
        closed-cell convention, ``EPSILON`` and the grid (``OccupancyGrid.describe``)."""
        return {"name": self.name, "motion": "straight-segment", "sound": True,
                "cells": "closed: touching an occupied cell at an edge or a corner is a collision",
                "epsilon_cells": EPSILON, "grid": self.grid.describe()}

    def reachable(self, parents: np.ndarray, children: np.ndarray) -> np.ndarray:
        """Whether each straight segment parent -> child stays in bounds and touches only free cells.

        Args:
            parents: Float (M, 2) (a single (2,) point is one pair), finite.
            children: Float array of the same shape.

        Returns:
            Bool (M,); adds M to ``evaluations``.

        Raises:
            ValueError: Shapes other than (M, 2), different shapes, or non-finite coordinates.
        """
        parents, children = as_pairs(parents, children, 2)
        out = np.zeros(parents.shape[0], dtype=np.bool_)
        self._check(parents, children, out)
        self.evaluations += int(parents.shape[0])
        return out

    def is_valid(self, points: np.ndarray) -> np.ndarray:
        """Bool (M,): each point is finite, in bounds, and every cell whose closed square contains
        it is free (the zero-length segment at the point is reachable). Not counted in
        ``evaluations``.

        Args:
            points: Float (M, 2) or (2,).

        Returns:
            Bool (M,).
        """
        points = np.atleast_2d(np.asarray(points, dtype=float))
        if points.ndim != 2 or points.shape[1] != 2:
            raise ValueError(f"points must have shape (M, 2), got {points.shape}")
        finite = np.all(np.isfinite(points), axis=1)
        checked = np.ascontiguousarray(np.where(finite[:, None], points, self._bounds[:, 0]))
        out = np.zeros(points.shape[0], dtype=np.bool_)
        self._check(checked, checked, out)
        return out & finite

    def can_leave(self, point: np.ndarray) -> bool:
        """False exactly where no motion from ``point`` can be accepted: an invalid point (every
        segment from it contains it). From a valid point every short enough segment into the
        bounds stays in the free cells that contain the point.

        Args:
            point: Float (2,).

        Returns:
            ``is_valid(point)``.
        """
        return bool(self.is_valid(np.asarray(point, dtype=float).reshape(1, -1))[0])

    def _check(self, parents: np.ndarray, children: np.ndarray, out: np.ndarray) -> None:
        origin_x, origin_y = self.grid.origin
        segments_free(parents, children, self._occupied, origin_x, origin_y, self.grid.pixel_size,
                      self._bounds, out)

    def __repr__(self) -> str:
        return f"GridCheck({self.grid!r})"


def image_world(path: str | Path, pixel_size: float, free_threshold: float = 0.5, negate: bool = False,
                origin: tuple[float, float] = (0.0, 0.0)) -> tuple[Environment, GridCheck]:
    """The world of an occupancy image: an ``Environment`` with the grid's bounds and no boxes
    (every obstacle is in the grid), and the ``GridCheck`` of its straight segments
    (``problems.families.image_problem`` adds a start and a goal).

    Args:
        path: A PNG, PGM or PPM file (``OccupancyGrid.from_image``).
        pixel_size: The side of a pixel in world units (a finite number > 0).
        free_threshold: A pixel is free where its grey value is >= this (in [0, 1]; default 0.5).
        negate: Read 1 - grey instead of grey (default False: white free).
        origin: The world position of the image's bottom-left corner (default (0, 0)).

    Returns:
        (environment, check); the environment is named after the file's stem.

    Raises:
        ValueError: Anything ``OccupancyGrid.from_image`` refuses.
        TypeError: A non-numeric ``pixel_size`` or ``free_threshold``.

    Example:
        >>> import os, tempfile
        >>> import qrrt_circuits as qc
        >>> path = os.path.join(tempfile.mkdtemp(), "room.pgm")
        >>> with open(path, "wb") as handle:  # a 4 x 4 room with one black pixel
        ...     _ = handle.write(b"P5 4 4 255\\n" + bytes([255] * 5 + [0] + [255] * 10))
        >>> env, check = qc.image_world(path, 1.0)
        >>> env.bounds.tolist(), check.is_valid([[1.5, 2.5], [0.5, 0.5]]).tolist()
        ([[0.0, 4.0], [0.0, 4.0]], [False, True])
    """
    grid = OccupancyGrid.from_image(path, pixel_size, free_threshold, negate, origin)
    return grid_world(grid, name=f"image:{Path(path).stem}")


def grid_world(grid: OccupancyGrid, name: str = "grid") -> tuple[Environment, GridCheck]:
    """The world of an ``OccupancyGrid``: an ``Environment`` with the grid's bounds and no boxes,
    and the grid's ``GridCheck`` (``image_world`` for a grid read from an image).

    Args:
        grid: The grid.
        name: The environment's name.

    Returns:
        (environment, check).
    """
    check = GridCheck(grid)
    return Environment(grid.bounds(), np.zeros((0, 2, 2)), name=name, metadata={"occupancy": grid.describe()}), check


def check_map_point(check: GridCheck, name: str, point: Any) -> None:
    """Refuse ``point`` unless it is a free point of the map (``check.is_valid``).

    Args:
        check: The grid's check.
        name: The point's name for the message (``"start"``, ``"goal"``).
        point: (x, y).

    Raises:
        ValueError: A point outside the bounds or in or on an occupied cell, naming the pixel.
    """
    point = check_real_array(point, name).reshape(-1)
    if point.shape == (2,) and np.all(np.isfinite(point)) and not check.is_valid(point)[0]:
        raise ValueError(f"{name} {point.tolist()} is not a free point of the map: {_why_invalid(check.grid, point)}; "
                         f"accepted: a point inside a free cell, within the bounds {check.grid.bounds().tolist()}")


def _why_invalid(grid: OccupancyGrid, point: np.ndarray) -> str:
    """Why ``GridCheck(grid).is_valid`` rejects ``point``: out of bounds, or the occupied image
    pixel (row, col) whose closed cell contains it."""
    bounds = grid.bounds()
    if not np.all((point >= bounds[:, 0]) & (point <= bounds[:, 1])):
        return "it lies outside the bounds"
    u = (point[0] - grid.origin[0]) / grid.pixel_size
    v = (point[1] - grid.origin[1]) / grid.pixel_size
    for col in sorted({min(int(math.floor(u)), grid.cols - 1), int(math.ceil(u)) - 1}):
        for row_up in sorted({min(int(math.floor(v)), grid.rows - 1), int(math.ceil(v)) - 1}):
            row = grid.rows - 1 - row_up
            if 0 <= col < grid.cols and 0 <= row < grid.rows and not grid.free[row, col]:
                return f"it lies in or on the boundary of the occupied image pixel (row {row}, col {col})"
    return "it lies within rounding of an occupied cell"
