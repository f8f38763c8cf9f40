"""When a plan stops: composable termination conditions and the plan's status.

Modelled on OMPL's ``PlannerTerminationCondition`` (``plannerOrTerminationCondition``): a
condition looks at the plan's progress before each round and either lets the round start or names
itself; ``a | b`` ends the plan when either ends it, and the status says which one did.

Conditions are checked *before* each round, so the last round may overshoot an oracle-call budget
by less than one round's cost and a node budget by fewer than ``workers`` nodes (the paper's
cut-offs behave the same way). The planner checks its condition before every round, as OMPL does;
a condition whose test is costly caches inside itself. Rounds a planner has ready (classical tests
made ahead) are checked on the counters they will start from (``rounds_that_start``), all at once,
so a wall-time limit is checked again before the next round that does work.

Every plan terminates: ``Planner.plan`` adds the ``safety_limits`` the caller's condition lacks.
Without a budget (oracle calls, critical-path calls, rounds or wall time: ``is_budget``) those are
``MaxRounds(DEFAULT_MAX_ROUNDS)`` and ``Stall(DEFAULT_STALL_ROUNDS)``, so a plan that can add no
node (a start boxed in) ends as ``"stalled"``. With a budget, the budget ends the plan: no stall
limit is added, and the round limit, if any, lies beyond what the budget allows. ``MaxNodes
(DEFAULT_MAX_NODES)`` is added unless the condition limits nodes, so no plan's tree outgrows memory
(``memory.PlanSize.check`` checks the limits in force before the first round). A plan a safety
limit ended says so (``PlanResult.safety_limit``, ``PlanResult.status_text``).
"""

from __future__ import annotations

import abc
import math
from collections.abc import Iterable
from dataclasses import dataclass
from enum import StrEnum
from typing import ClassVar, NamedTuple

from .._support.validation import check_int, check_positive_float

#: the round limit in force whenever the caller gives none
DEFAULT_MAX_ROUNDS = 20000
#: consecutive rounds without a new node that end a plan whenever the caller gives no stall limit.
#: Large enough not to cut a plan that is still growing: at a per-round success rate of 0.7 % (RRT
#: in 1000-box worlds, the lowest of the library's experiments) 5000 failures in a row have
#: probability 0.993^5000 < 1e-15.
DEFAULT_STALL_ROUNDS = 5000
#: the node limit in force whenever the caller gives none. Without it the round limit alone bounds
#: the tree: a round of 4 096 parallel-RRT workers adds up to 4 096 nodes, so 20 000 rounds of a
#: plan whose goal is walled in could make about 80 million nodes (about 14 GiB at d = 2 by the
#: memory guard's estimate, ``memory.plan_bytes``). A million nodes take about 180 MiB by that
#: estimate, far beyond any tree of the paper's experiments (thousands of nodes).
DEFAULT_MAX_NODES = 1_000_000


class PlanStatus(StrEnum):
    """Why a plan ended: the goal was reached, or the name of the condition that ended it.

    A ``StrEnum``: ``result.status == "reached"`` works, and it is written to JSON and CSV as its
    value. ``REACHED`` is the goal; each other member is the status of one condition
    (``MaxOracleCalls``, ``MaxCriticalPathCalls``, ``MaxNodes``, ``MaxRounds``, ``MaxWallTime``,
    ``Stall``).

    Example:
        >>> from qrrt_circuits.planners.termination import PlanStatus
        >>> PlanStatus.MAX_NODES == "max_nodes", str(PlanStatus.STALLED)
        (True, 'stalled')
        >>> PlanStatus("reached").reached
        True
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
        """Whether this is ``REACHED`` (the goal was reached)."""
        return self is PlanStatus.REACHED


class Progress(NamedTuple):
    """What the conditions may look at: the plan's counters before the next round (immutable).

    Args:
        oracle_calls: Oracle calls so far (quantum + verification, DESIGN §2).
        critical_path_oracle_calls: Critical-path oracle calls so far (per round the largest count
            of one worker).
        nodes: Nodes in the tree, root excluded.
        rounds: Rounds run so far.
        rounds_without_new_node: Consecutive rounds, up to now, that added no node.
        elapsed_s: Wall-clock seconds since the plan started.
    """

    oracle_calls: int
    critical_path_oracle_calls: int
    nodes: int
    rounds: int
    rounds_without_new_node: int
    elapsed_s: float


class TerminationCondition(abc.ABC):
    """Decides, before each round, whether the plan ends; ``a | b`` combines two.

    Modelled on OMPL's ``PlannerTerminationCondition``. A subclass implements ``ended_by`` (the
    ``PlanStatus`` it ends the plan with, or None) and ``describe`` (its JSON-able settings).
    ``a | b`` is ``AnyOf((a, b))``: the plan ends as soon as either ends it, and the first one in
    order that does names the status.

    Example:
        >>> from qrrt_circuits.planners.termination import MaxNodes, MaxOracleCalls, Progress
        >>> condition = MaxOracleCalls(1000) | MaxNodes(50)
        >>> condition
        AnyOf(conditions=(MaxOracleCalls(limit=1000), MaxNodes(limit=50)))
        >>> condition.describe()
        {'max_oracle_calls': 1000, 'max_nodes': 50}
        >>> progress = Progress(oracle_calls=1200, critical_path_oracle_calls=300, nodes=10,
        ...                     rounds=40, rounds_without_new_node=0, elapsed_s=1.0)
        >>> condition.ended_by(progress)
        <PlanStatus.MAX_ORACLE_CALLS: 'max_oracle_calls'>
    """

    @abc.abstractmethod
    def ended_by(self, progress: Progress) -> PlanStatus | None:
        """The status if this condition ends the plan now, else None.

        Args:
            progress: The plan's counters before the next round.

        Returns:
            The ``PlanStatus`` naming this condition if it ends the plan, else None.
        """

    @abc.abstractmethod
    def describe(self) -> dict:
        """The condition as JSON-able settings (recorded in ``PlanResult.settings``).

        Returns:
            A dict from the condition's name (``"max_nodes"``, ``"stall_rounds"``, ...) to its limit.
        """

    @property
    def limits_rounds(self) -> bool:
        """Whether this condition alone guarantees the plan ends (bounds the number of rounds)."""
        return False

    @property
    def detects_stall(self) -> bool:
        """Whether this condition ends a plan that stopped adding nodes."""
        return False

    @property
    def node_limit(self) -> int | None:
        """The node count at which this condition ends the plan, if it sets one (else None). A
        user's condition that reports one must end the plan there: the default node limit is not
        added then, and the memory check trusts it."""
        return None

    @property
    def round_limit(self) -> int | None:
        """The round count at which this condition ends the plan, if it sets one (else None)."""
        return None

    @property
    def is_budget(self) -> bool:
        """Whether this condition is a budget that ends every plan by itself (oracle calls,
        critical-path calls, rounds or wall time): the safety limits ``with_defaults`` adds then
        never end the plan before it."""
        return False

    @property
    def budget_rounds(self) -> int | None:
        """For a budget on work (oracle calls, critical-path calls or rounds), the most rounds it
        lets a plan run when every round makes at least one oracle call; else None."""
        return None

    def __or__(self, other: TerminationCondition) -> AnyOf:
        """``AnyOf((self, other))``: ends the plan when either does (nested ``AnyOf`` flattened)."""
        if not isinstance(other, TerminationCondition):
            return NotImplemented
        return AnyOf((self, other))


@dataclass(frozen=True)
class _Limit(TerminationCondition):
    limit: int
    status = PlanStatus.MAX_ROUNDS

    def __post_init__(self) -> None:  # kept as a Python int (a numpy integer wrapped in limit arithmetic)
        object.__setattr__(self, "limit", check_int(self.limit, f"{type(self).__name__}.limit", 1))

    #: the ``Progress`` field this limit counts
    counter: ClassVar[str] = "rounds"

    def ended_by(self, progress: Progress) -> PlanStatus | None:
        return self.status if getattr(progress, self.counter) >= self.limit else None

    def describe(self) -> dict:
        return {str(self.status): self.limit}


@dataclass(frozen=True)
class _WorkBudget(_Limit):
    """A budget on work (rounds, or oracle calls: every round makes at least one), so it ends a plan
    within ``limit`` rounds (``budget_rounds``)."""

    @property
    def is_budget(self) -> bool:
        """True: a budget on work."""
        return True

    @property
    def budget_rounds(self) -> int:
        """``limit``: a round is one round, and makes at least one (critical-path) oracle call."""
        return self.limit


@dataclass(frozen=True)
class MaxOracleCalls(_WorkBudget):
    """Ends the plan once ``oracle_calls`` (quantum + verification) reach ``limit``.

    Status ``PlanStatus.MAX_ORACLE_CALLS``. Checked before each round, so the last round may
    overshoot ``limit`` by less than one round's cost.

    Args:
        limit: The oracle-call budget (DESIGN §2 counting), an integer >= 1.

    Raises:
        TypeError: A non-integer ``limit``.
        ValueError: ``limit`` < 1.

    Example:
        >>> from qrrt_circuits.planners.termination import MaxOracleCalls
        >>> MaxOracleCalls(500).describe()
        {'max_oracle_calls': 500}
    """

    status = PlanStatus.MAX_ORACLE_CALLS

    counter = "oracle_calls"


@dataclass(frozen=True)
class MaxCriticalPathCalls(_WorkBudget):
    """Ends the plan once the critical-path oracle calls (per round the largest count of one
    worker: the time of p parallel quantum devices) reach ``limit``.

    Status ``PlanStatus.MAX_CRITICAL_PATH_CALLS``.

    Args:
        limit: The critical-path oracle-call budget, an integer >= 1.

    Raises:
        TypeError: A non-integer ``limit``.
        ValueError: ``limit`` < 1.
    """

    status = PlanStatus.MAX_CRITICAL_PATH_CALLS

    counter = "critical_path_oracle_calls"


@dataclass(frozen=True)
class MaxNodes(_Limit):
    """Ends the plan once the tree holds ``limit`` nodes (root excluded).

    Status ``PlanStatus.MAX_NODES``. A round of p workers may add up to p nodes, so the tree may end
    with up to p - 1 nodes more than ``limit``.

    Args:
        limit: The node budget, an integer >= 1.

    Raises:
        TypeError: A non-integer ``limit``.
        ValueError: ``limit`` < 1.
    """

    status = PlanStatus.MAX_NODES

    counter = "nodes"

    @property
    def node_limit(self) -> int:
        """``limit``."""
        return self.limit


@dataclass(frozen=True)
class MaxRounds(_WorkBudget):
    """Ends the plan after ``limit`` rounds.

    Status ``PlanStatus.MAX_ROUNDS``; it bounds the number of rounds (``limits_rounds`` is True), so
    ``with_defaults`` adds no other round limit.

    Args:
        limit: The round budget, an integer >= 1.

    Raises:
        TypeError: A non-integer ``limit``.
        ValueError: ``limit`` < 1.
    """

    status = PlanStatus.MAX_ROUNDS

    counter = "rounds"

    @property
    def limits_rounds(self) -> bool:
        """True: a round limit."""
        return True

    @property
    def round_limit(self) -> int:
        """``limit``."""
        return self.limit


@dataclass(frozen=True)
class Stall(_Limit):
    """Ends the plan when ``limit`` consecutive rounds added no node.

    Status ``PlanStatus.STALLED``; described as ``{"stall_rounds": limit}``.

    Args:
        limit: Consecutive rounds without a new node that end the plan, an integer >= 1.

    Raises:
        TypeError: A non-integer ``limit``.
        ValueError: ``limit`` < 1.

    Example:
        >>> from qrrt_circuits.planners.termination import Progress, Stall
        >>> stuck = Progress(oracle_calls=0, critical_path_oracle_calls=0, nodes=0, rounds=5,
        ...                  rounds_without_new_node=3, elapsed_s=0.0)
        >>> Stall(3).ended_by(stuck)
        <PlanStatus.STALLED: 'stalled'>
    """

    status = PlanStatus.STALLED

    counter = "rounds_without_new_node"

    def describe(self) -> dict:
        return {"stall_rounds": self.limit}

    @property
    def detects_stall(self) -> bool:
        """True: a stall limit."""
        return True


@dataclass(frozen=True)
class MaxWallTime(TerminationCondition):
    """Ends the plan once ``seconds`` of wall-clock time have passed (not reproducible: prefer
    the other conditions in experiments and tests).

    Status ``PlanStatus.MAX_TIME``; described as ``{"max_time_s": seconds}``.

    Args:
        seconds: The wall-clock budget in seconds, a finite real number > 0.

    Raises:
        TypeError: A non-real ``seconds``.
        ValueError: ``seconds`` not finite or not > 0.
    """

    seconds: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "seconds", check_positive_float(self.seconds, "max_time_s"))

    def ended_by(self, progress: Progress) -> PlanStatus | None:
        return PlanStatus.MAX_TIME if progress.elapsed_s >= self.seconds else None

    def describe(self) -> dict:
        return {"max_time_s": self.seconds}

    @property
    def is_budget(self) -> bool:
        """True: a wall-clock budget ends every plan."""
        return True


@dataclass(frozen=True)
class AnyOf(TerminationCondition):
    """Ends the plan when any of ``conditions`` does; the first one (in order) names the status.

    What ``a | b`` builds (OMPL's ``plannerOrTerminationCondition``). Nested ``AnyOf`` are
    flattened (a subclass of ``AnyOf`` stays one part: it may have a test of its own);
    ``describe`` merges the parts' settings; ``limits_rounds`` and ``detects_stall`` hold if they
    hold for any part.

    Args:
        conditions: The ``TerminationCondition`` objects, at least one.

    Raises:
        TypeError: An element that is not a ``TerminationCondition``.
        ValueError: No condition.

    Example:
        >>> from qrrt_circuits.planners.termination import AnyOf, MaxNodes, MaxRounds, Stall
        >>> AnyOf((MaxNodes(50) | MaxRounds(100), Stall(10))).conditions
        (MaxNodes(limit=50), MaxRounds(limit=100), Stall(limit=10))
    """

    conditions: tuple[TerminationCondition, ...]

    def __post_init__(self) -> None:
        flat: list[TerminationCondition] = []
        for condition in self.conditions:
            if not isinstance(condition, TerminationCondition):
                raise TypeError(f"AnyOf takes TerminationCondition objects, got {type(condition).__name__}")
            # (an AnyOf subclass stays a part: it may have a test of its own)
            flat.extend(condition.conditions if type(condition) is AnyOf else (condition,))
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
        """The parts' settings merged; where two parts set the same limit of this module (the
        keys of ``_LIMIT_KEYS``), the smaller finite number (the one that ends the plan); for any
        other key the last part's value."""
        out: dict = {}
        for condition in self.conditions:
            for key, value in condition.describe().items():
                if key not in _LIMIT_KEYS or key not in out:
                    out[key] = value
                elif _is_real(out[key]) and _is_real(value):
                    out[key] = min(out[key], value)
                elif _is_real(value):  # a user's part that described a limit key with a non-number
                    out[key] = value
        return out

    @property
    def limits_rounds(self) -> bool:
        """Whether any part limits rounds."""
        return any(condition.limits_rounds for condition in self.conditions)

    @property
    def detects_stall(self) -> bool:
        """Whether any part detects a stall."""
        return any(condition.detects_stall for condition in self.conditions)

    @property
    def node_limit(self) -> int | None:
        """The smallest node limit of the parts (None if none sets one)."""
        return _smallest(checked_limit(part, "node_limit") for part in self.conditions)

    @property
    def round_limit(self) -> int | None:
        """The smallest round limit of the parts (None if none sets one)."""
        return _smallest(checked_limit(part, "round_limit") for part in self.conditions)

    @property
    def is_budget(self) -> bool:
        """Whether any part is a budget."""
        return any(condition.is_budget for condition in self.conditions)

    @property
    def budget_rounds(self) -> int | None:
        """The smallest ``budget_rounds`` of the parts (None if none sets one)."""
        return _smallest(checked_limit(part, "budget_rounds") for part in self.conditions)


#: the ``describe`` keys of this module's limits (a smaller value ends a plan sooner)
_LIMIT_KEYS = frozenset({"max_oracle_calls", "max_critical_path_calls", "max_nodes", "max_rounds", "max_time_s",
                         "stall_rounds"})


def _is_real(value: object) -> bool:
    """A finite real number (``bool``, NaN and infinities excluded)."""
    return isinstance(value, int | float) and not isinstance(value, bool) and math.isfinite(value)


def _smallest(limits: Iterable[int | None]) -> int | None:
    present = [limit for limit in limits if limit is not None]
    return min(present) if present else None


def checked_limit(condition: TerminationCondition, which: str) -> int | None:
    """``condition.node_limit``, ``condition.round_limit`` or ``condition.budget_rounds``
    (``which``), checked: None or an integer >= 1 (a user's own condition may return anything).

    Args:
        condition: A ``TerminationCondition``.
        which: ``"node_limit"``, ``"round_limit"`` or ``"budget_rounds"``.

    Returns:
        None, or the limit as a Python int.

    Raises:
        TypeError: A limit that is not None or an integer.
        ValueError: A limit < 1.
    """
    value = getattr(condition, which)
    return None if value is None else check_int(value, f"{type(condition).__name__}.{which}", 1)


@dataclass(frozen=True)
class LimitsInForce:
    """The node and round limits a plan runs under once the defaults are added (``with_defaults``),
    and whether each is the default one (the caller's condition set none)."""

    node_limit: int
    round_limit: int | None
    default_nodes: bool
    default_rounds: bool


def limits_in_force(given: TerminationCondition | None) -> LimitsInForce:
    """The ``LimitsInForce`` of a plan given ``given`` (None: no condition): what ``Planner.plan``
    checks against the available memory (``memory.PlanSize.check``) before its first round.

    Example:
        >>> from qrrt_circuits.planners.termination import MaxNodes, limits_in_force
        >>> limits_in_force(MaxNodes(50))
        LimitsInForce(node_limit=50, round_limit=20000, default_nodes=False, default_rounds=True)
    """
    condition = with_defaults(given)
    node_limit = checked_limit(condition, "node_limit")
    assert node_limit is not None  # with_defaults adds one
    return LimitsInForce(node_limit, checked_limit(condition, "round_limit"),
                         given is None or checked_limit(given, "node_limit") is None,
                         given is None or not given.limits_rounds)


def from_budgets(max_oracle_calls: int | None = None, max_nodes: int | None = None,
                 max_rounds: int | None = None, max_time_s: float | None = None,
                 max_critical_path_calls: int | None = None,
                 stall_rounds: int | None = None) -> TerminationCondition | None:
    """The condition the ``plan()`` keyword shorthands stand for (None if none is given).

    Args:
        max_oracle_calls: ``MaxOracleCalls`` limit (integer >= 1) or None.
        max_nodes: ``MaxNodes`` limit (integer >= 1) or None.
        max_rounds: ``MaxRounds`` limit (integer >= 1) or None.
        max_time_s: ``MaxWallTime`` seconds (finite, > 0) or None.
        max_critical_path_calls: ``MaxCriticalPathCalls`` limit (integer >= 1) or None.
        stall_rounds: ``Stall`` limit (integer >= 1) or None.

    Returns:
        None if every argument is None, the one condition if one is given, else their ``AnyOf``
        (in the order oracle calls, critical path, nodes, rounds, stall, time).

    Raises:
        TypeError: A non-integer count or a non-real ``max_time_s``.
        ValueError: A count < 1, or a ``max_time_s`` that is not finite and > 0.

    Example:
        >>> from qrrt_circuits.planners.termination import from_budgets
        >>> from_budgets(max_nodes=50, max_rounds=100)
        AnyOf(conditions=(MaxNodes(limit=50), MaxRounds(limit=100)))
        >>> from_budgets() is None
        True
    """
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


def safety_limits(condition: TerminationCondition | None, default_max_rounds: int | None = None,
                  default_stall_rounds: int | None = None,
                  default_max_nodes: int | None = None) -> tuple[MaxRounds | Stall | MaxNodes, ...]:
    """The safety limits ``Planner.plan`` adds to the caller's ``condition`` so that every plan ends,
    soon when it cannot grow, with a tree of bounded size; none of them ends a plan before a budget
    of the caller's (``is_budget``).

    - A round limit unless ``condition`` limits rounds: ``MaxRounds(default_max_rounds)`` without a
      budget; with a budget on oracle or critical-path calls B, ``MaxRounds(max(default, B + 1))``,
      which only a plan whose rounds make no oracle call can reach first; none with a wall-clock
      budget alone (it ends the plan itself).
    - ``Stall(default_stall_rounds)`` unless ``condition`` detects a stall or is a budget.
    - ``MaxNodes(default_max_nodes)`` unless ``condition`` limits nodes: the memory bound, which a
      plan with a budget can also reach (its status then says so, ``PlanResult.safety_limit``).

    Args:
        condition: The caller's condition, or None.
        default_max_rounds: The round limit; None means ``DEFAULT_MAX_ROUNDS``.
        default_stall_rounds: The stall limit; None means ``DEFAULT_STALL_ROUNDS``.
        default_max_nodes: The node limit; None means ``DEFAULT_MAX_NODES``.

    Returns:
        The limits to add, in the order rounds, stall, nodes (possibly none).

    Raises:
        TypeError: A non-integer default that has to be added.
        ValueError: A default < 1 that has to be added.

    Example:
        >>> from qrrt_circuits.planners.termination import MaxNodes, MaxOracleCalls, safety_limits
        >>> safety_limits(MaxNodes(50))
        (MaxRounds(limit=20000), Stall(limit=5000))
        >>> safety_limits(MaxOracleCalls(100000))
        (MaxRounds(limit=100001), MaxNodes(limit=1000000))
    """
    def default(value: int | None, fallback: int, name: str) -> int:
        return fallback if value is None else check_int(value, name, 1)

    budget = condition is not None and condition.is_budget
    added: list[MaxRounds | Stall | MaxNodes] = []
    if condition is None or not condition.limits_rounds:
        rounds = default(default_max_rounds, DEFAULT_MAX_ROUNDS, "default_max_rounds")
        bound = None if condition is None else checked_limit(condition, "budget_rounds")
        if not budget:
            added.append(MaxRounds(rounds))
        elif bound is not None:
            added.append(MaxRounds(max(rounds, bound + 1)))
    if not budget and (condition is None or not condition.detects_stall):
        added.append(Stall(default(default_stall_rounds, DEFAULT_STALL_ROUNDS, "default_stall_rounds")))
    if condition is None or checked_limit(condition, "node_limit") is None:
        added.append(MaxNodes(default(default_max_nodes, DEFAULT_MAX_NODES, "default_max_nodes")))
    return tuple(added)


def with_defaults(condition: TerminationCondition | None, default_max_rounds: int | None = None,
                  default_stall_rounds: int | None = None,
                  default_max_nodes: int | None = None) -> TerminationCondition:
    """``condition`` with its ``safety_limits`` added: the guarantee that every plan ends, soon when
    it cannot grow and with a tree of bounded size, never before a budget of the caller's.

    Args:
        condition: The caller's condition, or None.
        default_max_rounds: The round limit to add; None means ``DEFAULT_MAX_ROUNDS``.
        default_stall_rounds: The stall limit to add; None means ``DEFAULT_STALL_ROUNDS``.
        default_max_nodes: The node limit to add; None means ``DEFAULT_MAX_NODES``.

    Returns:
        ``condition`` itself if no limit is added, else an ``AnyOf`` with the limits appended.

    Raises:
        TypeError: A non-integer default that has to be added.
        ValueError: A default < 1 that has to be added.

    Example:
        >>> from qrrt_circuits.planners.termination import MaxNodes, with_defaults
        >>> with_defaults(MaxNodes(50))
        AnyOf(conditions=(MaxNodes(limit=50), MaxRounds(limit=20000), Stall(limit=5000)))
        >>> with_defaults(None).node_limit
        1000000
    """
    parts: list[TerminationCondition] = [] if condition is None else [condition]
    parts.extend(safety_limits(condition, default_max_rounds, default_stall_rounds, default_max_nodes))
    return parts[0] if len(parts) == 1 else AnyOf(tuple(parts))


def with_round_limit(condition: TerminationCondition | None,
                     default_max_rounds: int = DEFAULT_MAX_ROUNDS) -> TerminationCondition:
    """``condition`` with ``MaxRounds(default_max_rounds)`` added unless it already limits rounds.

    Args:
        condition: The caller's condition, or None.
        default_max_rounds: The round limit to add (default ``DEFAULT_MAX_ROUNDS``).

    Returns:
        ``MaxRounds(default_max_rounds)`` for None, ``condition`` if it limits rounds, else
        ``condition | MaxRounds(default_max_rounds)``.

    Raises:
        TypeError: A non-integer ``default_max_rounds`` that has to be added.
        ValueError: A ``default_max_rounds`` < 1 that has to be added.

    Example:
        >>> from qrrt_circuits.planners.termination import MaxNodes, with_round_limit
        >>> with_round_limit(MaxNodes(50), 100)
        AnyOf(conditions=(MaxNodes(limit=50), MaxRounds(limit=100)))
    """
    if condition is None:
        return MaxRounds(default_max_rounds)
    if condition.limits_rounds:
        return condition
    return condition | MaxRounds(default_max_rounds)


def rounds_that_start(condition: TerminationCondition, progress: Progress, growth: Progress, ready: int) -> int:
    """How many of ``ready`` rounds start before ``condition`` ends the plan, when each round but
    the last adds no node and grows the counters by ``growth`` (``nodes`` unchanged, ``elapsed_s``
    unused): the rounds checking the condition before each would run.

    The first always starts (the caller checked ``progress``); round k + 1 starts if
    ``condition.ended_by`` lets it start from the counters after k rounds.

    Args:
        condition: The plan's condition.
        progress: The counters before the first of the rounds.
        growth: What one of the rounds adds to each counter.
        ready: Rounds ready to run (>= 1).

    Returns:
        An integer in [1, ready].

    Example:
        >>> from qrrt_circuits.planners.termination import MaxOracleCalls, Progress, rounds_that_start
        >>> now = Progress(oracle_calls=10, critical_path_oracle_calls=10, nodes=3, rounds=10,
        ...                rounds_without_new_node=2, elapsed_s=0.0)
        >>> growth = Progress(1, 1, 0, 1, 1, 0.0)
        >>> rounds_that_start(MaxOracleCalls(13), now, growth, 8)  # rounds from 10, 11, 12 calls
        3
    """
    calls, critical, nodes, rounds, idle, elapsed = progress
    for started in range(1, ready):
        after = Progress(calls + started * growth.oracle_calls,
                         critical + started * growth.critical_path_oracle_calls, nodes,
                         rounds + started * growth.rounds, idle + started * growth.rounds_without_new_node, elapsed)
        if condition.ended_by(after) is not None:
            return started
    return ready
