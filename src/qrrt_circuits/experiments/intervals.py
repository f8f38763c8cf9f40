"""95 % intervals on reproduced numbers: a percentile bootstrap over trials for any statistic of
the records, a two-level bootstrap over worlds and the runs inside each, and the exact
(Clopper-Pearson) interval for a binomial rate.

A number "differs from the paper" when the paper's value lies outside our interval. The bootstrap
resamples whole trials (a trial is the independent unit: one tree, one world), with a generator
seeded from the experiment's seed, so a summary is reproducible. A claim about a setting (a
geometry, an obstacle count, a problem family) rather than one drawn world takes the world as its
unit: ``two_level_bootstrap_interval`` resamples worlds, then runs inside each resampled world, so
its interval carries the spread between worlds as well as the spread between runs.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

LEVEL = 0.95
RESAMPLES = 2000
#: fewer worlds than this give a range (min-max over single worlds), not a bootstrap interval: a
#: percentile bootstrap over a handful of worlds covers well below its level
MIN_BOOTSTRAP_WORLDS = 20


def bootstrap_interval(trials: Sequence[Any], statistic: Callable[[list], float], seed: int,
                       resamples: int = RESAMPLES, level: float = LEVEL) -> tuple[float, float]:
    """Percentile bootstrap interval of ``statistic(trials)``, resampling whole trials.

    Args:
        trials: The independent units (records, or world indices).
        statistic: The number computed from a list of trials; resamples where it raises
            ``ValueError`` or ``ZeroDivisionError`` or gives a non-finite value are left out.
        seed: Seed of the resampling generator (a summary is reproducible).
        resamples: Bootstrap resamples.
        level: Coverage of the interval.

    Returns:
        ``(low, high)``: the (1 - level) / 2 and (1 + level) / 2 quantiles of the resampled
        statistic; ``(s, s)`` for fewer than two trials, NaNs if no resample is defined.
    """
    trials = list(trials)
    if len(trials) < 2:
        value = float(statistic(trials)) if trials else float("nan")
        return value, value
    rng = np.random.default_rng(seed)
    values = np.array([_defined(statistic, [trials[i] for i in rng.integers(0, len(trials), len(trials))])
                       for _ in range(resamples)], dtype=float)
    values = values[np.isfinite(values)]
    if values.size == 0:
        return float("nan"), float("nan")
    tail = (1.0 - level) / 2.0
    return float(np.quantile(values, tail)), float(np.quantile(values, 1.0 - tail))


def bootstrap_ratio_interval(numerators: Sequence[int], denominators: Sequence[int] | None, seed: int,
                             resamples: int = RESAMPLES, level: float = LEVEL,
                             per_trials: float | None = None) -> tuple[float, float]:
    """``bootstrap_interval`` of sum(numerators) / sum(denominators) (of sum(numerators) when
    ``denominators`` is None, or of ``per_trials * sum(numerators) / len(numerators)`` with
    ``per_trials``) over resampled trials, on index arrays.

    The same interval, bit for bit, as ``bootstrap_interval(trials, statistic, seed)`` with that
    statistic, for integer counts: the same resamples (``Generator.integers`` draws the
    (resamples, n) index matrix as ``resamples`` consecutive draws of n), exact integer sums, the
    same float operations in the same order, and resamples with a zero denominator left out as
    undefined.

    Args:
        numerators: One integer count per trial (nodes, say).
        denominators: One integer count per trial (oracle calls, say), or None for a plain sum.
        seed: Seed of the resampling generator.
        resamples: Bootstrap resamples (default ``RESAMPLES``).
        level: Confidence level of the percentile interval (default ``LEVEL``).
        per_trials: Without ``denominators``: the total per this many trials (``per_trials *
            sum / n``, e.g. 100.0 for nodes per 100 trials), or None (default) for the sum.

    Returns:
        (low, high); both the statistic itself for fewer than two trials, NaN for none.

    Raises:
        TypeError: Counts that are not integers.
        ValueError: ``denominators`` of another length than ``numerators``, or ``per_trials``
            given with ``denominators``.
    """
    top = np.asarray(numerators)
    bottom = None if denominators is None else np.asarray(denominators)
    for values, name in ((top, "numerators"), (bottom, "denominators")):
        if values is not None and values.size and not np.issubdtype(values.dtype, np.integer):
            raise TypeError(f"{name} must be integer counts, got dtype {values.dtype}")
    if bottom is not None and bottom.shape != top.shape:
        raise ValueError(f"denominators must have the length of numerators ({top.shape[0]}), got {bottom.shape[0]}")
    if per_trials is not None and bottom is not None:
        raise ValueError("per_trials scales a plain sum; give it without denominators")
    count = top.shape[0]

    def statistic(index: np.ndarray) -> np.ndarray:
        total = top[index].sum(axis=-1)
        if bottom is None:
            if per_trials is not None:
                return float(per_trials) * total / count
            return total.astype(float)
        calls = bottom[index].sum(axis=-1)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(calls != 0, total / np.where(calls != 0, calls, 1), np.nan)

    if count < 2:
        value = float(statistic(np.arange(count))) if count else float("nan")
        return value, value
    rng = np.random.default_rng(seed)
    values = statistic(rng.integers(0, count, (resamples, count)))
    values = values[np.isfinite(values)]
    if values.size == 0:
        return float("nan"), float("nan")
    tail = (1.0 - level) / 2.0
    return float(np.quantile(values, tail)), float(np.quantile(values, 1.0 - tail))


def two_level_bootstrap_counts(sizes: Sequence[int], seed: int, resamples: int = RESAMPLES) -> np.ndarray:
    """How often each run is drawn in each resample of a two-level bootstrap over worlds and runs.

    One resample draws as many worlds as there are, uniformly with replacement, and for each drawn
    world as many of its runs as it has, uniformly with replacement. A world drawn ``c`` times
    contributes ``c * size`` independent uniform draws of its runs, so its runs' counts are one
    multinomial draw of that total.

    Args:
        sizes: The runs of each world, in the order of the pooled runs (world 0's runs first);
            every size >= 1.
        seed: Seed of the resampling generator.
        resamples: Bootstrap resamples.

    Returns:
        Int array (resamples, sum(sizes)): the count of each pooled run in each resample; each
        row sums to sum(sizes) in expectation (exactly when all worlds have one size).

    Raises:
        ValueError: An empty ``sizes`` or a size below 1.
    """
    sizes = [int(size) for size in sizes]
    if not sizes or min(sizes) < 1:
        raise ValueError(f"sizes must be a non-empty list of sizes >= 1, got {sizes}")
    rng = np.random.default_rng(seed)
    worlds = rng.integers(0, len(sizes), (resamples, len(sizes)))
    counts = np.zeros((resamples, sum(sizes)), dtype=np.int64)
    start = 0
    for world, size in enumerate(sizes):
        drawn = np.count_nonzero(worlds == world, axis=1)
        counts[:, start:start + size] = rng.multinomial(drawn * size, np.full(size, 1.0 / size))
        start += size
    return counts


def two_level_bootstrap_interval(groups: Mapping[Any, Sequence[Any]], statistic: Callable[[list], float],
                                 seed: int, resamples: int = RESAMPLES,
                                 level: float = LEVEL) -> tuple[float, float]:
    """Percentile interval of ``statistic`` over a two-level bootstrap: worlds, then runs in each.

    One resample draws as many worlds as there are, with replacement, and inside each drawn world
    as many of its runs as it has, with replacement (``two_level_bootstrap_counts``); ``statistic``
    is evaluated on all the runs so drawn, pooled. This is the random-effects bootstrap of Davison
    and Hinkley, *Bootstrap Methods and their Application* (1997), Sec. 3.8 (resampling at both
    stages). Its variance is about ``(sigma_b^2 + 2 sigma_w^2 / r) / a`` for ``a`` worlds of ``r``
    runs, against the true ``(sigma_b^2 + sigma_w^2 / r) / a``: it is conservative where the spread
    between runs of one world dominates, and like every percentile bootstrap it is a little narrow
    for few worlds (``tests/experiments/test_intervals.py`` measures both).

    Args:
        groups: World key -> that world's runs (records, or numbers); worlds without runs are
            left out; worlds are taken in the order of their keys' strings.
        statistic: The number computed from a flat list of runs; resamples where it raises
            ``ValueError`` or ``ZeroDivisionError`` or gives a non-finite value are left out.
        seed: Seed of the resampling generator.
        resamples: Bootstrap resamples.
        level: Coverage of the interval.

    Returns:
        ``(low, high)``; ``(s, s)`` for fewer than two worlds (no spread between worlds can be
        measured), NaNs if no resample is defined.
    """
    worlds = [list(runs) for _, runs in sorted(groups.items(), key=lambda item: str(item[0])) if len(runs)]
    pooled = [run for runs in worlds for run in runs]
    if len(worlds) < 2:
        value = _defined(statistic, pooled) if pooled else float("nan")
        return value, value
    counts = two_level_bootstrap_counts([len(runs) for runs in worlds], seed, resamples)
    values = np.array([_defined(statistic, [run for run, count in zip(pooled, row, strict=True)
                                            for _ in range(count)]) for row in counts])
    return percentile_interval(values, level)


def percentile_interval(values: np.ndarray, level: float = LEVEL) -> tuple[float, float]:
    """The (1 - level) / 2 and (1 + level) / 2 quantiles of the finite ``values`` (NaNs if none)."""
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    if values.size == 0:
        return float("nan"), float("nan")
    tail = (1.0 - level) / 2.0
    return float(np.quantile(values, tail)), float(np.quantile(values, 1.0 - tail))


def _defined(statistic: Callable[[list], float], sample: list) -> float:
    """The statistic of one resample, or NaN where it is undefined there (a line fit through one
    distinct x, say): such resamples are left out of the percentiles."""
    try:
        return float(statistic(sample))
    except (ValueError, ZeroDivisionError):
        return float("nan")


def binomial_interval(successes: int, trials: int, level: float = LEVEL) -> tuple[float, float]:
    """Exact (Clopper-Pearson) interval of a success rate.

    Args:
        successes: Observed successes.
        trials: Bernoulli trials.
        level: Coverage of the interval.

    Returns:
        ``(low, high)``; NaNs when ``trials`` is 0.
    """
    if trials <= 0:
        return float("nan"), float("nan")
    from scipy.stats import binomtest  # a slow import: only the summaries that need it import it

    interval = binomtest(int(successes), int(trials)).proportion_ci(confidence_level=level, method="exact")
    return float(interval.low), float(interval.high)


def rounded_interval(interval: tuple[float, float], digits: int = 4) -> list[float]:
    """An interval as a JSON list, rounded.

    Args:
        interval: ``(low, high)``.
        digits: Decimal digits kept.

    Returns:
        ``[low, high]`` rounded to ``digits``.
    """
    return [round(interval[0], digits), round(interval[1], digits)]


def differs(paper: float | None, interval: Sequence[float]) -> bool | None:
    """True if the paper's value lies outside our interval (None if there is nothing to compare).

    Args:
        paper: The paper's value, or None.
        interval: Our ``[low, high]``.

    Returns:
        Whether ``paper`` is outside the closed interval; None if ``paper`` is None or the
        interval is not finite.
    """
    if paper is None or not np.all(np.isfinite(interval)):
        return None
    return bool(paper < interval[0] or paper > interval[1])
