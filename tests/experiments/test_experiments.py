import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from qrrt_circuits.cli import main
from qrrt_circuits.experiments import EXPERIMENTS, read_records, run_experiment
from qrrt_circuits.experiments.base import TIMING_SUFFIX
from qrrt_circuits.experiments.fitting import linear_fit, power_law_exponent, slope_through_origin

RESULTS = Path(__file__).resolve().parents[2] / "docs" / "results"
TINY = {"oracle-efficiency": 1, "wallclock": 1, "heatmaps": 2, "corridor": 2, "annealing": 1,
        "lemmas": 60, "scaling": 1, "oracle-check": 1,
        "tree-size": 1, "heatmap-hypotheses": 3,
        "corridor-sensitivity": 2, "corridor-worlds": 2, "search-policies": 1, "noise": 1, "resources": 1,
        "heatmap-worlds": 5, "annealing-density": 2, "problems": 2,
        "coherent-oracle": 1}


def _is_png(path):
    return path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and path.stat().st_size > 5000


@pytest.mark.parametrize("name", sorted(EXPERIMENTS))
def test_quick_path_writes_summary_records_and_figure(name, tmp_path):
    summary = run_experiment(name, out=tmp_path, quick=True, trials=TINY[name], progress=False)
    directory = tmp_path / name
    stored = json.loads((directory / "summary.json").read_text())
    assert stored["experiment"] == name and stored["complete"]
    assert {"settings", "ours", "paper"} <= set(stored)
    assert stored["ours"] and stored["paper"]
    trials = EXPERIMENTS[name].trials(stored["settings"])
    records = read_records(directory / "records.csv")
    assert sorted(r["trial_id"] for r in records) == sorted(t.id for t in trials)
    assert summary["figures"] and all(_is_png(directory / f) for f in summary["figures"])
    CHECKS[name](stored, records)
    comparison = EXPERIMENTS[name].paper_comparison(stored)
    if comparison is not None:  # numbers read from the summary, each with its interval
        assert comparison.numbers and comparison.quantity
        for number in comparison.numbers:
            assert len(number.interval) == 2 and np.isfinite(number.paper)


def _leaves(value, path=()):
    if isinstance(value, dict):
        for key, item in value.items():
            yield from _leaves(item, (*path, key))
    else:
        yield path, value


def _assert_intervals_hold(ours, intervals):
    """Every number of ``ours`` has a 95 % interval at the same place: low <= high (a null end is
    unbounded), and the interval holds the number up to the rounding of either."""
    for path, value in _leaves(ours):
        span = intervals
        for key in path:
            span = span[key]
        assert isinstance(span, list) and len(span) == 2, (path, span)
        if value is None or not np.isfinite(value):  # (a break-even beyond the levels; an undefined fit)
            continue
        low = -np.inf if span[0] is None else span[0]
        high = np.inf if span[1] is None else span[1]
        slack = 5e-5 + 1e-3 * abs(value)
        assert low <= high and low - slack <= value <= high + slack, (path, value, span)


def _check_oracle_efficiency(summary, records):
    assert set(summary["ours"]) == {"RRT", "ParallelRRT", "QRRT", "PQRRT"}
    for r in records:
        assert r["oracle_calls"] == r["quantum_oracle_calls"] + r["verification_calls"]
        assert r["nodes"] >= summary["settings"]["nodes"] or r["status"] == "reached"
    for kind in summary["ours"]:  # a slope of calls against nodes: calls per node, at least 1
        assert summary["ours"][kind] >= 1.0 - 1e-9 or kind == "PQRRT"
        assert summary["critical_path_slope"][kind] <= summary["ours"][kind] + 1e-9
        code = summary["authors_code"]  # the reported Octave run beside ours under its design
        low, high = code["ours_pooled_range_95"][kind]
        assert 1.0 - 1e-9 <= low <= high or kind == "PQRRT"
        assert code["reported_pooled_plausible"][kind] == (low <= code["reported_pooled"][kind] <= high)


def _check_wallclock(summary, records):
    _assert_intervals_hold(summary["ours"], summary["interval_95"])
    for name, per_node in summary["ours"]["seconds_per_node"].items():
        assert per_node > 0
        paper = summary["paper"]["seconds_per_node"][name.split(" ")[0]]
        assert summary["speedup_over_paper_per_node"][name] == round(paper / per_node, 1)
        low, high = summary["speedup_over_paper_per_node_interval_95"][name]
        assert low - 0.1 <= summary["speedup_over_paper_per_node"][name] <= high + 0.1
    for backend, ratio in summary["ours"]["per_call_ratio_qrrt_over_pqrrt"].items():
        # per call = (Pq-RRT's calls per critical-path call) x per critical-path call, when every
        # Pq-RRT tree has the same calls per critical-path call (one tree here)
        per_worker = summary["ours"]["per_critical_path_call_ratio_qrrt_over_pqrrt"][backend]
        assert ratio == pytest.approx(summary["pqrrt_calls_per_critical_path_call"][backend] * per_worker, rel=1e-2)


def _check_heatmaps(summary, records):
    cuts = [str(c) for c in summary["settings"]["cuts"]]
    for kind, by_cut in summary["ours"].items():
        if kind == "PQRRT_total_calls":
            continue
        rows = [r for r in records if r["planner"] == kind]
        for cut in cuts:
            assert by_cut[cut]["nodes"] == sum(r[f"nodes_at_{cut}"] for r in rows)
            # a run is cut after the first round that reaches the budget (or it reached the goal)
            assert all(r[f"calls_at_{cut}"] >= int(cut) or r["status"] == "reached" for r in rows)
        assert [by_cut[c]["nodes"] for c in cuts] == sorted(by_cut[c]["nodes"] for c in cuts)
    pq = [r for r in records if r["planner"] == "PQRRT"]
    for cut in cuts:  # Pq-RRT cut on total calls: the same runs, read earlier than on the critical path
        total = summary["ours"]["PQRRT_total_calls"][cut]
        assert total["nodes"] == sum(r[f"nodes_at_{cut}_total"] for r in pq) <= summary["ours"]["PQRRT"][cut]["nodes"]
        assert all(r[f"calls_at_{cut}_total"] >= int(cut) or r["status"] == "reached" for r in pq)
        low, high = summary["interval_95"]["PQRRT_total_calls"][cut]["efficiency"]
        assert low <= total["efficiency"] <= high
        for cut_on, kind in (("critical_path", "PQRRT"), ("total_calls", "PQRRT_total_calls")):
            assert summary["pqrrt_over_qrrt_nodes"][cut_on][cut] == pytest.approx(
                summary["ours"][kind][cut]["nodes"] / summary["ours"]["QRRT"][cut]["nodes"], abs=0.005)
    for r in records:
        if r["planner"] != "PQRRT":
            assert all(r[f"nodes_at_{c}_total"] == r[f"nodes_at_{c}"] for c in cuts)


def _check_heatmap_worlds(summary, records):
    assert summary["round_costs"]["fitting"] == [3]  # the paper's totals fit only a 3-call round
    variants, roots = summary["settings"]["variants"], summary["settings"]["planner_root_seeds"]
    assert variants == ["RRT", "QRRT", "QRRT_PAPER"] and len(roots) >= 2
    worlds = summary["per_world"]
    assert len(worlds) == summary["worlds_run"] == len(records) // (len(variants) * len(roots))
    for root in map(str, roots):  # the rule, re-applied to the stored intervals of each root seed
        by_root = summary["per_root_seed"][root]
        for key, intervals in by_root["rrt_efficiency_interval_95"].items():
            inside = all(intervals[c][0] <= summary["paper"]["RRT"][c]["efficiency"] <= intervals[c][1]
                         for c in ("10", "20", "40"))
            assert (key in by_root["passing_worlds"]) == inside == (int(root) in worlds[key]["passes_under_root_seeds"])
        assert summary["passing_worlds_by_root_seed"][root] == by_root["passing_worlds"]
        assert by_root["pass_rate"] == round(len(by_root["passing_worlds"]) / len(worlds), 4)
    for entry in worlds.values():
        for variant in variants:
            for cut in ("10", "20", "40"):
                assert 0.0 <= entry[variant][cut]["reachable_fraction"] <= 1.0
                low, high = entry[variant][cut]["nodes_interval_95"]
                assert low <= entry[variant][cut]["nodes"] <= high
        # the paper's schedule spends 6 calls a round: at most ceil(b / 6) nodes a run
        for cut, most in summary["round_costs"]["paper_schedule_most_nodes"].items():
            assert entry["QRRT_PAPER"][cut]["nodes"] <= most
    by_id = {(r["variant"], r["boxes"], r["world_seed"], r["planner_root_seed"]): r for r in records}
    for (_, boxes, w, root), record in by_id.items():  # the variants of one world share its planner seeds ...
        assert record["seed"] == by_id[("RRT", boxes, w, root)]["seed"]
        for other in roots:  # ... and another root seed gives it other ones
            assert other == root or record["seed"] != by_id[("RRT", boxes, w, other)]["seed"]
    overlap = summary["pass_overlap"]
    assert len(overlap["pairs"]) == len(roots) * (len(roots) - 1)
    assert summary["passing_worlds_any_root_seed"] == len(overlap["in_any_root_seed"])
    for label, by_planner in summary["efficiency_at_10_quantiles_over_worlds"].items():
        for low, middle, high in by_planner.values():
            assert low <= middle <= high, label
    for label, by_planner in summary["advantage_at_10_over_worlds"].items():
        for advantage in by_planner.values():
            low, middle, high = advantage["difference"]
            assert low <= middle <= high and 0 <= advantage["worlds_quantum_below_rrt"] <= len(worlds), label
    for variant, by_cut in summary["highest_nodes_over_worlds"].items():
        for cut, best in by_cut.items():
            assert best["nodes"] == max(entry[variant][cut]["nodes"] for entry in worlds.values())
    for variant, by_cut in summary["ours"].items():  # pooled values inside the range of the blocks' own
        for cut, value in by_cut.items():
            if value["nodes"] is None:
                assert summary["passing_blocks"] == 0
                continue
            low, high = summary["range_over_passing_worlds"][variant][cut]["nodes"]
            assert low <= value["nodes"] <= high
            low, high = summary["interval_95"][variant][cut]["nodes"]
            assert low - 0.1 <= value["nodes"] <= high + 0.1


def _check_corridor(summary, records):
    for kind, inside in summary["ours"].items():
        assert 0 <= inside <= summary["nodes"][kind]
        low, high = summary["through_channel_interval_95"][kind]
        assert low <= summary["through_channel"][kind] <= high
    assert all(r["oracle_calls"] >= summary["settings"]["budget"] for r in records)


def _check_annealing(summary, records):
    low, high = summary["settings"]["bands"][0]
    hot = summary["settings"]["switch_at"]
    for r in records:  # QDA's first switch_at nodes are placed in the hot band, by construction
        if r["method"] == "QDA" and r["nodes"] >= hot:
            assert low <= r[f"mean_parent_distance_{hot}"] <= high
    ours = summary["ours"]
    assert summary["ratio_qda_over_uniform"]["16"] == round(ours["QDA"]["16"] / ours["QRRT"]["16"], 2)
    assert ours["ratio_qda_over_uniform"] == summary["ratio_qda_over_uniform"]
    _assert_intervals_hold({k: v for k, v in ours.items() if k != "ratio_qda_over_uniform"},
                           summary["interval_95"])
    for size, (low, high) in summary["interval_95"]["ratio_qda_over_uniform"].items():  # rounded to 0.01
        assert low - 0.01 <= ours["ratio_qda_over_uniform"][size] <= high + 0.01
    design = summary["paper_design"]
    for method, by_size in design["range_95"].items():  # single trees spread at least as wide as their mean
        trees = [r["mean_parent_distance_16"] for r in records if r["method"] == method]
        low, high = by_size["16"]
        assert min(trees) - 1e-3 <= low <= high <= max(trees) + 1e-3
        assert design["paper_plausible"][method]["16"] == (low <= summary["paper"][method] <= high)


def _check_annealing_density(summary, records):
    settings, ours = summary["settings"], summary["ours"]
    _assert_intervals_hold({k: v for k, v in ours.items() if k != "ratio_qda_over_uniform"}, summary["interval_95"])
    low, high = settings["bands"][0]
    for r in records:  # every QDA tree of 16 nodes is grown in the hot band, under every reading but
        # "band, databases", whose h may reach the cold band first
        assert r["nodes"] == settings["size"] or r["rounds"] == settings["max_rounds"] or r["status"] == "reached"
        if r["method"] == "QDA" and r["counter"] == "nodes" and r["nodes"]:
            assert low - 1e-9 <= r["mean_parent_distance_16"] <= high + 1e-9
    for head, by_key in summary["incomplete_trees"].items():  # trees short of 16 nodes, left out of the means
        for key, count in by_key.items():
            trials = settings["trials"]
            assert 0 <= count <= trials and (count < trials) == (ours[head][key] is not None)
    densities = [str(float(d)) for d in settings["densities"]]
    assert list(ours["QRRT"]) == list(ours["QDA"]) == densities
    assert set(ours["QDA_readings"]) == {f"{p}, {c}" for p, c in settings["readings"]}
    assert ours["QDA_readings"]["band, nodes"] == ours["QDA"]["1.0"]  # the same trees
    for key, edges in summary["nodes_at_band_edges"].items():  # clamp piles nodes on the edges
        assert key in ours["QDA_readings"]
        assert all(value is None or 0.0 <= value <= 1.0 for value in edges.values())
    for d in densities:
        assert ours["ratio_qda_over_uniform"][d] == round(ours["QDA"][d] / ours["QRRT"][d], 2)
        assert summary["side"][d] == round(20 * (6025 / 525 / float(d)) ** 0.5, 2)  # 6025 boxes at density d
    assert summary["free_fraction"]["0.5"] > summary["free_fraction"]["1.0"]  # denser, less free
    design = summary["paper_design"]
    for method, where in summary["where_paper_falls"].items():
        paper = summary["paper"][method]
        assert where["inside_our_mean_at"] == [d for d in densities if not summary["differs_from_paper"][method][d]]
        assert where["plausible_for_one_tree_at"] == [d for d in densities if design["paper_plausible"][method][d]]
        assert all(design["range_95"][method][d][0] <= paper <= design["range_95"][method][d][1]
                   for d in where["plausible_for_one_tree_at"])


def _check_lemmas(summary, records):
    _assert_intervals_hold(summary["ours"], summary["interval_95"])
    for lemma, stats in summary["z_scores"].items():  # points with a zero standard error are left out
        assert 0 < stats["points"] <= len(records) and 0.0 <= summary["ours"][lemma]["within_3_sigma"] <= 1.0
        low, high = stats["max_abs_z_range_if_exact_95"]
        assert 0 < low < high
        inside = [point[lemma]["inside"] for point in summary["per_point"].values() if lemma in point]
        assert len(inside) == stats["points"]
        assert summary["ours"][lemma]["inside_interval_95"] == round(sum(inside) / len(inside), 3)
    for point in summary["per_point"].values():  # each measured value lies in its own interval
        for value in point.values():
            assert value["interval_95"][0] <= value["observed"] <= value["interval_95"][1]
        assert all(value["inside"] == (value["interval_95"][0] <= value["lemma"] <= value["interval_95"][1])
                   for value in point.values())
    for r in records:  # every lemma agrees with the Aer shots within 5.5 standard errors
        for lemma in ("lemma1", "lemma2", "lemma4", "lemma5"):
            assert abs(r[f"{lemma}_observed"] - r[f"{lemma}_theory"]) <= 5.5 * r[f"{lemma}_stderr"] + 1e-12


def _check_scaling(summary, records):
    assert summary["fits"]["RRT"]["exponent"] == pytest.approx(-1.0)  # RRT's f is its own success rate
    for r in records:
        assert 0.0 < r["reachable_fraction"] <= 1.0 and r["calls_per_node"] >= 1.0


def _check_oracle_check(summary, records):
    _assert_intervals_hold(summary["ours"], summary["interval_95"])
    # the exact check's trees never contain an edge it rejects; the finer check rejects a subset
    assert all(value == 0.0 for value in summary["ours"]["invalid_edge_fraction"]["exact"].values())
    assert all(r["invalid_edges"] == 0 for r in records if r["check"] == "exact")
    assert all(0 <= r["invalid_edges_fine"] <= r["invalid_edges"] <= r["nodes"] for r in records)


def _check_tree_size(summary, records):
    sizes = summary["settings"]["sizes"]
    for r in records:  # cumulative calls at each size never decrease, and each size was reached
        points = json.loads(r["points_json"])
        assert [p[0] for p in points] == sizes
        assert all(a[1] <= b[1] and a[2] <= b[2] <= b[1] for a, b in zip(points, points[1:], strict=False))
    _assert_intervals_hold(summary["ours"], summary["interval_95"])
    _assert_intervals_hold(summary["critical_path_per_node"], summary["critical_path_interval_95"])
    _assert_intervals_hold(summary["mean_reachable_fraction"], summary["mean_reachable_fraction_interval_95"])


def _check_heatmap_hypotheses(summary, records):
    from qrrt_circuits.experiments.heatmap_hypotheses import calibrate, max_nodes_within

    # the arithmetic that rules out the paper schedule: 6 calls a round, at most 2 rounds by 10 calls
    assert summary["arithmetic"]["paper_schedule_max_nodes_at_10_calls"] == 200 < 372
    assert max_nodes_within(10, 3, 100) == 400 and calibrate([100, 200], [0.2, 0.1], 0.15) == 150
    assert calibrate([100, 200], [0.2, 0.1], 0.5) is None
    for variant, by_count in summary["table"].items():
        for boxes, by_cut in by_count.items():
            rows = [r for r in records if r["variant"] == variant and r["boxes"] == int(boxes)]
            assert by_cut["10"]["nodes"] == round(100 * sum(r["nodes_at_10"] for r in rows) / len(rows), 1)


def _check_corridor_sensitivity(summary, records):
    from qrrt_circuits.experiments.corridor_sensitivity import (
        FACTORS,
        GAP,
        PAPER,
        PAPER_TRIALS,
        cell_id,
        cells,
        single_block_range,
    )

    settings = summary["settings"]
    assert len(cells(FACTORS, "QRRT")) == 243 and len(cells(FACTORS, "RRT")) == 81  # the full design
    for kind in ("RRT", "QRRT"):
        keys = {cell_id(c, kind) for c in cells(settings["factors"], kind)}
        assert set(summary["ours"][kind]) == set(summary["interval_95"][kind]) == keys
        for key in keys:  # the per-50 mean of the cell's runs, inside its interval
            counts = [n for r in records if r["planner"] == kind and cell_id(r, kind) == key
                      for n in json.loads(r["in_channel_json"])]
            assert len(counts) == settings["blocks"] * settings["block_size"]
            assert summary["ours"][kind][key] == pytest.approx(PAPER_TRIALS * np.mean(counts), abs=0.01)
            low, high = summary["interval_95"][kind][key]
            assert low - 0.01 <= summary["ours"][kind][key] <= high + 0.01
            assert summary["differs_from_paper"][kind][key] == (not low <= PAPER[kind] <= high)
    for q in summary["paper_pair_inside"]:
        assert not summary["differs_from_paper"]["QRRT"][q]
    assert summary["intervals_wider_than_gap"] == [
        f"{kind}/{key}" for kind in ("RRT", "QRRT") for key, (low, high) in summary["interval_95"][kind].items()
        if high - low >= GAP]
    assert summary["closest_to_paper"]["cell"] in summary["ours"]["QRRT"]
    for r in records:
        inside = json.loads(r["in_channel_json"])
        assert len(inside) == settings["block_size"] and sum(inside) == r["in_channel"] <= r["nodes"]
        assert r["start_distance"] >= r["distance"] and (r["iterations"] == "none") == (r["planner"] == "RRT")
        # each run cut at the budget (a round overshoots it by less than its cost) or at the goal
        assert 0 < r["oracle_calls"] < settings["block_size"] * (settings["budget"] + 10)
    # one block's range: a constant count gives a point; counts of 0 or 1 give a binomial's range
    assert single_block_range(np.full(20, 2), 50, 0) == (100.0, 100.0)
    low, high = single_block_range(np.array([0, 1] * 200), 50, 0)
    assert 25 - 2.2 * 3.54 <= low < 25 < high <= 25 + 2.2 * 3.54  # Binomial(50, 1/2): sd 3.54


def _check_search_policies(summary, records):
    from qrrt_circuits.experiments.search_policies import CONFIGS

    assert set(summary["ours"]) == set(CONFIGS)
    for r in records:
        assert r["oracle_calls"] == r["quantum_oracle_calls"] + r["verification_calls"]
        assert r["critical_path_calls"] <= r["oracle_calls"]
        assert (r["estimation_calls"] > 0) == r["config"].endswith("estimated")
        assert r["estimation_calls"] <= r["quantum_oracle_calls"]
    for label, row in summary["whole_run"].items():
        if label.startswith("QRRT") or label == "RRT":  # one worker: the critical path is every call
            assert row["critical_path_per_node"] == row["calls_per_node"]
    for label, by_window in summary["critical_path_per_node"].items():  # each value has its interval
        assert set(summary["critical_path_interval_95"][label]) == set(by_window)
        if label.startswith("QRRT") or label == "RRT":
            assert summary["critical_path_interval_95"][label] == summary["interval_95"][label]
    _assert_intervals_hold(summary["ours"], summary["interval_95"])
    _assert_intervals_hold(summary["critical_path_per_node"], summary["critical_path_interval_95"])
    _assert_intervals_hold(summary["whole_run"], summary["whole_run_interval_95"])
    _assert_intervals_hold(summary["mean_reachable_fraction"], summary["mean_reachable_fraction_interval_95"])
    estimation = {key: value for key, value in summary["estimation"].items() if key != "break_even_note"}
    _assert_intervals_hold(estimation, summary["estimation_interval_95"])


def _check_problems(summary, records):
    from qrrt_circuits.experiments.connect_star import BUDGET_SHARES
    from qrrt_circuits.experiments.default_policy import POLICY_CANDIDATES, TIE_MARGIN

    settings = summary["settings"]
    for r in records:
        if r["reached"]:  # the shortcut never lengthens a path (straight segments, a metric)
            assert r["path_length_simplified"] <= r["path_length"] + 1e-9
        else:  # only the budget ends a run that did not reach the goal
            assert r["status"] == "max_oracle_calls" and r["oracle_calls"] >= settings["budget"]
        assert r["critical_path_calls"] <= r["oracle_calls"]
        assert r["classical_checks"] >= r["simulation_checks"]
        if r["config"] in ("QRRTConnect", "QRRTStar"):  # extension databases of 2^n, and smaller ones
            assert r["simulation_checks"] >= 1 << settings["num_qubits"]
        elif r["config"].startswith("QRRT") or r["config"].startswith("PQRRT"):
            assert r["simulation_checks"] > 0 and r["simulation_checks"] % (1 << settings["num_qubits"]) == 0
        elif r["config"].startswith("OMPL"):  # no check thrown away
            assert r["classical_checks"] == r["oracle_calls"]
        else:  # the classical planners' checks made ahead and thrown away are not oracle calls
            assert r["classical_checks"] >= r["oracle_calls"] and r["simulation_checks"] == 0
        costs = [r[f"cost_at_{share}"] for share in BUDGET_SHARES]
        if r["config"] in ("QRRTStar", "OMPL RRTstar"):  # an anytime planner's best cost never rises
            held = [cost for cost in costs if math.isfinite(cost)]
            assert held == sorted(held, reverse=True) and bool(held) == bool(r["reached"])
            if r["config"] == "QRRTStar":  # (its cost is the problem's metric; OMPL's is its own; the last
                # round may pass the budget and shorten the path further)
                assert not held or held[-1] >= r["path_length"] * (1 - 1e-9)
        else:
            assert all(math.isnan(cost) for cost in costs)
    for family, planners in summary["ours"].items():
        for config, row in planners.items():
            runs = [r for r in records if r["family"] == family and r["config"] == config]
            solved = sum(r["reached"] for r in runs)
            assert row["success_rate"] == round(solved / len(runs), 4)
            if solved:
                assert row["calls_per_solution"] == round(sum(r["oracle_calls"] for r in runs) / solved, 4)
        _assert_intervals_hold(planners, summary["interval_95"][family])
        _assert_intervals_hold(summary["details"][family], summary["details_interval_95"][family])
    for family in settings["families"]:
        assert set(summary["connect_vs_ompl"][family]) == {"median", "interval_95", "runs", "both_solved"}
        star = summary["star_vs_ompl"][family]
        assert set(star["mean_cost"]) == {"QRRTStar", "OMPL RRTstar"}
    for rule in summary["default_policy"].values():
        assert rule["chosen"] in POLICY_CANDIDATES and rule["chosen_by_root_seed"]
        worst = {c: math.inf if v is None else v for c, v in rule["worst"].items()}  # JSON's null is inf
        assert worst[rule["chosen"]] <= min(worst.values()) * TIE_MARGIN
        assert abs(sum(rule["chosen_share_in_resamples"].values()) - 1) < 1e-3


def _check_coherent_oracle(summary, records):
    for r in records:
        if r["kind"] == "verify":  # the circuit equals its reference on every index state
            assert r["mismatches"] == 0 and r["ancillas_clean"] == 1 and r["index_preserved"] == 1
            assert r["entries"] == 2 ** r["index_bits"]
        elif r["kind"] == "plan":  # a run that did not reach the goal spent its budget
            assert r["reached"] == 1 or r["oracle_calls"] >= summary["settings"]["plan_budget"]
        elif r["kind"] == "grover":  # within 4 binomial sd of sin^2((2k+1) theta)
            sd = (max(r["expected"] * (1 - r["expected"]), 1e-12) / r["shots"]) ** 0.5
            assert abs(r["hits"] / r["shots"] - r["expected"]) <= 4 * sd
        else:
            assert r["toffolis"] == 2 * r["oracle_ands"] and r["lookup_qrom_ands"] == 2 * (2 ** r["index_bits"] - 2)
    assert summary["largest_verified_index_bits"] == max(summary["settings"]["verify_bits"])
    assert set(summary["ours"]["planning"]) == set(summary["settings"]["plan_configs"])
    _assert_intervals_hold(summary["ours"], summary["interval_95"])


def _check_noise(summary, records):
    for r in records:
        if r["part"] == "sweep" and r["p2"] == 0 and r["shots"] == 0:  # zero noise: exactly the ideal
            assert r["success"] == pytest.approx(r["ideal"], abs=1e-9)
        if r["part"] == "sweep" and r["shots"] == 0:
            assert 0.0 < r["fidelity"] <= 1.0 and r["collision"] >= r["collision_uniform"] - 1e-12
        if r["part"] == "planning":
            assert r["oracle_calls"] == r["quantum_oracle_calls"] + r["verification_calls"]
            assert r["config"] != "RRT" or r["quantum_oracle_calls"] == 0
    assert set(summary["ours"]["break_even_p2"]) == set(summary["settings"]["planning_configs"])
    _assert_intervals_hold(summary["ours"], summary["interval_95"])
    assert summary["device"]["name"] or "pip install" in summary["device"]["missing"]


def _check_resources(summary, records):
    for r in records:
        if r["part"] == "fault-tolerant" and r["lookup"] == "qrom":  # Babbush et al.: 2 x (2^n - 2) + (n - 2)
            assert r["oracle_ands"] + r["diffuser_ands"] == 2 * (2 ** r["n"] - 2) + r["n"] - 2
        if r["part"] == "near-term" and r["synthesis"] == "diagonal" and r["connectivity"] == "all-to-all":
            assert r["two_qubit_gates"] >= 2 ** r["n"] - 2  # the oracle alone has 2^n - 2 CX
    plan = summary["plan"]["table"]
    expected = (plan["rrt_calls"] - plan["verifications"]) * plan["test_s"] / plan["quantum_calls"]
    assert plan["break_even_call_s"] == pytest.approx(expected)
    assert plan["qrrt_fault_tolerant_with_table_s"] > plan["qrrt_fault_tolerant_s"]


def _check_corridor_worlds(summary, records):
    from qrrt_circuits.experiments.corridor_sensitivity import FACTORS, PAPER, PAPER_TRIALS, cell_id
    from qrrt_circuits.experiments.corridor_worlds import CENTRES, design_cells, geometries

    settings = summary["settings"]
    assert len(geometries(CENTRES, FACTORS)) == 7  # the centre and its 6 one-level neighbours
    seeds = summary["design"]["world_seeds"]
    assert seeds == list(range(1, 1 + settings["draws"])) and summary["design"]["draws"] == settings["draws"]
    for kind in ("RRT", "QRRT"):
        keys = {cell_id(c, kind) for c in design_cells(settings, kind)}
        assert set(summary["ours"][kind]) == set(summary["interval_95"][kind]) == keys
        for key in keys:
            per_draw = summary["per_draw"][kind][key]
            for w in seeds:  # each draw's mean per 50 runs, from that draw's records only
                counts = [n for r in records if r["planner"] == kind and cell_id(r, kind) == key
                          and r["world_seed"] == w for n in json.loads(r["in_channel_json"])]
                assert len(counts) == settings["blocks"] * settings["block_size"]
                assert per_draw[str(w)] == pytest.approx(PAPER_TRIALS * np.mean(counts), abs=0.01)
            assert summary["range_over_draws"][kind][key] == [min(per_draw.values()), max(per_draw.values())]
            low, high = summary["interval_95"][kind][key]
            assert low - 0.01 <= summary["ours"][kind][key] <= high + 0.01
    for claim, count in summary["claims_over_worlds"].items():
        assert count["draws"] == len(seeds) and count["holds_in"] == len(count["world_seeds"]) <= len(seeds)
        if claim.startswith("paper_pair_inside/"):  # the rule, per draw, from the per-draw intervals
            q = claim.split("/", 1)[1]
            r = q.rsplit("-", 1)[0]
            spans = summary["per_draw_interval_95"]
            assert count["world_seeds"] == [
                w for w in seeds if spans["QRRT"][q][str(w)][0] <= PAPER["QRRT"] <= spans["QRRT"][q][str(w)][1]
                and spans["RRT"][r][str(w)][0] <= PAPER["RRT"] <= spans["RRT"][r][str(w)][1]]
    assert set(summary["claims_for_the_setting"]) == set(summary["claims_over_worlds"])


CHECKS = {"oracle-efficiency": _check_oracle_efficiency, "wallclock": _check_wallclock,
          "heatmaps": _check_heatmaps, "corridor": _check_corridor, "annealing": _check_annealing,
          "lemmas": _check_lemmas, "scaling": _check_scaling, "oracle-check": _check_oracle_check,
          "tree-size": _check_tree_size, "heatmap-hypotheses": _check_heatmap_hypotheses,
          "corridor-sensitivity": _check_corridor_sensitivity, "corridor-worlds": _check_corridor_worlds,
          "search-policies": _check_search_policies,
          "noise": _check_noise, "resources": _check_resources, "heatmap-worlds": _check_heatmap_worlds,
          "annealing-density": _check_annealing_density, "problems": _check_problems,
          "coherent-oracle": _check_coherent_oracle}


def _comparable(records):
    return sorted(({k: v for k, v in r.items() if not k.endswith(TIMING_SUFFIX)} for r in records),
                  key=lambda r: r["trial_id"])


def test_resume_ends_with_exactly_the_uninterrupted_trials(tmp_path):
    whole = run_experiment("oracle-efficiency", out=tmp_path / "a", quick=True, trials=2, progress=False)
    partial = run_experiment("oracle-efficiency", out=tmp_path / "b", quick=True, trials=2, progress=False,
                             stop_after=3)
    assert partial["complete"] is False and partial["finished_trials"] == 3
    path = tmp_path / "b" / "oracle-efficiency" / "records.csv"
    # a run killed mid-write leaves a torn last line: it must be dropped, not kept or duplicated
    with path.open("a") as handle:
        handle.write("PQRRT-1,123,PQRRT,1")
    assert len(read_records(path)) == 3
    seen = []
    resumed = run_experiment("oracle-efficiency", out=tmp_path / "b", quick=True, trials=2, progress=False,
                             on_record=seen.append)
    assert resumed["complete"] and len(seen) == 8 - 3
    a = read_records(tmp_path / "a" / "oracle-efficiency" / "records.csv")
    b = read_records(path)
    assert len(b) == len({r["trial_id"] for r in b}) == 8
    assert _comparable(a) == _comparable(b)
    assert resumed["ours"] == whole["ours"]


def test_corridor_worlds_centres_are_the_factorials_paper_pair_cells():
    """The draws rerun the geometry of every cell that holds the paper's pair in the committed
    factorial (world seed 0), with every iteration level of the factorial."""
    from qrrt_circuits.experiments.corridor_sensitivity import FACTORS, cell_id
    from qrrt_circuits.experiments.corridor_worlds import CENTRES, design_cells

    factorial = json.loads((RESULTS / "corridor-sensitivity" / "summary.json").read_text())
    assert factorial["paper_pair_inside"]
    assert {q.rsplit("-", 1)[0] for q in factorial["paper_pair_inside"]} == {cell_id(c, "RRT") for c in CENTRES}
    settings = EXPERIMENTS["corridor-worlds"].settings(False, None, 0)
    assert settings["factors"] == FACTORS
    assert set(factorial["paper_pair_inside"]) <= {cell_id(c, "QRRT") for c in design_cells(settings, "QRRT")}


def test_corridor_worlds_quick_path_resumes_to_the_uninterrupted_records(tmp_path):
    whole = run_experiment("corridor-worlds", out=tmp_path / "a", quick=True, trials=2, progress=False)
    partial = run_experiment("corridor-worlds", out=tmp_path / "b", quick=True, trials=2, progress=False,
                             stop_after=5)
    assert partial["complete"] is False and partial["finished_trials"] == 5
    seen = []
    resumed = run_experiment("corridor-worlds", out=tmp_path / "b", quick=True, trials=2, progress=False,
                             on_record=seen.append)
    total = len(EXPERIMENTS["corridor-worlds"].trials(resumed["settings"]))
    assert resumed["complete"] and len(seen) == total - 5
    a = read_records(tmp_path / "a" / "corridor-worlds" / "records.csv")
    b = read_records(tmp_path / "b" / "corridor-worlds" / "records.csv")
    assert len(b) == len({r["trial_id"] for r in b}) == total
    assert _comparable(a) == _comparable(b)
    for key in ("ours", "interval_95", "per_draw", "claims_over_worlds", "claims_for_the_setting"):
        assert resumed[key] == whole[key]


def test_other_settings_in_the_same_directory_are_refused(tmp_path):
    run_experiment("lemmas", out=tmp_path, quick=True, trials=20, progress=False)
    with pytest.raises(ValueError, match="holds results for other settings"):
        run_experiment("lemmas", out=tmp_path, quick=True, trials=30, progress=False)


def test_bad_arguments(tmp_path):
    with pytest.raises(ValueError, match="unknown experiment"):
        run_experiment("nope", out=tmp_path)
    with pytest.raises(ValueError, match="trials must be"):
        run_experiment("lemmas", out=tmp_path, trials=0)


def test_compare_checks_sets_runs_beside_the_paper(tmp_path, capsys):
    """``qrrt compare-checks`` draws one panel per experiment that every folder holds, with each
    folder's numbers as its summary states them, and refuses folders with nothing to compare."""
    from qrrt_circuits.experiments.compare import comparisons

    exact, authors = tmp_path / "exact", tmp_path / "authors"
    run_experiment("corridor", out=exact, quick=True, trials=2, progress=False)
    run_experiment("corridor", out=authors, quick=True, trials=2, progress=False, predicate="authors")
    run_experiment("lemmas", out=exact, quick=True, trials=20, progress=False)  # in one folder only
    assert main(["compare-checks", str(exact), str(authors)]) == 0
    figure = authors / "checks_vs_paper.png"
    assert _is_png(figure) and str(figure) in capsys.readouterr().out
    panel, = comparisons([exact, authors])
    assert [label for label, _ in panel] == ["ours, exact check", "ours, authors' check"]
    for (_, comparison), folder in zip(panel, (exact, authors), strict=True):
        summary = json.loads((folder / "corridor" / "summary.json").read_text())
        assert [(n.label, n.ours, list(n.interval), n.paper) for n in comparison.numbers] == [
            (kind, summary["ours"][kind], summary["interval_95"][kind], summary["paper"][kind])
            for kind in ("RRT", "QRRT")]
    with pytest.raises(SystemExit) as exc:
        main(["compare-checks", str(exact / "corridor")])
    assert exc.value.code == 2 and "no experiment that compares with the paper" in capsys.readouterr().err


def test_linear_fit_recovers_a_known_slope():
    rng = np.random.default_rng(0)
    x = rng.uniform(0, 30, 400)
    y = 7.6 * x + 3.0 + rng.normal(scale=2.0, size=x.size)
    fit = linear_fit(x, y)
    assert abs(fit.slope - 7.6) <= 5 * fit.slope_stderr
    assert fit.slope_stderr < 0.05
    assert slope_through_origin(x, 2.5 * x) == pytest.approx(2.5)
    f = np.geomspace(0.01, 0.5, 50)
    assert power_law_exponent(f, 3 * f**-0.5).slope == pytest.approx(-0.5)
    with pytest.raises(ValueError, match="two distinct"):
        linear_fit([1, 1], [2, 3])


def test_reproduce_command(tmp_path, capsys):
    assert main(["reproduce", "lemmas", "--quick", "--trials", "20", "--out", str(tmp_path),
                 "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "== lemmas" in out and "summary.json" in out
    with pytest.raises(SystemExit):
        main(["reproduce", "nope", "--out", str(tmp_path)])


def test_intervals_cover_at_their_level():
    """The bootstrap interval of a mean and the exact binomial interval cover the true value in at
    least the binomial lower bound of 95 % of 200 replicates (a bootstrap percentile interval of
    30 normal samples undercovers slightly: allow the nominal level minus that known bias, 0.93)."""
    from tolerances import binomial_counts

    from qrrt_circuits.experiments.intervals import binomial_interval, bootstrap_interval, differs

    rng = np.random.default_rng(0)
    replicates, boot, exact = 200, 0, 0
    for seed in range(replicates):
        sample = list(rng.normal(3.0, 1.0, 30))
        low, high = bootstrap_interval(sample, lambda s: float(np.mean(s)), seed, resamples=400)
        boot += low <= 3.0 <= high
        successes = int(rng.binomial(50, 0.3))
        low, high = binomial_interval(successes, 50)
        exact += low <= 0.3 <= high
    assert boot >= binomial_counts(replicates, 0.93)[0]
    assert exact >= binomial_counts(replicates, 0.95)[0]
    assert differs(5.0, [1.0, 2.0]) is True and differs(1.5, [1.0, 2.0]) is False
    assert differs(None, [1.0, 2.0]) is None


def _predicate_names():
    from qrrt_circuits.registry import PREDICATES

    return [label.replace(":K", ":50") for label in PREDICATES.labels() if label != "exact"]


@pytest.mark.parametrize("predicate", _predicate_names())
@pytest.mark.parametrize("name", sorted(n for n in EXPERIMENTS if EXPERIMENTS[n].uses_predicate))
def test_quick_path_under_each_predicate(name, predicate, tmp_path):
    summary = run_experiment(name, out=tmp_path, quick=True, trials=TINY[name], progress=False,
                             predicate=predicate)
    assert summary["complete"] and summary["settings"]["predicate"] == predicate
    records = read_records(tmp_path / name / "records.csv")
    assert len(records) == len(EXPERIMENTS[name].trials(summary["settings"]))


def test_settings_written_before_predicates_existed_mean_the_exact_check(tmp_path):
    run_experiment("corridor", out=tmp_path, quick=True, trials=1, progress=False)
    path = tmp_path / "corridor" / "settings.json"
    old = json.loads(path.read_text())
    del old["predicate"]
    path.write_text(json.dumps(old))
    assert run_experiment("corridor", out=tmp_path, quick=True, trials=1, progress=False)["complete"]
    with pytest.raises(ValueError, match="holds results for other settings"):
        run_experiment("corridor", out=tmp_path, quick=True, trials=1, progress=False, predicate="time-samples:20")
    with pytest.raises(ValueError, match="experiment 'lemmas' does not take a predicate"):
        run_experiment("lemmas", out=tmp_path, predicate="time-samples:20")


def test_resume_never_counts_a_trial_twice_or_without_its_settings(tmp_path):
    whole = run_experiment("corridor", out=tmp_path, quick=True, trials=2, progress=False)
    path = tmp_path / "corridor" / "records.csv"
    lines = path.read_text().splitlines(keepends=True)
    path.write_text("".join(lines + [lines[1]]))  # a duplicated row
    with pytest.warns(UserWarning, match="second record of trial"):
        again = run_experiment("corridor", out=tmp_path, quick=True, trials=2, progress=False)
    assert again["ours"] == whole["ours"] and again["nodes"] == whole["nodes"]
    with warnings.catch_warnings():  # the excluded row was moved aside: reported once, never counted
        warnings.simplefilter("error")
        assert len(read_records(path)) == 4
    assert (tmp_path / "corridor" / "records.csv.excluded").read_text().count(lines[1].split(",")[0]) == 1
    settings = tmp_path / "corridor" / "settings.json"
    settings.write_text("{not json")
    with pytest.raises(ValueError, match=r"settings.json is corrupt"):
        run_experiment("corridor", out=tmp_path, quick=True, trials=2, progress=False)
    settings.unlink()
    with pytest.raises(ValueError, match=r"records.csv has records but .*settings.json is missing"):
        run_experiment("corridor", out=tmp_path, quick=True, trials=2, seed=1, progress=False)


def test_trial_count_has_a_documented_limit(tmp_path):
    with pytest.raises(ValueError, match=r"trials must be an integer in \[1, 100000\]"):
        run_experiment("heatmaps", out=tmp_path, trials=10**9)
    assert not (tmp_path / "heatmaps").exists()  # refused before any file is written


def test_heatmaps_share_one_colour_scale(tmp_path, monkeypatch):
    """The heatmaps figure puts every panel on one logarithmic scale whose top is the largest cell
    count of any panel, with one colour bar for the figure (not one per panel)."""
    import matplotlib.pyplot as plt

    from qrrt_circuits.experiments import figures
    from qrrt_circuits.experiments.heatmaps import Heatmaps
    from qrrt_circuits.experiments.worlds import world

    run_experiment("heatmaps", quick=True, trials=2, out=tmp_path, seed=3, progress=False)
    out = tmp_path / "heatmaps"
    settings = json.loads((out / "settings.json").read_text())
    summary = json.loads((out / "summary.json").read_text())
    records = read_records(out / "records.csv")
    kept = []
    monkeypatch.setattr(plt, "close", kept.append)  # keep the figure open to inspect it
    (tmp_path / "again").mkdir()
    Heatmaps().plot(records, settings, summary, tmp_path / "again")
    fig, = kept
    images = [image for ax in fig.axes for image in ax.images]
    assert 1 <= len(images) <= 9  # a panel without nodes has no image
    assert len({id(image.norm) for image in images}) == 1
    env = world(settings["scenario"], settings["world_seed"]).env
    largest = max(float(image.get_array().max()) for image in images)
    assert images[0].norm.vmax == max(largest, 2.0)
    assert images[0].norm.vmin == 1
    assert len(fig.axes) == 10  # nine panels and one colour bar
    assert figures.heatmap_counts(env, np.zeros((0, 2))).shape == (50, 50)
    plt.close(fig)


def _without_nan(records):
    return [{k: None if isinstance(v, float) and math.isnan(v) else v for k, v in r.items()} for r in records]


def _reproducible(value):
    """A summary part without wall times (not reproducible), NaN as None (NaN != NaN)."""
    if isinstance(value, dict):
        return {k: _reproducible(v) for k, v in value.items() if "wall_time" not in k}
    if isinstance(value, list):
        return [_reproducible(v) for v in value]
    return None if isinstance(value, float) and math.isnan(value) else value


def test_problems_quick_path_resumes_to_the_uninterrupted_summary(tmp_path):
    """Two root seeds, one replicate: a run stopped after 40 trials and resumed holds every trial
    once and summarises (family costs, intervals over worlds, the default-policy rule) exactly as
    the uninterrupted run."""
    whole = run_experiment("problems", out=tmp_path / "a", quick=True, trials=1, progress=False)
    partial = run_experiment("problems", out=tmp_path / "b", quick=True, trials=1, progress=False, stop_after=40)
    assert partial["complete"] is False and partial["finished_trials"] == 40
    resumed = run_experiment("problems", out=tmp_path / "b", quick=True, trials=1, progress=False)
    a = read_records(tmp_path / "a" / "problems" / "records.csv")
    b = read_records(tmp_path / "b" / "problems" / "records.csv")
    assert len(b) == len({r["trial_id"] for r in b}) == len(a)
    roots = whole["settings"]["root_seeds"]
    assert {r["root_seed"] for r in b} == set(roots) and len(roots) == 2
    assert _without_nan(_comparable(a)) == _without_nan(_comparable(b))  # (OMPL's runs count no nodes: NaN)
    for key in ("interval_95", "ratios_interval_95", "worlds"):
        assert _reproducible(resumed[key]) == _reproducible(whole[key])
    for rule in ("QRRT", "PQRRT"):
        for key in ("relative_cost", "chosen", "chosen_by_root_seed", "chosen_share_in_resamples"):
            assert resumed["default_policy"][rule][key] == whole["default_policy"][rule][key]
