"""Narrow corridor as a sensitivity study (beyond Figs. 13-14): under which conditions does q-RRT
place more nodes in the channel than RRT, and is the paper's 47 vs 14 reached anywhere?

One factor at a time around a base cell (start 1.0 before the mouth on its axis, clutter kept 1.5
from the mouths, the paper's iteration schedule, databases of 2^8): the start's distance from the
mouth, the clutter's clearance from the mouth (smaller: denser clutter beside it), q-RRT's
iterations (1, 2, the paper's schedule) and the database size. Each cell runs RRT and q-RRT 50
times, cut at 25 oracle calls as in the paper, and counts nodes inside the 0.4 x 4 channel (sum
over the trials, with a 95 % bootstrap interval).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .base import Experiment, Record, Settings, Summary, Trial, TrialStream, replicate_seed
from .corridor import in_channel
from .figures import new_figure, save
from .intervals import bootstrap_interval, rounded_interval
from .measures import cut_at
from .planners import planner_for
from .worlds import world

if TYPE_CHECKING:
    from ..world.environment import Environment

#: factor -> value of the base cell (numbers and a policy name)
BASE: dict[str, Any] = {"distance": 1.0, "mouth_clearance": 1.5, "policy": "paper", "num_qubits": 8}
#: factor -> the values it takes, one at a time
FACTORS: dict[str, list[Any]] = {"distance": [0.25, 0.5, 1.0, 2.0, 4.0], "mouth_clearance": [0.3, 0.75, 1.5, 3.0],
           "policy": ["fixed:1", "fixed:2", "paper"], "num_qubits": [4, 6, 8, 10]}
PAPER = {"QRRT": 47, "RRT": 14}
PLANNERS = ("RRT", "QRRT")


def cells(factors: dict[str, list[Any]]) -> list[dict[str, Any]]:
    """The base cell and every one-factor change of it (each distinct cell once).

    Args:
        factors: Factor -> the values it takes (a subset of ``FACTORS``).

    Returns:
        Cells (``BASE`` with one factor changed), in the order of ``factors``, without repeats.
    """
    out: list[dict[str, Any]] = []
    seen: set[tuple[tuple[str, Any], ...]] = set()
    for factor, values in factors.items():
        for value in values:
            cell = {**BASE, factor: value}
            key = tuple(sorted(cell.items()))
            if key not in seen:
                seen.add(key)
                out.append(cell)
    return out


def cell_id(cell: dict[str, Any]) -> str:
    """A cell's id, e.g. ``d1.0-c1.5-paper-n8``.

    Args:
        cell: A cell (or a record holding its factors).

    Returns:
        The id naming its distance, mouth clearance, policy and qubits.
    """
    return f"d{cell['distance']}-c{cell['mouth_clearance']}-{cell['policy']}-n{cell['num_qubits']}"


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


class CorridorSensitivity(Experiment):
    """The narrow corridor as a sensitivity study (beyond paper Figs. 13-14).

    Each cell of ``cells(FACTORS)`` changes one factor of ``BASE`` (start distance, mouth
    clearance, iteration schedule, database size); a trial runs RRT or q-RRT there, cut at 25
    oracle calls, and counts nodes in the channel. The summary lists, per cell, the sums with 95 %
    intervals, the cells where q-RRT is ahead of RRT and those where the paper's 47 vs 14 is reached.
    """

    name = "corridor-sensitivity"
    title = "Narrow corridor: channel nodes against start, clutter, iterations and database size"
    paper = PAPER

    def settings(self, quick: bool, trials: int | None, seed: int) -> Settings:
        factors = {key: values[::2] if quick else values for key, values in FACTORS.items()}
        if quick:
            factors = {key: sorted(set(values) | {BASE[key]}, key=str) for key, values in factors.items()}
        return {"trials": trials or (10 if quick else 50), "budget": 25, "backend": "statevector",
                "scenario": "narrow_corridor", "world_seed": 0, "factors": factors, "seed": seed, "quick": quick}

    def trials(self, settings: Settings) -> list[Trial]:
        return [Trial(f"{kind}-{cell_id(cell)}-{i}", {"planner": kind, **cell, "replicate": i},
                      replicate_seed(settings["seed"], i, TrialStream.CORRIDOR_SENSITIVITY))
                for cell in cells(settings["factors"]) for kind in PLANNERS for i in range(settings["trials"])]

    def run_trial(self, trial: Trial, settings: Settings) -> Record:
        params = trial.params
        env = world(settings["scenario"], settings["world_seed"], mouth_clearance=params["mouth_clearance"])
        start, distance = start_before_mouth(env, params["distance"])
        planner = planner_for(settings, params["planner"], env, trial.seed, settings["backend"],
                              num_qubits=params["num_qubits"], search_policy=params["policy"])
        result = planner.plan(start=start, max_oracle_calls=settings["budget"])
        nodes, calls = cut_at(result, settings["budget"])
        positions = result.nodes[1: nodes + 1]
        return {"nodes": nodes, "oracle_calls": calls, "start_distance": round(distance, 3),
                "in_channel": int(in_channel(positions, env.metadata["channel"]).sum())}

    def summarize(self, records: list[Record], settings: Settings) -> Summary:
        ours: dict[str, dict[str, int]] = {}
        interval: dict[str, dict[str, list[float]]] = {}
        for cell in cells(settings["factors"]):
            key = cell_id(cell)
            ours[key], interval[key] = {}, {}
            for kind in PLANNERS:
                rows = [r for r in records if r["planner"] == kind and cell_id(r) == key]
                ours[key][kind] = sum(r["in_channel"] for r in rows)
                interval[key][kind] = rounded_interval(bootstrap_interval(
                    rows, lambda sample: sum(r["in_channel"] for r in sample), settings["seed"]), 1)
        # q-RRT ahead of RRT: its interval lies above RRT's (and the paper's pair, scaled to 50 trials)
        ahead = [key for key in ours if interval[key]["QRRT"][0] > interval[key]["RRT"][1]]
        scale = settings["trials"] / 50
        paper_reached = [key for key in ours if interval[key]["QRRT"][0] <= PAPER["QRRT"] * scale
                         <= interval[key]["QRRT"][1] and interval[key]["RRT"][0] <= PAPER["RRT"] * scale
                         <= interval[key]["RRT"][1]]
        return {"ours": ours, "paper": PAPER, "interval_95": interval, "base": cell_id(BASE),
                "qrrt_ahead_of_rrt": ahead, "paper_pair_reached_in": paper_reached,
                "note": "nodes inside the channel summed over the trials of a cell (the paper: 50 trials); "
                        "cells vary one factor from the base; qrrt_ahead_of_rrt lists cells where q-RRT's "
                        "95 % interval lies above RRT's",
                "labels": ["phase oracle from a classical lookup of all 2^n entries",
                           "backend: exact statevector (ideal; same statistics as Aer)"]}

    def plot(self, records: list[Record], settings: Settings, summary: Summary, out_dir: Path) -> list[Path]:
        factors = settings["factors"]
        fig, axes = new_figure(1, len(factors), (4.4 * len(factors), 4.2))
        colors = {"RRT": "tab:gray", "QRRT": "tab:blue"}
        for ax, (factor, values) in zip(axes[0], factors.items(), strict=True):
            x = np.arange(len(values))
            for offset, kind in ((-0.15, "RRT"), (0.15, "QRRT")):
                keys = [cell_id({**BASE, factor: value}) for value in values]
                y = np.array([summary["ours"][k][kind] for k in keys], dtype=float)
                spans = np.array([summary["interval_95"][k][kind] for k in keys], dtype=float)
                ax.errorbar(x + offset, y, yerr=[y - spans[:, 0], spans[:, 1] - y], fmt="o", capsize=3,
                            color=colors[kind], label=kind)
                ax.axhline(PAPER[kind] * settings["trials"] / 50, color=colors[kind], ls="--", lw=1,
                           label=f"paper {kind}")
            ax.set_xticks(x, [str(v) for v in values])
            ax.set_xlabel(factor.replace("_", " "))
            ax.set_ylabel(f"nodes in the channel ({settings['trials']} trials)")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7)
        return [save(fig, out_dir / "corridor_sensitivity.png")]
