"""The rows of ``qrrt reproduce problems`` for the quantum RRT-Connect and RRT*: q-RRT-Connect's
calls to its first solution over OMPL RRTConnect's motion checks, and q-RRT*'s path cost against
OMPL RRT*'s at equal budgets in motion checks.

Per run (one root seed and replicate, both planners' records of it):

- **connect ratio**: q-RRT-Connect's oracle calls over OMPL RRTConnect's motion checks, each the
  calls until the first solution or the whole budget for a run that failed; reported as the median
  over the family's runs with a 95 % interval from the two-level bootstrap of ``family_runs`` (worlds,
  then the runs in each; its 2.5 % and 97.5 % quantiles, inf where the resampled median is inf).
- **star cost ratio**: q-RRT*'s path length at the budget over OMPL RRT*'s (both under the problem's
  metric, ``path_length``; inf where q-RRT* holds no path, a run OMPL RRT* did not solve left out),
  median and interval as above; and the **share of the budget** q-RRT* needs to reach OMPL RRT*'s
  path length at the full budget: the least of ``BUDGET_SHARES`` at which its best cost is at most
  that, inf where it never is. The mean costs at each share are each planner's own (OMPL's
  ``bestCost()`` is under its real-vector metric, which differs from the problem's in SE(2)).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from .base import Record
from .family_runs import Units

__all__ = ["BUDGET_SHARES", "NO_ANYTIME", "anytime_columns", "connect_summary", "cost_at_shares", "star_summary"]

#: the shares of the budget (percent) at which an anytime planner's best cost is recorded
BUDGET_SHARES = (5, 10, 25, 50, 75, 100)
#: the anytime columns of a planner that is not anytime (every record of a run has the same columns)
NO_ANYTIME: Record = {**{f"cost_at_{share}": math.nan for share in BUDGET_SHARES}, "first_solution_calls": math.nan}


def cost_at_shares(calls: ArrayLike, costs: ArrayLike, budget: int) -> dict[str, float]:
    """``cost_at_P``: the best cost held once at most P % of ``budget`` calls were spent (NaN before
    the first solution).

    Args:
        calls: Oracle calls (or motion checks) at which the best cost changed or was read, increasing.
        costs: The best cost then (NaN before the first solution).
        budget: The run's budget.

    Returns:
        One column per share of ``BUDGET_SHARES``.
    """
    calls_array, cost_array = np.asarray(calls, dtype=float), np.asarray(costs, dtype=float)
    columns = {}
    for share in BUDGET_SHARES:
        held = np.flatnonzero(calls_array <= share * budget / 100.0)
        columns[f"cost_at_{share}"] = float(cost_array[held[-1]]) if held.size else math.nan
    return columns


def anytime_columns(calls: ArrayLike, costs: ArrayLike, budget: int) -> Record:
    """``cost_at_shares`` and ``first_solution_calls`` (the calls when a path was first held, NaN if
    never)."""
    calls_array, cost_array = np.asarray(calls, dtype=float), np.asarray(costs, dtype=float)
    finite = calls_array[np.isfinite(cost_array)]
    first = float(finite[0]) if finite.size else math.nan
    return cost_at_shares(calls, costs, budget) | {"first_solution_calls": first}


def _median_with_interval(values: np.ndarray, counts: np.ndarray) -> tuple[float, list[float]]:
    """The median of the per-run ``values`` that are not NaN (inf counts as larger than any), and the
    2.5 % and 97.5 % quantiles of the medians over the resampled runs of ``counts`` (resamples x runs),
    inf included."""
    keep = ~np.isnan(values)
    if not keep.any():
        return math.nan, [math.nan, math.nan]
    medians = []
    for row in counts:
        drawn = np.repeat(values[keep], row[keep])
        if drawn.size:
            medians.append(float(np.median(drawn)))
    value = float(np.median(values[keep]))
    low, high = (float(q) for q in np.quantile(np.asarray(medians), [0.025, 0.975], method="inverted_cdf"))
    return _rounded(value), [_rounded(low), _rounded(high)]


def _rounded(value: float) -> float:
    """4 decimals, inf kept (a median over runs that never reach the reference is inf)."""
    return round(value, 4) if math.isfinite(value) else value


def connect_summary(units: Units, counts: np.ndarray, config: str, reference: str) -> dict:
    """The connect ratio (module docstring) of ``config`` against ``reference`` in one family.

    Returns:
        ``{"median": ..., "interval_95": [low, high], "runs": ..., "both_solved": ...}``.
    """
    ratios, both = [], 0
    for _, unit in units:
        if config in unit and reference in unit:
            ours, theirs = unit[config], unit[reference]
            ratios.append(float(ours["oracle_calls"]) / max(1.0, float(theirs["oracle_calls"])))
            both += int(ours["reached"]) and int(theirs["reached"])
        else:
            ratios.append(math.nan)
    median, interval = _median_with_interval(np.asarray(ratios), counts)
    return {"median": median, "interval_95": interval, "runs": int(np.count_nonzero(~np.isnan(ratios))),
            "both_solved": both}


def star_summary(units: Units, counts: np.ndarray, config: str, reference: str) -> dict:
    """The star cost ratio and the share of the budget to reach the reference's cost (module
    docstring), with each planner's mean cost at every share of the budget over its runs with a path.

    Returns:
        ``cost_ratio`` / ``cost_ratio_interval_95`` (median over runs), ``share_to_reach`` /
        ``share_to_reach_interval_95`` (median over runs, percent, inf if more than the budget),
        ``mean_cost`` (planner -> share -> mean cost) and ``solved_share`` (planner -> share ->
        share of runs holding a path).
    """
    ratios, shares = [], []
    for _, unit in units:
        ours, theirs = unit.get(config), unit.get(reference)
        target = math.nan if ours is None or theirs is None else float(theirs["path_length"])
        if not math.isfinite(target):
            ratios.append(math.nan)
            shares.append(math.nan)
            continue
        assert ours is not None
        ratios.append(float(ours["path_length"]) / target if math.isfinite(float(ours["path_length"])) else math.inf)
        reached = [share for share in BUDGET_SHARES if float(ours[f"cost_at_{share}"]) <= target]
        shares.append(float(reached[0]) if reached else math.inf)
    ratio, ratio_interval = _median_with_interval(np.asarray(ratios), counts)
    share, share_interval = _median_with_interval(np.asarray(shares), counts)
    mean_cost: dict[str, dict[str, float]] = {}
    solved_share: dict[str, dict[str, float]] = {}
    for name in (config, reference):
        runs = [unit[name] for _, unit in units if name in unit]
        for budget_share in BUDGET_SHARES:
            values = np.array([float(run[f"cost_at_{budget_share}"]) for run in runs])
            finite = values[np.isfinite(values)]
            mean_cost.setdefault(name, {})[str(budget_share)] = round(float(finite.mean()), 4) if finite.size \
                else math.nan
            solved_share.setdefault(name, {})[str(budget_share)] = round(finite.size / len(runs), 4) if runs \
                else math.nan
    return {"cost_ratio": ratio, "cost_ratio_interval_95": ratio_interval, "share_to_reach": share,
            "share_to_reach_interval_95": share_interval, "mean_cost": mean_cost, "solved_share": solved_share}
