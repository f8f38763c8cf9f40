"""Paper Figs. 10-12: exploration speed. 100 trials per planner in one paper_clutter world, each
cut at 10, 20 and 40 oracle calls; node-density heatmaps; total nodes placed and oracle efficiency
(nodes / oracle calls) at each cut.

Pq-RRT's workers call the oracle simultaneously (one round costs 8 x (k + 1) calls), so it is cut
on critical-path oracle calls (``max_critical_path_calls``), the time of 8 parallel devices, and
labelled so. Cut on total oracle calls as well (``PQRRT_total_calls`` in ``ours``): the same runs
read at the first round whose total calls reach the cut, which with the paper's schedule is the
first round (8 x 6 = 48 calls) at every cut. ``pqrrt_over_qrrt_nodes`` gives Pq-RRT's nodes over
q-RRT's on either cut (the paper calls its Pq-RRT heatmaps "largely similar" to q-RRT's).

Each trial runs once to 40 calls and the 10- and 20-call cuts are read from its round history:
conditions are checked before each round, so a run stopped at 10 calls is exactly the prefix of the
same run that ends after the first round reaching 10 calls.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .base import (
    Experiment,
    PaperComparison,
    PaperNumber,
    Record,
    Settings,
    Summary,
    Trial,
    TrialStream,
    replicate_seed,
)
from .figures import heatmap_counts, new_figure, node_heatmap, save
from .intervals import bootstrap_ratio_interval, differs, rounded_interval
from .measures import cut_at, dumps, loads, reachable_fraction, rounded
from .planners import BACKEND_LABEL, experiment_problem, make_planner
from .worlds import world

PLANNERS = ("RRT", "QRRT", "PQRRT")
#: the key of Pq-RRT cut on total oracle calls in the summary's ``ours`` and ``interval_95``
TOTAL = "PQRRT_total_calls"
CUTS = (10, 20, 40)


class Heatmaps(Experiment):
    """Exploration speed (paper Figs. 10-12): nodes and oracle efficiency at 10, 20 and 40 calls.

    A trial grows RRT, q-RRT or Pq-RRT (cut on critical-path calls) in one ``paper_clutter`` world
    to 40 calls and reads the 10- and 20-call cuts from its history (``cut_at``). The summary gives
    the total nodes and the efficiency (nodes / calls) at each cut with 95 % bootstrap intervals,
    against the paper's; the figure shows node heatmaps.
    """

    name = "heatmaps"
    title = "Exploration heatmaps at 10, 20 and 40 oracle calls (paper Figs. 10-12)"
    paper = {"QRRT": {"10": {"nodes": 372, "efficiency": 0.312}, "20": {"nodes": 650, "efficiency": 0.310},
                      "40": {"nodes": 1091, "efficiency": 0.260}},
             "RRT": {"10": {"nodes": 125, "efficiency": 0.125}, "20": {"nodes": 231, "efficiency": 0.116},
                     "40": {"nodes": 526, "efficiency": 0.132}}}

    def settings(self, quick: bool, trials: int | None, seed: int) -> Settings:
        return {"trials": trials or (50 if quick else 100), "cuts": list(CUTS), "workers": 8,
                "num_qubits": 8, "backend": "aer", "schedule": "paper", "scenario": "paper_clutter",
                "world_seed": 0, "seed": seed, "quick": quick}

    def trials(self, settings: Settings) -> list[Trial]:
        return [Trial(f"{kind}-{i}", {"planner": kind, "replicate": i},
                      replicate_seed(settings["seed"], i, TrialStream.HEATMAPS))
                for kind in PLANNERS for i in range(settings["trials"])]

    def run_trial(self, trial: Trial, settings: Settings) -> Record:
        problem = experiment_problem(settings, world(settings["scenario"], settings["world_seed"]))
        planner = make_planner(trial.params["planner"], trial.seed, settings["backend"],
                               settings["workers"], settings["num_qubits"])
        critical = trial.params["planner"] == "PQRRT"
        if critical:
            result = planner.plan(problem, max_critical_path_calls=max(settings["cuts"]))
        else:
            result = planner.plan(problem, max_oracle_calls=max(settings["cuts"]))
        record: Record = {"cut_on": "critical_path" if critical else "oracle_calls"}
        for cut in settings["cuts"]:
            nodes, calls = cut_at(result, cut, "critical_path" if critical else "oracle_calls")
            record[f"nodes_at_{cut}"] = nodes
            record[f"calls_at_{cut}"] = calls
            # every planner cut on total oracle calls too (for RRT and q-RRT the same numbers)
            record[f"nodes_at_{cut}_total"], record[f"calls_at_{cut}_total"] = cut_at(result, cut, "oracle_calls")
        record["reachable_fraction"] = reachable_fraction(result)
        record["status"] = str(result.status)
        record["positions_json"] = dumps(rounded(result.nodes[1:]))
        return record

    def summarize(self, records: list[Record], settings: Settings) -> Summary:
        ours: dict[str, dict[str, dict[str, Any]]] = {}
        for kind in PLANNERS:
            rows = [r for r in records if r["planner"] == kind]
            ours[kind] = {}
            for cut in settings["cuts"]:
                nodes = sum(r[f"nodes_at_{cut}"] for r in rows)
                calls = sum(r[f"calls_at_{cut}"] for r in rows)
                ours[kind][str(cut)] = {"nodes": nodes, "calls": calls,
                                        "efficiency": round(nodes / calls, 4) if calls else None}
        fractions = {k: round(float(np.mean([r["reachable_fraction"] for r in records if r["planner"] == k])), 4)
                     for k in PLANNERS}
        interval: dict[str, dict[str, dict[str, list[float]]]] = {}
        differs_from_paper: dict[str, dict[str, dict[str, bool | None]]] = {}
        for kind in PLANNERS:
            rows = [r for r in records if r["planner"] == kind]
            interval[kind], differs_from_paper[kind] = {}, {}
            for cut in settings["cuts"]:
                nodes = [r[f"nodes_at_{cut}"] for r in rows]
                calls = [r[f"calls_at_{cut}"] for r in rows]
                span = {"nodes": rounded_interval(bootstrap_ratio_interval(nodes, None, settings["seed"]), 1),
                        "efficiency": rounded_interval(bootstrap_ratio_interval(nodes, calls, settings["seed"]))}
                interval[kind][str(cut)] = span
                paper = self.paper.get(kind, {}).get(str(cut))
                if paper:
                    differs_from_paper[kind][str(cut)] = {key: differs(paper[key], span[key]) for key in span}
        pq = [r for r in records if r["planner"] == "PQRRT"]
        ours[TOTAL], interval[TOTAL] = {}, {}
        for cut in settings["cuts"]:  # Pq-RRT's same runs, cut on total oracle calls
            nodes = [r[f"nodes_at_{cut}_total"] for r in pq]
            calls = [r[f"calls_at_{cut}_total"] for r in pq]
            interval[TOTAL][str(cut)] = {
                "nodes": rounded_interval(bootstrap_ratio_interval(nodes, None, settings["seed"]), 1),
                "efficiency": rounded_interval(bootstrap_ratio_interval(nodes, calls, settings["seed"]))}
            ours[TOTAL][str(cut)] = {"nodes": sum(nodes), "calls": sum(calls),
                                     "efficiency": round(sum(nodes) / sum(calls), 4) if sum(calls) else None}
        ratio = {cut_on: {str(cut): (round(ours[kind][str(cut)]["nodes"] / ours["QRRT"][str(cut)]["nodes"], 2)
                                     if ours["QRRT"][str(cut)]["nodes"] else None) for cut in settings["cuts"]}
                 for cut_on, kind in (("critical_path", "PQRRT"), ("total_calls", TOTAL))}
        return {"ours": ours, "paper": self.paper, "mean_reachable_fraction": fractions,
                "interval_95": interval, "differs_from_paper": differs_from_paper,
                "pqrrt_over_qrrt_nodes": ratio,
                "note": f"totals over {settings['trials']} trials per planner; the paper used 100. "
                        "PQRRT is cut on critical-path calls (8 parallel devices); its 'calls' are those. "
                        f"{TOTAL}: the same Pq-RRT runs cut on total oracle calls (the paper reports no "
                        "Pq-RRT numbers; it calls its Pq-RRT heatmaps 'largely similar' to q-RRT's). The "
                        "paper's Fig. 12 caption says 60 calls where its text says 40; 40 is used.",
                "labels": ["phase oracle from a classical lookup of all 2^8 entries",
                           f"backend: {BACKEND_LABEL[settings['backend']]}"]}

    def paper_comparison(self, summary: Summary) -> PaperComparison:
        """Oracle efficiency at each cut, for the planners the paper reports (not Pq-RRT)."""
        numbers = tuple(
            PaperNumber(f"{kind}\n{cut} calls", summary["ours"][kind][str(cut)]["efficiency"],
                        tuple(summary["interval_95"][kind][str(cut)]["efficiency"]),
                        summary["paper"][kind][str(cut)]["efficiency"])
            for kind in PLANNERS for cut in summary["settings"]["cuts"]
            if str(cut) in summary["paper"].get(kind, {}))
        return PaperComparison(self.title, "oracle efficiency at the cut (nodes / calls)", numbers)

    def plot(self, records: list[Record], settings: Settings, summary: Summary, out_dir: Path) -> list[Path]:
        """One panel per planner (rows) and cut (columns), all on one logarithmic colour scale (the
        largest count of any cell), so the panels can be compared; the axes are placed by hand
        (``save(..., tight=False)``)."""
        from matplotlib.colors import LogNorm

        problem = world(settings["scenario"], settings["world_seed"])
        env = problem.env
        cuts = settings["cuts"]
        rows, cols = len(PLANNERS), len(cuts)
        fig, axes = new_figure(rows, cols, (4.4 * cols + 1.0, 4.3 * rows))
        fig.subplots_adjust(left=0.04, right=0.9, bottom=0.03, top=0.94, wspace=0.18, hspace=0.38)
        panels = []
        for kind in PLANNERS:
            kept = [r for r in records if r["planner"] == kind]
            for cut in cuts:
                clouds = [np.array(loads(r["positions_json"]))[: r[f"nodes_at_{cut}"]] for r in kept]
                panels.append(np.concatenate([p.reshape(-1, 2) for p in clouds]) if clouds else np.zeros((0, 2)))
        largest = max((float(heatmap_counts(env, points).max()) for points in panels), default=0.0)
        norm = LogNorm(vmin=1, vmax=max(largest, 2.0))
        image = None
        for index, points in enumerate(panels):
            kind, cut = PLANNERS[index // cols], cuts[index % cols]
            stats = summary["ours"][kind][str(cut)]
            paper = self.paper.get(kind, {}).get(str(cut))
            unit = "critical-path calls" if kind == "PQRRT" else "calls"
            low, high = summary["interval_95"][kind][str(cut)]["efficiency"]
            text = (f"{kind}, {cut} {unit}\n{stats['nodes']} nodes, eff. {stats['efficiency']:.1%} "
                    f"[{low:.1%}, {high:.1%}]")
            if paper:
                text += f"\npaper: {paper['nodes']} nodes, {paper['efficiency']:.1%}"
            drawn = node_heatmap(axes[index // cols, index % cols], problem, points, text, norm=norm)
            image = drawn or image
        if image is not None:
            fig.colorbar(image, cax=fig.add_axes((0.92, 0.2, 0.015, 0.6)),
                         label=f"nodes per cell, summed over {settings['trials']} trials")
        return [save(fig, out_dir / "heatmaps.png", tight=False)]
