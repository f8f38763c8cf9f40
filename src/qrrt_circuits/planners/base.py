"""What every planner shares: the problem checks, the round loop, termination and the result.

Oracle calls are counted as DESIGN §2 says: classical planners 1 per reachability test; quantum
planners 1 per Grover iteration per worker plus 1 per classical verification of a measured
candidate. Every classical check of one candidate (the finalizer of the quantum planners, the
reachability test of the classical ones) is a ``verification_call``, so
``oracle_calls == quantum_oracle_calls + verification_calls`` for every planner. Evaluating all 2^n
entries to build the phase oracle in simulation is reported as ``simulation_checks``, not as oracle
calls.

A plan runs rounds until the goal is reached or its termination condition ends it
(``qrrt_circuits.planners.termination``); the condition is checked before each round, and a round limit
(``DEFAULT_MAX_ROUNDS``), a stall limit (``DEFAULT_STALL_ROUNDS``) and a node limit
(``DEFAULT_MAX_NODES``) are always in force unless the caller gives their own, so every plan ends.

Memory: a plan makes one check, before it allocates anything (``memory.PlanSize.check``): its tree
and round history up to the node and round limits in force and, for a quantum planner, one round at
its peak (``_round_memory``). Its searches make no check of their own. A ``MemoryError`` raised
while it runs is raised again as a one-line ``memory.OutOfMemory``.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from concurrent.futures import Executor
from typing import Any

import numpy as np

from .._support.memory import MemoryEstimate, OutOfMemory, PlanSize
from .._support.randomness import RandomStreams, Stream
from .._support.validation import check_float, check_instance, check_real_array, check_seed
from ..reachability.dynamics import LinearTrackingDynamics
from ..reachability.exact import ExactCheck
from ..reachability.oracle_errors import OracleErrorModel
from ..reachability.predicate import (
    ReachabilityPredicate,
    can_leave,
    check_predicate,
    check_within_space,
    valid_states,
)
from ..world.environment import Environment
from ..world.spaces import RealVectorSpace, StateSpace
from . import termination as _termination
from .context import RoundView, WorkerContext
from .goals import Goal, GoalBall, ball_of, check_goal, first_satisfying
from .result import Metrics, PlanResult
from .run_state import RunState
from .termination import (
    PlanStatus,
    TerminationCondition,
    from_budgets,
    limits_in_force,
    safety_limits,
    with_defaults,
)

__all__ = ["Metrics", "PlanResult", "Planner", "RunState"]


#: the members a state space must have (``world.spaces.StateSpace``)
SPACE_MEMBERS = ("dim", "distance", "interpolate", "nearest_neighbors", "check_bounds", "describe")


def check_space(space: Any, env: Environment) -> StateSpace:
    """``space`` if it implements ``StateSpace`` in ``env``'s dimension and accepts its bounds.

    Raises:
        TypeError: A member of ``SPACE_MEMBERS`` missing.
        ValueError: A dimension mismatch, or bounds the space refuses (``check_bounds``).
    """
    missing = [member for member in SPACE_MEMBERS if not hasattr(space, member)]
    if missing:
        raise TypeError(f"space must be a StateSpace (RealVectorSpace, SE2Space, ...); {type(space).__name__} lacks "
                        f"{', '.join(missing)}")
    if space.dim != env.dim:
        raise ValueError(f"dimension mismatch: the space has d = {space.dim}, the environment has d = {env.dim}")
    space.check_bounds(env.bounds)
    return space


def resolve_predicate(env: Environment, predicate: ReachabilityPredicate | None,
                      dynamics: LinearTrackingDynamics | None, resolution: float) -> ReachabilityPredicate:
    """The planner's predicate: ``predicate=``, else the sound ``ExactCheck`` built with
    ``dynamics`` and ``resolution``."""
    if predicate is None:
        if dynamics is not None:
            check_instance(dynamics, "dynamics", LinearTrackingDynamics, "a LinearTrackingDynamics")
            if dynamics.dim != env.dim:
                raise ValueError(f"dimension mismatch: the dynamics act in d = {dynamics.dim}, the environment "
                                 f"has d = {env.dim}")
        return ExactCheck(env, dynamics, resolution=resolution)
    if dynamics is not None:
        raise ValueError("give dynamics= or predicate=, not both (a predicate carries its own motion model)")
    check_predicate(predicate, env.dim)
    check_within_space(predicate, env.bounds)
    return predicate


class Planner:
    """Base class of the planners: checks the problem, runs rounds until the goal or the
    termination condition, and reports.

    Subclasses define one round (``_round``: the paper's Alg. 1-3), what their rounds carry from
    one to the next (``_start_rounds``) and their own settings; ``_run`` is the one round loop.
    ``RRT``, ``ParallelRRT``, ``QRRT`` and ``PQRRT`` document only their own arguments; the ones
    they share are documented here, once.

    Arguments every planner takes (all keyword-only after ``env``):

    Args:
        env: The ``Environment``: workspace bounds, obstacles and the default start, goal and goal
            radius.
        predicate: The ``ReachabilityPredicate`` that decides whether a child is reachable from its
            parent (its ``dim`` must equal ``env.dim``). Default: the sound ``ExactCheck``
            of ``env`` built with ``dynamics`` and ``resolution``.
        dynamics: A ``LinearTrackingDynamics`` (same ``dim`` as ``env``) for the default predicate;
            give it only without ``predicate`` (a predicate carries its own motion model). Default:
            ``LinearTrackingDynamics.paper()``.
        oracle_errors: An ``OracleErrorModel`` that corrupts the answers the algorithm sees (false
            positives and negatives): the reachability tests of the classical planners, the marks
            of the phase oracle of the quantum planners; or None (default) for exact answers. No
            wrong answer adds a node: a classical planner verifies a positive answer with the true
            predicate (one more verification call) before it adds the node, and a quantum
            planner's finalizer verifies every measured entry, so an error costs oracle calls only.
        goal_bias: Probability in [0, 1) that a sample is drawn in the goal ball instead of
            uniformly in the workspace. Default 0 (the paper's uniform sampling).
        max_extension: The longest step from a parent (OMPL's RRT ``range``): a candidate farther
            from its nearest node is moved toward it until the distance is ``max_extension``
            (``database.steer``), for the classical tests and the quantum databases alike. A finite
            number > 0, or None (default: the raw samples, as the paper's algorithms take them).
        space: The ``StateSpace`` whose metric picks nearest nodes and steers candidates
            (``world.spaces``: ``RealVectorSpace``, ``SE2Space``, or your own); its ``dim`` must
            be ``env.dim`` and it must accept ``env.bounds``. Default ``RealVectorSpace(env.dim)``
            (Euclidean, the paper's).
        resolution: Clearance of the default ``ExactCheck`` in length units (> 0, finite;
            default 0.01): a free trajectory is accepted if it passes farther than (1 + sqrt(d)) *
            resolution from every obstacle and 2 * resolution from the workspace boundary. Unused
            when ``predicate`` is given.
        seed: Non-negative integer seed of the keyed random streams (one generator per (round,
            worker, stream), so results do not depend on the executor or the order of the calls), or
            None (default) for fresh entropy.
        executor: ``ParallelRRT`` and ``PQRRT`` only: a ``concurrent.futures.Executor`` that runs
            the workers' tasks (a ``ParallelRRT`` worker's reachability test, a ``PQRRT``
            database's search), or None (default) to run them in-process, with the same results.
            Not pickled with the planner.

    Raises:
        TypeError: ``env`` not an ``Environment``, a non-integer ``seed``, a non-real
            ``goal_bias`` or ``resolution``, ``dynamics`` or ``oracle_errors`` of the wrong class,
            or a ``predicate`` that lacks the members of the ``ReachabilityPredicate`` protocol.
        ValueError: ``goal_bias`` outside [0, 1), a ``max_extension`` that is not finite and > 0, a
            negative ``seed``, a dimension mismatch
            between ``env`` and ``predicate`` or ``dynamics``, both ``predicate`` and ``dynamics``
            given, or, for the default predicate, a
            ``resolution`` that is not finite and > 0 or one too fine for the workspace
            (``ExactCheck``).
    """

    name = "planner"

    def __init__(
        self,
        env: Environment,
        *,
        predicate: ReachabilityPredicate | None = None,
        dynamics: LinearTrackingDynamics | None = None,
        oracle_errors: OracleErrorModel | None = None,
        goal_bias: float = 0.0,
        max_extension: float | None = None,
        space: StateSpace | None = None,
        resolution: float = 0.01,
        seed: int | None = None,
        executor: Executor | None = None,
    ) -> None:
        check_instance(env, "env", Environment, "an Environment")
        self.env = env
        self.predicate = resolve_predicate(env, predicate, dynamics, resolution)
        try:
            bias: float | None = check_float(goal_bias, "goal_bias", 0.0, 1.0)
        except ValueError:
            bias = None
        if bias is None or bias >= 1.0:  # one message for 1, 1.5, -0.5 and NaN: the range is [0, 1)
            raise ValueError(f"goal_bias must be a finite number in [0.0, 1.0), got {goal_bias!r}")
        self.goal_bias = bias
        self.max_extension = None if max_extension is None else check_float(
            max_extension, "max_extension", 0.0, open_minimum=True)
        self.space = RealVectorSpace(env.dim) if space is None else check_space(space, env)
        if oracle_errors is not None:
            check_instance(oracle_errors, "oracle_errors", OracleErrorModel, "an OracleErrorModel or None")
        self.oracle_errors = oracle_errors
        self.seed = check_seed(seed)
        self.streams = RandomStreams.from_seed(self.seed)
        self.executor = executor

    def rng(self, round_index: int, worker: int = 0, stream: int = Stream.CANDIDATES) -> np.random.Generator:
        """The generator of one (round, worker, stream): independent of call order and executor.

        Args:
            round_index: The round (>= 0).
            worker: The worker (>= 0, default 0).
            stream: A ``Stream`` number (default ``Stream.CANDIDATES``).

        Returns:
            The ``numpy.random.Generator`` of that key (``RandomStreams.generator``).

        Raises:
            ValueError: A negative key or an unknown stream number.
        """
        return self.streams.generator(round_index, worker, Stream(stream))

    def __getstate__(self) -> dict:
        """A planner pickles without its executor (executors do not travel)."""
        state = self.__dict__.copy()
        state["executor"] = None
        return state

    # ----------------------------------------------------------------- planning
    def plan(
        self,
        start: np.ndarray | None = None,
        goal: Goal | np.ndarray | None = None,
        goal_radius: float | None = None,
        max_oracle_calls: int | None = None,
        max_nodes: int | None = None,
        max_rounds: int | None = None,
        max_time_s: float | None = None,
        *,
        max_critical_path_calls: int | None = None,
        stall_rounds: int | None = None,
        termination: TerminationCondition | None = None,
    ) -> PlanResult:
        """Grow a tree from ``start`` until a node satisfies the goal (a node in the goal ball, as
        in the paper) or the termination condition ends the plan.

        The paper's Alg. 1 for RRT, Alg. 2 for q-RRT, Alg. 3 for Pq-RRT; Alg. 4 with an annealing
        schedule.

        The ``max_*`` and ``stall_rounds`` keywords are shorthands for the conditions of
        ``qrrt_circuits.planners.termination``; they combine (any of them ends the plan) with
        ``termination``. Safety limits are added so that every plan ends (``termination.safety_limits``):
        without a budget of the caller's, a round limit (``DEFAULT_MAX_ROUNDS``) and a stall limit
        (``DEFAULT_STALL_ROUNDS``); with one, none that could end the plan before it; and a node
        limit (``DEFAULT_MAX_NODES``) unless the condition has its own. A plan a safety limit ended
        says so (``PlanResult.safety_limit``). Before anything is allocated, the plan's
        estimated peak (its tree and round history up to the limits in force, and a quantum
        planner's round) is checked once against the available memory (``memory.PlanSize``).
        Conditions are checked before each round, so a round may overshoot an oracle-call budget
        by less than one round's cost.

        Args:
            start: Root of the tree, shape (d,); default the environment's start. A start on the
                workspace boundary, which the exact check can never leave, is refused.
            goal: A goal point, shape (d,) (default the environment's goal), the centre of a ball of
                ``goal_radius``; or any ``Goal`` (``GoalBall``, ``GoalState``, a region of your own
                with ``is_satisfied``): it needs ``sample`` where ``goal_bias > 0``, and a goal
                without volume (``GoalState``) needs ``goal_bias > 0``. A start that already
                satisfies the goal is reached at once.
            goal_radius: Radius of the goal ball (> 0) with a goal point; default the environment's.
                Not given with a ``Goal``.
            max_oracle_calls: End after this many oracle calls (DESIGN §2 counting).
            max_nodes: End once the tree has this many nodes besides the root.
            max_rounds: End after this many rounds.
            max_time_s: End after this much wall time (seconds).
            max_critical_path_calls: End after this many critical-path oracle calls (per round the
                largest of any worker: the time of p parallel quantum devices).
            stall_rounds: End after this many consecutive rounds without a new node.
            termination: Any ``TerminationCondition`` (compose them with ``|``).

        Returns:
            A frozen ``PlanResult``: ``status`` (``PlanStatus``: ``"reached"`` or the condition that
            ended the plan), the tree (``nodes``, ``parents``, ``tree``), ``path``, ``metrics``
            (oracle calls as DESIGN §2 counts them), ``history``, ``settings`` and ``labels`` (every
            simulation shortcut the numbers depend on).

        Raises:
            ValueError: A point outside the workspace or inside an obstacle, a start or goal the
                predicate's own validity check rejects (``is_valid``), a boundary start, a
                non-positive radius or budget, an estimated peak memory that exceeds the available
                memory (naming ``num_qubits``, ``max_nodes`` or ``max_rounds`` and the largest
                value that fits), or a dimension mismatch, before any work.
            TypeError: An argument of the wrong type (e.g. a ``termination`` that is not a
                ``TerminationCondition``).
            qrrt_circuits._support.memory.OutOfMemory: A ``MemoryError`` while the plan ran (one line: the
                size to lower, what the allocator reported, the largest smaller value whose
                estimate fits in the memory available when the plan started).
        """
        start, region = self._check_problem(start, goal, goal_radius)
        condition = from_budgets(max_oracle_calls, max_nodes, max_rounds, max_time_s,
                                 max_critical_path_calls, stall_rounds)
        if termination is not None:
            check_instance(termination, "termination", TerminationCondition, "a TerminationCondition")
            condition = termination if condition is None else termination | condition
        limits = limits_in_force(condition)
        defaults = (_termination.DEFAULT_MAX_ROUNDS, _termination.DEFAULT_STALL_ROUNDS, _termination.DEFAULT_MAX_NODES)
        safety = frozenset(limit.status for limit in safety_limits(condition, *defaults))
        condition = with_defaults(condition, *defaults)
        self._check_ready()
        round_estimate, num_qubits = self._round_memory()
        size = PlanSize(limits.node_limit, self._max_new_nodes_per_round(), limits.round_limit, self.env.dim,
                        round_estimate, num_qubits, default_nodes=limits.default_nodes,
                        default_rounds=limits.default_rounds)
        size.check()  # the plan's one memory check, before its first allocation
        try:
            return self._plan_checked(start, region, condition, safety)
        except OutOfMemory:
            raise
        except MemoryError as error:  # (its frames, and the plan's arrays, are released before the message)
            raise size.out_of_memory(error) from error

    def _plan_checked(self, start: np.ndarray, goal: Goal, condition: TerminationCondition,
                      safety: frozenset[PlanStatus]) -> PlanResult:
        """The plan after its checks: the run state, the rounds and the result (``safety``: the
        statuses of the safety limits added to the caller's condition)."""
        state = RunState(start, goal, self.space.nearest_neighbors())  # the plan's structure, chosen once
        state.context = self._context()
        self._start_rounds(state)
        began = time.perf_counter()
        status = self._run(state, condition, began)
        elapsed = time.perf_counter() - began
        return self._result(state, status, elapsed, start, goal, condition, status in safety)

    def _run(self, state: RunState, condition: TerminationCondition, began: float) -> PlanStatus:
        """The round loop: check the condition before every round, run the round, record it; until
        the goal or the end."""
        while state.goal_node is None:
            ended = condition.ended_by(state.progress(time.perf_counter() - began))
            if ended is not None:
                return ended
            self._round(state)
            state.end_round()
        return PlanStatus.REACHED

    def _check_problem(self, start: np.ndarray | None, goal: Goal | np.ndarray | None,
                       goal_radius: float | None) -> tuple[np.ndarray, Goal]:
        """The start as a point and the goal as a ``Goal``, each checked against the environment
        (bounds, obstacles) and the predicate's own validity check before any work."""
        env = self.env
        start = env.start if start is None else start
        if start is None:
            raise ValueError("start is required (the environment sets none)")
        start = self._checked_point("start", start)
        if isinstance(goal, Goal):  # a goal object: the goal radius belongs to a goal point
            if goal_radius is not None:
                raise ValueError("goal_radius is given with a goal point, not with a Goal object "
                                 f"({type(goal).__name__} carries its own extent)")
            region = check_goal(goal, env.dim, self.goal_bias)
            ball = ball_of(region)
            if ball is not None:  # a ball's centre (a goal state) must be a valid point
                self._checked_point("goal", ball[0])
        else:
            point = env.goal if goal is None else goal
            radius = env.goal_radius if goal_radius is None else goal_radius
            if point is None or radius is None:
                raise ValueError("goal and goal_radius are required (the environment sets none)")
            region = GoalBall(self._checked_point("goal", point), check_float(radius, "goal_radius", 0.0,
                                                                               open_minimum=True))
        reached = first_satisfying(region, start[None]) == 0  # a start in the goal ends at once
        if not reached and not can_leave(self.predicate, start):
            raise ValueError(
                f"start {start.tolist()} lies on the workspace boundary {env.bounds.tolist()}: the "
                f"{self.predicate.name} check rejects every motion from it, so no node could ever be "
                "added (move the start inside the workspace)")
        return start, region

    def _checked_point(self, name: str, point: Any) -> np.ndarray:
        """``point`` as d finite coordinates inside the bounds, free of the environment's obstacles
        and valid under the predicate's own validity check (``is_valid``)."""
        env = self.env
        if point is None or isinstance(point, str | bytes):
            raise ValueError(f"{name} must be {env.dim} numbers, got {point!r}")
        try:
            point = check_real_array(point, name).reshape(-1)  # booleans and strings refused
        except ValueError as exc:
            raise ValueError(f"{name} must be {env.dim} numbers, got {point!r}") from exc
        if point.shape != (env.dim,):
            raise ValueError(
                f"dimension mismatch: {name} has {point.shape[0]} coordinates, the environment "
                f"has d = {env.dim}"
            )
        if not np.all(np.isfinite(point)):
            raise ValueError(f"{name} must be finite, got {point.tolist()}")
        if not env.in_bounds(point):
            raise ValueError(f"{name} {point.tolist()} is out of bounds {env.bounds.tolist()}")
        if not env.is_free(point):
            raise ValueError(f"{name} {point.tolist()} is in collision with an obstacle")
        if not valid_states(self.predicate, point[None])[0]:
            raise ValueError(f"{name} {point.tolist()} is not a valid state: the {self.predicate.name} "
                             f"check's own validity check (is_valid) rejects it")
        return np.array(point, dtype=float)

    def _check_ready(self) -> None:
        """Subclasses validate their own settings before any work."""

    def _max_new_nodes_per_round(self) -> int:
        """The most nodes one round can add (1 here; p for p workers): the bound the memory check
        (``memory.PlanSize``) sizes the tree by."""
        return 1

    def _round_memory(self) -> tuple[Callable[[int], MemoryEstimate] | None, int]:
        """What the plan's memory check adds for one round: (its ``MemoryEstimate`` as a function
        of n, the plan's n); (None, 0) here, a plan without databases."""
        return None, 0

    def _start_rounds(self, state: RunState) -> None:
        """Set up, once per plan, what the rounds carry from one to the next (the quantum planners'
        policy state, the classical planners' tests made ahead); nothing here."""

    def _round(self, state: RunState) -> None:
        raise NotImplementedError

    def _context(self) -> WorkerContext:
        """What workers need for this plan (subclasses add their backend, schedule, sizes)."""
        return WorkerContext(self.env, self.predicate, self.streams, self.goal_bias, self.oracle_errors,
                             max_extension=self.max_extension, space=self.space)

    def _view(self, state: RunState, temperature_index: int = 0) -> RoundView:
        return RoundView(state.tree, state.neighbors, state.goal, state.rounds, temperature_index,
                         state.policy_state)

    # ----------------------------------------------------------------- reporting
    def settings(self) -> dict:
        """Everything that fixes this planner's answers (JSON-able; recorded in the result)."""
        predicate = self.predicate.describe()
        return {"planner": self.name, "seed": self.seed, "goal_bias": self.goal_bias,
                "max_extension": self.max_extension, "space": self.space.describe(), "predicate": predicate,
                "dynamics": predicate.get("dynamics"),
                "oracle_errors": None if self.oracle_errors is None else self.oracle_errors.describe()}

    def labels(self) -> tuple[str, ...]:
        """Every simulation shortcut this planner's numbers depend on (copied into each result).

        Returns:
            Label sentences (none for the base class).
        """
        return ()

    def _result(self, state: RunState, status: PlanStatus, elapsed: float, start: np.ndarray, goal: Goal,
                condition: TerminationCondition, safety_limit: bool = False) -> PlanResult:
        tree = state.tree
        path = None
        if state.goal_node is not None:
            chain = [state.goal_node]
            while tree.parents[chain[-1]] >= 0:
                chain.append(int(tree.parents[chain[-1]]))
            path = tree.nodes[chain[::-1]].copy()
        metrics = Metrics(
            oracle_calls=state.oracle_calls,
            quantum_oracle_calls=state.quantum_calls,
            verification_calls=state.verification_calls,
            critical_path_oracle_calls=state.critical_path,
            simulation_checks=state.simulation_checks,
            nodes=state.nodes,
            rounds=state.rounds,
            databases=state.databases,
            duplicates=state.duplicates,
            rejected=state.rejected,
            wall_time_s=elapsed,
            wasted_checks=state.wasted_checks,
        )
        ball = ball_of(goal)
        settings = self.settings() | {"start": start.tolist(), "goal": None if ball is None else ball[0].tolist(),
                                      "goal_radius": None if ball is None else ball[1],
                                      "goal_region": goal.describe(), "termination": condition.describe(),
                                      "environment": self.env.name}
        history = {key: np.asarray(value, dtype=np.int64) for key, value in state.history.items()}
        return PlanResult(
            status=status,
            nodes=tree.nodes.copy(),
            parents=tree.parents.copy(),
            path=path,
            metrics=metrics,
            planner=self.name,
            settings=settings,
            labels=self.labels(),
            history=history,
            goal_node=state.goal_node,
            safety_limit=safety_limit,
        )

