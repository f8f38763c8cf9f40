"""Paper Figs. 6-8: wall-clock seconds per oracle call and per node.

Same trees as oracle-efficiency (30 nodes, paper_clutter), timed for RRT, parallel RRT, and
q-RRT / Pq-RRT on both backends. Slopes are least-squares fits through the origin of seconds
against oracle calls (or nodes) over the trials. The paper's numbers come from MATLAB on an
8-core M2; ours from the machine that runs the trials, with everything in one process (the
shared Pq-RRT shortcut — one search with p shots — is the same one the paper's simulation used).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .base import Experiment, Record, Settings, Summary, Trial, TrialStream, paired_trials
from .figures import new_figure, save, with_intervals, wrapped
from .fitting import slope_through_origin
from .intervals import bootstrap_interval, rounded_interval
from .planners import planner_for
from .worlds import world

CONFIGS = (("RRT", "none"), ("ParallelRRT", "none"), ("QRRT", "aer"), ("QRRT", "statevector"),
           ("PQRRT", "aer"), ("PQRRT", "statevector"))


def label(planner: str, backend: str) -> str:
    """A configuration's label in records and summaries.

    Args:
        planner: A planner of ``CONFIGS``.
        backend: Its backend, ``"none"`` for the classical planners.

    Returns:
        ``planner`` alone, or ``"planner (backend)"``.
    """
    return planner if backend == "none" else f"{planner} ({backend})"


class Wallclock(Experiment):
    """Wall-clock seconds per oracle call and per node (paper Figs. 6-8).

    A trial times one 30-node tree of a configuration of ``CONFIGS`` (the worlds and seeds of
    oracle-efficiency). The summary fits seconds against oracle calls and against nodes through
    the origin (``slope_through_origin``), a 95 % interval on the per-node slope, next to the
    paper's MATLAB times; the timings are those of the machine that runs the trials and are
    labelled so.
    """

    name = "wallclock"
    title = "Wall-clock seconds per oracle call and per node (paper Figs. 6-8)"
    paper = {"seconds_per_oracle_call": {"QRRT": 3.52, "PQRRT": 0.20},
             "seconds_per_node": {"RRT": 1.23, "ParallelRRT": 0.58, "QRRT": 25.3, "PQRRT": 3.17}}

    def settings(self, quick: bool, trials: int | None, seed: int) -> Settings:
        return {"trials": trials or (3 if quick else 20), "nodes": 30, "workers": 8, "num_qubits": 8,
                "scenario": "paper_clutter", "seed": seed, "quick": quick}

    def trials(self, settings: Settings) -> list[Trial]:
        variants = [(label(planner, backend), {"planner": planner, "backend": backend}) for planner, backend in CONFIGS]
        return paired_trials(settings, variants, TrialStream.PAPER_WORLDS, TrialStream.PAPER_PLANNERS)

    def run_trial(self, trial: Trial, settings: Settings) -> Record:
        env = world(settings["scenario"], trial.params["world_seed"])
        backend = trial.params["backend"]
        planner = planner_for(settings, trial.params["planner"], env, trial.seed,
                               "statevector" if backend == "none" else backend,
                               settings["workers"], settings["num_qubits"])
        planner.plan(max_rounds=2)  # warm-up: compile kernels, build simulators
        result = planner.plan(max_nodes=settings["nodes"])
        m = result.metrics
        return {"status": result.status, "nodes": m.nodes, "oracle_calls": m.oracle_calls,
                "critical_path_oracle_calls": m.critical_path_oracle_calls,
                "wall_time_s": m.wall_time_s}

    def summarize(self, records: list[Record], settings: Settings) -> Summary:
        per_call, per_node, ms_node, ms_interval = {}, {}, {}, {}
        for planner, backend in CONFIGS:
            rows = [r for r in records if r["planner"] == planner and r["backend"] == backend]
            times = np.array([r["wall_time_s"] for r in rows])
            name = label(planner, backend)
            per_node[name] = slope_through_origin([r["nodes"] for r in rows], times)
            ms_node[name] = round(per_node[name] * 1e3, 4)
            ms_interval[name] = rounded_interval(bootstrap_interval(rows, lambda sample: 1e3 * slope_through_origin(
                [r["nodes"] for r in sample], [r["wall_time_s"] for r in sample]), settings["seed"]))
            if backend != "none":
                per_call[name] = slope_through_origin([r["oracle_calls"] for r in rows], times)
        speedup = {}
        for name, value in per_node.items():
            base = name.split(" ")[0]
            speedup[name] = round(self.paper["seconds_per_node"][base] / value, 1)
        return {"ours": {"seconds_per_oracle_call": per_call, "seconds_per_node": per_node},
                "paper": self.paper, "ms_per_node": ms_node, "ms_per_node_interval_95": ms_interval,
                "speedup_over_paper_per_node": speedup,
                "note": "the paper's times are MATLAB on an 8-core M2; ours one process on this machine"}

    def plot(self, records: list[Record], settings: Settings, summary: Summary, out_dir: Path) -> list[Path]:
        """Left: each tree's seconds per node and the fitted slope (the fit through the origin of
        seconds against nodes, which at about 30 nodes a tree is the level of the trees' ratios),
        with its 95 % interval and the paper's value on the same logarithmic axis. Right: seconds
        against oracle calls on log-log axes, where a line through the origin has unit slope and
        its height is the seconds per call; each fit is drawn over its configuration's data."""
        fig, axes = new_figure(1, 2, (13, 5.0))
        colors = dict(zip([label(*c) for c in CONFIGS],
                          ["tab:gray", "tab:brown", "tab:blue", "tab:cyan", "tab:orange", "gold"], strict=True))
        ax = axes[0, 0]
        names = [label(*c) for c in CONFIGS]
        for index, (planner, backend) in enumerate(CONFIGS):
            name = label(planner, backend)
            rows = [r for r in records if r["planner"] == planner and r["backend"] == backend]
            ratios = np.array([r["wall_time_s"] / r["nodes"] for r in rows])
            jitter = np.linspace(-0.18, 0.18, len(rows)) if len(rows) > 1 else np.zeros(len(rows))
            ax.scatter(index + jitter, ratios, s=12, color=colors[name], alpha=0.6, zorder=2,
                       label="each tree: seconds / nodes" if index == 0 else None)
            slope = summary["ours"]["seconds_per_node"][name]
            low, high = summary["ms_per_node_interval_95"][name]
            with_intervals(ax, [index + 0.3], [slope], [[low / 1e3, high / 1e3]], fmt="_", ms=14, mew=2,
                           color="black", zorder=3,
                           label="fit through the origin, 95 % interval" if index == 0 else None)
            ax.annotate(f"{slope * 1e3:.2g} ms", (index + 0.45, slope), fontsize=7.5, va="center")
            paper = self.paper["seconds_per_node"][planner]
            ax.plot(index, paper, "D", color="black", mfc="white", ms=7,
                    label="paper (MATLAB, 8-core M2)" if index == 0 else None)
            ax.annotate(f"{paper} s", (index + 0.15, paper), fontsize=7.5, va="center")
        ax.set_xticks(range(len(names)), [wrapped(n) for n in names], fontsize=8)
        ax.set_xlim(-0.5, len(names) - 0.1)
        ax.set_yscale("log")
        ax.set_ylabel("wall-clock seconds per node")
        ax.set_title(f"Seconds per node (Figs. 7-8), {settings['nodes']}-node trees", fontsize=10)
        ax.legend(fontsize=7.5, loc="center left")
        ax.grid(alpha=0.3, axis="y")

        ax = axes[0, 1]
        for planner, backend in CONFIGS:
            name = label(planner, backend)
            if name not in summary["ours"]["seconds_per_oracle_call"]:
                continue
            rows = [r for r in records if r["planner"] == planner and r["backend"] == backend]
            x = np.array([r["oracle_calls"] for r in rows], dtype=float)
            y = np.array([r["wall_time_s"] for r in rows])
            slope = summary["ours"]["seconds_per_oracle_call"][name]
            paper = self.paper["seconds_per_oracle_call"][planner]
            ax.scatter(x, y, s=12, color=colors[name], alpha=0.6)
            span = np.array([x.min(), x.max()])
            ax.plot(span, slope * span, color=colors[name], lw=2.2,
                    label=f"{name}: {slope * 1e3:.3g} ms per call (paper {paper} s)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("oracle calls of the tree")
        ax.set_ylabel("wall-clock seconds per tree")
        ax.set_title("Seconds vs oracle calls (Fig. 6); lines: fits through the origin", fontsize=10)
        ax.legend(fontsize=7.5)
        ax.grid(alpha=0.3, which="both")
        return [save(fig, out_dir / "wallclock.png")]
