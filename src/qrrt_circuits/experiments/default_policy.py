"""The default-policy rule of ``qrrt reproduce problems``, fixed before its runs.

Per family, each candidate search policy's cost per solution (q-RRT's oracle calls, Pq-RRT's
critical-path calls) over the smallest candidate's is its *family ratio* (a family no candidate
solved is left out; a candidate that solved none where another did has ratio inf). The default is
the candidate whose worst family ratio is smallest; candidates whose worst ratios lie within
``TIE_MARGIN`` of the smallest are tied, and the tie goes to the lower geometric mean of the family
ratios, then to the earlier candidate in ``POLICY_CANDIDATES``. The goal is a worst ratio of at
most 1.5. The rule is also applied to each root seed's runs alone and to two-level bootstrap
resamples (its stability), and each family ratio has its interval over worlds and runs.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from .base import Record, Settings
from .family_runs import family_counts, family_units, resampled, statistic

#: the search policies the rule compares (``registry.POLICIES`` names), in tie-breaking order
POLICY_CANDIDATES = ("paper", "adaptive", "bbht", "thompson")
#: the rule's tie margin: worst ratios within this factor of the smallest are tied
TIE_MARGIN = 1.05
#: bootstrap resamples of the rule (its intervals and stability)
RULE_RESAMPLES = 400


def family_ratios(costs: dict[str, dict[str, float]]) -> dict[str, dict[str, float]]:
    """Each candidate's cost over the smallest candidate's, per family (the rule's family ratio).

    Args:
        costs: Family -> candidate -> cost per solution (inf where the candidate solved none).

    Returns:
        Candidate -> family -> ratio; families where no candidate solved are left out, a candidate
        that solved none where another did has ratio inf.
    """
    relative: dict[str, dict[str, float]] = {}
    for family, by_candidate in costs.items():
        best = min(by_candidate.values(), default=math.inf)
        if not math.isfinite(best) or best <= 0:
            continue
        for candidate, cost in by_candidate.items():
            relative.setdefault(candidate, {})[family] = cost / best if math.isfinite(cost) else math.inf
    return relative


def choose_by_worst_ratio(relative: dict[str, dict[str, float]], order: Sequence[str],
                          margin: float = TIE_MARGIN) -> str | None:
    """The default-policy rule of the module docstring on family ratios.

    Args:
        relative: Candidate -> family -> ratio (``family_ratios``).
        order: The candidates in their tie-breaking order (earlier wins a full tie).
        margin: Worst ratios within this factor of the smallest are tied (>= 1).

    Returns:
        The chosen candidate, or None if no candidate has a family ratio.
    """
    worst = {c: max(relative[c].values()) for c in order if relative.get(c)}
    if not worst:
        return None
    smallest = min(worst.values())
    tied = [c for c in order if c in worst and worst[c] <= smallest * margin]
    return min(tied, key=lambda c: (_geometric_mean(relative[c].values()), order.index(c)))


def _geometric_mean(values: Any) -> float:
    values = list(values)
    if not values:
        return math.nan
    return math.inf if not all(math.isfinite(v) for v in values) else float(np.exp(np.mean(np.log(values))))


def _candidate_costs(records: Sequence[Record], families: Sequence[str], configs: dict[str, str],
                     quantity: str) -> dict[str, dict[str, float]]:
    costs: dict[str, dict[str, float]] = {}
    for family in families:
        for candidate, config in configs.items():
            runs = [r for r in records if r["family"] == family and r["config"] == config]
            if runs:
                costs.setdefault(family, {})[candidate] = statistic(runs, quantity)
    return costs


def choose_default_policy(records: Sequence[Record], settings: Settings, planner: str, quantity: str,
                          resamples: int = RULE_RESAMPLES) -> dict[str, Any]:
    """The default search policy of ``planner`` by the rule of the module docstring.

    Args:
        records: The experiment's records.
        settings: Its settings (families, configs, root seeds, seed).
        planner: ``"QRRT"`` or ``"PQRRT"`` (its configs ``f"{planner} {policy}"``).
        quantity: ``"calls_per_solution"`` or ``"critical_path_per_solution"``.
        resamples: Two-level bootstrap resamples for the intervals and the rule's stability.

    Returns:
        ``{"rule", "quantity", "relative_cost": {policy: {family: ratio}}, "relative_cost_interval_95",
        "worst": {policy: worst ratio}, "geometric_mean", "chosen", "chosen_by_root_seed",
        "chosen_share_in_resamples", "goal_met"}``.
    """
    configs = {c: f"{planner} {c}" for c in POLICY_CANDIDATES if f"{planner} {c}" in settings["configs"]}
    families, seed = settings["families"], settings["seed"]
    relative = family_ratios(_candidate_costs(records, families, configs, quantity))
    order = list(configs)
    chosen = choose_by_worst_ratio(relative, order)
    by_root = {str(root): choose_by_worst_ratio(family_ratios(_candidate_costs(
        [r for r in records if int(r["root_seed"]) == int(root)], families, configs, quantity)), order)
        for root in settings["root_seeds"]}
    spans: dict[str, dict[str, list[float]]] = {c: {} for c in configs}
    resampled_costs: dict[str, np.ndarray] = {}  # family -> (resamples, candidates)
    for index, family in enumerate(families):
        units = family_units(records, family)
        if not units:
            continue
        counts = family_counts(units, seed, index, resamples)
        costs = np.stack([resampled(units, counts, config, quantity) for config in configs.values()], axis=1)
        resampled_costs[family] = costs
        best = costs.min(axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratios = np.where(np.isfinite(best)[:, None] & (best[:, None] > 0), costs / best[:, None], np.nan)
        for column, candidate in enumerate(configs):
            if family in relative.get(candidate, {}):  # inf (solved none in a resample) kept, NaN left out
                kept = ratios[~np.isnan(ratios[:, column]), column]
                spans[candidate][family] = ([round(float(np.quantile(kept, 0.025, method="lower")), 4),
                                             round(float(np.quantile(kept, 0.975, method="higher")), 4)]
                                            if kept.size else [math.nan, math.nan])
    shares = dict.fromkeys(configs, 0)
    for row in range(resamples):
        picked = choose_by_worst_ratio(family_ratios(
            {family: dict(zip(configs, map(float, costs[row]), strict=True))
             for family, costs in resampled_costs.items()}), order)
        if picked is not None:
            shares[picked] += 1
    worst = {c: _rounded(max(v.values())) for c, v in relative.items() if v}
    return {"rule": "per family, each candidate's cost per solution over the smallest candidate's; the candidate "
                    "with the smallest worst family ratio wins; worst ratios within 5 % are tied and go to the "
                    "lower geometric mean, then to the earlier candidate",
            "quantity": quantity,
            "relative_cost": {c: {f: _rounded(v) for f, v in fam.items()} for c, fam in relative.items()},
            "relative_cost_interval_95": spans, "worst": worst,
            "geometric_mean": {c: _rounded(_geometric_mean(v.values())) for c, v in relative.items()},
            "chosen": chosen, "chosen_by_root_seed": by_root,
            "chosen_share_in_resamples": {c: round(n / resamples, 4) for c, n in shares.items()},
            "goal_met": bool(chosen is not None and worst[chosen] <= 1.5)}


def default_policies(records: Sequence[Record], settings: Settings) -> dict[str, Any]:
    """The rule for q-RRT (calls) and Pq-RRT (critical path; its total calls beside)."""
    out: dict[str, Any] = {}
    for key, planner, quantity in (("QRRT", "QRRT", "calls_per_solution"),
                                   ("PQRRT", "PQRRT", "critical_path_per_solution"),
                                   ("PQRRT_total_calls", "PQRRT", "calls_per_solution")):
        if any(f"{planner} {c}" in settings["configs"] for c in POLICY_CANDIDATES):
            out[key] = choose_default_policy(records, settings, planner, quantity)
    return out


def _rounded(value: float) -> float:
    return round(value, 4) if math.isfinite(value) else value
