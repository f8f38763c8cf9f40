"""Narrow corridor over clutter draws: do ``corridor-sensitivity``'s statements hold in other worlds?

``corridor-sensitivity`` runs every cell of its factorial in one world (world seed 0: one draw of
the clutter boxes and of the goal) and bootstraps runs, so its intervals say what that one world
gives. Here the world is the unit. The cells that decide the corridor's explanation run in
``draws`` further worlds, world seeds 1, 2, ... (seed 0 is left out: no draw is the world the
statements were read from):

- the geometry of every cell that holds the paper's pair in the factorial (``CENTRES``: channel 1
  wide and 8 long, 120 boxes, the start 3 before the mouth; the factorial's ``paper_pair_inside``
  holds this geometry with 1 and with 2 Grover iterations, and no other),
- every geometry one level away from it in one factor of ``corridor_sensitivity.FACTORS`` (width
  0.4 and 2, length 4, clutter 60 and 240, the start 1 before the mouth),
- each with RRT, and with q-RRT at every iteration level (1, 2 and the paper's schedule): the
  neighbours in iterations and the paper's-schedule row of every geometry,

7 geometries: 7 RRT and 21 q-RRT cells. The rest is the factorial's: a trial is one block of 50
runs of one planner in one cell of one world (``corridor_sensitivity.run_block``), each cut at 25
oracle calls, clearance 1.5 around the mouths, 2^8 databases, the exact statevector backend. Each
draw runs 8 blocks per cell (400 runs, the factorial's count, so one draw's intervals are as wide
as world seed 0's were). Run i of block b in world seed w has seed ``replicate_seed(seed,
RUN_STRIDE w + 50 b + i, TrialStream.CORRIDOR_WORLDS)``: the same in every cell of one world
(common random numbers), different between worlds. ``--trials`` is the number of draws.

Rules, fixed before the run.

*Per draw* (the unit: one world; every interval is the 95 % percentile bootstrap over that
world's runs, the factorial's rule applied to one draw):

- ``paper_pair_inside/CELL``: 47 lies in the q-RRT cell's interval and 14 in the interval of RRT
  in the same geometry.
- ``paper_pair_inside_fixed_iterations/GEOMETRY`` (each centre): the pair is inside the geometry
  with 1 or with 2 iterations.
- ``paper_pair_never_with_paper_schedule``: no paper's-schedule cell of the design holds the pair.
- ``qrrt_ahead_of_rrt/CELL``: the q-RRT cell's interval lies above the interval of RRT in the same
  geometry.

``claims_over_worlds[claim]`` is ``{"holds_in": k, "draws": n, "world_seeds": [...]}``: the draws in
which the claim holds. A statement *holds across draws* when it holds in every draw; otherwise
the summary says in how many.

*Over worlds* (the setting: a geometry whatever its clutter draw): ``ours`` is the mean channel
nodes per 50 runs over every draw's runs (every draw has as many runs, so draws weigh equally);
``interval_95`` is ``two_level_bootstrap_interval`` over draws, then runs inside each;
``range_over_draws`` is the least and the greatest per-draw mean (a range of ``draws`` draws, not an
interval). ``claims_for_the_setting`` applies the pair-inside and ahead rules to these intervals.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from .base import Experiment, Record, Settings, Summary, Trial, TrialStream, replicate_seed
from .corridor_sensitivity import (
    FACTORS,
    GEOMETRY,
    NO_ITERATIONS,
    PAPER,
    PAPER_TRIALS,
    PLANNERS,
    cell_id,
    pair_axes,
    run_block,
)
from .figures import new_figure, save
from .intervals import bootstrap_ratio_interval, differs, rounded_interval, two_level_bootstrap_interval
from .measures import loads

#: the geometry of every cell of ``corridor-sensitivity``'s ``paper_pair_inside`` (world seed 0)
CENTRES: list[dict[str, Any]] = [{"width": 1.0, "length": 8.0, "clutter": 120, "distance": 3.0}]
#: the quick path's levels (the centre and its wider neighbour; one fixed count and the schedule)
QUICK_FACTORS: dict[str, list[Any]] = {"width": [1.0, 2.0], "length": [8.0], "clutter": [120], "distance": [3.0],
                                       "iterations": ["fixed:1", "paper"]}
#: the first world seed of the draws (world seed 0 is the factorial's)
FIRST_WORLD_SEED = 1
#: replicate indices per world: run i of block b in world w is replicate RUN_STRIDE w + size b + i
RUN_STRIDE = 100_000
#: the schedule's level of ``iterations`` (the paper's; the other levels are fixed counts)
SCHEDULE = "paper"


def geometries(centres: Sequence[dict[str, Any]], factors: dict[str, list[Any]]) -> list[dict[str, Any]]:
    """Each centre, then every geometry one level away from it in one geometry factor.

    Args:
        centres: Geometries (``width``, ``length``, ``clutter``, ``distance``), each factor at one of
            its ``factors`` levels.
        factors: Factor -> levels, in order (``corridor_sensitivity.FACTORS``).

    Returns:
        The geometries, each once, centre by centre and factor by factor (lower level first).

    Raises:
        ValueError: If a centre's level is not one of its factor's levels.
    """
    out: list[dict[str, Any]] = []
    for centre in centres:
        near = [dict(centre)]
        for name in GEOMETRY:
            at = factors[name].index(centre[name])
            near += [{**centre, name: factors[name][i]} for i in (at - 1, at + 1) if 0 <= i < len(factors[name])]
        out += [geometry for geometry in near if geometry not in out]
    return out


def world_seeds(settings: Settings) -> list[int]:
    """The draws' world seeds: ``draws`` of them from ``first_world_seed``."""
    return list(range(settings["first_world_seed"], settings["first_world_seed"] + settings["draws"]))


def design_cells(settings: Settings, planner: str) -> list[dict[str, Any]]:
    """The planner's cells: every geometry (``geometries``), for q-RRT at every iteration level.

    Args:
        settings: The run's settings (``centres``, ``factors``).
        planner: ``"RRT"`` or ``"QRRT"``.

    Returns:
        The cells, geometry by geometry.
    """
    shapes = geometries(settings["centres"], settings["factors"])
    if planner == "RRT":
        return shapes
    return [{**shape, "iterations": level} for shape in shapes for level in settings["factors"]["iterations"]]


def claims(q_spans: Mapping[str, Sequence[float]], r_spans: Mapping[str, Sequence[float]],
           settings: Settings) -> dict[str, bool]:
    """The module's claims, under its rules, for one set of intervals (one draw's, or over worlds).

    Args:
        q_spans: q-RRT cell id -> its 95 % interval of channel nodes per 50 runs.
        r_spans: RRT cell id (a geometry) -> its interval.
        settings: The run's settings (the cells and centres).

    Returns:
        Claim -> whether it holds (a non-finite interval holds nothing).
    """
    out: dict[str, bool] = {}
    inside: dict[str, bool] = {}
    for cell in design_cells(settings, "QRRT"):
        q, r = cell_id(cell, "QRRT"), cell_id(cell, "RRT")
        inside[q] = differs(PAPER["QRRT"], q_spans[q]) is False and differs(PAPER["RRT"], r_spans[r]) is False
        out[f"paper_pair_inside/{q}"] = inside[q]
    for centre in settings["centres"]:
        fixed = [cell_id({**centre, "iterations": level}, "QRRT") for level in settings["factors"]["iterations"]
                 if level != SCHEDULE]
        out[f"paper_pair_inside_fixed_iterations/{cell_id(centre, 'RRT')}"] = any(inside[q] for q in fixed)
    out["paper_pair_never_with_paper_schedule"] = not any(
        inside[cell_id(cell, "QRRT")] for cell in design_cells(settings, "QRRT") if cell["iterations"] == SCHEDULE)
    for cell in design_cells(settings, "QRRT"):
        q, r = cell_id(cell, "QRRT"), cell_id(cell, "RRT")
        out[f"qrrt_ahead_of_rrt/{q}"] = bool(q_spans[q][0] > r_spans[r][1])  # NaN compares False
    return out


def per_fifty(runs: Sequence[int]) -> float:
    """Channel nodes per 50 runs: ``PAPER_TRIALS`` times the mean of ``runs`` (per-run counts)."""
    return PAPER_TRIALS * sum(runs) / len(runs)


class CorridorWorlds(Experiment):
    """The corridor's decisive cells over clutter draws (beyond paper Figs. 13-14): module docstring.

    ``trials`` (``--trials``) is the number of draws (worlds); ``blocks`` blocks of ``block_size``
    runs per draw and cell. The summary gives, per cell and planner, the mean channel nodes per 50
    runs over worlds with its two-level interval (``ours``, ``interval_95``), the range of the
    per-draw means (``range_over_draws``), each draw's mean and interval (``per_draw``,
    ``per_draw_interval_95``), and how many draws hold each claim (``claims_over_worlds``).
    """

    name = "corridor-worlds"
    title = "Narrow corridor: the decisive cells of the factorial over clutter draws"
    paper = PAPER

    def settings(self, quick: bool, trials: int | None, seed: int) -> Settings:
        return {"draws": trials or (2 if quick else 20), "first_world_seed": FIRST_WORLD_SEED,
                "blocks": 1 if quick else 8, "block_size": 10 if quick else PAPER_TRIALS, "budget": 25,
                "num_qubits": 8, "mouth_clearance": 1.5, "backend": "statevector", "scenario": "narrow_corridor",
                "centres": CENTRES, "factors": QUICK_FACTORS if quick else FACTORS, "seed": seed, "quick": quick}

    def trials(self, settings: Settings) -> list[Trial]:
        out = []
        for world_seed in world_seeds(settings):
            for planner in PLANNERS:
                for cell in design_cells(settings, planner):
                    for block in range(settings["blocks"]):
                        first = RUN_STRIDE * world_seed + block * settings["block_size"]
                        out.append(Trial(f"{planner}-{cell_id(cell, planner)}-s{world_seed}-b{block}",
                                         {"planner": planner, "iterations": NO_ITERATIONS, **cell,
                                          "world_seed": world_seed, "block": block},
                                         replicate_seed(settings["seed"], first, TrialStream.CORRIDOR_WORLDS)))
        return out

    def run_trial(self, trial: Trial, settings: Settings) -> Record:
        first = RUN_STRIDE * trial.params["world_seed"] + trial.params["block"] * settings["block_size"]
        seeds = [replicate_seed(settings["seed"], first + run, TrialStream.CORRIDOR_WORLDS)
                 for run in range(settings["block_size"])]
        return run_block(trial.params, settings, trial.params["world_seed"], seeds)

    def summarize(self, records: list[Record], settings: Settings) -> Summary:
        seed, seeds = settings["seed"], world_seeds(settings)
        runs: dict[str, dict[str, dict[int, list[int]]]] = {kind: {} for kind in PLANNERS}
        for r in records:
            by_world = runs[r["planner"]].setdefault(cell_id(r, r["planner"]), {})
            by_world.setdefault(int(r["world_seed"]), []).extend(loads(r["in_channel_json"]))
        ours: dict[str, dict[str, float]] = {kind: {} for kind in PLANNERS}
        interval: dict[str, dict[str, list[float]]] = {kind: {} for kind in PLANNERS}
        spread: dict[str, dict[str, list[float]]] = {kind: {} for kind in PLANNERS}
        per_draw: dict[str, dict[str, dict[str, float]]] = {kind: {} for kind in PLANNERS}
        per_draw_interval: dict[str, dict[str, dict[str, list[float]]]] = {kind: {} for kind in PLANNERS}
        for kind in PLANNERS:
            for cell in design_cells(settings, kind):
                key = cell_id(cell, kind)
                groups = {w: counts for w, counts in runs[kind].get(key, {}).items() if counts}
                pooled = [n for counts in groups.values() for n in counts]
                ours[kind][key] = round(per_fifty(pooled), 2) if pooled else float("nan")
                interval[kind][key] = rounded_interval(two_level_bootstrap_interval(groups, per_fifty, seed), 2)
                per_draw[kind][key] = {str(w): round(per_fifty(groups[w]), 2) for w in seeds if w in groups}
                per_draw_interval[kind][key] = {
                    str(w): rounded_interval(bootstrap_ratio_interval(groups[w], None, seed,
                                                                      per_trials=PAPER_TRIALS), 2)
                    for w in seeds if w in groups}
                means = list(per_draw[kind][key].values())
                spread[kind][key] = [min(means), max(means)] if means else [float("nan"), float("nan")]
        per_claim: dict[str, list[int]] = {}
        for w in seeds:
            held = claims({q: spans.get(str(w), [float("nan")] * 2) for q, spans in per_draw_interval["QRRT"].items()},
                          {r: spans.get(str(w), [float("nan")] * 2) for r, spans in per_draw_interval["RRT"].items()},
                          settings)
            for claim, holds in held.items():
                per_claim.setdefault(claim, [])
                if holds:
                    per_claim[claim].append(w)
        drawn = len({w for kind in PLANNERS for by_world in runs[kind].values() for w in by_world})
        over_worlds = {claim: {"holds_in": len(held_in), "draws": drawn, "world_seeds": held_in}
                       for claim, held_in in per_claim.items()}
        return {"ours": ours, "paper": PAPER, "interval_95": interval,
                "differs_from_paper": {kind: {key: differs(PAPER[kind], span) for key, span in interval[kind].items()}
                                       for kind in PLANNERS},
                "range_over_draws": spread, "per_draw": per_draw, "per_draw_interval_95": per_draw_interval,
                "claims_over_worlds": over_worlds,
                "claims_for_the_setting": claims(interval["QRRT"], interval["RRT"], settings),
                "design": {"geometries": len(design_cells(settings, "RRT")),
                           "qrrt_cells": len(design_cells(settings, "QRRT")),
                           "rrt_cells": len(design_cells(settings, "RRT")), "draws": drawn, "world_seeds": seeds,
                           "runs_per_draw_and_cell": settings["blocks"] * settings["block_size"]},
                "note": f"mean nodes inside the channel per {PAPER_TRIALS} runs, each cut at {settings['budget']} "
                        "oracle calls. ours and interval_95: over every draw's runs, the interval a two-level "
                        "bootstrap over draws (worlds), then runs in each; range_over_draws: the least and greatest "
                        "per-draw mean (a range, not an interval); per_draw_interval_95: a bootstrap over one draw's "
                        "runs. claims_over_worlds: the draws in which each claim holds by its per-draw intervals; "
                        "claims_for_the_setting: the same rules on the intervals over worlds",
                "labels": ["phase oracle from a classical lookup of all 2^n entries",
                           "backend: exact statevector (ideal; same statistics as Aer)"]}

    def plot(self, records: list[Record], settings: Settings, summary: Summary, out_dir: Path) -> list[Path]:
        levels = settings["factors"]["iterations"]
        shapes = design_cells(settings, "RRT")
        fig, axes = new_figure(1, len(levels), (5.0 * len(levels), 4.8))
        colors = ("black", "tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown", "tab:pink")
        highs = {kind: [span[1] for block in ("range_over_draws", "interval_95")
                        for span in summary[block][kind].values()] for kind in PLANNERS}
        top, right = (max([PAPER[kind], *highs[kind]]) * 1.05 for kind in ("QRRT", "RRT"))
        for ax, level in zip(axes[0], levels, strict=True):
            for shape, color in zip(shapes, colors * len(shapes), strict=False):
                r, q = cell_id(shape, "RRT"), cell_id({**shape, "iterations": level}, "QRRT")
                drawn = summary["per_draw"]["QRRT"][q]
                ax.plot([summary["per_draw"]["RRT"][r][w] for w in drawn], list(drawn.values()), ".", color=color,
                        alpha=0.45, ms=5)
                x, y = summary["ours"]["RRT"][r], summary["ours"]["QRRT"][q]
                (xl, xh), (yl, yh) = summary["interval_95"]["RRT"][r], summary["interval_95"]["QRRT"][q]
                ax.errorbar([x], [y], xerr=[[x - xl], [xh - x]], yerr=[[y - yl], [yh - y]], fmt="o", color=color,
                            mec="white", ms=7, lw=1.4, label=_label(shape, settings["centres"]))
            ax.plot([PAPER["RRT"]], [PAPER["QRRT"]], "*", color="gold", mec="black", ms=15, label="paper (14, 47)")
            ax.plot([0, max(top, right)], [0, max(top, right)], ":", color="gray", lw=1, label="q-RRT = RRT")
            pair_axes(ax, right, top, f"q-RRT iterations: {level} ({summary['design']['draws']} draws)")
        return [save(fig, out_dir / "corridor_worlds.png")]


def _label(shape: dict[str, Any], centres: Sequence[dict[str, Any]]) -> str:
    """A geometry's legend label: the centre's id, or the factor in which it differs from a centre."""
    for centre in centres:
        changed = [name for name in GEOMETRY if shape[name] != centre[name]]
        if not changed:
            return f"{cell_id(centre, 'RRT')} (dots: draws; bars: over draws)"
        if len(changed) == 1:
            return f"{changed[0]} {shape[changed[0]]}"
    return cell_id(shape, "RRT")
