"""The default-policy rule of ``qrrt reproduce problems`` on synthetic family costs: the smallest
worst family ratio wins, near-ties (within 5 %) go to the lower geometric mean, then to the
earlier candidate; families no candidate solved are left out."""

from __future__ import annotations

import math

import pytest

from qrrt_circuits.experiments.default_policy import TIE_MARGIN, choose_by_worst_ratio, family_ratios

ORDER = ["paper", "adaptive", "bbht"]


def test_family_ratios_divide_by_the_best_candidate_and_skip_unsolved_families() -> None:
    costs = {"a": {"paper": 30.0, "adaptive": 10.0, "bbht": 20.0},
             "b": {"paper": math.inf, "adaptive": 5.0, "bbht": 4.0},
             "c": {"paper": math.inf, "adaptive": math.inf, "bbht": math.inf}}
    relative = family_ratios(costs)
    assert relative["paper"] == {"a": 3.0, "b": math.inf}
    assert relative["adaptive"] == {"a": 1.0, "b": 1.25}
    assert relative["bbht"] == {"a": 2.0, "b": 1.0}


def test_one_bad_family_loses_to_a_policy_that_is_never_far_behind() -> None:
    """A candidate best on five families and 3x behind on one loses to one 1.3x behind everywhere:
    the rule is about the worst family, not the mean."""
    costs = {f"f{i}": {"paper": 13.0, "adaptive": 10.0, "bbht": 10.0 if i < 5 else 30.0} for i in range(6)}
    assert choose_by_worst_ratio(family_ratios(costs), ORDER) == "adaptive"


def test_a_near_tie_goes_to_the_lower_geometric_mean() -> None:
    """Worst ratios 1.30 and 1.33 (within 5 %): the geometric means decide."""
    relative = {"paper": {"a": 5.0, "b": 5.0}, "adaptive": {"a": 1.30, "b": 1.30},
                "bbht": {"a": 1.33, "b": 1.0}}
    assert choose_by_worst_ratio(relative, ORDER) == "bbht"


def test_a_gap_above_the_margin_is_not_a_tie() -> None:
    relative = {"adaptive": {"a": 1.30, "b": 1.30}, "bbht": {"a": 1.30 * TIE_MARGIN * 1.01, "b": 1.0}}
    assert choose_by_worst_ratio(relative, ORDER) == "adaptive"


def test_a_full_tie_goes_to_the_earlier_candidate() -> None:
    relative = {"paper": {"a": 1.2, "b": 1.0}, "bbht": {"a": 1.0, "b": 1.2}}
    assert choose_by_worst_ratio(relative, ORDER) == "paper"
    assert choose_by_worst_ratio(relative, ["bbht", "paper"]) == "bbht"


def test_a_candidate_that_solved_nothing_somewhere_has_an_infinite_worst_ratio() -> None:
    costs = {"a": {"adaptive": 10.0, "bbht": 1.0}, "b": {"adaptive": 10.0, "bbht": math.inf}}
    assert choose_by_worst_ratio(family_ratios(costs), ORDER) == "adaptive"


@pytest.mark.parametrize("relative", [{}, {"paper": {}}])
def test_no_ratio_no_choice(relative: dict) -> None:
    assert choose_by_worst_ratio(relative, ORDER) is None
