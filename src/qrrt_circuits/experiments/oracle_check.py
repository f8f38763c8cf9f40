"""Beyond the paper: how the collision check changes the results.

RRT and q-RRT run the heatmaps setting (one paper_clutter world, cut at 40 oracle calls) with our
exact check, with the authors' own check (``AuthorsCheck``: ``authors`` with MATLAB's Refine = 4
output, ``authors-octave`` as Octave runs it) and with checks of only K evenly spaced time samples
(``samples-K``, the unsound "points only" reading of an ODE solver's output, which the authors'
code does not use). Reported: oracle efficiency (nodes / calls), the reachable fraction of
candidates, and the fraction of tree edges the exact check says go through an obstacle.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..reachability.exact import ExactCheck
from ..registry import PREDICATES
from .base import Experiment, Record, Settings, Summary, Trial, TrialStream, replicate_seed
from .figures import new_figure, save, wrapped
from .intervals import bootstrap_interval, rounded_interval
from .measures import cut_at, reachable_fraction
from .planners import make_planner
from .worlds import world

if TYPE_CHECKING:
    from ..reachability.predicate import ReachabilityPredicate
    from ..world.environment import Environment

PLANNERS = ("RRT", "QRRT")
CHECKS = ("exact", "authors", "authors-octave", "samples-200", "samples-50", "samples-20")


def make_predicate(env: Environment, check: str) -> ReachabilityPredicate:
    """A registry predicate name, or ``samples-K`` (the registry's ``time-samples:K``).

    Args:
        env: The world the predicate checks motions in.
        check: A ``PREDICATES`` name or ``samples-K``.

    Returns:
        The predicate, built on ``env``.

    Raises:
        ValueError: If ``check`` names no predicate.
    """
    name = f"time-samples:{check.split('-')[1]}" if check.startswith("samples-") else check
    predicate: ReachabilityPredicate = PREDICATES.create(name, env=env)
    return predicate


def check_label(check: str) -> str:
    """A check's tick label, over two lines: ``authors`` (MATLAB), ``authors-octave``, ``samples-K``.

    Args:
        check: A name of ``CHECKS`` (another name is broken at its hyphens).

    Returns:
        The label.
    """
    if check == "authors":
        return "authors\n(MATLAB)"
    if check == "authors-octave":
        return "authors\n(Octave)"
    if check.startswith("samples-"):
        return f"{check.split('-', 1)[1]} time\nsamples"
    return wrapped(check)


def efficiency(rows: Sequence[Record]) -> float:
    """Nodes per oracle call over ``rows`` (the paper's oracle efficiency).

    Args:
        rows: Records with ``nodes`` and ``oracle_calls``.

    Returns:
        Summed nodes / summed oracle calls (0.0 without calls).
    """
    return sum(r["nodes"] for r in rows) / max(sum(r["oracle_calls"] for r in rows), 1)


class OracleCheck(Experiment):
    """The exact reachability check against the authors' and time-sampled checks (beyond the paper).

    A trial runs RRT or q-RRT with one check of ``CHECKS`` in ``paper_clutter``, cut at 40 oracle
    calls, and counts the tree edges the exact check rejects. The summary gives the oracle
    efficiency (``efficiency``) with 95 % intervals and the fraction of invalid edges per check,
    against the paper's efficiency at 40 calls (Figs. 10-12).
    """

    name = "oracle-check"
    uses_predicate = False  # it sweeps its own list of checks
    title = "Exact collision check vs time-sampled checks (beyond the paper)"
    paper = {"RRT": 0.132, "QRRT": 0.260}

    def settings(self, quick: bool, trials: int | None, seed: int) -> Settings:
        return {"trials": trials or (4 if quick else 30), "budget": 40, "num_qubits": 8, "backend": "statevector",
                "scenario": "paper_clutter", "world_seed": 0, "checks": list(CHECKS), "seed": seed,
                "quick": quick}

    def trials(self, settings: Settings) -> list[Trial]:
        return [Trial(f"{check}-{kind}-{i}", {"check": check, "planner": kind, "replicate": i},
                      replicate_seed(settings["seed"], i, TrialStream.ORACLE_CHECK))
                for check in settings["checks"] for kind in PLANNERS for i in range(settings["trials"])]

    def run_trial(self, trial: Trial, settings: Settings) -> Record:
        env = world(settings["scenario"], settings["world_seed"])
        predicate = make_predicate(env, trial.params["check"])
        planner = make_planner(trial.params["planner"], env, trial.seed, settings["backend"],
                               num_qubits=settings["num_qubits"], predicate=predicate)
        result = planner.plan(max_oracle_calls=settings["budget"])
        nodes, calls = cut_at(result, settings["budget"])
        exact = ExactCheck(env)
        children = np.arange(1, nodes + 1)
        valid: np.ndarray | list[bool] = (
            exact.reachable(result.nodes[result.parents[children]], result.nodes[children]) if nodes else [])
        return {"nodes": nodes, "oracle_calls": calls, "invalid_edges": int(nodes - np.sum(valid)),
                "reachable_fraction": reachable_fraction(result)}

    def summarize(self, records: list[Record], settings: Settings) -> Summary:
        ours: dict[str, dict[str, float]] = {}
        invalid: dict[str, dict[str, float]] = {}
        fraction: dict[str, dict[str, float]] = {}
        interval: dict[str, dict[str, list[float]]] = {}
        for check in settings["checks"]:
            ours[check], invalid[check], fraction[check], interval[check] = {}, {}, {}, {}
            for kind in PLANNERS:
                rows = [r for r in records if r["check"] == check and r["planner"] == kind]
                nodes = sum(r["nodes"] for r in rows)
                ours[check][kind] = round(efficiency(rows), 4)
                interval[check][kind] = rounded_interval(bootstrap_interval(rows, efficiency, settings["seed"]))
                invalid[check][kind] = round(sum(r["invalid_edges"] for r in rows) / max(nodes, 1), 4)
                fraction[check][kind] = round(float(np.mean([r["reachable_fraction"] for r in rows])), 4)
        return {"ours": ours, "paper": {"efficiency_at_40_calls": self.paper}, "interval_95": interval,
                "invalid_edge_fraction": invalid, "reachable_fraction": fraction,
                "note": "efficiency = nodes / oracle calls at the 40-call cut; invalid edges are tree edges the "
                        "exact check rejects (they pass through an obstacle)"}

    def plot(self, records: list[Record], settings: Settings, summary: Summary, out_dir: Path) -> list[Path]:
        fig, axes = new_figure(1, 2, (11, 4.2))
        checks = settings["checks"]
        x = np.arange(len(checks))
        for offset, kind, color in ((-0.2, "RRT", "tab:gray"), (0.2, "QRRT", "tab:blue")):
            values = np.array([summary["ours"][c][kind] for c in checks])
            spans = np.array([summary["interval_95"][c][kind] for c in checks])
            axes[0, 0].bar(x + offset, values, 0.4, color=color, label=f"{kind} (95 % interval)",
                           yerr=[values - spans[:, 0], spans[:, 1] - values], capsize=3)
            axes[0, 0].axhline(self.paper[kind], color=color, ls="--", lw=1, label=f"paper {kind} (40 calls)")
            axes[0, 1].bar(x + offset, [summary["invalid_edge_fraction"][c][kind] for c in checks], 0.4,
                           color=color, label=kind)
        for ax, label in ((axes[0, 0], "oracle efficiency (nodes / calls)"),
                          (axes[0, 1], "fraction of edges through an obstacle")):
            ax.set_xticks(x, [check_label(c) for c in checks], fontsize=8.5)
            ax.set_ylabel(label)
            ax.legend(fontsize=8)
            ax.grid(alpha=0.3, axis="y")
        axes[0, 0].set_title("Efficiency at 40 oracle calls", fontsize=10)
        axes[0, 1].set_title("Edges the exact check rejects", fontsize=10)
        return [save(fig, out_dir / "oracle_check.png")]
