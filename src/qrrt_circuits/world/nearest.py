"""Nearest-neighbour structures: which stored point is nearest to a query (OMPL's
``NearestNeighbors``), one structure per plan, chosen by the plan's state space
(``StateSpace.nearest_neighbors``).

A structure holds points in the order they were added (index 0 first) and answers, for each
query, the index of the nearest point under its metric; among equally near points the lowest
index. Two are built in:

- ``LinearNearest(space)``: a scan of every point under ``space.distance``; any metric (a space
  of your own).
- ``SE2Nearest(w)``: ``SE2Space``'s metric, exact and compiled, a scan below
  ``BRUTE_FORCE_BELOW_SE2`` points and an (x, y) bucket grid from there.
- ``GridNearest(dim)``: Euclidean, exact and compiled (``RealVectorSpace``'s). Below
  ``BRUTE_FORCE_BELOW`` points it searches by brute force (every query against every point, one
  pass over the points for all the queries at once, so the inner loop over the queries
  vectorizes). From there it keeps a uniform bucket grid over the bounding box of the points it
  held at the grid's last build, about one point per cell, in compressed form: the points sorted
  by cell with their coordinates copied in that order, and the offset of each cell's first point
  (a cell's points, and a run of cells along the last axis, are one contiguous slice). A query
  first scans, by the same brute force, the points added since the build (fewer than
  ``_pending_limit(built)``: max(32, sqrt(built))), then visits the grid's cells ring by ring
  (Chebyshev rings around its own cell, the first visit the block of 3^d cells around it; a nearer
  point replaces the best by selects, not branches) and stops once the distance from the query to
  the part of the grid not yet visited exceeds the best distance found (the cell technique of
  Bentley, Weide and Yao 1980). When the points added since the build reach that limit the grid
  is rebuilt (O(N), so O(sqrt N) amortized per point). A query therefore costs about the points of
  a few cells plus the recent points, however large the structure. It answers what a brute-force
  search does, ties and rounding-level near-ties included: the stopping bound allows for the
  rounding of a point's cell (tested on adversarial cell-edge cases). ``BRUTE_FORCE_BELOW`` is
  calibrated: the size from which the grid search costs less than brute force.
"""

from __future__ import annotations

import math
import threading
from typing import TYPE_CHECKING, Protocol, runtime_checkable

import numpy as np
from numba import njit

if TYPE_CHECKING:
    from .spaces import StateSpace

__all__ = ["BRUTE_FORCE_BELOW", "BRUTE_FORCE_BELOW_SE2", "GridNearest", "LinearNearest", "NearestNeighbors",
           "SE2Nearest"]

#: cells per point when the grid is (re)built, and the most cells one grid has
_CELLS_PER_NODE = 1.0
_MAX_CELLS = 1 << 22
#: structures with fewer points answer queries by brute force (see the module docstring)
BRUTE_FORCE_BELOW = 400
#: ``SE2Nearest`` scans every point below this size, and keeps an (x, y) grid from there (calibrated:
#: from about this size a batch of queries costs less through the grid)
BRUTE_FORCE_BELOW_SE2 = 64
#: the fewest points added since the grid's build that trigger a rebuild (see ``_pending_limit``)
_PENDING_MIN = 32
#: relative rounding allowance of the grid's stopping bound (a few units in the last place)
_EDGE_SLACK = 16 * float(np.finfo(float).eps)
_NOT_FINITE = "points must be finite (no NaN or infinity)"
#: serializes the lazy grid builds of ``GridNearest.grid_nearest`` (queries may come from several
#: threads)
_FIRST_GRID = threading.Lock()
#: queries times points per chunk of ``LinearNearest``'s scan (bounds its scratch memory)
_CHUNK = 1 << 20
#: the initial room of a structure's point buffer (grown by doubling)
_CAPACITY = 256


def _pending_limit(built: int) -> int:
    """Points added since a grid of ``built`` points was built at which it is rebuilt: max(32,
    isqrt(built)) (queries scan those points by brute force; a rebuild costs O(built))."""
    return max(_PENDING_MIN, math.isqrt(built))


@runtime_checkable
class NearestNeighbors(Protocol):
    """Points added in order, and the nearest of them to a query (see the module docstring).

    The point added first has index 0, the next 1, and so on. ``nearest`` is exact under the
    structure's metric; among equally near points it answers the lowest index.
    """

    @property
    def size(self) -> int:
        """The number of points added."""
        ...

    def add(self, points: np.ndarray) -> None:
        """Append the rows of ``points`` (m, d), indices ``size .. size + m - 1``."""
        ...

    def nearest(self, queries: np.ndarray) -> np.ndarray:
        """Int (M,): the index of the point nearest to each row of ``queries`` ((M, d) or (d,))."""
        ...

    def nearest_distance_from(self, queries: np.ndarray, first: int) -> np.ndarray:
        """Float (M,): the distance from each row of ``queries`` to the nearest of the points of
        index ``first`` on (``inf`` where there are none): whether a point added since index
        ``first`` may have taken a query's nearest."""
        ...


class _Points:
    """A growable (size, d) buffer of points, the storage every structure keeps of what it holds."""

    def __init__(self, dim: int, capacity: int = _CAPACITY) -> None:
        self.dim = dim
        self._buffer = np.empty((max(1, capacity), dim))
        self.size = 0

    @property
    def points(self) -> np.ndarray:
        """Float (size, d) view of the points added, in order."""
        return self._buffer[: self.size]

    def add(self, points: np.ndarray) -> None:
        """Append the rows of ``points`` (m, d).

        Raises:
            ValueError: ``points`` not of shape (m, d) for the structure's d.
        """
        if points.ndim != 2 or points.shape[1] != self.dim:
            raise ValueError(f"points must have shape (m, {self.dim}) (the structure's d), got {points.shape}")
        count = points.shape[0]
        size = self.size
        if size + count > self._buffer.shape[0]:
            capacity = self._buffer.shape[0]
            while capacity < size + count:
                capacity *= 2
            grown = np.empty((capacity, self.dim))
            grown[:size] = self._buffer[:size]
            self._buffer = grown
        self._buffer[size:size + count] = points
        self.size = size + count

    def queries(self, queries: np.ndarray) -> np.ndarray:
        """``queries`` as a C-contiguous float (M, d) array.

        Raises:
            ValueError: ``queries`` not of shape (M, d) or (d,) for the structure's d, or no point
                added yet.
        """
        queries = np.ascontiguousarray(np.atleast_2d(queries), dtype=float)
        if queries.ndim != 2 or queries.shape[1] != self.dim:
            raise ValueError(f"points must have shape (M, {self.dim}) (the structure's d), got {queries.shape}")
        if not self.size:
            raise ValueError("the structure holds no points yet: add one before asking for the nearest")
        return queries


class LinearNearest(_Points):
    """Exact nearest points under any space's metric, by a scan of every point (OMPL's
    ``NearestNeighborsLinear``).

    A query's nearest point is the ``argmin`` over the points of ``space.distance(query, point)``
    (computed as ``space.distance`` of the query repeated against the points in order, so the
    first of equally near points); the scan runs over chunks of queries of at most 2^20 (query,
    point) pairs.

    Args:
        space: The ``StateSpace`` whose ``distance`` (and ``dim``) the structure uses.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits.world.nearest import LinearNearest
        >>> from qrrt_circuits.world.spaces import SE2Space
        >>> near = LinearNearest(SE2Space())
        >>> near.add(np.array([[0.0, 0.0, 0.0], [0.0, 0.3, 3.1]]))
        >>> near.nearest(np.array([[0.0, 0.3, -3.1], [1.0, 0.0, 0.0]])).tolist()  # theta wraps
        [1, 0]
    """

    def __init__(self, space: StateSpace) -> None:
        super().__init__(space.dim)
        self.space = space

    def nearest(self, queries: np.ndarray) -> np.ndarray:
        """Int (M,): the index of the point nearest to each of ``queries`` ((M, d) or (d,)) under
        the space's distance; among equally near points the lowest index.

        Raises:
            ValueError: ``queries`` of the wrong shape, or no point added yet.
        """
        queries = self.queries(queries)
        points = self.points
        count = points.shape[0]
        out = np.empty(queries.shape[0], dtype=np.int64)
        step = max(1, _CHUNK // count)
        for first in range(0, queries.shape[0], step):
            block = queries[first:first + step]
            distance = self.space.distance(np.repeat(block, count, axis=0), np.tile(points, (block.shape[0], 1)))
            out[first:first + block.shape[0]] = np.argmin(distance.reshape(block.shape[0], count), axis=1)
        return out

    def nearest_distance_from(self, queries: np.ndarray, first: int) -> np.ndarray:
        """Float (M,): the distance, under the space's metric, from each of ``queries`` to the
        nearest of the points of index ``first`` on (``inf`` where there are none)."""
        queries = self.queries(queries)
        points = self.points[max(0, first):]
        count = points.shape[0]
        out = np.full(queries.shape[0], np.inf)
        step = max(1, _CHUNK // max(count, 1))
        for start in range(0, queries.shape[0] if count else 0, step):
            block = queries[start:start + step]
            distance = self.space.distance(np.repeat(block, count, axis=0), np.tile(points, (block.shape[0], 1)))
            out[start:start + block.shape[0]] = distance.reshape(block.shape[0], count).min(axis=1)
        return out


@njit(cache=True, nogil=True)
def _se2_scan(queries: np.ndarray, points: np.ndarray, first: int, stop: int, weight: float, best: np.ndarray,
              out: np.ndarray) -> None:
    """For each query, the nearest of points ``first .. stop - 1`` under the SE(2) metric into
    ``best`` (distance) and ``out`` (index; the lowest among equals): the operations of
    ``SE2Space.distance`` (offset = point - query, ``hypot`` of the position, the angle wrapped to
    [-pi, pi) by ``mod`` and taken absolute, times ``weight``), in that order, so the same bits."""
    two_pi = 2 * math.pi
    for row in range(queries.shape[0]):
        x, y, theta = queries[row, 0], queries[row, 1], queries[row, 2]
        nearest, index = np.inf, first
        for point in range(first, stop):
            turn = np.mod(points[point, 2] - theta + math.pi, two_pi) - math.pi
            distance = math.hypot(points[point, 0] - x, points[point, 1] - y) + weight * abs(turn)
            if distance < nearest:
                nearest, index = distance, point
        best[row] = nearest
        out[row] = index


@njit(cache=True, nogil=True, inline="always")
def _unvisited_bound(point: np.ndarray, outside: np.ndarray, outside_total: float, slack: np.ndarray,
                     centre: np.ndarray, ring: int, origin: np.ndarray, cell: float,
                     shape: np.ndarray) -> tuple[float, bool]:
    """(a lower bound on the squared distance from ``point`` to any grid cell outside the block of
    Chebyshev radius ``ring`` around ``centre``, whether that block covers the whole grid).

    Beyond one side of one axis: the gap to that side plus, along the other axes, the point's
    distance to the grid nodes' bounding box (``outside``, squares summed in ``outside_total``).
    Each gap is shortened by ``slack``, a few units in the last place of the coordinates involved:
    a node is filed by int((x - origin) / cell), which can put a node lying a rounding error below
    a computed edge origin + k * cell into cell k, and the search must not stop before reaching it
    (a node as near as the best, or a tie with a lower index)."""
    bound = np.inf
    covers = True
    for axis in range(point.shape[0]):
        others = outside_total - outside[axis] * outside[axis]
        if centre[axis] - ring - 1 >= 0:
            covers = False
            gap = max(point[axis] - (origin[axis] + (centre[axis] - ring) * cell) - slack[axis], 0.0)
            bound = min(bound, gap * gap + others)
        if centre[axis] + ring + 1 <= shape[axis] - 1:
            covers = False
            gap = max(origin[axis] + (centre[axis] + ring + 1) * cell - point[axis] - slack[axis], 0.0)
            bound = min(bound, gap * gap + others)
    return bound, covers


@njit(cache=True, nogil=True)
def _se2_grid_search(queries: np.ndarray, start: np.ndarray, order: np.ndarray, ordered: np.ndarray,
                     origin: np.ndarray, cell: float, shape: np.ndarray, low: np.ndarray, high: np.ndarray,
                     weight: float, best: np.ndarray, out: np.ndarray) -> None:
    """Ring search of an (x, y) bucket grid under the SE(2) metric, from the nearest (``best``,
    ``out``) found so far: for each query, the point with the smallest (distance, index), the
    distance computed as ``_se2_scan`` computes it (the same bits). The grid files the points by
    (x, y) (``ordered``: their (x, y, theta) sorted by cell); the metric is at least the (x, y)
    distance, so the rings stop, as ``_grid_search``'s, once every cell left is farther in (x, y)
    than the best distance found."""
    two_pi = 2 * math.pi
    centre = np.empty(2, dtype=np.int64)
    here = np.empty(2)
    outside = np.empty(2)
    slack = np.empty(2)
    for row in range(queries.shape[0]):
        x, y, theta = queries[row, 0], queries[row, 1], queries[row, 2]
        here[0], here[1] = x, y
        _cell_of(here, origin, cell, shape, centre)
        outside_total = 0.0
        for axis in range(2):
            outside[axis] = max(low[axis] - here[axis], here[axis] - high[axis], 0.0)
            outside_total += outside[axis] * outside[axis]
            slack[axis] = _EDGE_SLACK * (abs(here[axis]) + abs(origin[axis]) + shape[axis] * cell)
        nearest, nearest_index = best[row], out[row]
        ring = 1  # the first visit covers rings 0 and 1 (the 3 x 3 cells around the centre)
        while True:
            lower_y, upper_y = max(centre[1] - ring, 0), min(centre[1] + ring, shape[1] - 1)
            for cell_x in range(max(centre[0] - ring, 0), min(centre[0] + ring, shape[0] - 1) + 1):
                prefix = cell_x * shape[1]
                on_ring = ring == 1 or abs(cell_x - centre[0]) == ring
                for end in range(2):  # on the ring: the run of cells along y once; else its two end cells
                    if on_ring:
                        if end:
                            break
                        first, stop = start[prefix + lower_y], start[prefix + upper_y + 1]
                    else:
                        cell_y = centre[1] - ring if end == 0 else centre[1] + ring
                        if cell_y < 0 or cell_y > shape[1] - 1:
                            continue
                        first, stop = start[prefix + cell_y], start[prefix + cell_y + 1]
                    for slot in range(first, stop):
                        turn = np.mod(ordered[slot, 2] - theta + math.pi, two_pi) - math.pi
                        distance = math.hypot(ordered[slot, 0] - x, ordered[slot, 1] - y) + weight * abs(turn)
                        candidate = order[slot]
                        if distance < nearest or (distance == nearest and candidate < nearest_index):
                            nearest, nearest_index = distance, candidate
            # the squared (x, y) distance from the query to any cell outside the visited block
            bound, covers = _unvisited_bound(here, outside, outside_total, slack, centre, ring, origin, cell, shape)
            reach = nearest * (1.0 + _EDGE_SLACK)
            if covers or bound > reach * reach:  # every cell visited, or none left nearer
                break
            ring += 1
        best[row] = nearest
        out[row] = nearest_index


@njit(cache=True, nogil=True)
def _se2_nearest_into(queries: np.ndarray, points: np.ndarray, size: int, built: int, start: np.ndarray,
                      order: np.ndarray, ordered: np.ndarray, origin: np.ndarray, cell: float, shape: np.ndarray,
                      low: np.ndarray, high: np.ndarray, weight: float, out: np.ndarray) -> None:
    """``SE2Nearest.nearest`` compiled: the scan of the points the grid does not hold (all of them
    without a grid, ``built`` = 0), then the grid's ring search from that best.

    Raises:
        ValueError: A query that is not finite.
    """
    for row in range(queries.shape[0]):
        for axis in range(3):
            if not np.isfinite(queries[row, axis]):
                raise ValueError(_NOT_FINITE)
    best = np.empty(queries.shape[0])
    _se2_scan(queries, points, built, size, weight, best, out)
    if built:
        _se2_grid_search(queries, start, order, ordered, origin, cell, shape, low, high, weight, best, out)


class SE2Nearest(_Points):
    """Exact nearest points under an ``SE2Space``'s metric, compiled: it answers what
    ``LinearNearest(space)`` answers, bit for bit, ties to the lowest index.

    Below ``BRUTE_FORCE_BELOW_SE2`` points every query scans every point (OMPL's
    ``NearestNeighborsLinear``) with the space's own operations. From there it keeps a bucket grid
    over the points' (x, y), built and rebuilt as ``GridNearest``'s (about one point per cell,
    rebuilt once the points added since reach ``_pending_limit``): a query scans the points added
    since the build, then the grid's cells ring by ring, and stops once every cell left is farther
    in (x, y) than the best SE(2) distance found (the metric is at least the (x, y) distance).

    Args:
        angle_weight: w of the metric ``||(dx, dy)|| + w |wrap(dtheta)|`` (``SE2Space.angle_weight``).

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits.world.nearest import SE2Nearest
        >>> near = SE2Nearest(0.5)
        >>> near.add(np.array([[0.0, 0.0, 0.0], [0.0, 0.3, 3.1]]))
        >>> near.nearest(np.array([[0.0, 0.3, -3.1], [1.0, 0.0, 0.0]])).tolist()  # theta wraps
        [1, 0]
    """

    def __init__(self, angle_weight: float) -> None:
        super().__init__(3)
        self.angle_weight = float(angle_weight)
        self._grid_built_at = 0  # the points the (x, y) grid holds (0: no grid yet)
        self._rebuild_at = BRUTE_FORCE_BELOW_SE2
        self._origin, self._low, self._high = np.zeros(2), np.zeros(2), np.zeros(2)
        self._cell = 1.0
        self._shape = np.ones(2, dtype=np.int64)
        self._start = np.zeros(2, dtype=np.int64)
        self._order = np.empty(0, dtype=np.int64)
        self._sorted = np.empty((0, 3))

    def add(self, points: np.ndarray) -> None:
        """Append the rows of ``points`` (m, 3) (the grid is rebuilt, once, when the points added
        since its build reach ``_pending_limit``).

        Raises:
            ValueError: ``points`` not of shape (m, 3).
        """
        super().add(points)
        if self.size >= self._rebuild_at:
            self._build_grid()

    def _scan(self, queries: np.ndarray, first: int) -> tuple[np.ndarray, np.ndarray]:
        best = np.empty(queries.shape[0])
        out = np.empty(queries.shape[0], dtype=np.int64)
        _se2_scan(queries, self._buffer, max(0, first), self.size, self.angle_weight, best, out)
        return best, out

    def nearest(self, queries: np.ndarray) -> np.ndarray:
        """Int (M,): the index of the point nearest to each of ``queries`` ((M, 3) or (3,)) under
        the SE(2) metric; among equally near points the lowest index.

        Raises:
            ValueError: ``queries`` of the wrong shape or not finite, or no point added yet.
        """
        queries = self.queries(queries)
        out = np.empty(queries.shape[0], dtype=np.int64)
        _se2_nearest_into(queries, self._buffer, self.size, self._grid_built_at, self._start, self._order,
                          self._sorted, self._origin, self._cell, self._shape, self._low, self._high,
                          self.angle_weight, out)
        return out

    def nearest_distance_from(self, queries: np.ndarray, first: int) -> np.ndarray:
        """Float (M,): the SE(2) distance from each of ``queries`` to the nearest of the points of
        index ``first`` on (``inf`` where there are none), by the scan."""
        return self._scan(self.queries(queries), first)[0]

    def _build_grid(self) -> None:
        points = self.points
        planar = np.ascontiguousarray(points[:, :2])
        low, high = _bounding_box(planar)
        extent = np.maximum(high - low, 1e-9)
        cell = max(math.sqrt(float(extent[0] * extent[1]) / min(self.size, _MAX_CELLS)), 1e-12,
                   float(extent.max()) / math.sqrt(_MAX_CELLS))
        shape = np.minimum(np.floor(extent / cell).astype(np.int64) + 1, 1 << 11)
        start = np.zeros(int(shape[0]) * int(shape[1]) + 1, dtype=np.int64)
        order = np.empty(self.size, dtype=np.int64)
        ordered = np.empty_like(planar)
        _file_by_cell(planar, low, cell, shape, start, order, ordered)
        self._origin, self._cell, self._shape, self._low, self._high = low.copy(), cell, shape, low, high
        self._start, self._order, self._sorted = start, order, np.ascontiguousarray(points[order])
        self._rebuild_at = self.size + _pending_limit(self.size)
        self._grid_built_at = self.size


class GridNearest(_Points):
    """Exact Euclidean nearest points, compiled: brute force for small structures, a bucket grid
    from ``BRUTE_FORCE_BELOW`` points on (see the module docstring).

    Args:
        dim: d >= 1, the coordinates of a point.
        capacity: Initial room for points (grown by doubling; default 256).

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits.world.nearest import GridNearest
        >>> near = GridNearest(2)
        >>> near.add(np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0]]))
        >>> near.nearest(np.array([[1.9, 1.5], [0.2, -0.1], [1.0, 0.0]])).tolist()  # a tie: the lower index
        [2, 0, 0]
    """

    def __init__(self, dim: int, capacity: int = _CAPACITY) -> None:
        super().__init__(dim, capacity)
        # the grid (built once the structure reaches BRUTE_FORCE_BELOW points, see ``add``, or by a
        # first ``grid_nearest`` call); until then empty arrays of the grid's types, and
        # _grid_built_at = 0 (the points it holds)
        self._grid_built_at = 0
        self._rebuild_at = BRUTE_FORCE_BELOW  # the size at which ``add`` (re)builds the grid
        self._origin, self._low, self._high = np.zeros(dim), np.zeros(dim), np.zeros(dim)
        self._cell = 1.0
        self._shape = np.ones(dim, dtype=np.int64)
        self._several_cells = False  # whether the grid has more than one cell (read by nearest)
        self._start = np.zeros(2, dtype=np.int64)  # offset of each cell's first point in _order, and the end
        self._order = np.empty(0, dtype=np.int64)  # the grid's point indices sorted by cell
        self._sorted = np.empty((0, dim))  # their positions, in that order

    def add(self, points: np.ndarray) -> None:
        """Append the rows of ``points`` (m, d) (amortized O(sqrt N) a point: the grid is rebuilt,
        once, when the points added since its build reach ``_pending_limit``).

        Raises:
            ValueError: ``points`` not of shape (m, d) for the structure's d.
        """
        super().add(points)
        if self.size >= self._rebuild_at:  # BRUTE_FORCE_BELOW reached, or too many points since the build
            self._build_grid()

    def nearest(self, queries: np.ndarray) -> np.ndarray:
        """Int (M,): the index of the point nearest (Euclidean) to each of ``queries`` ((M, d) or
        (d,)); exact, among equally near points the lowest index.

        Raises:
            ValueError: ``queries`` not of shape (M, d) or (d,) for the structure's d, or not finite.
        """
        queries = self.queries(queries)
        out = np.empty(queries.shape[0], dtype=np.int64)
        # a one-cell grid (high d, see _build_grid) is searched by the brute-force block instead,
        # which scans the same points (vectorized over the queries)
        nearest_into(queries, *self._search_arrays(self.size >= BRUTE_FORCE_BELOW and self._several_cells), out)
        return out

    def nearest_distance_from(self, queries: np.ndarray, first: int) -> np.ndarray:
        """Float (M,): the Euclidean distance from each of ``queries`` to the nearest of the points
        of index ``first`` on (``inf`` where there are none), by the brute-force block.

        Raises:
            ValueError: ``queries`` not of shape (M, d) or (d,) for the structure's d.
        """
        queries = self.queries(queries)
        best = np.empty(queries.shape[0])
        _brute_block(queries, self._buffer, max(0, first), self.size, best, np.empty(queries.shape[0], np.int64))
        return np.sqrt(best)

    def grid_nearest(self, queries: np.ndarray) -> np.ndarray:
        """``nearest`` through the grid whatever the structure's size (for tests, and for comparing
        the two searches): the same argument, result and errors."""
        queries = self.queries(queries)
        if not self._grid_built_at:  # a small structure's first grid query builds the grid, once
            with _FIRST_GRID:
                if not self._grid_built_at:  # (_build_grid sets it last: a built grid is complete)
                    self._build_grid()
        out = np.empty(queries.shape[0], dtype=np.int64)
        nearest_into(queries, *self._search_arrays(True), out)
        return out

    def _search_arrays(self, grid: bool) -> tuple[np.ndarray, int, int, np.ndarray, np.ndarray, np.ndarray,
                                                   np.ndarray, float, np.ndarray, np.ndarray, np.ndarray]:
        return (self._buffer, self.size, self._grid_built_at if grid else 0, self._start, self._order, self._sorted,
                self._origin, self._cell, self._shape, self._low, self._high)

    def _build_grid(self) -> None:
        points = self.points
        low, high = _bounding_box(points)  # (one compiled pass for both, not numpy's min and max)
        extent = np.maximum(high - low, 1e-9)
        cells = min(max(1.0, _CELLS_PER_NODE * self.size), _MAX_CELLS)
        cell = float(np.prod(extent) / cells) ** (1.0 / self.dim)
        cell = max(cell, float(extent.max()) / _MAX_CELLS ** (1.0 / self.dim), 1e-12)
        shape = np.minimum(np.floor(extent / cell).astype(np.int64) + 1, 1 << 20)
        # the most cells: _MAX_CELLS; or one cell (a scan of every point, as brute force) where a
        # query's first visit, the block of 3^d cells around its own, would exceed the point count
        # (high d: at d = 20, 2 cells per axis would make a query visit all 2^20). Products in
        # Python integers: in int64, 2^64 wraps to 0 and the grid would be filed out of bounds.
        most = 1 if 3 ** self.dim > self.size else _MAX_CELLS
        while math.prod(int(count) for count in shape) > most:  # a very flat box, or high d: coarser cells
            cell *= 2.0
            shape = np.minimum(np.floor(extent / cell).astype(np.int64) + 1, 1 << 20)
        start = np.zeros(math.prod(int(count) for count in shape) + 1, dtype=np.int64)
        order = np.empty(self.size, dtype=np.int64)
        ordered = np.empty_like(points)
        _file_by_cell(points, low, cell, shape, start, order, ordered)
        self._origin, self._cell, self._shape = low.copy(), cell, shape
        self._several_cells = math.prod(int(count) for count in shape) > 1
        self._low, self._high = low, high
        self._start, self._order, self._sorted = start, order, ordered
        self._rebuild_at = self.size + _pending_limit(self.size)
        self._grid_built_at = self.size


@njit(cache=True, nogil=True, inline="always")
def _cell_of(point: np.ndarray, origin: np.ndarray, cell: float, shape: np.ndarray, out: np.ndarray) -> int:
    """The (clamped) integer cell coordinates of ``point`` into ``out``; returns the flat index."""
    flat = 0
    for axis in range(point.shape[0]):
        value = (point[axis] - origin[axis]) / cell
        if value < 0.0:
            coordinate = 0
        elif value >= shape[axis]:
            coordinate = shape[axis] - 1
        else:
            coordinate = min(int(value), shape[axis] - 1)
        out[axis] = coordinate
        flat = flat * shape[axis] + coordinate
    return flat


@njit(cache=True, nogil=True)
def _file_by_cell(nodes: np.ndarray, origin: np.ndarray, cell: float, shape: np.ndarray, start: np.ndarray,
                  order: np.ndarray, ordered: np.ndarray) -> None:
    """A counting sort of the nodes by cell: ``order`` the node indices by cell (ascending within a
    cell), ``ordered`` their positions in that order (``nodes[order]``), ``start[c]`` the position
    in ``order`` of cell c's first node (``start`` has one entry per cell plus the end, zero on
    entry)."""
    size = nodes.shape[0]
    coordinates = np.empty(shape.shape[0], dtype=np.int64)
    cells = np.empty(size, dtype=np.int64)
    for index in range(size):
        cells[index] = _cell_of(nodes[index], origin, cell, shape, coordinates)
        start[cells[index] + 1] += 1
    for flat in range(start.shape[0] - 1):
        start[flat + 1] += start[flat]
    filled = start[:-1].copy()
    for index in range(size):
        slot = filled[cells[index]]
        order[slot] = index
        for axis in range(nodes.shape[1]):
            ordered[slot, axis] = nodes[index, axis]
        filled[cells[index]] += 1


@njit(cache=True, nogil=True)
def _bounding_box(nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The smallest and largest coordinate of the (M >= 1, d) ``nodes`` along each axis (what
    ``nodes.min(axis=0)`` and ``nodes.max(axis=0)`` give, for finite coordinates) in one pass."""
    low = nodes[0].copy()
    high = nodes[0].copy()
    for axis in range(nodes.shape[1]):
        smallest = largest = nodes[0, axis]
        for index in range(1, nodes.shape[0]):
            value = nodes[index, axis]
            smallest = value if value < smallest else smallest
            largest = value if value > largest else largest
        low[axis], high[axis] = smallest, largest
    return low, high


@njit(cache=True, nogil=True)
def _brute_block(points: np.ndarray, nodes: np.ndarray, first: int, stop: int, best: np.ndarray,
                 out: np.ndarray) -> None:
    """For each point, the nearest of nodes ``first .. stop - 1`` (the smallest squared distance,
    summed over the axes in order; among equals the lowest index) into ``best`` (squared distance)
    and ``out`` (index); ``inf`` and ``first`` where there are no such nodes or every squared
    distance overflows. One pass over the nodes for all points (the loop over the points is the
    inner one, without branches, so it vectorizes)."""
    count, dim = points.shape
    for row in range(count):
        best[row] = np.inf
        out[row] = first
    if dim == 2:  # the planners' case, unrolled (the same sum: 0.0 + dx^2 == dx^2 exactly)
        xs = points[:, 0].copy()
        ys = points[:, 1].copy()
        for node in range(first, stop):
            x, y = nodes[node, 0], nodes[node, 1]
            for row in range(count):
                dx = xs[row] - x
                dy = ys[row] - y
                squared = dx * dx + dy * dy
                nearer = squared < best[row]
                best[row] = squared if nearer else best[row]
                out[row] = node if nearer else out[row]
        return
    coordinates = points.T.copy()
    squared = np.empty(count)
    for node in range(first, stop):
        squared[:] = 0.0
        for axis in range(dim):
            value = nodes[node, axis]
            for row in range(count):
                delta = coordinates[axis, row] - value
                squared[row] += delta * delta
        for row in range(count):
            nearer = squared[row] < best[row]
            best[row] = squared[row] if nearer else best[row]
            out[row] = node if nearer else out[row]


@njit(cache=True, nogil=True)
def _grid_search(points: np.ndarray, start: np.ndarray, order: np.ndarray, ordered: np.ndarray, origin: np.ndarray,
                 cell: float, shape: np.ndarray, low: np.ndarray, high: np.ndarray, best: np.ndarray,
                 out: np.ndarray) -> None:
    """Ring search of the grid, from the nearest (``best``, ``out``) found so far: for each point,
    the node with the smallest (squared distance, index)."""
    dim = points.shape[1]
    last = dim - 1
    centre = np.empty(dim, dtype=np.int64)
    current = np.empty(dim, dtype=np.int64)
    lower = np.empty(dim, dtype=np.int64)
    upper = np.empty(dim, dtype=np.int64)
    outside = np.empty(dim)  # the point's distance to the grid nodes' bounding box along each axis
    slack = np.empty(dim)  # the rounding allowance of the cell edges along each axis (see below)
    for row in range(points.shape[0]):
        point = points[row]
        _cell_of(point, origin, cell, shape, centre)
        outside_total = 0.0
        for axis in range(dim):
            below = low[axis] - point[axis]
            above = point[axis] - high[axis]
            outside[axis] = max(below, above, 0.0)
            outside_total += outside[axis] * outside[axis]
            slack[axis] = _EDGE_SLACK * (abs(point[axis]) + abs(origin[axis]) + shape[axis] * cell)
        nearest = best[row]
        nearest_index = out[row]
        ring = 1  # the first visit covers rings 0 and 1 (the block of 3^d cells around the centre)
        while True:
            # visit the cells at Chebyshev distance ``ring`` from the centre (clipped to the grid),
            # on the first visit every cell of the block: an odometer over the first d - 1 axes;
            # along the last axis the whole run of cells (one slice of the sorted nodes) where the
            # prefix is on the ring (or on the first visit), else its two ends
            for axis in range(dim):
                lower[axis] = max(centre[axis] - ring, 0)
                upper[axis] = min(centre[axis] + ring, shape[axis] - 1)
                current[axis] = lower[axis]
            while True:
                on_ring = ring == 1
                prefix = 0
                for axis in range(last):
                    if abs(current[axis] - centre[axis]) == ring:
                        on_ring = True
                    prefix = prefix * shape[axis] + current[axis]
                prefix *= shape[last]
                for end in range(2):  # on the ring: the run [lower, upper] once; else its two end cells
                    if on_ring:
                        if end:
                            break
                        first, stop = start[prefix + lower[last]], start[prefix + upper[last] + 1]
                    else:
                        cell_last = centre[last] - ring if end == 0 else centre[last] + ring
                        if cell_last < 0 or cell_last > shape[last] - 1:
                            continue
                        first, stop = start[prefix + cell_last], start[prefix + cell_last + 1]
                    for slot in range(first, stop):  # the scan written out (an inlined helper is slower)
                        squared = 0.0
                        for axis in range(dim):
                            delta = point[axis] - ordered[slot, axis]
                            squared += delta * delta
                        candidate = order[slot]  # the update without branches
                        nearer = (squared < nearest) | ((squared == nearest) & (candidate < nearest_index))
                        nearest = squared if nearer else nearest
                        nearest_index = candidate if nearer else nearest_index
                axis = last - 1  # odometer step over the prefix
                while axis >= 0:
                    current[axis] += 1
                    if current[axis] <= upper[axis]:
                        break
                    current[axis] = lower[axis]
                    axis -= 1
                if axis < 0:
                    break
            bound, covers = _unvisited_bound(point, outside, outside_total, slack, centre, ring, origin, cell, shape)
            if covers or bound > nearest * (1.0 + _EDGE_SLACK):  # every cell visited, or none left nearer
                break
            ring += 1
        best[row] = nearest
        out[row] = nearest_index


@njit(cache=True, nogil=True)
def nearest_into(points: np.ndarray, nodes: np.ndarray, size: int, built: int, start: np.ndarray, order: np.ndarray,
                 ordered: np.ndarray, origin: np.ndarray, cell: float, shape: np.ndarray, low: np.ndarray,
                 high: np.ndarray, out: np.ndarray) -> None:
    """``GridNearest.nearest`` compiled (the arguments after ``points`` are
    ``GridNearest._search_arrays``): the brute force over the points the grid does not hold (all of
    them without a grid), then the grid's ring search from that best; writes the point indices into
    ``out``.

    Raises:
        ValueError: A point that is not finite.
    """
    for row in range(points.shape[0]):
        for axis in range(points.shape[1]):
            if not np.isfinite(points[row, axis]):
                raise ValueError(_NOT_FINITE)
    best = np.empty(points.shape[0])
    _brute_block(points, nodes, built, size, best, out)
    if built:
        _grid_search(points, start, order, ordered, origin, cell, shape, low, high, best, out)
