"""The vectorized ratio bootstrap gives bootstrap_interval's interval bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from qrrt_circuits.experiments.intervals import bootstrap_interval, bootstrap_ratio_interval


@pytest.mark.parametrize("trials", [0, 1, 2, 7, 50])
def test_ratio_bootstrap_equals_the_generic_one(trials):
    rng = np.random.default_rng(trials)
    nodes = rng.integers(0, 40, trials).tolist()
    calls = rng.choice([0, 0, 5, 17, 100], trials).tolist()  # zero denominators: undefined resamples
    rows = [{"nodes": n, "calls": c} for n, c in zip(nodes, calls, strict=True)]

    def total(sample):
        return sum(r["nodes"] for r in sample)

    def ratio(sample):
        denominator = sum(r["calls"] for r in sample)
        return sum(r["nodes"] for r in sample) / denominator if denominator else float("nan")

    for seed in (0, 3):
        expected_total = bootstrap_interval(rows, total, seed, resamples=500)
        expected_ratio = bootstrap_interval(rows, ratio, seed, resamples=500)
        got_total = bootstrap_ratio_interval(nodes, None, seed, resamples=500)
        got_ratio = bootstrap_ratio_interval(nodes, calls, seed, resamples=500)
        np.testing.assert_array_equal(got_total, expected_total)
        np.testing.assert_array_equal(got_ratio, expected_ratio)
        for scale in (100.0, 3.0):  # heatmap-hypotheses: nodes per 100 trials
            def per_trials(sample, scale=scale):
                return scale * sum(r["nodes"] for r in sample) / len(sample)

            if trials:
                np.testing.assert_array_equal(
                    bootstrap_ratio_interval(nodes, None, seed, resamples=500, per_trials=scale),
                    bootstrap_interval(rows, per_trials, seed, resamples=500))


def test_ratio_bootstrap_refuses_bad_counts():
    with pytest.raises(TypeError, match="numerators"):
        bootstrap_ratio_interval([1.5, 2.0], None, 0)
    with pytest.raises(ValueError, match="denominators"):
        bootstrap_ratio_interval([1, 2], [1], 0)
    with pytest.raises(ValueError, match="per_trials"):
        bootstrap_ratio_interval([1, 2], [1, 1], 0, per_trials=100.0)


@pytest.mark.parametrize("trials", [1, 2, 9, 40])
def test_pooled_window_interval_equals_the_generic_one(trials):
    """tree-size / search-policies: the interval of pooled calls per node in a window, from
    per-row counts, is bootstrap_interval's over the records, bit for bit (rows that never reach
    the window's upper size count as nothing; a resample of only such rows is undefined)."""
    import functools

    from qrrt_circuits.experiments.measures import dumps
    from qrrt_circuits.experiments.tree_size import pooled_calls_per_node, pooled_interval

    rng = np.random.default_rng(100 + trials)
    rows = []
    for _ in range(trials):
        sizes = [10, 30, 100] if rng.random() < 0.7 else [10, 30]  # some trees stop early
        calls = np.cumsum(rng.integers(1, 400, len(sizes))).tolist()
        rows.append({"points_json": dumps([[size, call, call // 8] for size, call in zip(sizes, calls, strict=True)])})
    for window in ("10-30", "30-100"):
        for seed in (0, 5):
            expected = bootstrap_interval(rows, functools.partial(pooled_calls_per_node, window=window), seed)
            np.testing.assert_array_equal(pooled_interval(rows, window, seed), expected)
