"""Beyond the paper: oracle calls per node against the fraction f of reachable candidates.

Obstacle density is varied (paper_clutter's box model with 100 ... 1000 boxes); RRT and q-RRT
under KnownOptimal, BBHT and Adaptive grow 30-node trees. f is measured as the fraction of truly
reachable entries over all the run's candidates (RRT: its tests; q-RRT: its databases). Fitting
calls/node = C f^alpha gives alpha near -1 for RRT (one test per candidate) and near -1/2 for
Grover search, whose cost is O(sqrt(N/m)).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..search.policies.adaptive import Adaptive
from ..search.policies.base import IterationPolicy
from ..search.policies.bbht import BBHT
from ..search.policies.schedules import KnownOptimal
from .base import Experiment, Record, Settings, Summary, Trial, TrialStream, replicate_seed
from .figures import new_figure, save
from .fitting import power_law_exponent
from .intervals import bootstrap_interval, rounded_interval
from .measures import reachable_fraction
from .planners import BACKEND_LABEL, experiment_problem, make_planner
from .worlds import world

#: label -> q-RRT's search policy (its class), or None for RRT
CONFIGS: dict[str, Callable[[], IterationPolicy] | None] = {
    "RRT": None, "QRRT optimal": KnownOptimal, "QRRT bbht": BBHT, "QRRT adaptive": Adaptive}
DENSITIES = (100, 250, 400, 550, 700, 850, 1000)


class Scaling(Experiment):
    """Oracle calls per node against the reachable fraction f (beyond the paper).

    A trial grows a 30-node tree with RRT or q-RRT (KnownOptimal, BBHT, Adaptive) in a
    ``paper_clutter`` world of a given obstacle density and records calls per node and f
    (``reachable_fraction``). The summary fits calls/node = C f^alpha (``power_law_exponent``):
    alpha near -1 for RRT and near -1/2 for Grover search, with 95 % bootstrap intervals.
    """

    name = "scaling"
    title = "Oracle calls per node against the reachable fraction (beyond the paper)"
    paper = {"RRT": -1.0, "QRRT optimal": -0.5, "QRRT bbht": -0.5, "QRRT adaptive": -0.5}

    def settings(self, quick: bool, trials: int | None, seed: int) -> Settings:
        return {"trials": trials or (2 if quick else 6),
                "densities": list(DENSITIES[::2] if quick else DENSITIES), "nodes": 30,
                "num_qubits": 8, "backend": "statevector", "seed": seed, "quick": quick}

    def trials(self, settings: Settings) -> list[Trial]:
        out: list[Trial] = []
        for density in settings["densities"]:
            for replicate in range(settings["trials"]):
                world_seed = replicate_seed(settings["seed"], replicate * 1000 + density, TrialStream.SCALING_WORLDS)
                for name in CONFIGS:
                    out.append(Trial(f"{name}-{density}-{replicate}",
                                     {"config": name, "boxes": density, "replicate": replicate,
                                      "world_seed": world_seed},
                                     replicate_seed(settings["seed"], replicate * 1000 + density,
                                                    TrialStream.SCALING_PLANNERS)))
        return out

    def run_trial(self, trial: Trial, settings: Settings) -> Record:
        problem = experiment_problem(settings, world("paper_clutter", trial.params["world_seed"],
                                                     num_boxes=trial.params["boxes"]))
        make_policy = CONFIGS[trial.params["config"]]
        if make_policy is None:  # RRT
            planner = make_planner("RRT", trial.seed)
        else:
            planner = make_planner("QRRT", trial.seed, settings["backend"],
                                   num_qubits=settings["num_qubits"], search_policy=make_policy())
        result = planner.plan(problem, max_nodes=settings["nodes"])
        m = result.metrics
        return {"nodes": m.nodes, "oracle_calls": m.oracle_calls,
                "calls_per_node": m.oracle_calls / max(m.nodes, 1),
                "reachable_fraction": reachable_fraction(result)}

    def summarize(self, records: list[Record], settings: Settings) -> Summary:
        ours, fits = {}, {}
        for name in CONFIGS:
            rows = [r for r in records if r["config"] == name and r["nodes"] > 0]
            fit = power_law_exponent([r["reachable_fraction"] for r in rows], [r["calls_per_node"] for r in rows])
            ours[name] = round(fit.slope, 3)
            fits[name] = {"exponent": fit.slope, "stderr": fit.slope_stderr, "prefactor": float(np.exp(fit.intercept)),
                          "points": fit.points,
                          "interval_95": rounded_interval(bootstrap_interval(rows, lambda sample: power_law_exponent(
                              [r["reachable_fraction"] for r in sample], [r["calls_per_node"] for r in sample]).slope,
                              settings["seed"]), 3)}
        return {"ours": ours, "paper": self.paper, "fits": fits,
                "note": "'paper' holds the theoretical exponents (-1 classical, -1/2 Grover); the "
                        "paper itself does not run this experiment",
                "labels": ["QRRT optimal uses the true m of each database (simulation knowledge)",
                           f"backend: {BACKEND_LABEL[settings['backend']]}"]}

    def plot(self, records: list[Record], settings: Settings, summary: Summary, out_dir: Path) -> list[Path]:
        fig, axes = new_figure(1, 1, (6.5, 5))
        ax = axes[0, 0]
        colors = dict(zip(CONFIGS, ["tab:gray", "tab:blue", "tab:green", "tab:orange"], strict=True))
        for name in CONFIGS:
            rows = [r for r in records if r["config"] == name and r["nodes"] > 0]
            f = np.array([r["reachable_fraction"] for r in rows])
            y = np.array([r["calls_per_node"] for r in rows])
            fit = summary["fits"][name]
            ax.scatter(f, y, s=12, color=colors[name], alpha=0.6)
            xs = np.geomspace(f.min(), f.max(), 20)
            ax.plot(xs, fit["prefactor"] * xs ** fit["exponent"], color=colors[name],
                    label=f"{name}: exponent {fit['exponent']:.2f} {fit['interval_95']} (theory {self.paper[name]})")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("reachable fraction of candidates f")
        ax.set_ylabel("oracle calls per node")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3, which="both")
        ax.set_title("Scaling with the reachable fraction", fontsize=10)
        return [save(fig, out_dir / "scaling.png")]
