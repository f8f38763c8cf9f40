"""Paper Figs. 15-17 against the annealing world's density, and the readings of Alg. 4, line 7.

The paper fixes 6025 obstacles but not the square they lie on; ``annealing_field``'s side (about
67.75, ``paper_clutter``'s box density) is our assumption (DESIGN §4). Here the 6025 boxes lie on
squares of side 67.75 / sqrt(x), x the box density relative to that default, and 16-node trees of
uniform q-RRT and of QDA (``annealing``'s setup: 2^9 databases, 2 Grover iterations, the hot band
[2.7, 4.2] for all 16 nodes) give the mean distance from a node to its parent at each density.

At the default density QDA also runs under each reading of Alg. 4, line 7 that the paper's text
allows (``AnnealingSchedule``'s ``placement``, stated there with the text each reads, and
``counter``):

- ``band, nodes``: the distance drawn uniformly in the band, h counting nodes (``annealing``'s);
- ``band, databases``: h counting databases (Alg. 4's h++ per loop) with the switch at 16
  databases: a database whose measured entry fails verification still advances h, so the cold band
  [0.8, 2.0] can take over before the 16th node;
- ``clamp, nodes``: the sample projected onto the band (only samples outside it move);
- ``annulus, nodes``: the distance of a point uniform over the annulus (density proportional to r);
- ``admit, nodes``: samples admitted only if their distance to the nearest node lies in the band.

Acceptance rules, fixed before the run (the paper's numbers are never used to choose a setting):
the paper's value is *inside our mean* where it lies in the 95 % bootstrap interval (over trees)
of the mean of ``trials`` trees, the like-for-like comparison if the paper's number averages many
trees; it is *plausible for one tree* where it lies in the 2.5-97.5 % range of single trees' means,
the like-for-like comparison if it is the mean of the one tree each of Figs. 15-17 shows. The text
does not say which; the figures show one tree each.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..planners.database import AnnealingSchedule
from ..problems.scenarios import CLUTTER_BOXES, CLUTTER_SIZE
from ..search.policies.schedules import FixedIterations
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
from .figures import new_figure, save, with_intervals
from .intervals import bootstrap_interval, differs, rounded_interval
from .measures import dumps, loads, rounded
from .planners import experiment_problem, make_planner
from .worlds import world

#: the box density of each point, relative to ``annealing_field``'s default
DENSITIES = (0.25, 0.5, 0.75, 1.0, 1.25, 1.5)
#: QDA's readings of Alg. 4, line 7 run at the default density: (placement, counter)
READINGS = (("band", "nodes"), ("band", "databases"), ("clamp", "nodes"), ("annulus", "nodes"),
            ("admit", "nodes"))
#: the paper's boxes (§V.D)
BOXES = 6025
#: ``annealing_field``'s default side (``paper_clutter``'s box density)
DEFAULT_SIDE = CLUTTER_SIZE * float(np.sqrt(BOXES / CLUTTER_BOXES))
#: the trees' size (the paper's Figs. 15 and 17: 16-node trees)
TREE_NODES = 16
#: a distance this close to a band edge counts as on it (the records round distances to 1e-3)
EDGE_TOLERANCE = 2e-3
#: the summary's key of the readings
READINGS_KEY = "QDA_readings"
RATIO_KEY = "ratio_qda_over_uniform"


def side(density: float) -> float:
    """The square's side that puts 6025 boxes at ``density`` times the default box density.

    Args:
        density: x > 0.

    Returns:
        67.75 / sqrt(x).
    """
    return DEFAULT_SIDE / float(np.sqrt(density))


def reading_label(placement: str, counter: str) -> str:
    """A reading's key in the summary: ``"placement, counter"``."""
    return f"{placement}, {counter}"


def _complete(rows: Sequence[Record]) -> list[Record]:
    """The rows whose tree reached ``TREE_NODES`` nodes (a tree stopped by ``max_rounds`` or at the
    goal before that has no 16-node mean to compare)."""
    return [r for r in rows if r["nodes"] >= TREE_NODES]


def _mean(rows: Sequence[Record]) -> float:
    """The mean over the complete trees of ``rows`` of their mean distance to the parent."""
    values = [r["mean_parent_distance_16"] for r in _complete(rows)]
    if not values:
        raise ValueError("no complete tree")
    return float(np.mean(values))


class AnnealingDensity(Experiment):
    """Mean distance to the parent of uniform q-RRT and QDA against the annealing world's density,
    and QDA under each reading of Alg. 4, line 7 (paper Figs. 15-17; the setup and acceptance rules
    are in the module docstring).

    A trial grows one 16-node tree in one world; the trees of a replicate share its world seed and
    planner seed (the worlds of one replicate at different densities draw the same numbers, scaled).
    """

    name = "annealing-density"
    title = "QDA and uniform q-RRT parent distance against the world's density (paper Figs. 15-17)"
    paper = {"QRRT": 1.70, "QDA": 3.68, READINGS_KEY: 3.68, RATIO_KEY: round(3.68 / 1.70, 2)}

    def settings(self, quick: bool, trials: int | None, seed: int) -> Settings:
        return {"trials": trials or (2 if quick else 20),
                "densities": [0.5, 1.0] if quick else list(DENSITIES),
                "readings": [list(r) for r in (READINGS[:1] + READINGS[2:3] + READINGS[4:] if quick else READINGS)],
                "num_boxes": BOXES, "num_qubits": 9, "iterations": 2, "bands": [[2.7, 4.2], [0.8, 2.0]],
                "switch_at": 16, "size": TREE_NODES, "max_rounds": 20000, "backend": "aer",
                "scenario": "annealing_field", "seed": seed, "quick": quick}

    def trials(self, settings: Settings) -> list[Trial]:
        """Per replicate: uniform q-RRT and QDA (``band, nodes``) at every density, then QDA's other
        readings at density 1."""
        variants: list[tuple[str, dict[str, Any]]] = []
        for density in settings["densities"]:
            variants.append((f"QRRT-d{density}", {"method": "QRRT", "density": density,
                                                  "placement": "uniform", "counter": "none"}))
            variants.append((f"QDA-band-nodes-d{density}", {"method": "QDA", "density": density,
                                                            "placement": "band", "counter": "nodes"}))
        for placement, counter in settings["readings"]:
            if (placement, counter) != ("band", "nodes") and 1.0 in settings["densities"]:
                variants.append((f"QDA-{placement}-{counter}-d1.0", {"method": "QDA", "density": 1.0,
                                                                    "placement": placement, "counter": counter}))
        trials = []
        for replicate in range(settings["trials"]):
            world_seed = replicate_seed(settings["seed"], replicate, TrialStream.ANNEALING_DENSITY_WORLDS)
            seed = replicate_seed(settings["seed"], replicate, TrialStream.ANNEALING_DENSITY_PLANNERS)
            for label, params in variants:
                trials.append(Trial(f"{label}-{replicate}",
                                    {**params, "replicate": replicate, "world_seed": world_seed}, seed))
        return trials

    def run_trial(self, trial: Trial, settings: Settings) -> Record:
        params = trial.params
        problem = experiment_problem(settings, world(settings["scenario"], params["world_seed"],
                                                     num_boxes=settings["num_boxes"], side=side(params["density"])))
        env = problem.env
        annealing = None
        if params["method"] == "QDA":
            annealing = AnnealingSchedule(bands=tuple((low, high) for low, high in settings["bands"]),
                                          switch_at=(settings["switch_at"],), counter=params["counter"],
                                          placement=params["placement"])
        planner = make_planner("QRRT", trial.seed, settings["backend"],
                              num_qubits=settings["num_qubits"],
                              search_policy=FixedIterations(settings["iterations"]), annealing=annealing)
        result = planner.plan(problem, max_nodes=settings["size"], max_rounds=settings["max_rounds"])
        distances = np.linalg.norm(result.nodes[1:] - result.nodes[result.parents[1:]], axis=1)[: settings["size"]]
        return {"status": result.status, "nodes": result.metrics.nodes, "rounds": result.metrics.rounds,
                "oracle_calls": result.metrics.oracle_calls, "free_fraction": env.free_fraction(),
                "mean_parent_distance_16": float(distances.mean()) if distances.size else float("nan"),
                "parent_distances_json": dumps(rounded(distances))}

    def summarize(self, records: list[Record], settings: Settings) -> Summary:
        seed = settings["seed"]
        groups: dict[tuple[str, ...], list[Record]] = {}
        for density in settings["densities"]:
            key = str(float(density))
            groups[("QRRT", key)] = [r for r in records if r["method"] == "QRRT" and r["density"] == density]
            groups[("QDA", key)] = [r for r in records if r["method"] == "QDA" and r["density"] == density
                                    and (r["placement"], r["counter"]) == ("band", "nodes")]
        if 1.0 in settings["densities"]:
            for placement, counter in settings["readings"]:
                groups[(READINGS_KEY, reading_label(placement, counter))] = [
                    r for r in records if r["method"] == "QDA" and r["density"] == 1.0
                    and (r["placement"], r["counter"]) == (placement, counter)]
        ours: dict[str, dict[str, Any]] = {"QRRT": {}, "QDA": {}, READINGS_KEY: {}, RATIO_KEY: {}}
        interval: dict[str, dict[str, Any]] = {key: {} for key in ours}
        spread: dict[str, dict[str, Any]] = {key: {} for key in ours if key != RATIO_KEY}
        incomplete: dict[str, dict[str, int]] = {}
        for (head, key), rows in groups.items():
            trees = [r["mean_parent_distance_16"] for r in _complete(rows)]
            incomplete.setdefault(head, {})[key] = len(rows) - len(trees)
            if not trees:  # no tree reached 16 nodes: nothing to compare
                ours[head][key], interval[head][key], spread[head][key] = None, [None, None], [None, None]
                continue
            ours[head][key] = round(_mean(rows), 3)
            interval[head][key] = rounded_interval(bootstrap_interval(rows, _mean, seed), 3)
            spread[head][key] = [round(float(v), 3) for v in np.percentile(trees, [2.5, 97.5])]
        for density in settings["densities"]:
            key = str(float(density))
            uniform = {r["replicate"]: r for r in groups[("QRRT", key)]}
            pairs = [(r, uniform[r["replicate"]]) for r in groups[("QDA", key)]]
            if ours["QDA"][key] is None or ours["QRRT"][key] is None:
                ours[RATIO_KEY][key], interval[RATIO_KEY][key] = None, [None, None]
                continue
            ours[RATIO_KEY][key] = round(ours["QDA"][key] / ours["QRRT"][key], 2)
            interval[RATIO_KEY][key] = rounded_interval(bootstrap_interval(pairs, _ratio, seed), 2)
        if not ours[READINGS_KEY]:
            del ours[READINGS_KEY], interval[READINGS_KEY], spread[READINGS_KEY]
        differs_from_paper = {head: {key: None if span[0] is None else differs(self.paper[head], span)
                                     for key, span in spans.items()} for head, spans in interval.items()}
        plausible = {head: {key: None if span[0] is None else bool(span[0] <= self.paper[head] <= span[1])
                            for key, span in spans.items()} for head, spans in spread.items()}
        free = {str(float(d)): round(float(np.mean([r["free_fraction"] for r in records if r["density"] == d])), 3)
                for d in settings["densities"]}
        where = {method: {"inside_our_mean_at": [d for d, out in differs_from_paper[method].items() if out is False],
                          "plausible_for_one_tree_at": [d for d, ok in plausible[method].items() if ok],
                          "our_mean_crosses_paper_between": _crossing(ours[method], self.paper[method])}
                 for method in ("QRRT", "QDA")}
        summary: Summary = {
            "ours": ours, "paper": self.paper, "interval_95": interval, "differs_from_paper": differs_from_paper,
            "paper_design": {
                "range_95": spread, "paper_plausible": plausible, "trees": 1, "resamples": settings["trials"],
                "meaning": "one 16-node tree's mean distance to the parent (each of Figs. 15-17 shows one tree): "
                           "the 2.5-97.5 % range of our single trees' means at each point"},
            "where_paper_falls": where,
            "incomplete_trees": incomplete,
            "free_fraction": free,
            "side": {str(float(d)): round(side(d), 2) for d in settings["densities"]},
            "note": "density: 6025 boxes on a square of side 67.75 / sqrt(density) (1 is annealing_field's "
                    "default); mean distance from node to parent over the first 16 nodes, over the trees that "
                    "reach 16 nodes in max_rounds databases (incomplete_trees: those that do not, left out)"}
        if READINGS_KEY in ours:
            summary["readings_reaching_paper"] = {
                "inside_our_mean": [k for k, out in differs_from_paper[READINGS_KEY].items() if out is False],
                "plausible_for_one_tree": [k for k, ok in plausible[READINGS_KEY].items() if ok]}
            low, high = settings["bands"][0]
            summary["nodes_at_band_edges"] = {
                key: _at_edges([r for r in _complete(groups[(READINGS_KEY, key)])], low, high)
                for key in ours[READINGS_KEY]}
        return summary

    def paper_comparison(self, summary: Summary) -> PaperComparison:
        """The default density's uniform q-RRT and QDA, and QDA's other readings of Alg. 4, line 7."""
        ours, interval = summary["ours"], summary["interval_95"]
        numbers = []
        default = "1.0" if "1.0" in ours["QRRT"] else next(iter(ours["QRRT"]))
        numbers.append(PaperNumber(f"uniform q-RRT, density {default}", ours["QRRT"][default],
                                   tuple(interval["QRRT"][default]), summary["paper"]["QRRT"]))
        for key, value in ours.get(READINGS_KEY, {"band, nodes": None}).items():
            if value is None:
                value, span = ours["QDA"][default], interval["QDA"][default]
            else:
                span = interval[READINGS_KEY][key]
            numbers.append(PaperNumber(f"QDA {key}", value, tuple(span), summary["paper"]["QDA"]))
        return PaperComparison(self.title, "mean distance to parent, first 16 nodes", tuple(numbers))

    def plot(self, records: list[Record], settings: Settings, summary: Summary, out_dir: Path) -> list[Path]:
        """Left: each method's mean (95 % interval) and single-tree range against the density, with
        the paper's numbers; right: QDA's readings at the default density."""
        ours, interval, spread = summary["ours"], summary["interval_95"], summary["paper_design"]["range_95"]
        readings = ours.get(READINGS_KEY, {})
        fig, axes = new_figure(1, 2 if readings else 1, (13.0 if readings else 6.5, 4.8))
        ax = axes[0, 0]
        colors = {"QDA": "tab:red", "QRRT": "tab:blue"}
        labels = {"QDA": "QDA (band, nodes)", "QRRT": "uniform q-RRT"}
        for method in ("QRRT", "QDA"):
            keys = [k for k, v in ours[method].items() if v is not None]
            x = np.array([float(k) for k in keys])
            ranges = np.array([spread[method][k] for k in keys])
            ax.fill_between(x, ranges[:, 0], ranges[:, 1], color=colors[method], alpha=0.15,
                            label=f"{labels[method]}: single trees, 2.5-97.5 %")
            with_intervals(ax, x, [ours[method][k] for k in keys], [interval[method][k] for k in keys],
                           color=colors[method], fmt="o-", ms=4,
                           label=f"{labels[method]}: mean of {settings['trials']} trees, 95 % interval")
            ax.axhline(self.paper[method], color=colors[method], ls="--", lw=1.2,
                       label=f"paper, {labels[method].split(' (')[0]}: {self.paper[method]}")
        ax.set_xlabel("box density / annealing_field's default (6025 boxes, side 67.75 / sqrt(x))")
        ax.set_ylabel("mean distance to parent, first 16 nodes")
        ax.set_title("Parent distance against the world's density", fontsize=10)
        ax.legend(fontsize=7, loc="upper right")
        ax.grid(alpha=0.3)
        if readings:
            ax = axes[0, 1]
            keys = [k for k, v in readings.items() if v is not None]
            x = np.arange(len(keys))
            ranges = np.array([spread[READINGS_KEY][k] for k in keys])
            ax.vlines(x, ranges[:, 0], ranges[:, 1], color="tab:red", alpha=0.35, lw=6,
                      label="single trees, 2.5-97.5 %")
            with_intervals(ax, x, [readings[k] for k in keys], [interval[READINGS_KEY][k] for k in keys],
                           color="tab:red", fmt="o", ms=5, label=f"mean of {settings['trials']} trees, 95 % interval")
            low, high = settings["bands"][0]
            ax.axhspan(low, high, color="0.85", zorder=0, label=f"hot band [{low}, {high}]")
            ax.axhline(self.paper["QDA"], color="black", ls="--", lw=1.2, label=f"paper: {self.paper['QDA']}")
            ax.set_xticks(x, [k.replace(", ", "\n") for k in keys])
            ax.set_ylabel("QDA mean distance to parent, first 16 nodes")
            ax.set_title("QDA under the readings of Alg. 4, line 7 (default density)", fontsize=10)
            ax.legend(fontsize=7, loc="lower right")
            ax.grid(alpha=0.3, axis="y")
        return [save(fig, out_dir / "annealing-density.png")]


def _ratio(pairs: Sequence[tuple[Record, Record]]) -> float:
    """mean(QDA) / mean(uniform q-RRT) over paired (QDA, uniform) trees of one density (each mean
    over its complete trees)."""
    return _mean([qda for qda, _ in pairs]) / _mean([uniform for _, uniform in pairs])


def _at_edges(rows: Sequence[Record], low: float, high: float) -> dict[str, float | None]:
    """The fractions of the trees' nodes whose distance to the parent is the band's r_min or r_max
    (within the records' rounding to 1e-3), over all nodes of ``rows``."""
    distances = np.concatenate([np.asarray(loads(r["parent_distances_json"]), dtype=float) for r in rows]
                               or [np.zeros(0)])
    if not distances.size:
        return {"r_min": None, "r_max": None}
    return {"r_min": round(float(np.mean(np.abs(distances - low) <= EDGE_TOLERANCE)), 3),
            "r_max": round(float(np.mean(np.abs(distances - high) <= EDGE_TOLERANCE)), 3)}


def _crossing(means: dict[str, float | None], paper: float) -> list[float] | None:
    """The first pair of neighbouring densities between which our means pass the paper's value
    (``[low, high]``), or None if they stay on one side over the grid."""
    points = sorted((float(k), v) for k, v in means.items() if v is not None)
    for (d0, m0), (d1, m1) in zip(points, points[1:], strict=False):
        if (m0 - paper) * (m1 - paper) <= 0:
            return [d0, d1]
    return None


__all__ = ["READINGS", "AnnealingDensity", "side"]
