"""The paper's Fig. 9 estimator resampled from growth curves (experiments.random_bound_fit)."""

from __future__ import annotations

import numpy as np
import pytest

from qrrt_circuits.experiments.fitting import linear_fit
from qrrt_circuits.experiments.random_bound_fit import calls_at_bounds, random_bound_slopes


def test_a_tree_stops_at_the_first_round_with_at_least_the_bound():
    curve = np.array([[1, 5, 1], [3, 9, 2], [4, 20, 3]])  # nodes jump from 1 to 3 (parallel workers)
    table = calls_at_bounds(curve, 5)
    assert table[:4].tolist() == [[1, 5], [3, 9], [3, 9], [4, 20]]
    assert np.isnan(table[4]).all()  # never reached 5 nodes


def test_linear_trees_give_their_slope_in_every_replicate():
    curves = [np.array([[n, 3 * n + 2, n] for n in range(1, 31)]) for _ in range(3)]
    slopes = random_bound_slopes(curves, trees=10, resamples=200, rng=np.random.default_rng(0))
    finite = slopes[np.isfinite(slopes)]
    assert finite.size > 190 and np.allclose(finite, 3.0)


def test_each_replicate_is_an_ordinary_least_squares_fit():
    rng = np.random.default_rng(7)
    curves = [np.column_stack([np.arange(1, 31), np.cumsum(rng.integers(1, 40, 30)), np.arange(1, 31)])
              for _ in range(12)]
    slopes = random_bound_slopes(curves, trees=8, resamples=5, rng=np.random.default_rng(3))
    # the same draws, made one by one
    draw = np.random.default_rng(3)
    which = draw.integers(len(curves), size=(5, 8))
    bounds = np.maximum(1, np.ceil(30 * draw.random((5, 8)))).astype(int)
    for row in range(5):
        points = np.array([calls_at_bounds(curves[t], 30)[b - 1] for t, b in zip(which[row], bounds[row], strict=True)])
        assert slopes[row] == pytest.approx(linear_fit(points[:, 0], points[:, 1]).slope)


def test_bad_arguments_are_refused():
    with pytest.raises(ValueError, match="at least one growth curve"):
        random_bound_slopes([], 10, 10, np.random.default_rng(0))
    with pytest.raises(ValueError, match="trees must be >= 2"):
        random_bound_slopes([np.array([[1, 1, 1]])], 1, 10, np.random.default_rng(0))
