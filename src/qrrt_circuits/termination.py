"""When a plan stops: composable termination conditions and the plan's status.

Modelled on OMPL's ``PlannerTerminationCondition`` (``plannerOrTerminationCondition``): a
condition looks at the plan's progress before each round and either lets the round start or names
itself; ``a | b`` ends the plan when either ends it, and the status says which one did.

Conditions are checked *before* each round, so the last round may overshoot an oracle-call budget
by less than one round's cost and a node budget by fewer than ``workers`` nodes (the paper's
cut-offs behave the same way).

Every plan terminates: ``Planner.plan`` always adds ``MaxRounds(DEFAULT_MAX_ROUNDS)`` unless the
condition it is given already limits rounds, and ``Stall(DEFAULT_STALL_ROUNDS)`` unless it already
has a stall condition, so a plan that can add no node (a start boxed in) ends as ``"stalled"``.
"""

from __future__ import annotations

import abc
from dataclasses import dataclass
from enum import StrEnum

from .validation import check_int, check_positive_float

#: the round limit in force whenever the caller gives none
DEFAULT_MAX_ROUNDS = 20000
#: consecutive rounds without a new node that end a plan whenever the caller gives no stall limit.
#: Large enough never to cut a plan that is still growing in our experiments: at the smallest
#: per-round success rate measured there (RRT, about 0.7 % in 1000-box worlds) 5000 failures in a
#: row have probability 0.993^5000 < 1e-15.
DEFAULT_STALL_ROUNDS = 5000


class PlanStatus(StrEnum):
    """Why a plan ended: the goal was reached, or the name of the condition that ended it.

    A ``StrEnum``: ``result.status == "reached"`` works, and it is written to JSON and CSV as its
    value.
    """

    REACHED = "reached"
    MAX_ORACLE_CALLS = "max_oracle_calls"
    MAX_CRITICAL_PATH_CALLS = "max_critical_path_calls"
    MAX_NODES = "max_nodes"
    MAX_ROUNDS = "max_rounds"
    MAX_TIME = "max_time_s"
    STALLED = "stalled"

    @property
    def reached(self) -> bool:
        return self is PlanStatus.REACHED


@dataclass(frozen=True)
class Progress:
    """What the conditions may look at: the plan's counters before the next round."""

    oracle_calls: int
    critical_path_oracle_calls: int
    nodes: int
    rounds: int
    rounds_without_new_node: int
    elapsed_s: float


class TerminationCondition(abc.ABC):
    """Decides, before each round, whether the plan ends; ``a | b`` combines two."""

    @abc.abstractmethod
    def ended_by(self, progress: Progress) -> PlanStatus | None:
        """The status if this condition ends the plan now, else None."""

    @abc.abstractmethod
    def describe(self) -> dict:
        """The condition as JSON-able settings (recorded in ``PlanResult.settings``)."""

    @property
    def limits_rounds(self) -> bool:
        """Whether this condition alone guarantees the plan ends (bounds the number of rounds)."""
        return False

    @property
    def detects_stall(self) -> bool:
        """Whether this condition ends a plan that stopped adding nodes."""
        return False

    def __or__(self, other: TerminationCondition) -> AnyOf:
        if not isinstance(other, TerminationCondition):
            return NotImplemented
        return AnyOf((self, other))


@dataclass(frozen=True)
class _Limit(TerminationCondition):
    limit: int
    status = PlanStatus.MAX_ROUNDS

    def __post_init__(self) -> None:
        check_int(self.limit, f"{type(self).__name__}.limit", 1)

    def _value(self, progress: Progress) -> float:
        raise NotImplementedError

    def ended_by(self, progress: Progress) -> PlanStatus | None:
        return self.status if self._value(progress) >= self.limit else None

    def describe(self) -> dict:
        return {str(self.status): self.limit}


@dataclass(frozen=True)
class MaxOracleCalls(_Limit):
    """Ends the plan once ``oracle_calls`` (quantum + verification) reach ``limit``."""

    status = PlanStatus.MAX_ORACLE_CALLS

    def _value(self, progress: Progress) -> float:
        return progress.oracle_calls


@dataclass(frozen=True)
class MaxCriticalPathCalls(_Limit):
    """Ends the plan once the critical-path oracle calls (per round the largest count of one
    worker: the time of p parallel quantum devices) reach ``limit``."""

    status = PlanStatus.MAX_CRITICAL_PATH_CALLS

    def _value(self, progress: Progress) -> float:
        return progress.critical_path_oracle_calls


@dataclass(frozen=True)
class MaxNodes(_Limit):
    """Ends the plan once the tree holds ``limit`` nodes (root excluded)."""

    status = PlanStatus.MAX_NODES

    def _value(self, progress: Progress) -> float:
        return progress.nodes


@dataclass(frozen=True)
class MaxRounds(_Limit):
    """Ends the plan after ``limit`` rounds."""

    status = PlanStatus.MAX_ROUNDS

    def _value(self, progress: Progress) -> float:
        return progress.rounds

    @property
    def limits_rounds(self) -> bool:
        return True


@dataclass(frozen=True)
class Stall(_Limit):
    """Ends the plan when ``limit`` consecutive rounds added no node."""

    status = PlanStatus.STALLED

    def _value(self, progress: Progress) -> float:
        return progress.rounds_without_new_node

    def describe(self) -> dict:
        return {"stall_rounds": self.limit}

    @property
    def detects_stall(self) -> bool:
        return True


@dataclass(frozen=True)
class MaxWallTime(TerminationCondition):
    """Ends the plan once ``seconds`` of wall-clock time have passed (not reproducible: prefer
    the other conditions in experiments and tests)."""

    seconds: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "seconds", check_positive_float(self.seconds, "max_time_s"))

    def ended_by(self, progress: Progress) -> PlanStatus | None:
        return PlanStatus.MAX_TIME if progress.elapsed_s >= self.seconds else None

    def describe(self) -> dict:
        return {"max_time_s": self.seconds}


@dataclass(frozen=True)
class AnyOf(TerminationCondition):
    """Ends the plan when any of ``conditions`` does; the first one (in order) names the status."""

    conditions: tuple[TerminationCondition, ...]

    def __post_init__(self) -> None:
        flat: list[TerminationCondition] = []
        for condition in self.conditions:
            if not isinstance(condition, TerminationCondition):
                raise TypeError(f"AnyOf takes TerminationCondition objects, got {type(condition).__name__}")
            flat.extend(condition.conditions if isinstance(condition, AnyOf) else (condition,))
        if not flat:
            raise ValueError("AnyOf needs at least one condition")
        object.__setattr__(self, "conditions", tuple(flat))

    def ended_by(self, progress: Progress) -> PlanStatus | None:
        for condition in self.conditions:
            status = condition.ended_by(progress)
            if status is not None:
                return status
        return None

    def describe(self) -> dict:
        out: dict = {}
        for condition in self.conditions:
            out.update(condition.describe())
        return out

    @property
    def limits_rounds(self) -> bool:
        return any(condition.limits_rounds for condition in self.conditions)

    @property
    def detects_stall(self) -> bool:
        return any(condition.detects_stall for condition in self.conditions)


def from_budgets(max_oracle_calls: int | None = None, max_nodes: int | None = None,
                 max_rounds: int | None = None, max_time_s: float | None = None,
                 max_critical_path_calls: int | None = None,
                 stall_rounds: int | None = None) -> TerminationCondition | None:
    """The condition the ``plan()`` keyword shorthands stand for (None if none is given)."""
    parts: list[TerminationCondition] = []
    if max_oracle_calls is not None:
        parts.append(MaxOracleCalls(check_int(max_oracle_calls, "max_oracle_calls", 1)))
    if max_critical_path_calls is not None:
        parts.append(MaxCriticalPathCalls(check_int(max_critical_path_calls, "max_critical_path_calls", 1)))
    if max_nodes is not None:
        parts.append(MaxNodes(check_int(max_nodes, "max_nodes", 1)))
    if max_rounds is not None:
        parts.append(MaxRounds(check_int(max_rounds, "max_rounds", 1)))
    if stall_rounds is not None:
        parts.append(Stall(check_int(stall_rounds, "stall_rounds", 1)))
    if max_time_s is not None:
        parts.append(MaxWallTime(max_time_s))
    if not parts:
        return None
    return parts[0] if len(parts) == 1 else AnyOf(tuple(parts))


def with_defaults(condition: TerminationCondition | None, default_max_rounds: int | None = None,
                  default_stall_rounds: int | None = None) -> TerminationCondition:
    """``condition`` with ``MaxRounds(DEFAULT_MAX_ROUNDS)`` added unless it already limits rounds,
    and ``Stall(DEFAULT_STALL_ROUNDS)`` unless it already has a stall condition: the guarantee
    that every plan ends, and soon when it cannot grow."""
    rounds = DEFAULT_MAX_ROUNDS if default_max_rounds is None else default_max_rounds
    stall = DEFAULT_STALL_ROUNDS if default_stall_rounds is None else default_stall_rounds
    parts = [] if condition is None else [condition]
    if condition is None or not condition.limits_rounds:
        parts.append(MaxRounds(rounds))
    if condition is None or not condition.detects_stall:
        parts.append(Stall(stall))
    return parts[0] if len(parts) == 1 else AnyOf(tuple(parts))


def with_round_limit(condition: TerminationCondition | None,
                     default_max_rounds: int = DEFAULT_MAX_ROUNDS) -> TerminationCondition:
    """``condition`` with ``MaxRounds(default_max_rounds)`` added unless it already limits rounds."""
    if condition is None:
        return MaxRounds(default_max_rounds)
    if condition.limits_rounds:
        return condition
    return condition | MaxRounds(default_max_rounds)
