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
            want = np.argmin(squared, axis=1)
            assert np.array_equal(tree.nearest(queries), want)  # brute force below BRUTE_FORCE_BELOW
            assert np.array_equal(tree.grid_nearest(queries), want)  # the grid at every size
    assert tree.parents.shape == (701,) and tree.parents[0] == -1


def test_ties_go_to_the_lowest_index_and_clustered_nodes_work():
    tree = Tree(np.array([1.0, 1.0]))
    for point in ([1.0, 3.0], [3.0, 1.0], [1.0, 1.0], [5.0, 5.0]):
        tree.add(np.array(point), 0)
    for nearest in (tree.nearest, tree.grid_nearest):
        assert nearest(np.array([[2.0, 2.0], [1.0, 1.0], [9.0, 9.0]])).tolist() == [0, 0, 4]
        assert nearest(np.array([1.0, 2.0])).tolist() == [0]


def test_degenerate_trees_line_and_repeated_points():
    rng = np.random.default_rng(5)
    line = Tree(np.array([0.0, 3.0]))
    same = Tree(np.array([2.0, 2.0, 2.0]))
    for step in range(300):
        line.add(np.array([rng.random() * 50, 3.0]), 0)
        same.add(np.array([2.0, 2.0, 2.0]), step)
    queries = rng.random((40, 2)) * 60 - 5
    squared = ((queries[:, None, :] - line.nodes[None]) ** 2).sum(-1)
    for tree_line, tree_same in ((line.nearest, same.nearest), (line.grid_nearest, same.grid_nearest)):
        assert np.array_equal(tree_line(queries), np.argmin(squared, axis=1))
        assert tree_same(rng.random((10, 3))).tolist() == [0] * 10  # all equally near: the lowest index


def test_nearest_agrees_with_the_grid_on_both_sides_of_the_brute_force_switch():
    from qrrt_circuits import tree as tree_module

    rng = np.random.default_rng(8)
    tree = Tree(rng.random(2) * 20)
    while tree.size < tree_module.BRUTE_FORCE_BELOW + 50:
        tree.add(rng.random(2) * 20, 0)
        if tree.size in (tree_module.BRUTE_FORCE_BELOW - 1, tree_module.BRUTE_FORCE_BELOW):
            queries = rng.random((256, 2)) * 20
            assert np.array_equal(tree.nearest(queries), tree.grid_nearest(queries))
