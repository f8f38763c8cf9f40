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


def test_ratio_bootstrap_refuses_bad_counts():
    with pytest.raises(TypeError, match="numerators"):
        bootstrap_ratio_interval([1.5, 2.0], None, 0)
    with pytest.raises(ValueError, match="denominators"):
        bootstrap_ratio_interval([1, 2], [1], 0)
