"""The growing tree: node positions, parent indices and nearest-node queries.

Node 0 is the root. Nearest-node queries use a scipy KD-tree rebuilt each time the tree doubles,
plus brute force over the nodes added since the last rebuild, so a query costs O(log N + recent).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree


class Tree:
    """Growable arrays of node positions and parent indices; node 0 is the root."""

    def __init__(self, root: np.ndarray, capacity: int = 256) -> None:
        root = np.asarray(root, dtype=float)
        self.dim = root.shape[0]
        self._nodes = np.empty((capacity, self.dim))
        self._parents = np.empty(capacity, dtype=np.int64)
        self._nodes[0] = root
        self._parents[0] = -1
        self.size = 1
        self._kdtree: cKDTree | None = None
        self._indexed = 0

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
        self._nodes[self.size] = position
        self._parents[self.size] = parent
        self.size += 1
        return self.size - 1

    def nearest(self, points: np.ndarray) -> np.ndarray:
        """Index of the nearest node (Euclidean) to each of ``points`` (M, d)."""
        points = np.atleast_2d(points)
        if self.size >= 64 and self.size >= 2 * max(self._indexed, 32):
            self._kdtree = cKDTree(self.nodes.copy())
            self._indexed = self.size
        if self._kdtree is None:
            return _brute_nearest(points, self.nodes, 0)
        dist, index = self._kdtree.query(points)
        if self._indexed < self.size:
            recent = _brute_nearest(points, self._nodes[self._indexed : self.size], self._indexed)
            recent_dist = np.linalg.norm(points - self._nodes[recent], axis=1)
            closer = recent_dist < dist
            index = np.where(closer, recent, index)
        return np.asarray(index, dtype=np.int64)


#: brute-force distance blocks hold at most this many (point, node) pairs, so a query's scratch
#: memory stays about 3 x 8 MiB whatever the database and tree sizes (unblocked, 2^22 points
#: against 63 nodes took 1 KB per point: ``benchmarks/bench_memory.py``)
BRUTE_BLOCK_PAIRS = 1 << 20


def _brute_nearest(points: np.ndarray, nodes: np.ndarray, offset: int) -> np.ndarray:
    out = np.empty(points.shape[0], dtype=np.int64)
    node_norms = np.sum(nodes**2, axis=1)
    block = max(1, BRUTE_BLOCK_PAIRS // max(nodes.shape[0], 1))
    for first in range(0, points.shape[0], block):
        chunk = points[first : first + block]
        squared = np.sum(chunk**2, axis=1)[:, None] - 2 * chunk @ nodes.T + node_norms
        out[first : first + block] = np.argmin(squared, axis=1)
    return out + offset
