"""Narrow corridor as a factorial study (beyond Figs. 13-14): in which corridor, at which start and
with how many Grover iterations would 50 trials give the paper's 47 q-RRT and 14 RRT channel nodes?

The paper (§V.C) gives neither the channel's size, the clutter, the start nor the iterations of
its corridor world. Ours (the ``corridor`` experiment) has a channel 0.4 wide and 4 long: 0.4 % of
the workspace, so about 5 of RRT's 50 x 25 samples land in it. This study crosses every level of

- channel ``width`` 0.4, 1, 2 and ``length`` 2, 4, 8 (0.2 % to 4 % of the workspace),
- ``clutter``: 60, 120, 240 small boxes beside the wall (``narrow_corridor``'s ``clutter``),
- ``distance``: the start 0.5, 1 or 3 before the left mouth, on the channel's axis,
- ``iterations``: q-RRT's Grover iterations per search: 1, 2, or the paper's schedule (5, then 3
  once the tree has more than 10 nodes); RRT has none, so its cells are the 81 of the other four factors,

a full factorial of 243 q-RRT cells and 81 RRT cells, with clearance 1.5 around the mouths, world
seed 0, 2^8 databases and the exact statevector backend (the ideal; same statistics as Aer).

A trial is a block of 50 runs of one planner in one cell (the paper's 50 trials), each cut at 25
oracle calls as in the paper (a run whose tree reaches the goal ends there, as in ``corridor``).
Run i of block b has seed ``replicate_seed(seed, 50 b + i, TrialStream.CORRIDOR_SENSITIVITY)``,
the same in every cell (common random numbers). Each cell runs 8 blocks (400 runs). The reported
quantity is the mean number of nodes inside the channel rectangle per 50 runs, with a 95 %
percentile bootstrap over the cell's runs. Its half-width is about 1.96 * 50 * sd / sqrt(400) =
4.9 sd, where sd is one run's standard deviation: 8 blocks keep every interval narrower than the
paper's gap 47 - 14 = 33 for any sd below 3.3. A pilot of the first 2 blocks of every cell (the
same seeds) measured sd at most 1.7, which sized the blocks; the levels were fixed before it. The
summary lists every interval wider than the gap.

Rules, fixed before the run:

- *The paper's pair is inside a cell* when 47 lies in the cell's q-RRT interval and 14 in its RRT
  interval; every such cell is listed (``paper_pair_inside``), or the list is empty.
- *The closest cell* minimises the Euclidean distance between (RRT, q-RRT) per-50 means and
  (14, 47).
- The paper ran one block of 50 trials. ``single_block_range_95`` is the 95 % range of one block's
  total (the 2.5 and 97.5 % points of sums of 50 runs resampled from the cell's runs);
  ``paper_pair_plausible_single_block`` lists the cells whose ranges hold both of the paper's
  numbers: where the paper's single block could have come from.
- *q-RRT ahead of RRT* in a cell: its q-RRT interval lies above its RRT interval.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .base import Experiment, Record, Settings, Summary, Trial, TrialStream, replicate_seed
from .corridor import in_channel
from .figures import new_figure, save
from .intervals import LEVEL, RESAMPLES, bootstrap_ratio_interval, differs, rounded_interval
from .measures import cut_at, dumps, loads
from .planners import experiment_problem, make_planner
from .worlds import world

if TYPE_CHECKING:
    from ..world.environment import Environment

#: the factors of the full design and their levels (``corridor``'s world: width 0.4, length 4,
#: clutter 120, a start about 1 before the mouth)
FACTORS: dict[str, list[Any]] = {"width": [0.4, 1.0, 2.0], "length": [2.0, 4.0, 8.0], "clutter": [60, 120, 240],
                                 "distance": [0.5, 1.0, 3.0], "iterations": ["fixed:1", "fixed:2", "paper"]}
#: the quick path's levels
QUICK_FACTORS: dict[str, list[Any]] = {"width": [0.4, 1.0], "length": [4.0], "clutter": [120], "distance": [1.0],
                                       "iterations": ["paper"]}
#: the factors that shape the world and the start (RRT's cells)
GEOMETRY = ("width", "length", "clutter", "distance")
#: the paper's channel nodes over its 50 trials (Figs. 13-14)
PAPER = {"QRRT": 47, "RRT": 14}
#: the paper's trials per planner: every count is reported per this many runs
PAPER_TRIALS = 50
#: the paper's gap, QRRT - RRT: every cell's interval should be narrower
GAP = PAPER["QRRT"] - PAPER["RRT"]
PLANNERS = ("RRT", "QRRT")
#: the ``iterations`` column of RRT's records (it runs no search)
NO_ITERATIONS = "none"


def cells(factors: dict[str, list[Any]], planner: str) -> list[dict[str, Any]]:
    """Every cell of the full factorial for one planner (RRT: without ``iterations``).

    Args:
        factors: Factor -> levels (the keys of ``FACTORS``).
        planner: ``"RRT"`` or ``"QRRT"``.

    Returns:
        The cells, in the order of ``itertools.product`` over the factors.
    """
    names = [name for name in FACTORS if planner == "QRRT" or name != "iterations"]
    return [dict(zip(names, levels, strict=True)) for levels in itertools.product(*(factors[n] for n in names))]


def cell_id(cell: dict[str, Any], planner: str) -> str:
    """A cell's id, e.g. ``w0.4-l4.0-c120-d1.0`` (RRT) or ``w0.4-l4.0-c120-d1.0-paper`` (q-RRT).

    Args:
        cell: A cell (or a record holding its factors).
        planner: ``"RRT"`` or ``"QRRT"`` (only q-RRT's ids name the iterations).

    Returns:
        The id.
    """
    base = f"w{float(cell['width'])}-l{float(cell['length'])}-c{int(cell['clutter'])}-d{float(cell['distance'])}"
    return base if planner == "RRT" else f"{base}-{cell['iterations']}"


def start_before_mouth(env: Environment, distance: float) -> tuple[np.ndarray, float]:
    """A free start on the channel's axis at least ``distance`` before its left mouth (stepping
    back 0.05 at a time past any clutter box); returns it and its actual distance.

    Args:
        env: A ``narrow_corridor`` world (its ``metadata["channel"]``).
        distance: The least distance before the mouth.

    Returns:
        ``(start, actual_distance)``.

    Raises:
        ValueError: If no free start is found within 400 steps (20 units) or inside the bounds.
    """
    (x0, y0), (_, y1) = env.metadata["channel"]
    for step in range(400):
        actual = distance + 0.05 * step
        start = np.array([x0 - actual, (y0 + y1) / 2])
        if start[0] > env.bounds[0, 0] and env.is_free(start):
            return start, actual
    raise ValueError(f"no free start on the channel axis at distance >= {distance}")


def single_block_range(counts: np.ndarray, block: int, seed: int, resamples: int = RESAMPLES,
                       level: float = LEVEL) -> tuple[float, float]:
    """The ``level`` range of one block's total: quantiles of sums of ``block`` runs drawn with
    replacement from ``counts`` (what one run of the paper's design, ``block`` trials, could give).

    Args:
        counts: One count per run of a cell.
        block: Runs per block (the paper's 50).
        seed: Seed of the resampling generator.
        resamples: Resampled blocks.
        level: Coverage.

    Returns:
        ``(low, high)``; NaNs for no runs.
    """
    counts = np.asarray(counts)
    if counts.size == 0:
        return float("nan"), float("nan")
    sums = counts[np.random.default_rng(seed).integers(0, counts.size, (resamples, block))].sum(axis=1)
    tail = (1.0 - level) / 2.0
    return float(np.quantile(sums, tail)), float(np.quantile(sums, 1.0 - tail))


def run_block(params: dict[str, Any], settings: Settings, world_seed: int, seeds: Sequence[int]) -> Record:
    """One block: one run of ``params["planner"]`` per seed in one cell of world ``world_seed``,
    each cut at ``settings["budget"]`` oracle calls, counting its tree's nodes in the channel.

    Args:
        params: The cell (``width``, ``length``, ``clutter``, ``distance``), ``planner`` and,
            for q-RRT, ``iterations`` (a search-policy name).
        settings: ``scenario``, ``mouth_clearance``, ``budget``, ``backend``, ``num_qubits``
            and the planners' options (``planner_for``).
        world_seed: The world's seed (its clutter boxes and goal).
        seeds: One planner seed per run.

    Returns:
        The record's measurements: ``nodes`` and ``oracle_calls`` summed over the runs, the start's
        actual distance, and per run (``*_json``) and summed, the nodes inside the channel
        (``in_channel``) and beyond its far mouth (``through_channel``).
    """
    problem = experiment_problem(settings, world(settings["scenario"], world_seed, width=params["width"],
                                                 length=params["length"], clutter=params["clutter"],
                                                 mouth_clearance=settings["mouth_clearance"]))
    env = problem.env
    start, distance = start_before_mouth(env, params["distance"])
    channel = env.metadata["channel"]
    options = {"search_policy": params["iterations"]} if params["planner"] == "QRRT" else {}
    inside, through, nodes, calls = [], [], 0, 0
    for seed in seeds:
        planner = make_planner(params["planner"], seed, settings["backend"],
                              num_qubits=settings["num_qubits"], **options)
        result = planner.plan(problem.replace(start=start), max_oracle_calls=settings["budget"])
        kept, used = cut_at(result, settings["budget"])
        positions = result.nodes[1: kept + 1]
        inside.append(int(in_channel(positions, channel).sum()))
        through.append(int((positions[:, 0] > channel[1][0]).sum()))
        nodes, calls = nodes + kept, calls + used
    return {"nodes": nodes, "oracle_calls": calls, "start_distance": round(distance, 3),
            "in_channel": sum(inside), "through_channel": sum(through),
            "in_channel_json": dumps(inside), "through_channel_json": dumps(through)}


class CorridorSensitivity(Experiment):
    """The narrow corridor as a full factorial (beyond paper Figs. 13-14): module docstring.

    ``trials`` (``--trials``) is the number of blocks per cell; ``block_size`` runs make a block.
    The summary gives, per cell and planner, the mean channel nodes per 50 runs with its 95 %
    interval (``ours``, ``interval_95``, ``differs_from_paper``), the cells holding the paper's
    pair, the closest cell, single-block ranges and the widest interval.
    """

    name = "corridor-sensitivity"
    title = "Narrow corridor: channel nodes over channel width, length, clutter, start and iterations"
    paper = PAPER

    def settings(self, quick: bool, trials: int | None, seed: int) -> Settings:
        return {"blocks": trials or (2 if quick else 8), "block_size": 10 if quick else PAPER_TRIALS, "budget": 25,
                "num_qubits": 8, "mouth_clearance": 1.5, "backend": "statevector", "scenario": "narrow_corridor",
                "world_seed": 0, "factors": QUICK_FACTORS if quick else FACTORS, "seed": seed, "quick": quick}

    def trials(self, settings: Settings) -> list[Trial]:
        out = []
        for planner in PLANNERS:
            for cell in cells(settings["factors"], planner):
                for block in range(settings["blocks"]):
                    first = replicate_seed(settings["seed"], block * settings["block_size"],
                                           TrialStream.CORRIDOR_SENSITIVITY)
                    out.append(Trial(f"{planner}-{cell_id(cell, planner)}-b{block}",
                                     {"planner": planner, "iterations": NO_ITERATIONS, **cell, "block": block},
                                     first))
        return out

    def run_trial(self, trial: Trial, settings: Settings) -> Record:
        first = trial.params["block"] * settings["block_size"]
        seeds = [replicate_seed(settings["seed"], first + run, TrialStream.CORRIDOR_SENSITIVITY)
                 for run in range(settings["block_size"])]
        return run_block(trial.params, settings, settings["world_seed"], seeds)

    def summarize(self, records: list[Record], settings: Settings) -> Summary:
        seed = settings["seed"]
        ours: dict[str, dict[str, float]] = {kind: {} for kind in PLANNERS}
        interval: dict[str, dict[str, list[float]]] = {kind: {} for kind in PLANNERS}
        single: dict[str, dict[str, list[float]]] = {kind: {} for kind in PLANNERS}
        for kind in PLANNERS:
            by_cell: dict[str, list[int]] = {}
            for r in records:
                if r["planner"] == kind:
                    by_cell.setdefault(cell_id(r, kind), []).extend(loads(r["in_channel_json"]))
            for cell in cells(settings["factors"], kind):
                key = cell_id(cell, kind)
                counts = by_cell.get(key, [])
                ours[kind][key] = round(PAPER_TRIALS * float(np.mean(counts)), 2) if counts else float("nan")
                interval[kind][key] = rounded_interval(bootstrap_ratio_interval(
                    counts, None, seed, per_trials=PAPER_TRIALS), 2)
                single[kind][key] = rounded_interval(single_block_range(np.array(counts, dtype=np.int64),
                                                                        PAPER_TRIALS, seed), 1)
        differs_map = {kind: {key: differs(PAPER[kind], span) for key, span in interval[kind].items()}
                       for kind in PLANNERS}
        q_cells = cells(settings["factors"], "QRRT")
        pairs = [(cell_id(cell, "QRRT"), cell_id(cell, "RRT")) for cell in q_cells]
        inside = [q for q, r in pairs if differs_map["QRRT"][q] is False and differs_map["RRT"][r] is False]
        plausible = [q for q, r in pairs if single["QRRT"][q][0] <= PAPER["QRRT"] <= single["QRRT"][q][1]
                     and single["RRT"][r][0] <= PAPER["RRT"] <= single["RRT"][r][1]]
        ahead = [q for q, r in pairs if interval["QRRT"][q][0] > interval["RRT"][r][1]]
        closest_q, closest_r = min(pairs, key=lambda p: math.hypot(ours["QRRT"][p[0]] - PAPER["QRRT"],
                                                                   ours["RRT"][p[1]] - PAPER["RRT"]))
        widths = [(span[1] - span[0], kind, key) for kind in PLANNERS for key, span in interval[kind].items()]
        widest = max(widths)
        runs = settings["blocks"] * settings["block_size"]
        return {"ours": ours, "paper": PAPER, "interval_95": interval, "differs_from_paper": differs_map,
                "paper_pair_inside": inside,
                "closest_to_paper": {
                    "cell": closest_q, "RRT": ours["RRT"][closest_r], "QRRT": ours["QRRT"][closest_q],
                    "RRT_interval_95": interval["RRT"][closest_r], "QRRT_interval_95": interval["QRRT"][closest_q],
                    "distance": round(math.hypot(ours["QRRT"][closest_q] - PAPER["QRRT"],
                                                 ours["RRT"][closest_r] - PAPER["RRT"]), 2)},
                "single_block_range_95": single, "paper_pair_plausible_single_block": plausible,
                "qrrt_ahead_of_rrt": ahead,
                "widest_interval": {"planner": widest[1], "cell": widest[2], "width": round(widest[0], 2)},
                "intervals_wider_than_gap": [f"{kind}/{key}" for width, kind, key in widths if width >= GAP],
                "design": {"qrrt_cells": len(q_cells), "rrt_cells": len(cells(settings["factors"], "RRT")),
                           "runs_per_cell": runs, "gap": GAP},
                "note": f"mean nodes inside the channel per {PAPER_TRIALS} runs (the paper: one block of 50 trials) "
                        f"over {runs} runs per cell, each cut at {settings['budget']} oracle calls; RRT cells have no "
                        "iterations; paper_pair_inside lists the q-RRT cells whose interval holds 47 while their "
                        "RRT cell's holds 14; single_block_range_95 is the 95 % range of one block of 50 runs",
                "labels": ["phase oracle from a classical lookup of all 2^n entries",
                           "backend: exact statevector (ideal; same statistics as Aer)"]}

    def plot(self, records: list[Record], settings: Settings, summary: Summary, out_dir: Path) -> list[Path]:
        levels = settings["factors"]
        fig, axes = new_figure(1, len(levels["iterations"]), (5.0 * len(levels["iterations"]), 4.6))
        markers = dict(zip(levels["length"], "o^sDv", strict=False))
        colors = dict(zip(levels["width"], ("tab:blue", "tab:orange", "tab:green", "tab:red"), strict=False))
        top = max([PAPER["QRRT"], *(span[1] for span in summary["interval_95"]["QRRT"].values())]) * 1.05
        right = max([PAPER["RRT"], *(span[1] for span in summary["interval_95"]["RRT"].values())]) * 1.05
        for ax, iterations in zip(axes[0], levels["iterations"], strict=True):
            for cell in cells(levels, "QRRT"):
                if cell["iterations"] != iterations:
                    continue
                q, r = cell_id(cell, "QRRT"), cell_id(cell, "RRT")
                x, y = summary["ours"]["RRT"][r], summary["ours"]["QRRT"][q]
                (xl, xh), (yl, yh) = summary["interval_95"]["RRT"][r], summary["interval_95"]["QRRT"][q]
                ax.errorbar([x], [y], xerr=[[x - xl], [xh - x]], yerr=[[y - yl], [yh - y]], fmt=markers[cell["length"]],
                            color=colors[cell["width"]], ms=4, lw=0.6, alpha=0.7)
            ax.plot([PAPER["RRT"]], [PAPER["QRRT"]], "*", color="black", ms=14, label="paper (14, 47)")
            ax.plot([0, max(top, right)], [0, max(top, right)], ":", color="gray", lw=1, label="q-RRT = RRT")
            for width, color in colors.items():
                ax.plot([], [], "s", color=color, label=f"width {width}")
            for length, marker in markers.items():
                ax.plot([], [], marker, color="gray", label=f"length {length}")
            pair_axes(ax, right, top, f"q-RRT iterations: {iterations}")
        return [save(fig, out_dir / "corridor_sensitivity.png")]


def pair_axes(ax: Any, right: float, top: float, title: str) -> None:
    """An (RRT, q-RRT) channel-node panel: limits, title, axis labels per ``PAPER_TRIALS`` runs, grid
    and legend."""
    ax.set_xlim(0, right)
    ax.set_ylim(0, top)
    ax.set_title(title)
    ax.set_xlabel(f"RRT: channel nodes per {PAPER_TRIALS} runs")
    ax.set_ylabel(f"q-RRT: channel nodes per {PAPER_TRIALS} runs")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper left")
