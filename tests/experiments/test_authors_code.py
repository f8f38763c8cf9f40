"""The reported Octave run's estimators replicated from our trees (``experiments.authors_code``)."""

from __future__ import annotations

import numpy as np
import pytest

from qrrt_circuits.experiments.authors_code import REPORTED, median_coverage, pooled_ratio_design


def _curve(calls_of_nodes, nodes=30):
    n = np.arange(1, nodes + 1)
    return np.stack([n, calls_of_nodes(n), calls_of_nodes(n)], axis=1)


def test_a_constant_rate_gives_that_rate_for_every_design():
    curves = [_curve(lambda n: 10 * n) for _ in range(5)]
    pooled, median = pooled_ratio_design(curves, ((5, 17),) * 7, 200, np.random.default_rng(0))
    assert np.allclose(pooled, 10.0) and np.allclose(median, 10.0)


def test_sizes_are_drawn_inside_each_trees_range():
    # calls = nodes^2: a tree stopped at s nodes has calls per node s, so the median is a size
    curves = [_curve(lambda n: n * n)]
    _, median = pooled_ratio_design(curves, ((24, 29),) * 3, 2000, np.random.default_rng(1))
    assert median.min() >= 24 and median.max() <= 29
    assert len(np.unique(median)) == 6  # every size of the range is drawn


def test_the_pooled_ratio_weights_trees_by_their_nodes():
    # one tree at 2 calls per node, one at 20: the pooled ratio of (s1, s2) = (30, 10) nodes is
    # (60 + 200) / 40, not the mean of the two ratios
    curves = [_curve(lambda n: 2 * n), _curve(lambda n: 20 * n)]
    pooled, _ = pooled_ratio_design(curves, ((30, 30), (10, 10)), 4000, np.random.default_rng(2))
    expected = {(2 * 30 + 2 * 10) / 40, (2 * 30 + 20 * 10) / 40, (20 * 30 + 2 * 10) / 40, (20 * 30 + 20 * 10) / 40}
    assert set(np.round(pooled, 9)) == {round(v, 9) for v in expected}


def test_a_tree_short_of_its_size_gives_nan():
    pooled, median = pooled_ratio_design([_curve(lambda n: n, nodes=10)], ((20, 20), (5, 5)), 5,
                                         np.random.default_rng(3))
    assert np.isnan(pooled).all() and np.isnan(median).all()


def test_the_range_of_seven_values_covers_their_median_with_the_stated_probability():
    assert median_coverage(7) == pytest.approx(1 - 1 / 64)
    rng = np.random.default_rng(4)
    draws = rng.exponential(size=(20000, 7))
    covered = np.mean((draws.min(axis=1) <= np.log(2)) & (np.log(2) <= draws.max(axis=1)))
    sd = np.sqrt(median_coverage(7) * (1 - median_coverage(7)) / 20000)
    assert abs(covered - median_coverage(7)) < 4 * sd


def test_the_reported_run_is_seven_trees_per_planner_with_its_pooled_figure_inside_its_range():
    for run in REPORTED.values():
        assert run.trees == 7
        assert run.per_tree_range[0] <= run.pooled <= run.per_tree_range[1]


@pytest.mark.parametrize(("curves", "sizes", "resamples", "match"), [
    ([], ((1, 2), (1, 2)), 1, "at least one growth curve"),
    ([_curve(lambda n: n)], ((1, 2),), 1, "tree_sizes must name >= 2 trees"),
    ([_curve(lambda n: n)], ((1, 2), (1, 2)), 0, "resamples must be >= 1"),
    ([_curve(lambda n: n)], ((0, 2), (1, 2)), 1, "1 <= low <= high"),
    ([_curve(lambda n: n)], ((3, 2), (1, 2)), 1, "1 <= low <= high"),
])
def test_bad_designs_are_refused(curves, sizes, resamples, match):
    with pytest.raises(ValueError, match=match):
        pooled_ratio_design(curves, sizes, resamples, np.random.default_rng(0))
    with pytest.raises(ValueError, match="trees must be >= 2"):
        median_coverage(1)
