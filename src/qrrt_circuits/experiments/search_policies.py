"""Beyond the paper: search policies that cannot overshoot, or that estimate m first, against the
paper's schedule, BBHT, Adaptive and KnownOptimal, as the tree grows.

Every planner grows one tree per world in ``paper_clutter`` toward a goal it cannot reach (goal
radius 1e-9), as in ``tree-size``, and the cumulative oracle calls (total and critical path) are
read at tree sizes 30, 100, 300 and 1000; the marginal cost of each window is calls added / nodes
added. Each policy is run in q-RRT (1 worker) and in Pq-RRT with 8 workers on a shared database,
where ``EstimatedOptimal``'s amplitude estimation is paid once per database and used by the 8
workers (its shots are shared among them, so its critical path is one worker's share).

For ``EstimatedOptimal`` the trial also records the estimation's oracle calls separately from the
search's, and the summary derives, from the q-RRT runs, the number of workers p* at which one
estimation per database would make its calls per node equal Adaptive's:
calls per node(p) = (E + p s) / (p r) with E the estimation calls per database, s the search calls
(k + 1) per worker and r the success rate per worker; Adaptive's is s_a / r_a. Duplicate finds on a
shared database are ignored in that formula (they only make sharing worse), so p* is a lower bound.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from ..registry import POLICIES
from ..search.policies.base import IterationPolicy
from ..search.policies.estimated import EstimatedOptimal, EstimatedOptimalState
from .base import Experiment, Record, Settings, Summary, Trial, TrialStream, paired_trials
from .figures import dodge, new_figure, save, with_intervals
from .intervals import bootstrap_interval, bootstrap_ratio_interval, rounded_interval
from .measures import dumps
from .planners import experiment_problem, make_planner
from .tree_size import (
    calls_at_sizes,
    fraction_interval,
    mean_fraction,
    pooled_calls_per_node,
    pooled_interval,
    reachable_fraction_by_window,
)
from .worlds import world

SIZES = (30, 100, 300, 1000)
POLICY_NAMES = ("paper", "bbht", "adaptive", "fixed-point", "estimated", "optimal")
#: label -> (registry planner, search policy name or None)
CONFIGS = {"RRT": ("rrt", None)} | {
    f"{prefix} {policy}": (planner, policy)
    for prefix, planner in (("QRRT", "qrrt"), ("PQRRT", "pqrrt")) for policy in POLICY_NAMES}
COLORS = {"paper": "tab:blue", "bbht": "tab:green", "adaptive": "tab:orange", "fixed-point": "tab:red",
          "estimated": "tab:cyan", "optimal": "tab:purple"}


class _LoggedEstimatedOptimal(EstimatedOptimal):
    """EstimatedOptimal whose plan state is kept, to read its per-database (estimate, k) history."""

    states: list[EstimatedOptimalState]  # not a dataclass field: set in __post_init__

    def __post_init__(self) -> None:
        super().__post_init__()
        object.__setattr__(self, "states", [])  # a frozen dataclass; the list is this trial's log

    def start(self, num_items: int) -> EstimatedOptimalState:
        state = super().start(num_items)
        self.states.append(state)
        return state


#: a stand-in for "no number of workers pays" in a bootstrap resample (ranked above every finite p*)
NEVER = 1e12


def estimation_figures(records: Sequence[Record]) -> dict[str, Any]:
    """Estimation vs search calls of EstimatedOptimal, and the workers p* at which one estimation
    per database would match a rival's calls per node (from the q-RRT runs; module docstring).

    Args:
        records: The experiment's records (those of other configurations are ignored).

    Returns:
        ``{"QRRT" | "PQRRT": {"estimation_calls_per_database", "search_calls_per_worker",
        "estimation_share_of_calls"}, "break_even_workers": {rival: p* or None}, "break_even_note"}``,
        with the entries the records allow.
    """
    out: dict[str, Any] = {}
    for prefix in ("QRRT", "PQRRT"):
        rows = [r for r in records if r["config"] == f"{prefix} estimated"]
        databases = sum(r["databases"] for r in rows)
        searches = sum(r["verification_calls"] for r in rows)
        if not databases or not searches:
            continue
        out[prefix] = {"estimation_calls_per_database": round(sum(r["estimation_calls"] for r in rows)
                                                              / databases, 2),
                       "search_calls_per_worker": round((sum(r["quantum_oracle_calls"] - r["estimation_calls"]
                                                             for r in rows) + searches) / searches, 3),
                       "estimation_share_of_calls": round(sum(r["estimation_calls"] for r in rows)
                                                          / sum(r["oracle_calls"] for r in rows), 4)}
    single = [r for r in records if r["config"] == "QRRT estimated"]
    if single:
        searches = sum(r["verification_calls"] for r in single)
        estimation = sum(r["estimation_calls"] for r in single) / searches
        search_cost = (sum(r["quantum_oracle_calls"] - r["estimation_calls"] for r in single) + searches) / searches
        rate = sum(r["nodes"] for r in single) / searches
        out["break_even_workers"] = {}
        for rival in ("adaptive", "bbht", "paper"):
            rows = [r for r in records if r["config"] == f"QRRT {rival}"]
            if not rows:
                continue
            per_node = sum(r["oracle_calls"] for r in rows) / sum(r["nodes"] for r in rows)
            margin = rate * per_node - search_cost
            out["break_even_workers"][rival] = None if margin <= 0 else round(estimation / margin, 1)
        out["break_even_note"] = ("p* = E / (r x rival's calls per node - s) from the q-RRT runs (E: estimation "
                                  "calls per database, s: search calls per worker, r: nodes per worker search); "
                                  "None: the searches after an estimate cost more per node than the rival's, so "
                                  "no number of workers pays")
    return out


def _world_figure(by_world: dict[int, list[Record]], group: str, key: str, worlds: Sequence[int]) -> float:
    """One ``estimation_figures`` number on the records of the given worlds (a bootstrap resample:
    a world drawn twice counts twice); ``NEVER`` where no number of workers pays, NaN where the
    resample cannot give it."""
    figures = estimation_figures([r for w in worlds for r in by_world[w]])
    value = figures.get(group, {}).get(key, math.nan) if group in figures else math.nan
    if group == "break_even_workers" and key in figures.get(group, {}) and value is None:
        return NEVER
    return float(value)


def _policy(name: str | None) -> IterationPolicy | None:
    if name == "estimated":
        return _LoggedEstimatedOptimal()
    if name is None:
        return None
    policy: IterationPolicy = POLICIES.create(name)
    return policy


class SearchPolicies(Experiment):
    """Search policies that cannot overshoot or that estimate m, as the tree grows (beyond the paper).

    A trial grows one tree with RRT or q-RRT / Pq-RRT under one policy of ``POLICY_NAMES`` and
    records the calls at sizes 30, 100, 300 and 1000 (``calls_at_sizes``). The summary gives the
    marginal calls per node in each window (total and critical path), the whole run's calls per
    node, the mean reachable fraction, and for ``EstimatedOptimal`` the estimation's share of the
    calls and the break-even number of workers (module docstring), each with its 95 % bootstrap
    interval over worlds.
    """

    name = "search-policies"
    title = "Search that cannot overshoot: fixed-point amplification and estimated m (beyond the paper)"
    paper = {"note": "the paper uses a fixed schedule (5 then 3 iterations) and reports 30-node trees only"}

    def settings(self, quick: bool, trials: int | None, seed: int) -> Settings:
        return {"trials": trials or (2 if quick else 3), "sizes": list(SIZES[:2] if quick else SIZES),
                "workers": 8, "num_qubits": 8, "backend": "statevector", "scenario": "paper_clutter",
                "configs": list(CONFIGS), "policies": {name: POLICIES.create(name).describe()
                                                       for name in POLICY_NAMES},
                "seed": seed, "quick": quick}

    def trials(self, settings: Settings) -> list[Trial]:
        variants = [(label, {"config": label}) for label in settings["configs"]]
        return paired_trials(settings, variants, TrialStream.SEARCH_POLICIES_WORLDS,
                             TrialStream.SEARCH_POLICIES_PLANNERS)

    def run_trial(self, trial: Trial, settings: Settings) -> Record:
        problem = experiment_problem(settings, world(settings["scenario"], trial.params["world_seed"]))
        planner_name, policy_name = CONFIGS[trial.params["config"]]
        policy = _policy(policy_name)
        planner = make_planner(planner_name, trial.seed, settings["backend"], settings["workers"],
                              settings["num_qubits"], search_policy=policy)
        result = planner.plan(problem.with_goal_radius(1e-9), max_nodes=max(settings["sizes"]))
        m = result.metrics
        estimation = k_total = 0
        if isinstance(policy, _LoggedEstimatedOptimal):
            history = policy.states[-1].history
            estimation = sum(est.oracle_calls for est, _ in history)
            k_total = sum(k for _, k in history)
        return {"status": str(result.status), "nodes": m.nodes, "rounds": m.rounds,
                "oracle_calls": m.oracle_calls, "quantum_oracle_calls": m.quantum_oracle_calls,
                "verification_calls": m.verification_calls, "critical_path_calls": m.critical_path_oracle_calls,
                "databases": m.databases, "duplicates": m.duplicates,
                "estimation_calls": estimation, "estimated_k_total": k_total,
                "points_json": dumps(calls_at_sizes(result, settings["sizes"])),
                "fractions_json": dumps(reachable_fraction_by_window(result, settings["sizes"]))}

    def summarize(self, records: list[Record], settings: Settings) -> Summary:
        sizes = settings["sizes"]
        windows = [f"{a}-{b}" for a, b in zip(sizes[:-1], sizes[1:], strict=True)]

        ours: dict[str, dict[str, float]] = {}
        interval: dict[str, dict[str, list[float]]] = {}
        critical: dict[str, dict[str, float]] = {}
        critical_interval: dict[str, dict[str, list[float]]] = {}
        whole: dict[str, dict[str, float]] = {}
        whole_interval: dict[str, dict[str, list[float]]] = {}
        for label in settings["configs"]:
            rows = [r for r in records if r["config"] == label]
            ours[label] = {w: round(pooled_calls_per_node(rows, w), 3) for w in windows}
            interval[label] = {w: rounded_interval(pooled_interval(rows, w, settings["seed"]), 3) for w in windows}
            critical[label] = {w: round(pooled_calls_per_node(rows, w, 2), 3) for w in windows}
            critical_interval[label] = {w: rounded_interval(pooled_interval(rows, w, settings["seed"], 2), 3)
                                        for w in windows}
            nodes = [int(r["nodes"]) for r in rows]
            whole[label], whole_interval[label] = {}, {}
            for key, column in (("calls_per_node", "oracle_calls"), ("critical_path_per_node", "critical_path_calls")):
                calls = [int(r[column]) for r in rows]
                whole[label][key] = round(sum(calls) / sum(nodes), 3)
                whole_interval[label][key] = rounded_interval(bootstrap_ratio_interval(calls, nodes, settings["seed"]),
                                                              3)
        fractions = {w: round(mean_fraction(records, w), 4) for w in windows}
        fractions_interval = {w: fraction_interval(records, w, settings["seed"]) for w in windows}
        estimation, estimation_interval = self._estimation_summary(records, settings["seed"])
        return {"ours": ours, "paper": self.paper, "interval_95": interval, "critical_path_per_node": critical,
                "critical_path_interval_95": critical_interval,
                "whole_run": whole, "whole_run_interval_95": whole_interval,
                "mean_reachable_fraction": fractions, "mean_reachable_fraction_interval_95": fractions_interval,
                "estimation": estimation, "estimation_interval_95": estimation_interval,
                "note": "marginal oracle calls per node added in each window of tree sizes, pooled over worlds "
                        "(critical_path_per_node: the same for the critical path, the time of 8 parallel devices); "
                        "whole_run: all calls / all nodes up to the largest size; every interval is a percentile "
                        "bootstrap over worlds (all configurations of a resampled world together for the "
                        "estimation figures; a break-even resample where no number of workers pays ranks above "
                        "every finite one, and an interval end there is null)",
                "labels": ["QRRT/PQRRT optimal use the true m of each database (simulation knowledge)",
                           "estimated: amplitude-estimation shots are counted as quantum oracle calls (k + 1 per "
                           "shot of Q^k A|0>), run on qiskit-aer's SamplerV2; the searches on the exact statevector",
                           "phase oracle from a classical lookup of all 2^8 entries",
                           "backend: exact statevector (ideal; same statistics as Aer)"]}

    @staticmethod
    def _estimation_summary(records: Sequence[Record], seed: int) -> tuple[dict[str, Any], dict[str, Any]]:
        """Estimation vs search calls of EstimatedOptimal, and the workers p* at which one estimation
        per database would match a rival's calls per node (``estimation_figures``), with their 95 %
        bootstrap intervals over worlds (every configuration of a resampled world kept together)."""
        out = estimation_figures(records)
        by_world: dict[int, list[Record]] = {}
        for r in records:
            by_world.setdefault(int(r["replicate"]), []).append(r)
        worlds = sorted(by_world)
        intervals: dict[str, Any] = {}
        for prefix in ("QRRT", "PQRRT"):
            if prefix not in out:
                continue
            intervals[prefix] = {}
            for key in out[prefix]:
                spans = bootstrap_interval(worlds, partial(_world_figure, by_world, prefix, key), seed)
                intervals[prefix][key] = rounded_interval(spans, 4)
        if "break_even_workers" in out:
            intervals["break_even_workers"] = {}
            for rival in out["break_even_workers"]:
                low, high = bootstrap_interval(
                    worlds, partial(_world_figure, by_world, "break_even_workers", rival), seed)
                intervals["break_even_workers"][rival] = [None if v >= NEVER else round(v, 1) for v in (low, high)]
        return out, intervals

    def plot(self, records: list[Record], settings: Settings, summary: Summary, out_dir: Path) -> list[Path]:
        """Marginal calls per node in each window with 95 % intervals (policies side by side in each
        window): q-RRT; Pq-RRT's critical path (8 parallel devices); Pq-RRT's total calls."""
        fig, axes = new_figure(1, 3, (17, 5.2))
        windows = list(summary["ours"]["RRT"])
        x = np.arange(len(windows), dtype=float)
        offsets = dodge(len(POLICY_NAMES) + 1, 0.7)
        panels = ((axes[0, 0], "QRRT", "ours", "interval_95", "q-RRT: oracle calls per node added"),
                  (axes[0, 1], "PQRRT", "critical_path_per_node", "critical_path_interval_95",
                   f"Pq-RRT, {settings['workers']} workers, shared database: critical path"),
                  (axes[0, 2], "PQRRT", "ours", "interval_95", "Pq-RRT: total oracle calls per node added"))
        for ax, prefix, column, spans, title in panels:
            with_intervals(ax, x + offsets[0], [summary["ours"]["RRT"][w] for w in windows],
                           [summary["interval_95"]["RRT"][w] for w in windows], fmt="o", ms=6, color="tab:gray",
                           label="RRT")
            for offset, policy in zip(offsets[1:], POLICY_NAMES, strict=True):
                label = f"{prefix} {policy}"
                with_intervals(ax, x + offset, [summary[column][label][w] for w in windows],
                               [summary[spans][label][w] for w in windows], fmt="o", ms=5,
                               color=COLORS[policy], label=policy)
            for boundary in x[:-1] + 0.5:
                ax.axvline(boundary, color="0.85", lw=0.8)
            ax.set_xticks(x, [f"{w} nodes" for w in windows])
            ax.set_xlim(-0.5, len(windows) - 0.5)
            ax.set_yscale("log")
            ax.set_xlabel("window of tree sizes")
            ax.grid(alpha=0.3, axis="y", which="both")
            ax.set_title(f"{title} ({settings['trials']} worlds)", fontsize=10)
        axes[0, 0].set_ylabel("oracle calls per node added (95 % interval)")
        handles, names = axes[0, 0].get_legend_handles_labels()
        fig.legend(handles, [f"search policy: {n}" if n != "RRT" else n for n in names], loc="upper center",
                   ncol=len(names), fontsize=8.5, frameon=False)
        fig.tight_layout(rect=(0, 0, 1, 0.93))
        return [save(fig, out_dir / "search_policies.png", tight=False)]
