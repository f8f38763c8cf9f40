"""Paper Figs. 13-14: narrow corridor. 50 trials per planner cut at 25 oracle calls in
narrow_corridor (a channel 0.4 wide and 4 long); nodes inside the channel, nodes through it, and
node heatmaps."""

from __future__ import annotations

from pathlib import Path

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
from .figures import new_figure, node_heatmap, save
from .intervals import bootstrap_interval, differs, rounded_interval
from .measures import cut_at, dumps, loads, reachable_fraction, rounded
from .planners import experiment_problem, make_planner
from .worlds import world

PLANNERS = ("RRT", "QRRT")


def in_channel(points: np.ndarray, channel: tuple[tuple[float, float], tuple[float, float]]) -> np.ndarray:
    """Which points lie in the closed channel rectangle.

    Args:
        points: (N, >=2) positions.
        channel: ``((x0, y0), (x1, y1))``, the rectangle's lower-left and upper-right corners.

    Returns:
        (N,) booleans.
    """
    (x0, y0), (x1, y1) = channel
    return (points[:, 0] >= x0) & (points[:, 0] <= x1) & (points[:, 1] >= y0) & (points[:, 1] <= y1)


class Corridor(Experiment):
    """Narrow corridor (paper §V.C, Figs. 13-14): RRT and q-RRT cut at 25 oracle calls.

    A trial grows one tree in ``narrow_corridor`` and records the nodes inside the 0.4 x 4 channel
    and beyond its far mouth; the summary sums both over the trials (paper: 47 for q-RRT, 14 for
    RRT inside the channel over 50 trials), each with a 95 % bootstrap interval over trials, and the
    figure shows node heatmaps.
    """

    name = "corridor"
    title = "Narrow corridor at 25 oracle calls (paper Figs. 13-14)"
    paper = {"QRRT": 47, "RRT": 14}

    def settings(self, quick: bool, trials: int | None, seed: int) -> Settings:
        return {"trials": trials or (10 if quick else 50), "budget": 25, "num_qubits": 8,
                "backend": "aer", "schedule": "paper", "scenario": "narrow_corridor", "world_seed": 0,
                "seed": seed, "quick": quick}

    def trials(self, settings: Settings) -> list[Trial]:
        return [Trial(f"{kind}-{i}", {"planner": kind, "replicate": i},
                      replicate_seed(settings["seed"], i, TrialStream.CORRIDOR))
                for kind in PLANNERS for i in range(settings["trials"])]

    def run_trial(self, trial: Trial, settings: Settings) -> Record:
        problem = experiment_problem(settings, world(settings["scenario"], settings["world_seed"]))
        env = problem.env
        planner = make_planner(trial.params["planner"], trial.seed, settings["backend"],
                               num_qubits=settings["num_qubits"])
        result = planner.plan(problem, max_oracle_calls=settings["budget"])
        nodes, calls = cut_at(result, settings["budget"])
        positions = result.nodes[1 : nodes + 1]
        channel = env.metadata["channel"]
        return {"reachable_fraction": reachable_fraction(result),
                "nodes": nodes, "oracle_calls": calls,
                "in_channel": int(in_channel(positions, channel).sum()),
                "through_channel": int((positions[:, 0] > channel[1][0]).sum()),
                "positions_json": dumps(rounded(positions))}

    def summarize(self, records: list[Record], settings: Settings) -> Summary:
        ours = {kind: sum(r["in_channel"] for r in records if r["planner"] == kind) for kind in PLANNERS}
        interval = {kind: rounded_interval(bootstrap_interval(
            [r for r in records if r["planner"] == kind], lambda rows: sum(r["in_channel"] for r in rows),
            settings["seed"]), 1) for kind in PLANNERS}
        return {"ours": ours, "paper": self.paper, "interval_95": interval,
                "differs_from_paper": {kind: differs(self.paper[kind], interval[kind]) for kind in PLANNERS},
                "through_channel": {k: sum(r["through_channel"] for r in records if r["planner"] == k)
                                    for k in PLANNERS},
                "through_channel_interval_95": {k: rounded_interval(bootstrap_interval(
                    [r for r in records if r["planner"] == k], lambda rows: sum(r["through_channel"] for r in rows),
                    settings["seed"]), 1) for k in PLANNERS},
                "nodes": {k: sum(r["nodes"] for r in records if r["planner"] == k) for k in PLANNERS},
                "mean_reachable_fraction": {
                    k: round(float(np.mean([r["reachable_fraction"] for r in records if r["planner"] == k])), 4)
                    for k in PLANNERS},
                "note": "nodes inside the channel rectangle, summed over the trials; through_channel: nodes "
                        "beyond its far mouth, summed over the trials, with a 95 % bootstrap interval "
                        "(through_channel_interval_95); reachable_fraction is the share of candidates (RRT tests, "
                        "q-RRT database entries) that were reachable"}

    def paper_comparison(self, summary: Summary) -> PaperComparison:
        numbers = tuple(PaperNumber(kind, summary["ours"][kind], tuple(summary["interval_95"][kind]),
                                    summary["paper"][kind]) for kind in PLANNERS)
        return PaperComparison(self.title, f"nodes in the channel, summed over {summary['settings']['trials']} trials",
                               numbers)

    def plot(self, records: list[Record], settings: Settings, summary: Summary, out_dir: Path) -> list[Path]:
        problem = world(settings["scenario"], settings["world_seed"])
        fig, axes = new_figure(1, len(PLANNERS), (5.2 * len(PLANNERS), 4.6))
        for col, kind in enumerate(PLANNERS):
            clouds = [np.array(loads(r["positions_json"])).reshape(-1, 2) for r in records if r["planner"] == kind]
            points = np.concatenate(clouds) if clouds else np.zeros((0, 2))
            node_heatmap(axes[0, col], problem, points,
                         f"{kind}: {summary['ours'][kind]} nodes in the channel "
                         f"{summary['interval_95'][kind]} (paper {self.paper[kind]})")
        return [save(fig, out_dir / "corridor.png")]
