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
from typing import Any, ClassVar

import numpy as np

from .._support.memory import MemoryEstimate, OutOfMemory, PlanSize
from .._support.randomness import RandomStreams, Stream
from .._support.validation import check_instance
from ..problems.goals import check_reachable_by
from ..problems.problem import Problem
from . import termination as _termination
from .context import RoundView, WorkerContext
from .options import PlannerOptions
from .result import Metrics, PlanResult
from .run_state import FLOAT_HISTORY_KEYS, RunState
from .termination import (
    PlanStatus,
    Progress,
    TerminationCondition,
    from_budgets,
    limits_in_force,
    safety_limits,
    with_defaults,
)

__all__ = ["Metrics", "PlanResult", "Planner", "RunState"]


class Planner:
    """Base class of the planners: an algorithm with its settings (``options``) that plans any
    ``Problem`` in rounds until the goal or the termination condition, and reports.

    Subclasses define one round (``_round``: the paper's Alg. 1-3), what their rounds carry from
    one to the next (``_start_rounds``) and their options class (``Options``: every setting
    declared once, with its check and help; ``planners.options``); ``_run`` is the one round loop.

    Args:
        options: The planner's ``Options``, whole; or None (default) to build them from
            ``keywords``.
        executor: ``ParallelRRT`` and ``PQRRT`` only: a ``concurrent.futures.Executor`` that runs
            the workers' tasks (a ``ParallelRRT`` worker's reachability test, a ``PQRRT``
            database's search), or None (default) to run them in-process, with the same results.
            Not pickled with the planner.
        **keywords: The options one by one (``QRRT(num_qubits=6, seed=0)``); see ``Options``.

    Raises:
        TypeError: An option this planner does not take (naming it and the ones it takes), options
            of another planner's class, options and keywords both given, or an option of the wrong
            type.
        ValueError: An option out of its range (naming it and the range).
    """

    name = "planner"
    #: the planner's options class: every setting it takes, declared once
    Options: ClassVar[type[PlannerOptions]] = PlannerOptions
    #: whether the planner takes an ``executor``
    takes_executor: ClassVar[bool] = False

    def __init__(self, options: PlannerOptions | None = None, /, *, executor: Executor | None = None,
                 **keywords: Any) -> None:
        if options is None:
            options = self.Options.create(self.name, **keywords)
        else:  # (a problem or an environment given here belongs to plan)
            check_instance(options, "options", self.Options,
                           f"{self.Options.__name__} (the options of {self.name}; the problem is plan's argument)")
            if keywords:
                raise TypeError(f"give {self.name} its options or keywords, not both (got options and "
                                f"{', '.join(sorted(keywords))})")
        if executor is not None and not self.takes_executor:
            raise TypeError(f"{self.name} does not take executor= (its rounds have one task)")
        self.options = self._complete(options)
        self.streams = RandomStreams.from_seed(self.options.seed)
        self.executor = executor

    def _complete(self, options: Any) -> Any:
        """The options with the planner's own defaults filled in (none here)."""
        return options

    @property
    def seed(self) -> int | None:
        """The seed of the planner's random streams."""
        return self.options.seed

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
        problem: Problem,
        termination: TerminationCondition | None = None,
        *,
        max_oracle_calls: int | None = None,
        max_nodes: int | None = None,
        max_rounds: int | None = None,
        max_time_s: float | None = None,
        max_critical_path_calls: int | None = None,
        stall_rounds: int | None = None,
        on_round: Callable[[Progress], None] | None = None,
    ) -> PlanResult:
        """Grow a tree from the problem's start until a node satisfies its goal (a node in the goal
        ball, as in the paper) or the termination condition ends the plan (OMPL's ``solve(ptc)``).

        The paper's Alg. 1 for RRT, Alg. 2 for q-RRT, Alg. 3 for Pq-RRT; Alg. 4 with an annealing
        schedule.

        The keyword budgets are shorthands for the conditions of
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
            problem: The ``Problem`` (world, state space, motion check, start and goal; checked
                when it was built). A start that already satisfies the goal is reached at once.
            termination: Any ``TerminationCondition`` (compose them with ``|``), or None.
            max_oracle_calls: End after this many oracle calls (DESIGN §2 counting).
            max_nodes: End once the tree has this many nodes besides the root.
            max_rounds: End after this many rounds.
            max_time_s: End after this much wall time (seconds).
            max_critical_path_calls: End after this many critical-path oracle calls (per round the
                largest of any worker: the time of p parallel quantum devices).
            stall_rounds: End after this many consecutive rounds without a new node.
            on_round: Called after every round (after every block of rounds a planner runs at
                once: RRT's rounds tested ahead) with the plan's counters (``Progress``): an
                observer for a progress display (``qrrt plan`` passes one); it cannot change the
                plan, and None (default) calls nothing.

        Returns:
            A frozen ``PlanResult``: ``status`` (``PlanStatus``: ``"reached"`` or the condition that
            ended the plan), the tree (``nodes``, ``parents``, ``tree``), ``path``, ``metrics``
            (oracle calls as DESIGN §2 counts them), ``history``, ``settings`` and ``labels`` (every
            simulation shortcut the numbers depend on).

        Raises:
            TypeError: A ``problem`` that is not a ``Problem``, a ``termination`` that is not a
                ``TerminationCondition``, a budget of the wrong type, or a goal without ``sample``
                with ``goal_bias > 0``.
            ValueError: A non-positive budget, a goal without volume with ``goal_bias == 0``, a
                setting this problem cannot serve, or an estimated peak memory that exceeds the
                available memory (naming ``num_qubits``, ``max_nodes`` or ``max_rounds`` and the
                largest value that fits), before any work.
            qrrt_circuits._support.memory.OutOfMemory: A ``MemoryError`` while the plan ran (one line: the
                size to lower, what the allocator reported, the largest smaller value whose
                estimate fits in the memory available when the plan started).
        """
        check_instance(problem, "problem", Problem, "a Problem (qrrt_circuits.Problem.build(env, start, goal, "
                                                    "goal_radius), a scenario or a problem family)")
        self._check_goal(problem)
        condition = from_budgets(max_oracle_calls, max_nodes, max_rounds, max_time_s,
                                 max_critical_path_calls, stall_rounds)
        if termination is not None:
            check_instance(termination, "termination", TerminationCondition, "a TerminationCondition")
            condition = termination if condition is None else termination | condition
        limits = limits_in_force(condition)
        defaults = (_termination.DEFAULT_MAX_ROUNDS, _termination.DEFAULT_STALL_ROUNDS, _termination.DEFAULT_MAX_NODES)
        safety = frozenset(limit.status for limit in safety_limits(condition, *defaults))
        condition = with_defaults(condition, *defaults)
        self._check_serves(problem)
        round_estimate, num_qubits = self._round_memory(problem.dim)
        size = PlanSize(limits.node_limit, self._max_new_nodes_per_round(), limits.round_limit, problem.dim,
                        round_estimate, num_qubits, default_nodes=limits.default_nodes,
                        default_rounds=limits.default_rounds)
        size.check()  # the plan's one memory check, before its first allocation
        try:
            return self._plan_checked(problem, condition, safety, on_round)
        except OutOfMemory:
            raise
        except MemoryError as error:  # (its frames, and the plan's arrays, are released before the message)
            raise size.out_of_memory(error) from error

    def _plan_checked(self, problem: Problem, condition: TerminationCondition,
                      safety: frozenset[PlanStatus], on_round: Callable[[Progress], None] | None = None) -> PlanResult:
        """The plan after its checks: the run state, the rounds and the result (``safety``: the
        statuses of the safety limits added to the caller's condition; ``on_round``: the observer
        called after every round)."""
        state = RunState(problem.start, problem.goal, problem.space.nearest_neighbors())  # chosen once a plan
        state.context = self._context(problem)
        self._start_rounds(state)
        began = time.perf_counter()
        status = self._run(state, condition, began, on_round)
        elapsed = time.perf_counter() - began
        return self._result(state, status, elapsed, problem, condition, status in safety)

    def _run(self, state: RunState, condition: TerminationCondition, began: float,
             on_round: Callable[[Progress], None] | None = None) -> PlanStatus:
        """The round loop: check the condition before every round, run the round, record it (and
        show it to ``on_round``); until the plan is finished or its condition ends it."""
        while not self._finished(state):
            progress = state.progress(time.perf_counter() - began)
            ended = condition.ended_by(progress)
            if ended is not None:
                return self._status(state, ended)
            self._rounds(state, condition, progress)
            if on_round is not None:
                on_round(state.progress(time.perf_counter() - began))
        return PlanStatus.REACHED

    def _rounds(self, state: RunState, condition: TerminationCondition, progress: Progress) -> None:
        """Run and record (``RunState.end_round``) one round or more, all but the last adding no
        node, each one that ``condition`` lets start (``termination.rounds_that_start`` from
        ``progress``, the counters now, which it let start); here one ``_round``."""
        self._round(state)
        state.end_round()

    def _finished(self, state: RunState) -> bool:
        """Whether the plan is done before its condition ends it: here once a node satisfies the
        goal (an anytime planner, q-RRT*, runs until its condition)."""
        return state.goal_node is not None

    def _status(self, state: RunState, ended: PlanStatus) -> PlanStatus:
        """The status of a plan its condition ended (``ended``, here; an anytime planner that holds
        a solution reports it reached)."""
        return ended

    def _check_goal(self, problem: Problem) -> None:
        """Refuse a goal this planner cannot end in (``check_reachable_by``: one with ``sample``
        where ``goal_bias > 0``, and one with volume where ``goal_bias == 0``)."""
        check_reachable_by(problem.goal, self.options.goal_bias)

    def _check_serves(self, problem: Problem) -> None:
        """Refuse, before any work, a problem this planner's settings cannot serve (none here)."""

    def _max_new_nodes_per_round(self) -> int:
        """The most nodes one round can add (1 here; p for p workers): the bound the memory check
        (``memory.PlanSize``) sizes the tree by."""
        return 1

    def _round_memory(self, dim: int) -> tuple[Callable[[int], MemoryEstimate] | None, int]:
        """What the plan's memory check adds for one round in dimension ``dim``: (its
        ``MemoryEstimate`` as a function of n, the plan's n); (None, 0) here, a plan without
        databases."""
        return None, 0

    def _start_rounds(self, state: RunState) -> None:
        """Set up, once per plan, what the rounds carry from one to the next (the quantum planners'
        policy state, the classical planners' tests made ahead); nothing here."""

    def _round(self, state: RunState) -> None:
        raise NotImplementedError

    def _context(self, problem: Problem) -> WorkerContext:
        """What workers need for this plan (subclasses add their backend, schedule, sizes)."""
        return WorkerContext(problem.env, problem.predicate, problem.space, self.streams, self.options.goal_bias,
                             self.options.oracle_errors, max_extension=self.options.max_extension)

    def _view(self, state: RunState, temperature_index: int = 0) -> RoundView:
        return RoundView(state.tree, state.neighbors, state.goal, state.rounds, temperature_index,
                         state.policy_state)

    # ----------------------------------------------------------------- reporting
    def settings(self) -> dict:
        """Everything of the planner's that fixes its answers: its name and options (JSON-able;
        recorded in every result beside the problem's parts)."""
        return {"planner": self.name} | self.options.describe()

    def miss_reason(self) -> str:
        """Why a candidate this planner tests can fail its check, in one clause (``qrrt plan``
        prints it when most candidates failed): here, a random sample's motion from its nearest
        node is blocked."""
        return "a random sample's motion from its nearest node is blocked"

    def labels(self) -> tuple[str, ...]:
        """Every simulation shortcut this planner's numbers depend on (copied into each result).

        Returns:
            Label sentences (none for the base class).
        """
        return ()

    def _result(self, state: RunState, status: PlanStatus, elapsed: float, problem: Problem,
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
        predicate = problem.predicate.describe()
        settings = self.settings() | problem.describe() | {
            "space": problem.space.describe(), "predicate": predicate, "dynamics": predicate.get("dynamics"),
            "termination": condition.describe()}
        history = {key: np.asarray(value, dtype=np.float64 if key in FLOAT_HISTORY_KEYS else np.int64)
                   for key, value in state.history.items()}
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
            second_tree=self._second_tree(state),
        )

    def _second_tree(self, state: RunState) -> tuple[np.ndarray, np.ndarray] | None:
        """A bidirectional planner's second tree (its nodes and parents), or None (here)."""
        return None

