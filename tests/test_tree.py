"""Nearest-node queries of the growing tree answer what brute force answers."""

from __future__ import annotations

import numpy as np
import pytest

from qrrt_circuits.tree import Tree


@pytest.mark.parametrize("dim", [1, 2, 3, 5])
def test_nearest_equals_brute_force_as_the_tree_grows(dim):
    rng = np.random.default_rng(dim)
    tree = Tree(rng.random(dim) * 20, capacity=4)
    for step in range(700):
        tree.add(rng.random(dim) * 20, int(rng.integers(0, tree.size)))
        if step % 97 == 0 or step < 6:
            queries = rng.random((50, dim)) * 24 - 2  # some outside the nodes' span
            squared = ((queries[:, None, :] - tree.nodes[None]) ** 2).sum(-1)
            assert np.array_equal(tree.nearest(queries), np.argmin(squared, axis=1))
    assert tree.parents.shape == (701,) and tree.parents[0] == -1


def test_ties_go_to_the_lowest_index_and_clustered_nodes_work():
    tree = Tree(np.array([1.0, 1.0]))
    for point in ([1.0, 3.0], [3.0, 1.0], [1.0, 1.0], [5.0, 5.0]):
        tree.add(np.array(point), 0)
    assert tree.nearest(np.array([[2.0, 2.0], [1.0, 1.0], [9.0, 9.0]])).tolist() == [0, 0, 4]
    assert tree.nearest(np.array([1.0, 2.0])).tolist() == [0]


def test_degenerate_trees_line_and_repeated_points():
    rng = np.random.default_rng(5)
    line = Tree(np.array([0.0, 3.0]))
    same = Tree(np.array([2.0, 2.0, 2.0]))
    for step in range(300):
        line.add(np.array([rng.random() * 50, 3.0]), 0)
        same.add(np.array([2.0, 2.0, 2.0]), step)
    queries = rng.random((40, 2)) * 60 - 5
    squared = ((queries[:, None, :] - line.nodes[None]) ** 2).sum(-1)
    assert np.array_equal(line.nearest(queries), np.argmin(squared, axis=1))
    assert same.nearest(rng.random((10, 3))).tolist() == [0] * 10  # all equally near: the lowest index
