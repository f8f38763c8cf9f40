"""The single-world heatmap design: the round the paper's totals imply, and the acceptance rule."""

from __future__ import annotations

from qrrt_circuits.experiments.heatmap_worlds import PAPER, calls_per_trial, passes, round_costs


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
