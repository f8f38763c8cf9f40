"""Tolerances for shot- and sampling-based tests, derived from the distributions, never guessed."""

from __future__ import annotations

import math

from scipy.stats import binom

#: two-sided tail probability a correct implementation may fail a single test with
TAIL = 1e-6


def binomial_counts(trials: int, p: float, tail: float = TAIL) -> tuple[int, int]:
    """The central (1 - tail) interval of Binomial(trials, p) counts (exact, also for p near 0 or 1)."""
    low, high = binom.interval(1.0 - tail, trials, p)
    return int(low), int(high)


def within_binomial(successes: int, trials: int, p: float, tail: float = TAIL) -> bool:
    low, high = binomial_counts(trials, p, tail)
    return low <= successes <= high


def z_bound(tail: float = TAIL) -> float:
    """The two-sided normal quantile for ``tail`` (about 4.9 sigma for 1e-6)."""
    from scipy.stats import norm

    return float(norm.isf(tail / 2))


def difference_sigma(p1: float, n1: int, p2: float, n2: int) -> float:
    """Standard deviation of the difference of two independent binomial proportions."""
    return math.sqrt(p1 * (1 - p1) / n1 + p2 * (1 - p2) / n2)
