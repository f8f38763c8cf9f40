"""The single-world heatmap design: the round the paper's totals imply, the acceptance rule per planner
root seed, and the pooled values with their interval over worlds."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from qrrt_circuits.experiments import read_records, run_experiment
from qrrt_circuits.experiments.heatmap_worlds import (
    PAPER,
    HeatmapWorlds,
    _advantage,
    calls_per_trial,
    most_nodes,
    pass_overlap,
    passes,
    peak_fraction,
    round_costs,
)
from qrrt_circuits.experiments.measures import cut_at, dumps, reachable_at


def test_a_run_cut_at_b_calls_makes_whole_rounds():
    assert [calls_per_trial(3, b) for b in (10, 20, 40)] == [12, 21, 42]
    assert [calls_per_trial(6, b) for b in (10, 20, 40)] == [12, 24, 42]  # the paper's 5 + 1 round
    assert calls_per_trial(1, 7) == 7 and calls_per_trial(4, 8) == 8


def test_the_paper_totals_fit_only_a_three_call_round():
    costs = round_costs(PAPER["QRRT"])
    assert costs["fitting"] == [3]
    assert costs["paper_calls_per_trial"] == {"10": 11.923, "20": 20.968, "40": 41.962}
    # a total of exactly 24 calls a trial at the 20-call cut would fit the paper's 6-call round instead
    six = {"10": {"nodes": 12, "efficiency": 0.01}, "20": {"nodes": 24, "efficiency": 0.01},
           "40": {"nodes": 42, "efficiency": 0.01}}
    assert 6 in round_costs(six)["fitting"] and 3 not in round_costs(six)["fitting"]


def test_a_world_passes_only_with_every_paper_efficiency_inside():
    inside = {"10": [0.10, 0.15], "20": [0.10, 0.12], "40": [0.12, 0.14]}
    assert passes(inside, PAPER["RRT"])
    assert not passes(inside | {"20": [0.117, 0.13]}, PAPER["RRT"])  # 0.116 just below
    assert passes(inside | {"40": [0.132, 0.132]}, PAPER["RRT"])  # closed interval


def test_the_paper_schedule_cannot_place_the_paper_nodes():
    costs = round_costs(PAPER["QRRT"])
    assert costs["calls_per_trial_by_round"] == {"3": {"10": 12, "20": 21, "40": 42},
                                                 "6": {"10": 12, "20": 24, "40": 42}}
    assert costs["paper_schedule_most_nodes"] == {"10": 200, "20": 400, "40": 700}
    assert all(costs["paper_schedule_most_nodes"][cut] < PAPER["QRRT"][cut]["nodes"] for cut in PAPER["QRRT"])
    assert [most_nodes(3, b) for b in (10, 20, 40)] == [400, 700, 1400]  # the 3-call round can


def test_the_peak_reachable_share_makes_the_search_certain():
    for k in (1, 2, 3, 5):
        theta = math.asin(math.sqrt(peak_fraction(k)))
        assert math.sin((2 * k + 1) * theta) ** 2 == pytest.approx(1.0)
    assert peak_fraction(2) == pytest.approx(0.0955, abs=1e-4) and peak_fraction(5) == pytest.approx(0.0203, abs=1e-4)


def test_reachable_at_sums_the_rounds_cut_at_reads():
    history = {"oracle_calls": np.array([3, 6, 9, 12, 15]), "nodes": np.array([2, 2, 3, 4, 5]),
               "reachable": np.array([10, 20, 30, 40, 50]), "entries": np.array([256] * 5)}
    result = SimpleNamespace(history=history)
    assert cut_at(result, 10) == (4, 12) and reachable_at(result, 10) == (100, 1024)
    assert reachable_at(result, 99) == (150, 1280)  # no round reaches the cut: every round
    empty = SimpleNamespace(history={key: np.array([], dtype=int) for key in history})
    assert reachable_at(empty, 10) == (0, 0)


def test_the_advantage_over_worlds():
    advantage = _advantage([0.1, 0.0, 0.3, 0.05], [0.3, 0.2, 0.1, 0.25])
    assert advantage["worlds_rrt_added_none"] == 1 and advantage["worlds_quantum_below_rrt"] == 1
    assert advantage["difference"][1] == pytest.approx(0.2)  # median of 0.2, 0.2, -0.2, 0.2
    assert advantage["ratio"][1] == pytest.approx(3.0)  # median of 3, 1/3, 5 (RRT's zero left out)


def test_pass_overlap_counts_the_worlds_passing_again():
    overlap = pass_overlap({"0": ["a", "b", "c"], "1": ["b", "c", "d"], "2": []})
    assert overlap["pairs"]["0->1"] == {"passing": 3, "pass_again": 2}
    assert overlap["pairs"]["1->2"] == {"passing": 3, "pass_again": 0}
    assert overlap["pairs"]["2->0"] == {"passing": 0, "pass_again": 0}
    assert overlap["fraction_passing_again"] == round(4 / 12, 4)  # (2 + 0 + 2 + 0) of (3 + 3 + 3 + 3)
    assert overlap["in_every_root_seed"] == [] and overlap["in_any_root_seed"] == ["a", "b", "c", "d"]
    assert pass_overlap({"0": []})["fraction_passing_again"] is None


def _synthetic_records(settings, passing):
    """Records whose RRT runs straddle the paper's efficiencies in the (world, root seed) blocks of
    ``passing`` and place nothing elsewhere; q-RRT places 13.5 nodes a run at 40 calls in the even
    worlds, 12.5 in the odd ones."""
    calls = {"10": 12, "20": 21, "40": 42}
    straddle = {"10": 3, "20": 5, "40": 11}  # alternating 0 and these: efficiency 0.125, 0.119, 0.131
    records = []
    for trial in HeatmapWorlds().trials(settings):
        key = (f"{trial.params['boxes']}-{trial.params['world_seed']}", trial.params["planner_root_seed"])
        runs = range(settings["runs"])
        if trial.params["variant"] == "RRT":
            nodes = {c: [straddle[c] * (r % 2) if key in passing else 0 for r in runs] for c in calls}
        else:
            nodes = {c: [calls[c] // 3 - trial.params["world_seed"] % 2 - r % 2 for r in runs] for c in calls}
        records.append({**trial.params, "trial_id": trial.id, "seed": trial.seed,
                        "nodes_json": dumps(nodes), "calls_json": dumps({c: [calls[c]] * len(runs) for c in calls}),
                        "reachable_json": dumps({c: [1] * len(runs) for c in calls}),
                        "entries_json": dumps({c: [10] * len(runs) for c in calls})})
    return records


def test_the_rule_per_root_seed_and_the_interval_over_worlds():
    settings = HeatmapWorlds().settings(True, 20, 0) | {"box_counts": [150], "worlds": 3}
    passing = {("150-0", 0), ("150-1", 0), ("150-1", 1), ("150-2", 1)}
    summary = HeatmapWorlds().summarize(_synthetic_records(settings, passing), settings)
    assert summary["passing_worlds_by_root_seed"] == {"0": ["150-0", "150-1"], "1": ["150-1", "150-2"]}
    assert summary["pass_rate_by_root_seed"] == {"0": round(2 / 3, 4), "1": round(2 / 3, 4)}
    assert summary["pass_overlap"]["fraction_passing_again"] == 0.5
    assert summary["passing_blocks"] == 4 and summary["passing_worlds_any_root_seed"] == 3
    assert summary["per_world"]["150-1"]["passes_under_root_seeds"] == [0, 1]
    # pooled over the four passing blocks (world 150-1 under both root seeds)
    ours = summary["ours"]["QRRT"]["40"]["nodes"]
    low, high = summary["range_over_passing_worlds"]["QRRT"]["40"]["nodes"]
    assert (low, high, ours) == (1250.0, 1350.0, 1300.0)
    interval = summary["interval_95"]["QRRT"]["40"]["nodes"]
    assert interval[0] < ours < interval[1] and interval[1] - interval[0] > 10  # the worlds differ
    assert summary["interval_unit"].startswith("worlds")
    by_root = summary["per_root_seed"]["0"]
    assert set(by_root["passing"]) == {"150-0", "150-1"} and by_root["ours"]["QRRT"]["40"]["nodes"] == 1300.0


def test_quick_run_with_several_root_seeds_resumes_to_the_same_records(tmp_path):
    whole = run_experiment("heatmap-worlds", out=tmp_path / "a", quick=True, trials=3, progress=False)
    roots = whole["settings"]["planner_root_seeds"]
    assert len(roots) >= 2 and whole["root_seeds_run"] == len(roots)
    assert set(whole["pass_rate_by_root_seed"]) == {str(root) for root in roots}
    partial = run_experiment("heatmap-worlds", out=tmp_path / "b", quick=True, trials=3, progress=False,
                             stop_after=5)
    assert partial["complete"] is False and partial["finished_trials"] == 5
    resumed = run_experiment("heatmap-worlds", out=tmp_path / "b", quick=True, trials=3, progress=False)
    a = read_records(tmp_path / "a" / "heatmap-worlds" / "records.csv")
    b = read_records(tmp_path / "b" / "heatmap-worlds" / "records.csv")
    assert len(a) == len(HeatmapWorlds().trials(whole["settings"])) == len({r["trial_id"] for r in b})
    assert sorted(a, key=lambda r: r["trial_id"]) == sorted(b, key=lambda r: r["trial_id"])
    assert {k: v for k, v in resumed.items() if k != "provenance"} == {
        k: v for k, v in whole.items() if k != "provenance"}
    # the worlds do not depend on the root seed; the planner seeds do
    seeds = {(r["variant"], r["boxes"], r["world_seed"], r["planner_root_seed"]): r["seed"] for r in a}
    assert seeds[("RRT", 150, 0, roots[0])] != seeds[("RRT", 150, 0, roots[1])]
