"""The runs of one problem family, paired across planners, and their two-level bootstrap.

A *run* is one root seed and replicate of ``qrrt reproduce problems``: every planner's record of it.
A family's runs are grouped by world (``family_units``); ``family_counts`` draws the two-level
bootstrap (worlds, then runs in each) once per family, shared by all its planners so that ratios
between planners are paired; ``resampled`` evaluates a per-solution quantity in every resample.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from .base import Record
from .intervals import RESAMPLES, percentile_interval, rounded_interval, two_level_bootstrap_counts

#: families that draw a new world per replicate (its seed is the replicate index)
WORLD_FAMILIES = ("maze", "winding-band-2d", "winding-band-4d", "winding-band-6d")
#: the record column summed by each per-solution quantity
QUANTITY_COLUMN = {"calls_per_solution": "oracle_calls", "critical_path_per_solution": "critical_path_calls",
                   "classical_checks_per_solution": "classical_checks", "wall_time_per_solution_s": "wall_time_s"}

Units = Sequence[tuple[str, dict[str, Record]]]


def statistic(runs: Sequence[Record], quantity: str) -> float:
    """One quantity of ``HEADLINE`` or ``DETAILS`` over runs (module docstring); inf for a cost per solution
    without a solved run, NaN for a path length without one."""
    solved = [r for r in runs if int(r["reached"])]
    if quantity.startswith("path_length"):
        return float(np.mean([float(r[quantity]) for r in solved])) if solved else math.nan
    total = float(sum(float(r[QUANTITY_COLUMN[quantity]]) for r in runs))
    return total / len(solved) if solved else math.inf


def family_units(records: Sequence[Record], family: str) -> list[tuple[str, dict[str, Record]]]:
    """The runs of one family as ``(world, {config: record})``, one per root seed and replicate.

    A run's world is its replicate for ``WORLD_FAMILIES`` (the replicate seeds the world) and the
    run itself otherwise (one world: every run its own group of the two-level bootstrap).
    """
    units: dict[tuple[int, int], dict[str, Record]] = {}
    for record in records:
        if record["family"] == family:
            units.setdefault((int(record["root_seed"]), int(record["replicate"])), {})[record["config"]] = record
    return [(f"world {replicate}" if family in WORLD_FAMILIES else f"run {root}-{replicate}", unit)
            for (root, replicate), unit in sorted(units.items())]


def family_counts(units: Units, seed: int, family_index: int,
            resamples: int = RESAMPLES) -> np.ndarray:
    """The two-level bootstrap counts of a family's runs (``intervals.two_level_bootstrap_counts``),
    shared by all its planners so that their ratios are paired."""
    sizes = [sum(1 for w, _ in units if w == world) for world in dict.fromkeys(w for w, _ in units)]
    if not sizes:
        return np.zeros((resamples, 0), dtype=np.int64)
    return two_level_bootstrap_counts(sizes, seed + 7919 * family_index, resamples)


def _column(units: Units, config: str, key: str) -> np.ndarray:
    """One record field of ``config`` per run (0 where the run lacks the planner or the value)."""
    values = []
    for _, unit in units:
        value = float(unit[config][key]) if config in unit else 0.0
        values.append(value if math.isfinite(value) else 0.0)
    return np.array(values)


def resampled(units: Units, counts: np.ndarray, config: str,
               quantity: str) -> np.ndarray:
    """``statistic`` of ``config``'s runs in every resample of ``counts`` (inf for a cost, NaN for
    a path length, where a resample has no solved run)."""
    if counts.shape[1] == 0:
        return np.full(counts.shape[0], np.nan)
    reached = _column(units, config, "reached")
    solved = counts @ reached
    if quantity.startswith("path_length"):
        top = counts @ (_column(units, config, quantity) * reached)
    else:
        top = counts @ _column(units, config, QUANTITY_COLUMN[quantity])
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(solved > 0, top / np.where(solved > 0, solved, 1),
                        np.nan if quantity.startswith("path_length") else np.inf)


def paired_ratio(units: Units, counts: np.ndarray, config: str, reference: str,
                  quantity: str) -> tuple[float, list[float]]:
    """The ratio of ``quantity`` of ``config`` to that of ``reference`` and its two-level interval
    (the same resampled runs for both planners)."""
    top = statistic([unit[config] for _, unit in units if config in unit], quantity)
    bottom = statistic([unit[reference] for _, unit in units if reference in unit], quantity)
    value = round(top / bottom, 4) if math.isfinite(top) and math.isfinite(bottom) and bottom > 0 else math.nan
    bottoms = resampled(units, counts, reference, quantity)
    with np.errstate(divide="ignore", invalid="ignore"):  # undefined where the reference solved none
        ratios = np.where(np.isfinite(bottoms), resampled(units, counts, config, quantity) / bottoms, np.nan)
    return value, rounded_interval(percentile_interval(ratios), 4)


