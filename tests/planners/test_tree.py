"""The tree stores nodes and parents: ``add_many`` appends as ``add`` does one node at a time.

Its nearest-node queries belong to the plan's nearest-neighbour structure
(``tests/world/test_nearest.py``)."""

from __future__ import annotations

import numpy as np
import pytest

from qrrt_circuits.planners.tree import Tree


def test_add_many_builds_the_tree_add_builds_one_node_at_a_time():
    """``add_many`` appends as ``add`` does (indices, positions, parents, buffers grown)."""
    rng = np.random.default_rng(9)
    points = rng.random((1500, 2)) * 20
    parents = rng.integers(0, 10, 1500)
    one, many = Tree(points[0], capacity=4), Tree(points[0], capacity=4)
    for index in range(1, 1500):
        assert one.add(points[index], int(parents[index])) == index
    position = 1
    for count in (0, 1, 3, 250, 7, 1, 500):  # batches of every size, and buffer growth
        assert many.add_many(points[position:position + count], parents[position:position + count]) == position
        position += count
        assert many.size == position
    assert many.add_many(points[position:], parents[position:]) == position
    assert np.array_equal(one.nodes, many.nodes) and np.array_equal(one.nodes, points)
    assert np.array_equal(one.parents[1:], many.parents[1:]) and one.parents[0] == many.parents[0] == -1


def test_add_many_refuses_positions_that_do_not_match_the_parents():
    tree = Tree(np.zeros(2))
    three, one = np.zeros(3, dtype=np.int64), np.zeros(1, dtype=np.int64)
    for positions, parents in ((np.zeros((1, 2)), three),  # one row would be broadcast to three parents
                               (np.zeros((3, 3)), three), (np.zeros(2), one)):
        with pytest.raises(ValueError, match="positions must have shape"):
            tree.add_many(positions, parents)
    assert tree.size == 1
