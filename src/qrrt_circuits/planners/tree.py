"""The growing tree: node positions and parent indices.

Node 0 is the root. The tree stores nodes only; which node is nearest to a sample is the question
of the plan's nearest-neighbour structure (``world.nearest``, chosen once per plan by the state
space), which ``RunState`` keeps beside the tree and gives every node the tree gets.
"""

from __future__ import annotations

import numpy as np


class Tree:
    """Growable arrays of node positions and parent indices; node 0 is the root.

    The tree T of the paper's Alg. 1-4.

    Args:
        root: Float (d,), the root's position.
        capacity: Initial room for nodes (grown by doubling; default 256).

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits.planners.tree import Tree
        >>> tree = Tree(np.array([0.0, 0.0]))
        >>> tree.add(np.array([2.0, 0.0]), parent=0), tree.add(np.array([2.0, 2.0]), parent=1)
        (1, 2)
        >>> tree.nodes.tolist(), tree.parents.tolist()
        ([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0]], [-1, 0, 1])
    """

    def __init__(self, root: np.ndarray, capacity: int = 256) -> None:
        root = np.asarray(root, dtype=float)
        self.dim = root.shape[0]
        self._nodes = np.empty((capacity, self.dim))
        self._parents = np.empty(capacity, dtype=np.int64)
        self._nodes[0] = root
        self._parents[0] = -1
        self.size = 1

    @property
    def nodes(self) -> np.ndarray:
        """Float (size, d) view of the node positions, root in row 0."""
        return self._nodes[: self.size]

    @property
    def parents(self) -> np.ndarray:
        """Int (size,) view of the parent indices, -1 for the root."""
        return self._parents[: self.size]

    def add(self, position: np.ndarray, parent: int) -> int:
        """Append a node (amortized O(1)).

        Args:
            position: Float (d,), the new node.
            parent: Index of its parent node (unvalidated).

        Returns:
            The new node's index.
        """
        if self.size == self._nodes.shape[0]:
            self._grow(self.size + 1)
        index = self.size
        self._nodes[index] = position
        self._parents[index] = parent
        self.size += 1
        return index

    def add_many(self, positions: np.ndarray, parents: np.ndarray) -> int:
        """Append nodes in order, as ``add`` one by one would (the same indices and arrays).

        Args:
            positions: Float (m, d), the new nodes.
            parents: Int (m,), their parents' indices (unvalidated).

        Returns:
            The index of the first new node (the others follow it).

        Raises:
            ValueError: ``positions`` not of shape (m, d) for the m entries of ``parents`` and the
                tree's d.
        """
        count = parents.shape[0]
        if positions.shape != (count, self.dim):
            raise ValueError(f"positions must have shape ({count}, {self.dim}) (one row per parent, the tree's d), "
                             f"got {positions.shape}")
        first = self.size
        if first + count > self._nodes.shape[0]:
            self._grow(first + count)
        self._nodes[first:first + count] = positions
        self._parents[first:first + count] = parents
        self.size += count
        return first

    def _grow(self, needed: int) -> None:
        """Double the node buffers until they hold ``needed`` nodes."""
        capacity = self._nodes.shape[0]
        while capacity < needed:
            capacity *= 2
        nodes, parents = np.empty((capacity, self.dim)), np.empty(capacity, dtype=np.int64)
        nodes[:self.size], parents[:self.size] = self._nodes[:self.size], self._parents[:self.size]
        self._nodes, self._parents = nodes, parents

    def reparent(self, node: int, parent: int) -> None:
        """Give ``node`` a new parent (RRT*'s rewire; unvalidated: the caller keeps the tree acyclic).

        Args:
            node: A node index >= 1.
            parent: Its new parent's index.
        """
        self._parents[node] = parent
