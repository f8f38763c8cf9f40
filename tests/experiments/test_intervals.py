"""The two-level bootstrap over worlds and runs (``experiments.intervals``): its coverage on
synthetic data with a known between-world variance, and its edge cases."""

from __future__ import annotations

import math

import numpy as np
import pytest

from qrrt_circuits.experiments.intervals import LEVEL, bootstrap_interval, two_level_bootstrap_interval

DATASETS = 300
RESAMPLES = 300


def _coverage(worlds: int, runs: int, between_sd: float, within_sd: float, seed: int) -> float:
    """Share of simulated data sets (world means drawn with ``between_sd`` around 0, runs with
    ``within_sd`` around their world's mean) whose interval for the mean over runs covers 0."""
    rng = np.random.default_rng(seed)
    hits = 0
    for dataset in range(DATASETS):
        groups = {w: list(rng.normal(rng.normal(0.0, between_sd), within_sd, runs)) for w in range(worlds)}
        low, high = two_level_bootstrap_interval(groups, lambda sample: float(np.mean(sample)), dataset,
                                                 resamples=RESAMPLES)
        hits += int(low <= 0.0 <= high)
    return hits / DATASETS


def _binomial_sd() -> float:
    return math.sqrt(LEVEL * (1.0 - LEVEL) / DATASETS)


def test_coverage_near_nominal_when_worlds_differ_as_much_as_runs() -> None:
    """20 worlds of 5 runs, between-world and within-world spread equal: within two binomial
    standard deviations of 95 %."""
    coverage = _coverage(20, 5, 1.0, 1.0, seed=1)
    assert abs(coverage - LEVEL) <= 2 * _binomial_sd(), coverage


def test_coverage_conservative_when_runs_dominate() -> None:
    """Within-world spread 3x the between-world spread: the both-stage bootstrap counts it twice,
    so it covers at least 95 % (minus two binomial standard deviations)."""
    coverage = _coverage(20, 5, 1.0, 3.0, seed=2)
    assert coverage >= LEVEL - 2 * _binomial_sd(), coverage


def test_run_level_bootstrap_undercovers_a_setting() -> None:
    """The failure the two-level bootstrap exists for: resampling runs as if independent, with
    a between-world spread, misses the setting's mean far more often than 5 %."""
    rng = np.random.default_rng(3)
    hits = 0
    for dataset in range(100):
        runs = [x for _ in range(10) for x in rng.normal(rng.normal(0.0, 1.0), 0.5, 10)]
        low, high = bootstrap_interval(runs, lambda sample: float(np.mean(sample)), dataset, resamples=200)
        hits += int(low <= 0.0 <= high)
    assert hits / 100 < LEVEL - 4 * math.sqrt(LEVEL * (1 - LEVEL) / 100)


def test_two_level_interval_is_wider_than_the_run_level_one() -> None:
    rng = np.random.default_rng(4)
    groups = {w: list(rng.normal(rng.normal(0.0, 2.0), 0.5, 8)) for w in range(12)}
    pooled = [x for runs in groups.values() for x in runs]
    mean = lambda sample: float(np.mean(sample))  # noqa: E731
    two = two_level_bootstrap_interval(groups, mean, 0)
    one = bootstrap_interval(pooled, mean, 0)
    assert two[1] - two[0] > 2 * (one[1] - one[0])
    assert two[0] < float(np.mean(pooled)) < two[1]


def test_same_seed_same_interval_and_order_of_worlds_irrelevant() -> None:
    groups = {f"w{i}": [float(i), float(i) + 1.0, float(i) * 2] for i in range(6)}
    mean = lambda sample: float(np.mean(sample))  # noqa: E731
    reversed_groups = dict(reversed(list(groups.items())))
    assert two_level_bootstrap_interval(groups, mean, 7) == two_level_bootstrap_interval(reversed_groups, mean, 7)


@pytest.mark.parametrize("groups", [{}, {"a": []}, {"a": [1.0, 2.0]}, {"a": [1.0, 3.0], "b": []}])
def test_fewer_than_two_worlds_give_the_statistic_itself(groups: dict) -> None:
    low, high = two_level_bootstrap_interval(groups, lambda sample: float(np.mean(sample)), 0)
    runs = [x for xs in groups.values() for x in xs]
    if runs:
        assert low == high == float(np.mean(runs))
    else:
        assert math.isnan(low) and math.isnan(high)


def test_undefined_resamples_left_out() -> None:
    """A ratio whose denominator is zero in some resamples: those are left out, not infinite."""
    groups = {0: [(1, 0)], 1: [(2, 1)], 2: [(3, 1)]}

    def ratio(sample: list) -> float:
        return sum(a for a, _ in sample) / sum(b for _, b in sample)

    low, high = two_level_bootstrap_interval(groups, ratio, 0)
    assert math.isfinite(low) and math.isfinite(high)
    assert 2.0 <= low <= high <= 5.0 + 1e-12  # (1 + 1 + 3) / (0 + 0 + 1) at most
