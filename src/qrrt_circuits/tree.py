"""The growing tree: node positions, parent indices and nearest-node queries.

Node 0 is the root. Nearest-node queries are exact (Euclidean; among equally near nodes the
lowest index) and compiled: the nodes are kept sorted by their first coordinate, and a query scans
outwards from its own first coordinate in both directions until the gap in that coordinate alone
exceeds the best distance found (a sweep; Friedman, Baskett and Shustek 1975). A query costs about
the number of nodes in a slab as wide as twice the nearest distance, so its cost stays near flat as
a tree fills its workspace, and adding a node keeps the order with one shift (O(N) memory moves,
no rebuild). Up to ties at rounding level (distances equal to about 1e-14) it answers what a
brute-force search does.
"""

from __future__ import annotations

import numpy as np
from numba import njit


class Tree:
    """Growable arrays of node positions and parent indices; node 0 is the root."""

    def __init__(self, root: np.ndarray, capacity: int = 256) -> None:
        root = np.asarray(root, dtype=float)
        self.dim = root.shape[0]
        self._nodes = np.empty((capacity, self.dim))
        self._parents = np.empty(capacity, dtype=np.int64)
        self._order = np.empty(capacity, dtype=np.int64)  # node indices sorted by first coordinate
        self._sorted = np.empty((capacity, self.dim))  # the nodes in that order (contiguous scans)
        self._nodes[0] = root
        self._parents[0] = -1
        self._order[0] = 0
        self._sorted[0] = root
        self.size = 1

    @property
    def nodes(self) -> np.ndarray:
        return self._nodes[: self.size]

    @property
    def parents(self) -> np.ndarray:
        return self._parents[: self.size]

    def add(self, position: np.ndarray, parent: int) -> int:
        if self.size == self._nodes.shape[0]:
            self._nodes = np.concatenate([self._nodes, np.empty_like(self._nodes)])
            self._parents = np.concatenate([self._parents, np.empty_like(self._parents)])
            self._order = np.concatenate([self._order, np.empty_like(self._order)])
            self._sorted = np.concatenate([self._sorted, np.empty_like(self._sorted)])
        self._nodes[self.size] = position
        self._parents[self.size] = parent
        _insert_sorted(self._sorted, self._order, self.size, self._nodes[self.size])
        self.size += 1
        return self.size - 1

    def nearest(self, points: np.ndarray) -> np.ndarray:
        """Index of the nearest node (Euclidean) to each of ``points`` (M, d)."""
        points = np.ascontiguousarray(np.atleast_2d(points), dtype=float)
        out = np.empty(points.shape[0], dtype=np.int64)
        _nearest_sorted(points, self._sorted, self._order, self.size, out)
        return out


@njit(cache=True, nogil=True)
def _insert_sorted(sorted_nodes, order, size, position):
    """Insert node ``size`` at ``position`` into (sorted_nodes, order), kept ascending in the
    first coordinate (after any equal ones)."""
    key = position[0]
    at = size
    while at > 0 and sorted_nodes[at - 1, 0] > key:
        at -= 1
    for i in range(size, at, -1):
        sorted_nodes[i] = sorted_nodes[i - 1]
        order[i] = order[i - 1]
    sorted_nodes[at] = position
    order[at] = size


@njit(cache=True, nogil=True)
def _nearest_sorted(points, sorted_nodes, order, size, out):
    """The sweep: for each point, the node with the smallest (squared distance, index)."""
    dim = points.shape[1]
    keys = sorted_nodes[:size, 0]
    for row in range(points.shape[0]):
        first = points[row, 0]
        start = np.searchsorted(keys, first)
        best = np.inf
        best_index = size
        i = start - 1
        while i >= 0:
            gap = first - keys[i]
            if gap * gap > best:
                break
            squared = 0.0
            for axis in range(dim):
                delta = points[row, axis] - sorted_nodes[i, axis]
                squared += delta * delta
            if squared < best or (squared == best and order[i] < best_index):
                best = squared
                best_index = order[i]
            i -= 1
        i = start
        while i < size:
            gap = keys[i] - first
            if gap * gap > best:
                break
            squared = 0.0
            for axis in range(dim):
                delta = points[row, axis] - sorted_nodes[i, axis]
                squared += delta * delta
            if squared < best or (squared == best and order[i] < best_index):
                best = squared
                best_index = order[i]
            i += 1
        out[row] = best_index
