"""The growing tree: node positions, parent indices and nearest-node queries.

Node 0 is the root. Nearest-node queries are exact (Euclidean; among equally near nodes the
lowest index) and compiled, on a uniform bucket grid over the nodes' bounding box: each cell keeps
a linked list of its nodes, a query visits the cells ring by ring (Chebyshev rings around its own
cell) and stops once the distance from the query to the part of the grid not yet visited exceeds
the best distance found (the cell technique of Bentley, Weide and Yao 1980). The grid is rebuilt,
with about one node per cell, each time the tree doubles; nodes added in between are appended to
their cell's list (nodes outside the box go to the nearest border cell, which the stopping bound
allows for). A query therefore costs about the nodes of a few cells however large the tree, and
adding a node is O(1) (rebuilds are amortized O(1) per node). It answers what a brute-force search
does, ties and rounding-level near-ties included: the stopping bound allows for the rounding of a
node's cell (tested on adversarial cell-edge cases). Trees of fewer than
``BRUTE_FORCE_BELOW`` nodes are searched by that compiled brute force instead (every query against
every node), which is faster there: ``benchmarks/bench_nearest.py`` put the crossover between 150
and 200 nodes for a round's 256 queries on two machines.
"""

from __future__ import annotations

import threading

import numpy as np
from numba import njit

#: cells per node when the grid is (re)built, and the most cells one grid has
_CELLS_PER_NODE = 1.0
_MAX_CELLS = 1 << 22
#: trees with fewer nodes answer nearest-node queries by brute force (see the module docstring)
BRUTE_FORCE_BELOW = 160
#: relative rounding allowance of the grid's stopping bound (a few units in the last place)
_EDGE_SLACK = 16 * float(np.finfo(float).eps)
_NOT_FINITE = "points must be finite (no NaN or infinity)"
#: serializes the lazy grid builds of ``grid_nearest`` (queries may come from several threads)
_FIRST_GRID = threading.Lock()


class Tree:
    """Growable arrays of node positions and parent indices; node 0 is the root.

    The tree T of the paper's Alg. 1-4, with the exact nearest-node query of Alg. 1 line 6 (see the
    module docstring for the grid).

    Args:
        root: Float (d,), the root's position.
        capacity: Initial room for nodes (grown by doubling; default 256).

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits.tree import Tree
        >>> tree = Tree(np.array([0.0, 0.0]))
        >>> tree.add(np.array([2.0, 0.0]), parent=0), tree.add(np.array([2.0, 2.0]), parent=1)
        (1, 2)
        >>> tree.nearest(np.array([[1.9, 1.5], [0.2, -0.1]])).tolist(), tree.parents.tolist()
        ([2, 0], [-1, 0, 1])
    """

    def __init__(self, root: np.ndarray, capacity: int = 256) -> None:
        root = np.asarray(root, dtype=float)
        self.dim = root.shape[0]
        self._nodes = np.empty((capacity, self.dim))
        self._parents = np.empty(capacity, dtype=np.int64)
        self._next = np.empty(capacity, dtype=np.int64)  # next node in the same grid cell, or -1
        self._nodes[0] = root
        self._parents[0] = -1
        self.size = 1
        # the grid (built once the tree reaches BRUTE_FORCE_BELOW nodes, see ``add``); until then
        # placeholders of the grid's types, and _grid_built_at = 0 (the size at the last build)
        self._grid_built_at = 0
        self._origin, self._low, self._high = np.zeros(self.dim), np.zeros(self.dim), np.zeros(self.dim)
        self._cell = 1.0
        self._shape = np.ones(self.dim, dtype=np.int64)
        self._head = np.full(1, -1, dtype=np.int64)

    @property
    def nodes(self) -> np.ndarray:
        """Float (size, d) view of the node positions, root in row 0."""
        return self._nodes[: self.size]

    @property
    def parents(self) -> np.ndarray:
        """Int (size,) view of the parent indices, -1 for the root."""
        return self._parents[: self.size]

    def add(self, position: np.ndarray, parent: int) -> int:
        """Append a node (amortized O(1); the grid is rebuilt when the tree doubles).

        Args:
            position: Float (d,), the new node.
            parent: Index of its parent node (unvalidated).

        Returns:
            The new node's index.
        """
        if self.size == self._nodes.shape[0]:
            self._nodes = np.concatenate([self._nodes, np.empty_like(self._nodes)])
            self._parents = np.concatenate([self._parents, np.empty_like(self._parents)])
            self._next = np.concatenate([self._next, np.empty_like(self._next)])
        index = self.size
        self._nodes[index] = position
        self._parents[index] = parent
        self.size += 1
        if self._grid_built_at:  # a grid exists: keep it current (rebuilt each time the tree doubles)
            if self.size >= 2 * self._grid_built_at:
                self._build_grid()
            else:
                _grid_insert(self._nodes, self._next, self._head, self._origin, self._cell, self._shape, index,
                             self._low, self._high)
        elif self.size >= BRUTE_FORCE_BELOW:  # queries use the grid from here on
            self._build_grid()
        return index

    def nearest(self, points: np.ndarray) -> np.ndarray:
        """Index of the nearest node (Euclidean) to each of ``points`` (M, d).

        Exact; among equally near nodes the lowest index.

        Args:
            points: Float (M, d) or (d,).

        Returns:
            Int array (M,) of node indices.

        Raises:
            ValueError: ``points`` not of shape (M, d) or (d,) for the tree's d, or not finite.
        """
        points = self._queries(points)
        out = np.empty(points.shape[0], dtype=np.int64)
        nearest_into(points, *self.search_arrays(), out)
        return out

    def search_arrays(self) -> tuple[np.ndarray, int, np.ndarray, np.ndarray, np.ndarray, float, np.ndarray,
                                     np.ndarray, np.ndarray]:
        """The arguments of ``nearest_into`` after the points, for compiled callers (the planners'
        fused round, ``planners.fused_round``): the node buffer, the size, the grid's lists
        (next node, cell heads), origin, cell size, shape and the nodes' bounding box. The arrays
        are the tree's own (not copies) and stay valid until the next ``add``. Below
        ``BRUTE_FORCE_BELOW`` nodes the tree keeps no grid (``nearest_into`` does not read it) and
        the grid arrays are placeholders."""
        return (self._nodes, self.size, self._next, self._head, self._origin, self._cell, self._shape,
                self._low, self._high)

    def grid_nearest(self, points: np.ndarray) -> np.ndarray:
        """``nearest`` through the grid whatever the tree's size (for tests and benchmarks): the
        same argument (float points, (M, d) or (d,)), result (int (M,) node indices) and errors."""
        points = self._queries(points)
        if not self._grid_built_at:  # a small tree's first grid query builds the grid, once
            with _FIRST_GRID:
                if not self._grid_built_at:  # (_build_grid sets it last: a built grid is complete)
                    self._build_grid()
        out = np.empty(points.shape[0], dtype=np.int64)
        _grid_nearest(points, self._nodes, self._next, self._head, self._origin, self._cell, self._shape,
                      self.size, self._low, self._high, out)
        return out

    def _queries(self, points: np.ndarray) -> np.ndarray:
        points = np.ascontiguousarray(np.atleast_2d(points), dtype=float)
        if points.ndim != 2 or points.shape[1] != self.dim:
            raise ValueError(f"points must have shape (M, {self.dim}) (the tree's d), got {points.shape}")
        return points  # the kernels refuse points that are not finite

    def _build_grid(self) -> None:
        nodes = self.nodes
        low, high = nodes.min(axis=0), nodes.max(axis=0)
        extent = np.maximum(high - low, 1e-9)
        cells = min(max(1.0, _CELLS_PER_NODE * self.size), _MAX_CELLS)
        cell = float(np.prod(extent) / cells) ** (1.0 / self.dim)
        cell = max(cell, float(extent.max()) / _MAX_CELLS ** (1.0 / self.dim), 1e-12)
        shape = np.minimum(np.floor(extent / cell).astype(np.int64) + 1, 1 << 20)
        while int(np.prod(shape)) > _MAX_CELLS:  # a very flat box: coarser cells
            cell *= 2.0
            shape = np.minimum(np.floor(extent / cell).astype(np.int64) + 1, 1 << 20)
        self._origin = low.copy()
        self._cell = cell
        self._shape = shape
        self._head = np.full(int(np.prod(shape)), -1, dtype=np.int64)
        self._low, self._high = low.copy(), high.copy()  # the nodes' bounding box, kept up to date
        _grid_insert_all(self._nodes, self._next, self._head, self._origin, self._cell, self._shape, self.size,
                         self._low, self._high)
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
def _grid_insert(nodes: np.ndarray, next_node: np.ndarray, head: np.ndarray, origin: np.ndarray, cell: float,
                 shape: np.ndarray, index: int, low: np.ndarray, high: np.ndarray) -> None:
    for axis in range(low.shape[0]):
        low[axis] = min(low[axis], nodes[index, axis])
        high[axis] = max(high[axis], nodes[index, axis])
    coordinates = np.empty(shape.shape[0], dtype=np.int64)
    flat = _cell_of(nodes[index], origin, cell, shape, coordinates)
    next_node[index] = head[flat]
    head[flat] = index


@njit(cache=True, nogil=True)
def _grid_insert_all(nodes: np.ndarray, next_node: np.ndarray, head: np.ndarray, origin: np.ndarray, cell: float,
                     shape: np.ndarray, size: int, low: np.ndarray, high: np.ndarray) -> None:
    """``_grid_insert`` of nodes 0 .. size - 1, in order, in one call."""
    for index in range(size):
        _grid_insert(nodes, next_node, head, origin, cell, shape, index, low, high)


@njit(cache=True, nogil=True, inline="always")
def _visit_cell(point: np.ndarray, nodes: np.ndarray, next_node: np.ndarray, head: np.ndarray, flat: int, size: int,
                best: float, best_index: int) -> tuple[float, int]:
    node = head[flat]
    while node >= 0:
        if node < size:
            squared = 0.0
            for axis in range(point.shape[0]):
                delta = point[axis] - nodes[node, axis]
                squared += delta * delta
            if squared < best or (squared == best and node < best_index):
                best = squared
                best_index = node
        node = next_node[node]
    return best, best_index


@njit(cache=True, nogil=True)
def _brute_nearest(points: np.ndarray, nodes: np.ndarray, size: int, out: np.ndarray) -> None:
    """For each point, the node with the smallest (squared distance, index), trying every node (the
    squared distance summed over the axes in order, as ``_visit_cell`` does)."""
    dim = points.shape[1]
    for row in range(points.shape[0]):
        for axis in range(dim):
            if not np.isfinite(points[row, axis]):
                raise ValueError(_NOT_FINITE)
        # node 0 first, then strictly nearer ones: the lowest index among equals, also when every
        # squared distance overflows to inf (as _visit_cell's (squared distance, index) order)
        best = np.inf
        best_index = 0
        if dim == 2:  # the planners' case, unrolled (the same sum: 0.0 + dx^2 == dx^2 exactly)
            x, y = points[row, 0], points[row, 1]
            for node in range(size):
                dx = x - nodes[node, 0]
                dy = y - nodes[node, 1]
                squared = dx * dx + dy * dy
                if squared < best:
                    best = squared
                    best_index = node
        else:
            for node in range(size):
                squared = 0.0
                for axis in range(dim):
                    delta = points[row, axis] - nodes[node, axis]
                    squared += delta * delta
                if squared < best:
                    best = squared
                    best_index = node
        out[row] = best_index


@njit(cache=True, nogil=True)
def nearest_into(points: np.ndarray, nodes: np.ndarray, size: int, next_node: np.ndarray, head: np.ndarray,
                 origin: np.ndarray, cell: float, shape: np.ndarray, low: np.ndarray, high: np.ndarray,
                 out: np.ndarray) -> None:
    """``Tree.nearest`` compiled: the brute force below ``BRUTE_FORCE_BELOW`` nodes, else the grid
    (the arguments after ``points`` are ``Tree.search_arrays()``); writes the node indices into ``out``."""
    if size < BRUTE_FORCE_BELOW:
        _brute_nearest(points, nodes, size, out)
    else:
        _grid_nearest(points, nodes, next_node, head, origin, cell, shape, size, low, high, out)


@njit(cache=True, nogil=True)
def _grid_nearest(points: np.ndarray, nodes: np.ndarray, next_node: np.ndarray, head: np.ndarray, origin: np.ndarray,
                  cell: float, shape: np.ndarray, size: int, low: np.ndarray, high: np.ndarray,
                  out: np.ndarray) -> None:
    """Ring search: for each point, the node with the smallest (squared distance, index)."""
    dim = points.shape[1]
    last = dim - 1
    centre = np.empty(dim, dtype=np.int64)
    current = np.empty(dim, dtype=np.int64)
    lower = np.empty(dim, dtype=np.int64)
    upper = np.empty(dim, dtype=np.int64)
    outside = np.empty(dim)  # the point's distance to the nodes' bounding box along each axis
    slack = np.empty(dim)  # the rounding allowance of the cell edges along each axis (see below)
    for row in range(points.shape[0]):
        point = points[row]
        for axis in range(dim):
            if not np.isfinite(point[axis]):
                raise ValueError(_NOT_FINITE)
        _cell_of(point, origin, cell, shape, centre)
        outside_total = 0.0
        for axis in range(dim):
            below = low[axis] - point[axis]
            above = point[axis] - high[axis]
            outside[axis] = max(below, above, 0.0)
            outside_total += outside[axis] * outside[axis]
            slack[axis] = _EDGE_SLACK * (abs(point[axis]) + abs(origin[axis]) + shape[axis] * cell)
        best = np.inf
        best_index = size
        ring = 0
        while True:
            # visit the cells at Chebyshev distance ``ring`` from the centre (clipped to the grid):
            # an odometer over the first d - 1 axes; the last axis in full where the prefix is on
            # the ring, else only its two ends
            for axis in range(dim):
                lower[axis] = max(centre[axis] - ring, 0)
                upper[axis] = min(centre[axis] + ring, shape[axis] - 1)
                current[axis] = lower[axis]
            while True:
                on_ring = ring == 0
                prefix = 0
                for axis in range(last):
                    if abs(current[axis] - centre[axis]) == ring:
                        on_ring = True
                    prefix = prefix * shape[axis] + current[axis]
                prefix *= shape[last]
                if on_ring:
                    for value in range(lower[last], upper[last] + 1):
                        best, best_index = _visit_cell(point, nodes, next_node, head, prefix + value, size,
                                                       best, best_index)
                else:
                    if centre[last] - ring >= 0:
                        best, best_index = _visit_cell(point, nodes, next_node, head,
                                                       prefix + centre[last] - ring, size, best, best_index)
                    if centre[last] + ring <= shape[last] - 1:
                        best, best_index = _visit_cell(point, nodes, next_node, head,
                                                       prefix + centre[last] + ring, size, best, best_index)
                axis = last - 1  # odometer step over the prefix
                while axis >= 0:
                    current[axis] += 1
                    if current[axis] <= upper[axis]:
                        break
                    current[axis] = lower[axis]
                    axis -= 1
                if axis < 0:
                    break
            # a lower bound on the squared distance from the point to any cell outside the visited
            # block: beyond one side of one axis, the gap to that side plus, along the other axes,
            # the point's distance to the nodes' bounding box (nodes outside the grid's box sit in
            # its border cells, so the gaps hold for them too)
            # Each gap is shortened by a few units in the last place of the coordinates involved:
            # a node is filed by int((x - origin) / cell), which can put a node lying a rounding
            # error below a computed edge origin + k * cell into cell k, and the search must not
            # stop before reaching it (a node as near as the best, or a tie with a lower index).
            bound = np.inf
            covers = True
            for axis in range(dim):
                others = outside_total - outside[axis] * outside[axis]
                if centre[axis] - ring - 1 >= 0:
                    covers = False
                    gap = max(point[axis] - (origin[axis] + (centre[axis] - ring) * cell) - slack[axis], 0.0)
                    bound = min(bound, gap * gap + others)
                if centre[axis] + ring + 1 <= shape[axis] - 1:
                    covers = False
                    gap = max(origin[axis] + (centre[axis] + ring + 1) * cell - point[axis] - slack[axis], 0.0)
                    bound = min(bound, gap * gap + others)
            if covers or bound > best * (1.0 + _EDGE_SLACK):  # every cell visited, or none left nearer
                break
            ring += 1
        out[row] = best_index
