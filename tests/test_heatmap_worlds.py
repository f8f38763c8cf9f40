"""The single-world heatmap design: the round the paper's totals imply, and the acceptance rule."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from qrrt_circuits.experiments.heatmap_worlds import (
    PAPER,
    _advantage,
    calls_per_trial,
    most_nodes,
    passes,
    peak_fraction,
    round_costs,
)
from qrrt_circuits.experiments.measures import cut_at, reachable_at


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
