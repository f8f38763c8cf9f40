"""``FixedPointAmplification``: a search policy that cannot overshoot (Yoder, Low and Chuang, PRL
113, 210501, 2014; circuits and phases in ``search/iterate_sequence.py``).

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

from ..iterate_sequence import (
    LENGTH_RULES,
    IterateSequence,
    check_delta,
    check_fraction,
    fixed_point_iterates,
    fixed_point_success_probability,
)
from ..problem import DatabaseSearch, SearchOutcome
from ..requests import MAX_ITERATIONS
from .base import IterationPolicy, PolicyState

__all__ = ["FixedPointAmplification", "FixedPointState"]


@dataclass(frozen=True)
class FixedPointAmplification(IterationPolicy):
    """Fixed-point amplitude amplification: P(marked) >= 1 - delta^2 for every marked fraction >= w.

    Yoder, Low and Chuang, "Fixed-point quantum search with an optimal number of queries", PRL 113,
    210501 (2014). Replaces the fixed Grover iteration count of the paper's Alg. 2 / 3 worker by
    l generalized iterates that cannot overshoot: the success probability P_L(f) (L = 2l + 1) is at
    least 1 - delta^2 for every marked fraction f >= w, where Eq. 1's k iterations need the true m.
    Cost per worker and database (DESIGN §2): l quantum oracle calls + 1 verification.

    Args:
        delta: Target error, in (0, 1) (default 0.5: P >= 0.75).
        min_fraction: w, the lower bound on the marked fraction m/N that the guarantee covers, in
            (0, 1] (default 0.05).
        length_rule: ``"paper"`` (the smallest L = 2l + 1 >= log(2/delta)/sqrt(w), Yoder et al.; the
            default) or ``"tight"`` (the smallest L with the same guarantee).

    Raises:
        TypeError: A non-real ``delta`` or ``min_fraction``.
        ValueError: ``delta`` outside (0, 1), ``min_fraction`` outside (0, 1], an unknown
            ``length_rule``, or more than ``MAX_ITERATIONS`` iterates (a small ``min_fraction``).

    Example:
        >>> from qrrt_circuits import FixedPointAmplification
        >>> policy = FixedPointAmplification(delta=0.5, min_fraction=0.05)
        >>> policy.iterates  # the smallest l with 2l + 1 >= log(2/0.5) / sqrt(0.05)
        3
        >>> round(policy.success_probability(0.05), 4), round(policy.success_probability(0.5), 4)
        (0.9003, 0.906)
    """

    delta: float = 0.5
    min_fraction: float = 0.05
    length_rule: str = "paper"
    name = "fixed-point"
    runs_sequences = True

    def __post_init__(self) -> None:
        check_delta(self.delta)
        check_fraction(self.min_fraction)
        if self.length_rule not in LENGTH_RULES:
            raise ValueError(f"length_rule must be one of {LENGTH_RULES}, got {self.length_rule!r}")
        if self.iterates > MAX_ITERATIONS:  # refused here, not at the plan's first search
            raise ValueError(
                f"delta = {self.delta} and min_fraction = {self.min_fraction} need l = {self.iterates} iterates "
                f"per search, more than the {MAX_ITERATIONS} a search runs (MAX_ITERATIONS): raise min_fraction "
                "or delta")

    @property
    def iterates(self) -> int:
        """l, the generalized iterates (quantum oracle calls) per worker and database
        (``fixed_point_iterates(delta, min_fraction, length_rule)``)."""
        return fixed_point_iterates(self.delta, self.min_fraction, self.length_rule)

    def sequence(self) -> IterateSequence:
        """The phases of the l generalized iterates (Yoder et al.), as ``IterateSequence``.

        Returns:
            ``IterateSequence.fixed_point(delta, iterates)``.
        """
        return IterateSequence.fixed_point(self.delta, self.iterates)

    def success_probability(self, fraction: float) -> float:
        """Probability that one measurement is marked after this policy's sequence (Yoder et al.).

        Args:
            fraction: f = m/N, the database's marked fraction.

        Returns:
            P_L(f) = 1 - delta^2 T_L(T_(1/L)(1/delta) sqrt(1 - f))^2 (T: Chebyshev polynomials),
            >= 1 - delta^2 for f >= ``min_fraction``.
        """
        return fixed_point_success_probability(self.delta, self.iterates, fraction)

    def _iterations(self, num_items: int, tree_nodes: int, num_marked: int | None) -> int:
        return self.iterates

    def iterations_bound(self, num_items: int) -> int:
        """l, the generalized iterates of every search (``runs_sequences``)."""
        return self.iterates

    def start(self, num_items: int) -> FixedPointState:
        return FixedPointState(self, num_items)

    def miss_reason(self) -> str:
        return ("fixed-point amplification guarantees P >= 1 - delta^2 only for m/N >= min_fraction; "
                "databases with fewer reachable entries miss more")

    def describe(self) -> str:
        return (f"fixed-point (delta {self.delta}, min fraction {self.min_fraction}: {self.iterates} "
                f"generalized iterates, P >= {1 - self.delta ** 2:.3g} for f >= {self.min_fraction})")


class FixedPointState(PolicyState):
    """Per-plan state: every worker runs the fixed-point sequence, measures once and verifies.

    Args:
        policy: The ``FixedPointAmplification`` policy.
        num_items: N, the entries of each database.
    """

    policy: FixedPointAmplification

    def __init__(self, policy: FixedPointAmplification, num_items: int) -> None:
        super().__init__(policy, num_items)
        self.sequence = policy.sequence()

    def run(self, problem: DatabaseSearch, workers: int, tree_nodes: int) -> tuple[SearchOutcome, ...]:
        """``workers`` workers search one database with the fixed-point sequence.

        One backend call with ``shots = workers`` stands for the workers' independent preparations;
        each worker verifies its own measurement.

        Args:
            problem: The database search.
            workers: Number p of workers (>= 1).
            tree_nodes: Nodes in the tree so far (unused).

        Returns:
            One ``SearchOutcome`` per worker: the verified index or None, l quantum calls and 1
            verification.
        """
        calls = self.sequence.oracle_calls
        outcomes = []
        for measured in problem.search_sequence(self.sequence, workers, problem.shared_seed()):
            good = problem.verify(int(measured))
            outcomes.append(SearchOutcome(int(measured) if good else None, calls, 1))
        return tuple(outcomes)
