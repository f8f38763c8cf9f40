"""Beyond the paper: oracle calls per node against tree size, and where each quantum search policy
stops beating RRT.

The paper compares planners on 30-node trees. As a tree grows, more of the workspace is near a
node, so more candidates are reachable: RRT's calls per node fall, while a fixed Grover schedule
(the paper's 5 then 3 iterations) overshoots once more than about 19 % of a database is marked.
Here every planner grows one tree per world in ``paper_clutter`` toward a goal it cannot reach
(goal radius 1e-9), and the cumulative oracle calls are read at tree sizes 30, 100, 300, 1000 and
3000. The marginal cost of a window (calls added / nodes added between two sizes) is compared with
RRT's on the same worlds; the crossover is the first window where a quantum planner's marginal
cost is not below RRT's.

Pq-RRT is reported on its critical path (the time of 8 parallel devices) and in total calls.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .base import Experiment, Record, Settings, Summary, Trial, TrialStream, paired_trials
from .figures import new_figure, save
from .intervals import bootstrap_interval, bootstrap_ratio_interval, rounded_interval
from .measures import dumps, loads
from .planners import experiment_problem, make_planner
from .worlds import world

if TYPE_CHECKING:
    from ..planners.result import PlanResult

SIZES = (30, 100, 300, 1000, 3000)
#: label -> (registry planner, search policy)
CONFIGS = {
    "RRT": ("rrt", None),
    "ParallelRRT": ("prrt", None),
    "QRRT paper": ("qrrt", "paper"),
    "QRRT optimal": ("qrrt", "optimal"),
    "QRRT bbht": ("qrrt", "bbht"),
    "QRRT adaptive": ("qrrt", "adaptive"),
    "PQRRT paper": ("pqrrt", "paper"),
}
COLORS = {"RRT": "tab:gray", "ParallelRRT": "tab:brown", "QRRT paper": "tab:blue", "QRRT optimal": "tab:purple",
          "QRRT bbht": "tab:green", "QRRT adaptive": "tab:orange", "PQRRT paper": "tab:red"}


def window_counts(rows: Sequence[Record], window: str, column: int = 1) -> tuple[list[int], list[int]]:
    """Per row, the calls and the nodes added in ``window`` ("low-high"); (0, 0) for a row whose
    tree did not reach both sizes.

    Args:
        rows: Records with a ``points_json`` column (``calls_at_sizes`` points).
        window: ``"low-high"``, two tree sizes.
        column: 1 for oracle calls, 2 for critical-path calls.

    Returns:
        (calls added per row, nodes added per row), integers.
    """
    low, high = (int(v) for v in window.split("-"))
    calls, nodes = [], []
    for r in rows:
        points = {p[0]: p for p in loads(r["points_json"])}
        reached = low in points and high in points
        calls.append(int(points[high][column] - points[low][column]) if reached else 0)
        nodes.append(high - low if reached else 0)
    return calls, nodes


def pooled_calls_per_node(rows: Sequence[Record], window: str, column: int = 1) -> float:
    """Calls added / nodes added in ``window`` ("low-high") over the rows (a pooled ratio);
    ``column`` 1 counts oracle calls, 2 critical-path calls (the points of ``calls_at_sizes``).

    Args:
        rows: Records with a ``points_json`` column (``calls_at_sizes`` points).
        window: ``"low-high"``, two tree sizes.
        column: 1 for oracle calls, 2 for critical-path calls.

    Returns:
        Summed calls added / summed nodes added over the rows whose trees reached both sizes;
        NaN if none did.
    """
    calls, nodes = window_counts(rows, window, column)
    return sum(calls) / sum(nodes) if sum(nodes) else float("nan")


def pooled_interval(rows: Sequence[Record], window: str, seed: int, column: int = 1) -> tuple[float, float]:
    """The 95 % bootstrap interval of ``pooled_calls_per_node(rows, window, column)`` over the rows
    (``bootstrap_ratio_interval`` on the per-row counts: the interval ``bootstrap_interval`` gives
    with that statistic, bit for bit, without re-reading every record in every resample).

    Args:
        rows: Records with a ``points_json`` column.
        window: ``"low-high"``.
        seed: Seed of the resampling generator.
        column: 1 for oracle calls (default), 2 for critical-path calls.

    Returns:
        (low, high).
    """
    calls, nodes = window_counts(rows, window, column)
    return bootstrap_ratio_interval(calls, nodes, seed)


def window_fractions(rows: Sequence[Record], window: str) -> list[float]:
    """The reachable fraction in ``window`` (``reachable_fraction_by_window``, stored as
    ``fractions_json``) of each row whose tree grew through it.

    Args:
        rows: Records with a ``fractions_json`` column.
        window: ``"low-high"``.

    Returns:
        One fraction per such row.
    """
    return [fractions[window] for fractions in (loads(r["fractions_json"]) for r in rows) if window in fractions]


def mean_fraction(rows: Sequence[Record], window: str) -> float:
    """The mean of ``window_fractions(rows, window)``; NaN if no row has the window.

    Args:
        rows: Records with a ``fractions_json`` column.
        window: ``"low-high"``.

    Returns:
        The mean reachable fraction.
    """
    values = window_fractions(rows, window)
    return float(np.mean(values)) if values else float("nan")


def fraction_interval(rows: Sequence[Record], window: str, seed: int) -> list[float]:
    """The 95 % percentile bootstrap interval of ``mean_fraction(rows, window)``, resampling the
    trees that grew through the window, rounded to 4 decimals.

    Args:
        rows: Records with a ``fractions_json`` column.
        window: ``"low-high"``.
        seed: Seed of the resampling generator.

    Returns:
        ``[low, high]`` (NaNs if no tree grew through the window).
    """
    return rounded_interval(bootstrap_interval(window_fractions(rows, window), _mean, seed))


def _mean(values: list[float]) -> float:
    return float(np.mean(values))


def calls_at_sizes(result: PlanResult, sizes: Sequence[int]) -> list[list[int]]:
    """[[size, oracle calls, critical-path calls], ...] at the first round the tree reaches each size.

    Args:
        result: A finished plan (its per-round ``history``).
        sizes: Tree sizes (nodes).

    Returns:
        One ``[size, oracle_calls, critical_path_calls]`` triple per size the tree reached.
    """
    nodes = result.history["nodes"]
    out: list[list[int]] = []
    for size in sizes:
        reached = np.flatnonzero(nodes >= size)
        if reached.size:
            index = int(reached[0])
            out.append([int(size), int(result.history["oracle_calls"][index]),
                        int(result.history["critical_path"][index])])
    return out


def reachable_fraction_by_window(result: PlanResult, sizes: Sequence[int]) -> dict[str, float]:
    """The truly reachable share of the candidates evaluated while the tree grew through each window
    of sizes (RRT: its tests; q-RRT: its database entries): what sets Grover's success
    probability sin^2((2k+1) theta), sin^2 theta = f.

    Args:
        result: A finished plan (its per-round ``history``).
        sizes: Increasing tree sizes; consecutive pairs are the windows.

    Returns:
        ``{"low-high": f}`` for each window the tree grew through and evaluated candidates in.
    """
    nodes = result.history["nodes"]
    out: dict[str, float] = {}
    for low, high in zip(sizes[:-1], sizes[1:], strict=True):
        rounds = (nodes >= low) & (np.concatenate([[0], nodes[:-1]]) < high)
        entries = int(result.history["entries"][rounds].sum())
        if entries and np.any(nodes >= high):
            out[f"{low}-{high}"] = int(result.history["reachable"][rounds].sum()) / entries
    return out


def marginal(points: list[list[int]], column: int = 1) -> dict[str, float]:
    """Calls added per node added between consecutive sizes: {"30-100": ..., ...}.

    Args:
        points: ``calls_at_sizes`` points, by increasing size.
        column: 1 for oracle calls, 2 for critical-path calls.

    Returns:
        ``{"n0-n1": (calls at n1 - calls at n0) / (n1 - n0)}`` for consecutive points.
    """
    out: dict[str, float] = {}
    for (n0, *c0), (n1, *c1) in zip(points[:-1], points[1:], strict=False):
        out[f"{n0}-{n1}"] = (c1[column - 1] - c0[column - 1]) / (n1 - n0)
    return out


class TreeSize(Experiment):
    """Oracle calls per node against tree size (beyond the paper's 30-node trees of Fig. 9).

    A trial grows one tree with a configuration of ``CONFIGS`` toward an unreachable goal and
    records the calls at each tree size (``calls_at_sizes``). The summary gives the marginal calls
    per node in each window of sizes (``pooled_calls_per_node``), the critical path's and the mean
    reachable fraction (``mean_fraction``), each with its 95 % bootstrap interval over worlds, and
    the first window where a quantum planner stops being cheaper than RRT.
    """

    name = "tree-size"
    title = "Oracle calls per node against tree size (beyond the paper)"
    paper = {"note": "the paper reports 30-node trees only (Fig. 9)"}

    def settings(self, quick: bool, trials: int | None, seed: int) -> Settings:
        return {"trials": trials or (2 if quick else 5), "sizes": list(SIZES[:2] if quick else SIZES),
                "workers": 8, "num_qubits": 8, "backend": "statevector", "scenario": "paper_clutter",
                "configs": list(CONFIGS), "seed": seed, "quick": quick}

    def trials(self, settings: Settings) -> list[Trial]:
        variants = [(label, {"config": label}) for label in settings["configs"]]
        return paired_trials(settings, variants, TrialStream.TREE_SIZE_WORLDS, TrialStream.TREE_SIZE_PLANNERS)

    def run_trial(self, trial: Trial, settings: Settings) -> Record:
        problem = experiment_problem(settings, world(settings["scenario"], trial.params["world_seed"]))
        planner_name, policy = CONFIGS[trial.params["config"]]
        planner = make_planner(planner_name, trial.seed, settings["backend"], settings["workers"],
                              settings["num_qubits"], search_policy=policy)
        result = planner.plan(problem.with_goal_radius(1e-9), max_nodes=max(settings["sizes"]))
        return {"status": str(result.status), "nodes": result.metrics.nodes, "rounds": result.metrics.rounds,
                "oracle_calls": result.metrics.oracle_calls,
                "points_json": dumps(calls_at_sizes(result, settings["sizes"])),
                "fractions_json": dumps(reachable_fraction_by_window(result, settings["sizes"]))}

    def summarize(self, records: list[Record], settings: Settings) -> Summary:
        sizes = settings["sizes"]
        windows = [f"{a}-{b}" for a, b in zip(sizes[:-1], sizes[1:], strict=True)]

        ours, interval, critical, critical_interval, fractions, fractions_interval = {}, {}, {}, {}, {}, {}
        for label in settings["configs"]:
            rows = [r for r in records if r["config"] == label]
            ours[label] = {w: round(pooled_calls_per_node(rows, w), 3) for w in windows}
            interval[label] = {w: rounded_interval(pooled_interval(rows, w, settings["seed"]), 3) for w in windows}
            critical[label] = {w: round(pooled_calls_per_node(rows, w, 2), 3) for w in windows}
            critical_interval[label] = {w: rounded_interval(pooled_interval(rows, w, settings["seed"], 2), 3)
                                        for w in windows}
            fractions[label] = {w: round(mean_fraction(rows, w), 4) for w in windows}
            fractions_interval[label] = {w: fraction_interval(rows, w, settings["seed"]) for w in windows}
        crossover = {}
        for label in settings["configs"]:
            if label == "RRT":
                continue
            column = critical if label.startswith("PQRRT") else ours
            worse = [w for w in windows if column[label][w] >= ours["RRT"][w]]
            crossover[label] = worse[0] if worse else None
        return {"ours": ours, "paper": self.paper, "interval_95": interval,
                "critical_path_per_node": critical, "critical_path_interval_95": critical_interval,
                "crossover_window": crossover,
                "mean_reachable_fraction": fractions, "mean_reachable_fraction_interval_95": fractions_interval,
                "note": "marginal oracle calls per node added in each window of tree sizes, pooled over "
                        "worlds; crossover_window: the first window where the planner is no longer "
                        "cheaper per node than RRT (Pq-RRT compared on its critical path), read from the point "
                        "estimates; every interval is a percentile bootstrap over worlds",
                "labels": ["QRRT optimal uses the true m of each database (simulation knowledge)",
                           "phase oracle from a classical lookup of all 2^8 entries",
                           "backend: exact statevector (ideal; same statistics as Aer)"]}

    def plot(self, records: list[Record], settings: Settings, summary: Summary, out_dir: Path) -> list[Path]:
        fig, axes = new_figure(1, 1, (7.5, 5))
        ax = axes[0, 0]
        sizes = settings["sizes"]
        windows = list(summary["ours"]["RRT"])
        centres = [np.sqrt(a * b) for a, b in zip(sizes[:-1], sizes[1:], strict=True)]
        for label in settings["configs"]:
            values = [summary["ours"][label][w] for w in windows]
            spans = np.array([summary["interval_95"][label][w] for w in windows], dtype=float)
            ax.errorbar(centres, values, yerr=[np.array(values) - spans[:, 0], spans[:, 1] - np.array(values)],
                        color=COLORS[label], marker="o", ms=4, capsize=3, label=label)
            if label.startswith("PQRRT"):
                ax.plot(centres, [summary["critical_path_per_node"][label][w] for w in windows], "--",
                        color=COLORS[label], label=f"{label} (critical path)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("tree size (nodes, window centre)")
        ax.set_ylabel("oracle calls per node added (95 % bootstrap interval)")
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3, which="both")
        ax.set_title(f"Calls per node against tree size ({settings['trials']} worlds)", fontsize=10)
        return [save(fig, out_dir / "tree_size.png")]
