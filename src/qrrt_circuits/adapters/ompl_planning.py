"""OMPL problems planned by the library's planners, and those planners as OMPL planners (needs the
``ompl`` extra, OMPL >= 2.0).

- **In**: ``problem_from_setup(setup)`` reads an ``ompl.geometric.SimpleSetup`` on a
  ``RealVectorStateSpace`` as a ``Problem``: an ``Environment`` with the space's bounds (no boxes:
  every check goes to OMPL), an ``OMPLMotionPredicate`` asking the setup's motion validator and
  validity checker, the setup's start and the goal (``GoalState`` for OMPL's goal state, else an
  ``OMPLGoalRegion`` asking ``isSatisfied`` and drawing with ``sampleGoal`` where OMPL can).
- **Out**: ``LibraryPlanner(si, planner, name)`` is an ``ompl.base.Planner``: ``SimpleSetup.solve``
  runs any planner of the library on the setup's problem, ends it when OMPL's termination
  condition says so and stores the path as OMPL's solution; ``last_result`` keeps the
  ``PlanResult`` (oracle calls counted as DESIGN §2 says).
- **Benchmark logs**: ``benchmark_log`` runs OMPL's planners and the library's on one setup, one
  run after another in this thread, and writes OMPL's benchmark log format, which OMPL's
  ``ompl_benchmark_statistics`` reads into the SQLite database Planner Arena shows. The library's
  runs carry ``oracle calls`` and ``critical path oracle calls``; runs carry ``motion checks`` where
  they are counted (the library's planners; OMPL's on a ``PredicateMotionValidator``, which
  ``setup_from_problem`` installs to plan the library's problems on the same checks) and every run
  ``validity checks``. ``ompl.tools.Benchmark`` itself is not used: the wheel of OMPL 2.0.1 runs each
  planner in a worker thread and crashes when that thread calls Python (a Python planner, or a
  Python validity checker beside OMPL's own planners).
"""

from __future__ import annotations

import platform
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, cast

import numpy as np

from .._support.validation import check_float, check_instance, check_int
from ..planners.base import Planner
from ..planners.result import PlanResult
from ..planners.termination import PlanStatus, Progress, TerminationCondition
from ..problems.goals import Goal, GoalState, ball_of
from ..problems.problem import Problem
from ..reachability.predicate import ReachabilityPredicate
from ..world.environment import Environment
from ..world.spaces import RealVectorSpace
from .ompl import INSTALL_HINT, OMPLMotionPredicate, real_vector_space

try:
    import ompl
    from ompl import base as ob
    from ompl import geometric as og
except ImportError as exc:  # pragma: no cover - the same hint as adapters.ompl
    raise ImportError(f"qrrt_circuits.adapters.ompl_planning needs the OMPL Python bindings; install them with "
                      f"{INSTALL_HINT}") from exc

__all__ = ["LibraryPlanner", "OMPLGoalRegion", "OMPLTermination", "PredicateMotionValidator",
           "benchmark_log", "problem_from_setup", "setup_from_problem"]

def _coordinates(state: Any, dim: int) -> np.ndarray:
    return np.array([state[axis] for axis in range(dim)], dtype=float)


def _state(si: ob.SpaceInformation, point: np.ndarray) -> Any:
    state = si.allocState()  # owned by Python (never si.freeState)
    for axis, value in enumerate(point.tolist()):
        state[axis] = value
    return state


class OMPLGoalRegion:
    """An OMPL goal region as a ``Goal``: ``isSatisfied`` per state; ``sampleGoal`` where OMPL's
    goal can draw states (a ``GoalSampleableRegion`` that ``couldSample``).

    Args:
        goal: An ``ompl.base.Goal``.
        si: Its ``SpaceInformation`` (real-vector states of dimension ``dim``).
        dim: d.
    """

    has_volume = True

    def __init__(self, goal: ob.Goal, si: ob.SpaceInformation, dim: int) -> None:
        self.goal, self.si, self.dim = goal, si, dim
        if goal.hasType(ob.GoalType.GOAL_SAMPLEABLE_REGION) and goal.couldSample():
            self.sample = self._sample

    def is_satisfied(self, points: np.ndarray) -> np.ndarray:
        points = np.atleast_2d(points)
        return np.array([self.goal.isSatisfied(_state(self.si, point)) for point in points], dtype=bool)

    def _sample(self, count: int, rng: np.random.Generator) -> np.ndarray:
        """``count`` states from OMPL's ``sampleGoal`` (OMPL's own random generator: not seeded by
        the plan's seed)."""
        state = self.si.allocState()
        out = np.empty((count, self.dim))
        for row in range(count):
            self.goal.sampleGoal(state)
            out[row] = _coordinates(state, self.dim)
        return out

    def describe(self) -> dict:
        return {"kind": "ompl", "type": type(self.goal).__name__}


def problem_from_definition(pdef: ob.ProblemDefinition, name: str = "ompl") -> Problem:
    """The ``Problem`` of an OMPL ``ProblemDefinition``: an environment with the space's bounds
    and no boxes (every check goes to OMPL), the ``OMPLMotionPredicate`` of its ``SpaceInformation``,
    R^d, its one start state and its goal (``GoalState`` for a goal state, else
    ``OMPLGoalRegion``).

    Args:
        pdef: The problem definition.
        name: The environment's and predicate's name.

    Returns:
        The problem.

    Raises:
        ValueError: No valid start state, more than one start state (the planners grow one tree
            from one root), no goal, a state space other than a real-vector space, or what
            ``Problem`` refuses.
    """
    si = pdef.getSpaceInformation()
    predicate = OMPLMotionPredicate(si, name=name)
    inputs = ob.PlannerInputStates()  # (pdef.getStartState hands Python a state pdef still owns)
    inputs.use(pdef)
    first = inputs.nextStart()
    if first is None:
        raise ValueError("the OMPL problem has no valid start state (setStartState)")
    if inputs.nextStart() is not None:  # the planners grow one tree from one root
        raise ValueError(f"the OMPL problem has {pdef.getStartStateCount()} start states; the library's planners "
                         "grow one tree from one start: accepted is a problem with exactly one start state")
    goal = pdef.getGoal()
    if goal is None:
        raise ValueError("the OMPL problem has no goal (setGoal or setStartAndGoalStates)")
    dim = predicate.dim
    start = _coordinates(first, dim)
    env = Environment(predicate.bounds(), np.zeros((0, 2, dim)), name=name)
    region: Goal
    if goal.hasType(ob.GoalType.GOAL_STATE):
        region = GoalState(_coordinates(goal.getState(), dim), goal.getThreshold())
    else:
        region = OMPLGoalRegion(goal, si, dim)
    return Problem(env, start, region, predicate, RealVectorSpace(dim), name)


def problem_from_setup(setup: og.SimpleSetup, name: str = "ompl") -> Problem:
    """The ``Problem`` of an ``ompl.geometric.SimpleSetup`` (set up here if it is not yet;
    ``problem_from_definition``).

    Args:
        setup: The setup, with its state space, validity checker, start and goal.
        name: The environment's and predicate's name.

    Returns:
        The problem.
    """
    setup.setup()
    return problem_from_definition(setup.getProblemDefinition(), name)


@dataclass(frozen=True, eq=False)
class OMPLTermination(TerminationCondition):
    """OMPL's ``PlannerTerminationCondition`` as a ``TerminationCondition``: the plan ends with status
    ``MAX_TIME`` once ``ptc.eval()`` is true. A budget (``is_budget``): OMPL's condition is the
    caller's, so no safety stall limit is added beside it."""

    ptc: Any

    def ended_by(self, progress: Progress) -> PlanStatus | None:
        return PlanStatus.MAX_TIME if self.ptc.eval() else None

    def describe(self) -> dict:
        return {"ompl_termination": True}

    @property
    def is_budget(self) -> bool:
        return True


class LibraryPlanner(ob.Planner):
    """A planner of this library as an ``ompl.base.Planner``.

    ``solve(ptc)`` reads the planner's ``ProblemDefinition`` (``problem_from_definition``), plans
    it with the library's planner until the goal or OMPL's termination condition, and adds the
    path, if any, as an exact solution.

    Args:
        si: The ``SpaceInformation``.
        planner: The library's ``Planner`` (any, a planner of your own included), e.g.
            ``qc.QRRT(goal_bias=0.05, seed=0)``; each ``solve`` plans afresh with its settings.
        name: The planner's name in OMPL's output and benchmark logs.

    Attributes:
        last_result: The ``PlanResult`` of the last ``solve``, or None.
    """

    def __init__(self, si: ob.SpaceInformation, planner: Planner, name: str) -> None:
        super().__init__(si, name)
        self.planner = check_instance(planner, "planner", Planner, "a Planner of this library (qc.RRT(), ...)")
        self.last_result: PlanResult | None = None
        self.last_checks = 0

    def solve(self, ptc: Any) -> ob.PlannerStatus:
        problem = problem_from_definition(self.getProblemDefinition(), self.getName())
        result = self.planner.plan(problem, OMPLTermination(ptc))
        self.last_result, self.last_checks = result, cast(OMPLMotionPredicate, problem.predicate).evaluations
        if not result.reached or result.path is None:
            return ob.PlannerStatus(ob.PlannerStatus.TIMEOUT)
        si = self.getSpaceInformation()
        path = og.PathGeometric(si)
        for point in result.path:
            path.append(_state(si, point))
        self.getProblemDefinition().addSolutionPath(path, False, 0.0, self.getName())
        return ob.PlannerStatus(ob.PlannerStatus.EXACT_SOLUTION)

    def clear(self) -> None:
        super().clear()
        self.last_result = None


class PredicateMotionValidator(ob.MotionValidator):
    """A predicate of this library as OMPL's motion validator: ``checkMotion(s1, s2)`` asks
    ``predicate.reachable`` for the one pair, so OMPL's planners check motions as the library's
    planners do. ``checks`` counts the pairs asked.

    Args:
        si: The ``SpaceInformation`` (real-vector states of the predicate's dimension).
        predicate: Any ``ReachabilityPredicate``.
    """

    def __init__(self, si: ob.SpaceInformation, predicate: ReachabilityPredicate) -> None:
        super().__init__(si)
        self.predicate, self.dim, self.checks = predicate, predicate.dim, 0

    def checkMotion(self, first: Any, second: Any, *last_valid: Any) -> bool:  # noqa: N802 - OMPL's name
        self.checks += 1
        return bool(self.predicate.reachable(_coordinates(first, self.dim)[None],
                                             _coordinates(second, self.dim)[None])[0])


def setup_from_problem(problem: Problem) -> og.SimpleSetup:
    """An ``ompl.geometric.SimpleSetup`` for a problem of this library, so that OMPL's planners plan
    it on the same checks: a ``RealVectorStateSpace`` with the world's bounds, a validity checker
    (the predicate's ``is_valid`` where it has one, else ``env.is_free``), the predicate as the
    motion validator (``PredicateMotionValidator``), the start, and the goal ball as OMPL's goal
    state with its radius as the threshold.

    Args:
        problem: The problem (its goal a ball: ``GoalBall`` or ``GoalState``).

    Returns:
        The set-up ``SimpleSetup``; ``setup.getSpaceInformation().getMotionValidator().checks``
        counts the motions OMPL's planners check.

    Raises:
        ValueError: A goal that is not a ball.
    """
    ball = ball_of(problem.goal)
    if ball is None:
        raise ValueError(f"setup_from_problem needs a ball goal (OMPL's goal state and threshold), got "
                         f"{problem.goal!r}")
    goal, goal_radius = ball
    env, predicate = problem.env, problem.predicate
    dim = env.dim
    setup = og.SimpleSetup(real_vector_space(env.bounds))
    is_valid = getattr(predicate, "is_valid", None)

    def valid(state: Any) -> bool:
        point = _coordinates(state, dim)[None]
        return bool(is_valid(point)[0]) if is_valid is not None else bool(env.is_free(point[0]))

    setup.setStateValidityChecker(valid)
    si = setup.getSpaceInformation()
    si.setMotionValidator(PredicateMotionValidator(si, predicate))
    setup.setStartAndGoalStates(_state(si, problem.start), _state(si, goal), float(goal_radius))
    setup.setup()
    return setup


class _CountingValidity:
    """Counts the validity checks an OMPL planner makes through the setup's checker."""

    def __init__(self, checker: Any) -> None:
        self.checker, self.calls = checker, 0

    def __call__(self, state: Any) -> bool:
        self.calls += 1
        return bool(self.checker.isValid(state))


#: OMPL's status enumeration, in its benchmark logs' order
_STATUSES = ("Unknown status", "Invalid start", "Invalid goal", "Unrecognized goal type", "Timeout",
             "Approximate solution", "Exact solution", "Crash")


def benchmark_log(setup: og.SimpleSetup, planners: Mapping[str, Callable[[ob.SpaceInformation], ob.Planner]],
                  runs: int, max_time_s: float, path: str | Path, experiment: str = "qrrt") -> dict[str, list[dict]]:
    """Run each planner ``runs`` times on ``setup`` and write OMPL's benchmark log to ``path``.

    Each run gets a fresh planner from its allocator (``planners[name](si)``; for the library's,
    a ``LibraryPlanner``) and ``setup.solve(max_time_s)``. Properties per run: ``time``, ``solved``,
    ``status``, ``solution length``, ``solution segments``, ``validity checks``; ``motion checks``
    for the library's planners (the predicate's pairs, the simulated oracle's included) and for
    OMPL's on a ``PredicateMotionValidator`` (``setup_from_problem``); the library's planners add
    ``oracle calls``, ``critical path oracle calls`` and ``nodes``.

    Args:
        setup: The ``SimpleSetup`` (its validity checker is wrapped to count checks for the run).
        planners: Name to planner allocator.
        runs: Runs per planner (>= 1).
        max_time_s: Seconds per run (finite, > 0).
        path: The log file to write.
        experiment: The experiment's name in the log.

    Returns:
        Name to the list of each run's properties (as written).

    Raises:
        ValueError: Bad ``runs`` or ``max_time_s``, or no planner.
    """
    runs = check_int(runs, "runs", 1)
    max_time_s = check_float(max_time_s, "max_time_s", 0.0, open_minimum=True)
    if not planners:
        raise ValueError("planners must name at least one planner allocator")
    setup.setup()
    si = setup.getSpaceInformation()
    checker = si.getStateValidityChecker()
    began = time.perf_counter()
    results: dict[str, list[dict]] = {}
    for name, allocate in planners.items():
        rows = []
        for _ in range(runs):
            counting = _CountingValidity(checker)
            si.setStateValidityChecker(counting)
            validator = si.getMotionValidator()
            checked = getattr(validator, "checks", None)
            planner = allocate(si)
            setup.setPlanner(planner)
            setup.clear()
            status = setup.solve(max_time_s)
            solved = bool(setup.haveExactSolutionPath())
            row: dict[str, Any] = {"time REAL": setup.getLastPlanComputationTime(), "solved BOOLEAN": int(solved),
                                   "status ENUM": _STATUSES.index(status.asString())
                                   if status.asString() in _STATUSES else 0}
            solution = setup.getSolutionPath() if solved else None
            row["solution length REAL"] = solution.length() if solution is not None else 0.0
            row["solution segments INTEGER"] = solution.getStateCount() - 1 if solution is not None else 0
            row["validity checks INTEGER"] = counting.calls
            result = getattr(planner, "last_result", None)
            if result is not None:  # a LibraryPlanner: its own counters
                row["motion checks INTEGER"] = planner.last_checks
                row["oracle calls INTEGER"] = result.metrics.oracle_calls
                row["critical path oracle calls INTEGER"] = result.metrics.critical_path_oracle_calls
                row["nodes INTEGER"] = result.metrics.nodes
            elif checked is not None:  # OMPL's planner on a PredicateMotionValidator
                row["motion checks INTEGER"] = validator.checks - checked
            rows.append(row)
        si.setStateValidityChecker(checker)
        results[name] = rows
    _write_log(Path(path), experiment, results, runs, max_time_s, time.perf_counter() - began)
    return results


def _write_log(path: Path, experiment: str, results: dict[str, list[dict]], runs: int, max_time_s: float,
               elapsed: float) -> None:
    """OMPL's benchmark log (the format ``ompl_benchmark_statistics.readBenchmarkLog`` parses)."""
    from .. import __version__

    lines = [f"qrrt_circuits version {__version__}", f"Experiment {experiment}", "1 experiment properties",
             f"ompl_version VARCHAR(128) = {getattr(ompl, '__version__', 'unknown')}",
             f"Running on {platform.node() or 'unknown'}", f"Starting at {time.strftime('%Y-%m-%d %H:%M:%S')}",
             "<<<|", "qrrt_circuits benchmark_log: planners run one after another in one thread", "|>>>",
             "<<<|", platform.processor() or platform.machine(), "|>>>",
             "0 is the random seed", f"{max_time_s} seconds per run", "0 MB per run", f"{runs} runs per planner",
             f"{elapsed} seconds spent to collect the data", "1 enum type", "status|" + "|".join(_STATUSES),
             f"{len(results)} planners"]
    for name, rows in results.items():
        names = list(rows[0])
        lines += [name, "0 common properties", f"{len(names)} properties for each run", *names, f"{len(rows)} runs"]
        lines += ["; ".join(str(row[key]) for key in names) + "; " for row in rows]
        lines.append(".")
    path.write_text("\n".join(lines) + "\n")
