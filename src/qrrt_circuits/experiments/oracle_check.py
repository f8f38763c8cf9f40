"""Beyond the paper: how the collision check changes the results.

RRT and q-RRT run the heatmaps setting (one paper_clutter world, cut at 40 oracle calls) with our
exact check, with the authors' own check (``AuthorsCheck``: ``authors`` with MATLAB's Refine = 4
output, ``authors-octave`` as Octave runs it) and with checks of only K evenly spaced time samples
(``samples-K``, the unsound "points only" reading of an ODE solver's output, which the authors'
code does not use). Reported, each with its 95 % interval (a percentile bootstrap over trials):
oracle efficiency (nodes / calls), the reachable fraction of candidates, the fraction of tree edges
our exact check rejects, and the fraction that a finer exact check rejects.

Our exact check (resolution 0.01) is sound and conservative: it rejects every trajectory that
touches an obstacle, and a free one only if it passes within (1 + sqrt 2) x 0.01 = 0.024 of an
obstacle or 0.02 of the workspace edge (``ExactCheck.false_rejection_bound``). So an edge it rejects
passes through an obstacle *or* near one. The same check at ``FINE_RESOLUTION`` (1e-4), sound too,
separates the two: an edge both reject passes through an obstacle or within 0.00024 of one; an edge
only the coarse check rejects is collision-free (the fine check accepts it), a near miss.
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
from .intervals import bootstrap_interval, bootstrap_ratio_interval, differs, rounded_interval
from .measures import cut_at, reachable_fraction
from .planners import make_planner
from .worlds import world

if TYPE_CHECKING:
    from ..reachability.predicate import ReachabilityPredicate
    from ..world.environment import Environment

PLANNERS = ("RRT", "QRRT")
CHECKS = ("exact", "authors", "authors-octave", "samples-200", "samples-50", "samples-20")
#: resolution of the finer exact check that separates collisions from near misses
FINE_RESOLUTION = 1e-4


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


def mean_reachable_fraction(rows: Sequence[Record]) -> float:
    """The mean of the rows' ``reachable_fraction`` (one value per trial).

    Args:
        rows: Records with ``reachable_fraction``.

    Returns:
        The mean; NaN without rows.
    """
    return float(np.mean([r["reachable_fraction"] for r in rows])) if rows else float("nan")


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
    calls, and counts the tree edges the exact check rejects (``invalid_edges``: through or within
    0.024 of an obstacle) and those the check at ``FINE_RESOLUTION`` rejects too
    (``invalid_edges_fine``: through or within 0.00024 of one; the rest are free near misses).
    The summary gives per check and planner the oracle efficiency (``efficiency``), both edge
    fractions (pooled edges over pooled nodes) and the mean reachable fraction, each with its 95 %
    bootstrap interval over trials, against the paper's efficiency at 40 calls (Figs. 10-12).
    """

    name = "oracle-check"
    uses_predicate = False  # it sweeps its own list of checks
    title = "Exact collision check vs time-sampled checks (beyond the paper)"
    paper = {"RRT": 0.132, "QRRT": 0.260}  # efficiency at 40 oracle calls (Figs. 10-12)

    def settings(self, quick: bool, trials: int | None, seed: int) -> Settings:
        return {"trials": trials or (4 if quick else 30), "budget": 40, "num_qubits": 8, "backend": "statevector",
                "scenario": "paper_clutter", "world_seed": 0, "checks": list(CHECKS), "seed": seed,
                "quick": quick}

    def trials(self, settings: Settings) -> list[Trial]:
        return [Trial(f"{check}-{kind}-{i}", {"check": check, "planner": kind, "replicate": i},
                      replicate_seed(settings["seed"], i, TrialStream.ORACLE_CHECK))
                for check in settings["checks"] for kind in PLANNERS for i in range(settings["trials"])]

    def run_trial(self, trial: Trial, settings: Settings) -> Record:
        problem = world(settings["scenario"], settings["world_seed"])
        env = problem.env
        planner = make_planner(trial.params["planner"], trial.seed, settings["backend"],
                               num_qubits=settings["num_qubits"])
        result = planner.plan(problem.replace(predicate=make_predicate(env, trial.params["check"])),
                              max_oracle_calls=settings["budget"])
        nodes, calls = cut_at(result, settings["budget"])
        children = np.arange(1, nodes + 1)
        parents, ends = result.nodes[result.parents[children]], result.nodes[children]
        valid, valid_fine = (ExactCheck(env, resolution=resolution).reachable(parents, ends) if nodes
                             else np.zeros(0, dtype=bool) for resolution in (0.01, FINE_RESOLUTION))
        return {"nodes": nodes, "oracle_calls": calls, "invalid_edges": int(np.sum(~valid)),
                "invalid_edges_fine": int(np.sum(~valid & ~valid_fine)),
                "reachable_fraction": reachable_fraction(result)}

    def summarize(self, records: list[Record], settings: Settings) -> Summary:
        seed = settings["seed"]
        quantities = ("efficiency", "invalid_edge_fraction", "invalid_edge_fraction_fine", "reachable_fraction")
        ours: dict[str, dict[str, dict[str, float]]] = {q: {} for q in quantities}
        interval: dict[str, dict[str, dict[str, list[float]]]] = {q: {} for q in quantities}
        for check in settings["checks"]:
            for q in quantities:
                ours[q][check], interval[q][check] = {}, {}
            for kind in PLANNERS:
                rows = [r for r in records if r["check"] == check and r["planner"] == kind]
                nodes = [int(r["nodes"]) for r in rows]
                ours["efficiency"][check][kind] = round(efficiency(rows), 4)
                interval["efficiency"][check][kind] = rounded_interval(bootstrap_interval(rows, efficiency, seed))
                for q, column in (("invalid_edge_fraction", "invalid_edges"),
                                  ("invalid_edge_fraction_fine", "invalid_edges_fine")):
                    edges = [int(r[column]) for r in rows]
                    ours[q][check][kind] = round(sum(edges) / max(sum(nodes), 1), 4)
                    interval[q][check][kind] = rounded_interval(bootstrap_ratio_interval(edges, nodes, seed))
                ours["reachable_fraction"][check][kind] = round(mean_reachable_fraction(rows), 4)
                interval["reachable_fraction"][check][kind] = rounded_interval(
                    bootstrap_interval(rows, mean_reachable_fraction, seed))
        paper = {"efficiency": {check: dict(self.paper) for check in settings["checks"]}}
        return {"ours": ours, "paper": paper, "interval_95": interval,
                "differs_from_paper": {"efficiency": {check: {kind: differs(self.paper[kind],
                                                                            interval["efficiency"][check][kind])
                                                              for kind in PLANNERS}
                                                      for check in settings["checks"]}},
                "note": "efficiency = nodes / oracle calls at the 40-call cut (the paper's value, Figs. 10-12, is set "
                        "beside every check); invalid_edge_fraction: tree edges our exact check (resolution 0.01) "
                        "rejects, i.e. through an obstacle or within 0.024 of one (0.02 of the workspace edge), over "
                        "nodes; invalid_edge_fraction_fine: those the same check at resolution 1e-4 rejects too, "
                        "through an obstacle or within 0.00024 of one; the difference is free near misses. "
                        "Intervals: percentile bootstrap over trials (pooled edges over pooled nodes)"}

    def plot(self, records: list[Record], settings: Settings, summary: Summary, out_dir: Path) -> list[Path]:
        """Left: efficiency per check with its 95 % interval and the paper's values. Right: the
        fraction of tree edges our exact check rejects (through or within 0.024 of an obstacle, the
        whole bar, with its 95 % interval), split into those the finer check also rejects (through
        or within 0.00024 of one, dark) and near misses (light)."""
        fig, axes = new_figure(1, 2, (11, 4.4))
        checks = settings["checks"]
        x = np.arange(len(checks))
        ours, spans = summary["ours"], summary["interval_95"]
        for offset, kind, color in ((-0.2, "RRT", "tab:gray"), (0.2, "QRRT", "tab:blue")):
            values = np.array([ours["efficiency"][c][kind] for c in checks])
            span = np.array([spans["efficiency"][c][kind] for c in checks])
            axes[0, 0].bar(x + offset, values, 0.4, color=color, label=f"{kind} (95 % interval)",
                           yerr=[values - span[:, 0], span[:, 1] - values], capsize=3)
            axes[0, 0].axhline(self.paper[kind], color=color, ls="--", lw=1, label=f"paper {kind} (40 calls)")
            rejected = np.array([ours["invalid_edge_fraction"][c][kind] for c in checks])
            close = np.array([ours["invalid_edge_fraction_fine"][c][kind] for c in checks])
            span = np.array([spans["invalid_edge_fraction"][c][kind] for c in checks])
            axes[0, 1].bar(x + offset, close, 0.4, color=color,
                           label=f"{kind}: through or within 0.00024 of an obstacle")
            axes[0, 1].bar(x + offset, rejected - close, 0.4, bottom=close, color=color, alpha=0.35,
                           label=f"{kind}: near miss (0.00024-0.024 away)")
            axes[0, 1].errorbar(x + offset, rejected, yerr=[np.clip(rejected - span[:, 0], 0, None),
                                                            np.clip(span[:, 1] - rejected, 0, None)],
                                fmt="none", color="black", capsize=3, lw=1)
        for ax, label in ((axes[0, 0], "oracle efficiency (nodes / calls)"),
                          (axes[0, 1], "fraction of tree edges our exact check rejects")):
            ax.set_xticks(x, [check_label(c) for c in checks], fontsize=8.5)
            ax.set_ylabel(label)
            ax.legend(fontsize=7.5)
            ax.grid(alpha=0.3, axis="y")
        axes[0, 0].set_title("Efficiency at 40 oracle calls", fontsize=10)
        axes[0, 1].set_title("Edges through or within 0.024 of an obstacle (95 % interval)", fontsize=10)
        return [save(fig, out_dir / "oracle_check.png")]
