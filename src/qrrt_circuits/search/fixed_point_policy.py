"""``FixedPointAmplification``: a search policy that cannot overshoot (Yoder, Low and Chuang, PRL
113, 210501, 2014; circuits and phases in ``search/fixed_point.py``).

Every worker runs the same sequence of l generalized Grover iterates, chosen once from the target
error ``delta`` and the lower bound ``min_fraction`` = w on the marked fraction, then measures
once and verifies its measurement. For every database whose marked fraction is at least w, one
measurement is marked with probability P_L(f) >= 1 - delta^2 (L = 2l + 1); unlike k standard
Grover iterations, more marked entries never make it worse. Below w there is no guarantee.

Oracle calls per worker and database (DESIGN §2): l quantum calls (one per iterate) + 1
verification, so ``oracle_calls = (l + 1) x workers`` per shared database. As with the other
policies that fix their circuit before measuring, one backend call with ``shots = workers``
stands for the workers' independent preparations.
"""

from __future__ import annotations

from dataclasses import dataclass

from .fixed_point import (
    LENGTH_RULES,
    IterateSequence,
    check_delta,
    check_fraction,
    fixed_point_iterates,
    fixed_point_success_probability,
)
from .policies import IterationPolicy, PolicyState
from .problem import DatabaseSearch, SearchOutcome

__all__ = ["FixedPointAmplification", "FixedPointState"]


@dataclass(frozen=True)
class FixedPointAmplification(IterationPolicy):
    """Fixed-point amplitude amplification: P(marked) >= 1 - delta^2 for every marked fraction
    >= ``min_fraction``. ``length_rule``: ``"paper"`` (L >= log(2/delta)/sqrt(w), Yoder et al.) or
    ``"tight"`` (the smallest L with the same guarantee)."""

    delta: float = 0.5
    min_fraction: float = 0.05
    length_rule: str = "paper"
    name = "fixed-point"

    def __post_init__(self) -> None:
        check_delta(self.delta)
        check_fraction(self.min_fraction)
        if self.length_rule not in LENGTH_RULES:
            raise ValueError(f"length_rule must be one of {LENGTH_RULES}, got {self.length_rule!r}")

    @property
    def iterates(self) -> int:
        """l, the generalized iterates (oracle calls) per worker."""
        return fixed_point_iterates(self.delta, self.min_fraction, self.length_rule)

    def sequence(self) -> IterateSequence:
        return IterateSequence.fixed_point(self.delta, self.iterates)

    def success_probability(self, fraction: float) -> float:
        """P_L(f) for this policy's sequence (Yoder et al.)."""
        return fixed_point_success_probability(self.delta, self.iterates, fraction)

    def _iterations(self, num_items: int, tree_nodes: int, num_marked: int | None) -> int:
        return self.iterates

    def start(self, num_items: int) -> FixedPointState:
        return FixedPointState(self, num_items)

    def describe(self) -> str:
        return (f"fixed-point (delta {self.delta}, min fraction {self.min_fraction}: {self.iterates} "
                f"generalized iterates, P >= {1 - self.delta ** 2:.3g} for f >= {self.min_fraction})")


class FixedPointState(PolicyState):
    """Every worker: the fixed-point sequence, one measurement, one verification."""

    policy: FixedPointAmplification

    def __init__(self, policy: FixedPointAmplification, num_items: int) -> None:
        super().__init__(policy, num_items)
        self.sequence = policy.sequence()

    def run(self, problem: DatabaseSearch, workers: int, tree_nodes: int) -> tuple[SearchOutcome, ...]:
        calls = self.sequence.oracle_calls
        outcomes = []
        for measured in problem.search_sequence(self.sequence, workers, problem.shared_seed()):
            good = problem.verify(int(measured))
            outcomes.append(SearchOutcome(int(measured) if good else None, calls, 1))
        return tuple(outcomes)
