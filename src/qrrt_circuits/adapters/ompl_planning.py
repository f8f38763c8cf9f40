"""OMPL problems planned by the library's planners, and those planners as OMPL planners (needs the
``ompl`` extra, OMPL >= 2.0).

- **In**: ``problem_from_setup(setup)`` reads an ``ompl.geometric.SimpleSetup`` on a
  ``RealVectorStateSpace``, an ``SE2StateSpace`` or a compound of real-vector spaces
  (``ompl_states``) as a ``Problem``: an ``Environment`` with the space's bounds (no boxes: every
  check goes to OMPL), an ``OMPLMotionPredicate`` asking the setup's motion validator and validity
  checker, the setup's start and the goal as an ``OMPLGoalRegion``: OMPL's own ``isSatisfied``
  (strict, ``distance < threshold``, for a goal state), drawn from with ``sampleGoal`` where OMPL can.
- **Out**: ``LibraryPlanner(si, planner, name)`` is an ``ompl.base.Planner``: ``solve(ptc)``
  (``SimpleSetup.solve``) and ``solve(seconds)`` run any planner of the library on the problem,
  end it when OMPL's termination condition or an oracle-call budget says so, and store the path as
  OMPL's exact solution, or the tree's path nearest the goal as an approximate one; they return
  OMPL's statuses (``Invalid start`` without a valid start state). Each solve draws its seed
  from OMPL's random generator (``ompl.util.RNG.setSeed`` fixes them all) and records it
  (``last_seed``); ``last_result`` keeps the ``PlanResult`` (oracle calls counted as DESIGN §2 says).
- **Benchmark logs**: ``benchmark_log`` runs OMPL's planners and the library's on one setup, one
  run after another in this thread, and writes OMPL's benchmark log format, which OMPL's
  ``ompl_benchmark_statistics`` reads into the SQLite database Planner Arena shows. The library's
  runs carry ``oracle calls`` and ``critical path oracle calls``; runs carry ``motion checks`` where
  they are counted (the library's planners; OMPL's on a ``PredicateMotionValidator``, which
  ``setup_from_problem`` installs to plan the library's problems on the same checks) and every run
  ``validity checks``, and the library's runs their ``seed``. ``ompl.tools.Benchmark`` runs the
  library's planners too (``LibraryPlanner`` is an ``ob.Planner``), without the oracle-call columns.
"""

from __future__ import annotations

import numbers
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
from ..problems.goals import ball_of
from ..problems.problem import Problem
from ..reachability.predicate import ReachabilityPredicate
from ..world.environment import Environment
from .ompl import INSTALL_HINT, OMPLMotionPredicate, real_vector_space
from .ompl_states import OMPLCoordinates

try:
    import ompl
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou
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


class InvalidStart(ValueError):
    """The OMPL problem has no valid start state (OMPL's ``Invalid start``)."""


class OMPLGoalRegion:
    """An OMPL goal as a ``Goal``: OMPL's own ``isSatisfied`` per state (for a goal state or
    region, ``distanceGoal < threshold``, strict, as OMPL tests it); ``sampleGoal`` where OMPL's
    goal can draw states (a ``GoalSampleableRegion`` that ``couldSample``).

    A goal state (``setStartAndGoalStates``, ``GoalState``) has no volume to sample into: a plan
    reaches it only through goal bias, as OMPL's RRT does (``has_volume`` False).

    Args:
        goal: An ``ompl.base.Goal``.
        si: Its ``SpaceInformation``.
        coordinates: How its states read as coordinates (``ompl_states.coordinates_for``).
    """

    def __init__(self, goal: ob.Goal, si: ob.SpaceInformation, coordinates: OMPLCoordinates) -> None:
        self.goal, self.si, self.coordinates, self.dim = goal, si, coordinates, coordinates.dim
        self.has_volume = not goal.hasType(ob.GoalType.GOAL_STATE)
        self._probe = si.allocState()
        if goal.hasType(ob.GoalType.GOAL_SAMPLEABLE_REGION) and goal.couldSample():
            self.sample = self._sample

    def is_satisfied(self, points: np.ndarray) -> np.ndarray:
        points = np.atleast_2d(points)
        out = np.empty(points.shape[0], dtype=bool)
        for row, point in enumerate(points.tolist()):
            self.coordinates.write(self._probe, point)
            out[row] = self.goal.isSatisfied(self._probe)
        return out

    def distance(self, points: np.ndarray) -> np.ndarray:
        """OMPL's ``distanceGoal`` per point where the goal is a region (inf for other goals)."""
        points = np.atleast_2d(points)
        if not self.goal.hasType(ob.GoalType.GOAL_REGION):
            return np.full(points.shape[0], np.inf)
        out = np.empty(points.shape[0])
        for row, point in enumerate(points.tolist()):
            self.coordinates.write(self._probe, point)
            out[row] = self.goal.distanceGoal(self._probe)
        return out

    def _sample(self, count: int, rng: np.random.Generator) -> np.ndarray:
        """``count`` states from OMPL's ``sampleGoal`` (OMPL's own random generator: not seeded by
        the plan's seed)."""
        state = self.si.allocState()
        out = np.empty((count, self.dim))
        for row in range(count):
            self.goal.sampleGoal(state)
            out[row] = self.coordinates.read(state)
        return out

    def __repr__(self) -> str:
        fields = ", ".join(f"{key}={value}" for key, value in self.describe().items() if key != "kind")
        return f"OMPLGoalRegion({fields})"

    def describe(self) -> dict:
        described: dict[str, Any] = {"kind": "ompl", "type": type(self.goal).__name__}
        if self.goal.hasType(ob.GoalType.GOAL_REGION):
            described["threshold"] = float(self.goal.getThreshold())
        if self.goal.hasType(ob.GoalType.GOAL_STATE):
            described["state"] = self.coordinates.read(self.goal.getState())
        return described


def problem_from_definition(pdef: ob.ProblemDefinition, name: str = "ompl") -> Problem:
    """The ``Problem`` of an OMPL ``ProblemDefinition``: an environment with the space's bounds
    and no boxes (every check goes to OMPL), the ``OMPLMotionPredicate`` of its ``SpaceInformation``,
    the library's space for OMPL's (``ompl_states.coordinates_for``), its one start state and its
    goal as an ``OMPLGoalRegion`` (OMPL's own goal test).

    Args:
        pdef: The problem definition.
        name: The environment's and predicate's name.

    Returns:
        The problem.

    Raises:
        InvalidStart: No valid start state (none set, or none valid and within bounds: OMPL's
            ``Invalid start``); a ``ValueError``.
        ValueError: More than one start state (the planners grow one tree from one root), no goal,
            a state space ``coordinates_for`` does not map, or what ``Problem`` refuses.
    """
    si = pdef.getSpaceInformation()
    predicate = OMPLMotionPredicate(si, name=name)
    coordinates = predicate.coordinates
    inputs = ob.PlannerInputStates()  # (pdef.getStartState hands Python a state pdef still owns)
    inputs.use(pdef)
    first = inputs.nextStart()  # (OMPL skips a start state outside the bounds or invalid)
    if first is None:
        raise InvalidStart("the OMPL problem has no valid start state (none set, or none valid and within "
                           "the bounds)")
    if inputs.nextStart() is not None:  # the planners grow one tree from one root
        raise ValueError(f"the OMPL problem has {pdef.getStartStateCount()} start states; the library's planners "
                         "grow one tree from one start: accepted is a problem with exactly one start state")
    goal = pdef.getGoal()
    if goal is None:
        raise ValueError("the OMPL problem has no goal (setGoal or setStartAndGoalStates)")
    dim = predicate.dim
    start = np.array(coordinates.read(first), dtype=float)
    env = Environment(predicate.bounds(), np.zeros((0, 2, dim)), name=name)
    region = OMPLGoalRegion(goal, si, coordinates)
    return Problem(env, start, region, predicate, coordinates.library_space(), name)


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
        return {"max_time_s": "OMPL's termination condition"}

    @property
    def is_budget(self) -> bool:
        return True


#: the library's plan budgets a ``LibraryPlanner`` passes to every solve (``Planner.plan``'s keywords)
BUDGETS = ("max_oracle_calls", "max_critical_path_calls", "max_nodes", "max_rounds")


class LibraryPlanner(ob.Planner):
    """A planner of this library as an ``ompl.base.Planner``.

    ``solve(ptc)`` (what ``SimpleSetup.solve`` calls) or ``solve(seconds)`` (OMPL's
    ``Planner::solve(double)``) reads the planner's ``ProblemDefinition``
    (``problem_from_definition``), plans it with the library's planner until the goal, OMPL's
    termination condition or a budget given here, and returns OMPL's status:

    - ``Exact solution``: the path to the goal, added to the problem definition;
    - ``Approximate solution``: no node satisfied the goal; the tree's path to the node nearest it
      (OMPL's ``distanceGoal``) is added as approximate, with that distance as its difference, as
      OMPL's RRT does (the start alone where the tree has no other node); ``Timeout`` for a goal
      without a distance (not a ``GoalRegion``);
    - ``Invalid start``: no valid start state (nothing is planned).

    Seeds: each solve plans with the library's planner at a seed drawn from OMPL's random
    generator (an ``ompl.util.RNG`` made here, seeded from OMPL's seed sequence as OMPL's own
    planners' generators are, so ``ou.RNG.setSeed(s)`` before making the planner fixes every
    solve); the planner's own ``seed`` option is replaced, and ``last_seed`` records the one used.

    Args:
        si: The ``SpaceInformation``.
        planner: The library's ``Planner`` (any, a planner of your own included), e.g.
            ``qc.QRRT(goal_bias=0.05)``; each ``solve`` plans afresh with its settings.
        name: The planner's name in OMPL's output and benchmark logs.
        **budgets: Budgets for every solve, any of ``BUDGETS`` (``max_oracle_calls=20000``); the
            plan ends at the first of them or OMPL's condition.

    Attributes:
        last_result: The ``PlanResult`` of the last ``solve``, or None.
        last_seed: The seed of the last ``solve``, or None.

    Raises:
        TypeError: ``planner`` not a ``Planner``, or a budget that is not one of ``BUDGETS``.
    """

    def __init__(self, si: ob.SpaceInformation, planner: Planner, name: str, **budgets: int) -> None:
        super().__init__(si, name)
        self.planner = check_instance(planner, "planner", Planner, "a Planner of this library (qc.RRT(), ...)")
        unknown = sorted(set(budgets) - set(BUDGETS))
        if unknown:
            raise TypeError(f"LibraryPlanner takes the budgets {', '.join(BUDGETS)}, not {', '.join(unknown)}")
        self.budgets = dict(budgets)
        self.rng = ou.RNG()
        self.last_result: PlanResult | None = None
        self.last_seed: int | None = None
        self.last_checks = 0

    def solve(self, ptc: Any, *interval: float) -> ob.PlannerStatus:
        """Plan the problem definition until ``ptc`` says stop: an OMPL
        ``PlannerTerminationCondition``, seconds (OMPL's ``solve(double)``) or a function that
        returns True to stop (``solve(fn, check_interval)``)."""
        condition = _termination_condition(ptc, *interval)
        self.last_result = None
        try:
            problem = problem_from_definition(self.getProblemDefinition(), self.getName())
        except InvalidStart as error:
            ou.OMPL_ERROR(f"{self.getName()}: {error}")
            return ob.PlannerStatus(ob.PlannerStatus.INVALID_START)
        self.last_seed = int(self.rng.uniformInt(0, 2**31 - 2))
        planner = type(self.planner)(self.planner.options.replace(seed=self.last_seed),
                                     executor=self.planner.executor)
        result = planner.plan(problem, OMPLTermination(condition), **self.budgets)
        self.last_result, self.last_checks = result, cast(OMPLMotionPredicate, problem.predicate).evaluations
        goal = cast(OMPLGoalRegion, problem.goal)
        if result.reached and result.path is not None:
            self._add_path(result.path, goal, approximate=False)
            return ob.PlannerStatus(ob.PlannerStatus.EXACT_SOLUTION)
        distances = goal.distance(result.nodes)
        nearest = int(np.argmin(distances))
        if not np.isfinite(distances[nearest]):
            return ob.PlannerStatus(ob.PlannerStatus.TIMEOUT)
        self._add_path(result.nodes[_chain(result.parents, nearest)], goal, approximate=True,
                       difference=float(distances[nearest]))
        return ob.PlannerStatus(ob.PlannerStatus.APPROXIMATE_SOLUTION)

    def _add_path(self, points: np.ndarray, goal: OMPLGoalRegion, approximate: bool, difference: float = 0.0) -> None:
        si = self.getSpaceInformation()
        path = og.PathGeometric(si)
        for point in points:
            path.append(goal.coordinates.state(point.tolist()))
        self.getProblemDefinition().addSolutionPath(path, approximate, difference, self.getName())

    def clear(self) -> None:
        super().clear()
        self.last_result = None


def _chain(parents: np.ndarray, node: int) -> list[int]:
    """The nodes from the root to ``node`` along ``parents``."""
    chain = [node]
    while parents[chain[-1]] >= 0:
        chain.append(int(parents[chain[-1]]))
    return chain[::-1]


def _termination_condition(ptc: Any, *interval: float) -> Any:
    """OMPL's termination condition from what ``Planner.solve`` accepts in OMPL: a condition as it
    is, seconds as ``timedPlannerTerminationCondition``, a function (with an optional check
    interval) as ``PlannerTerminationCondition``."""
    if isinstance(ptc, numbers.Real):  # OMPL's solve(double): the overload is told by its argument
        seconds = check_float(float(ptc), "solve time", 0.0, open_minimum=True)
        return ob.timedPlannerTerminationCondition(seconds)
    if not hasattr(ptc, "eval") and callable(ptc):  # solve(fn, check_interval)
        return ob.PlannerTerminationCondition(ptc, *interval) if interval else ob.PlannerTerminationCondition(ptc)
    return ptc


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
            if result is not None:  # a LibraryPlanner that planned: its own counters
                row["motion checks INTEGER"] = planner.last_checks
                row["oracle calls INTEGER"] = result.metrics.oracle_calls
                row["critical path oracle calls INTEGER"] = result.metrics.critical_path_oracle_calls
                row["nodes INTEGER"] = result.metrics.nodes
                row["seed INTEGER"] = planner.last_seed
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
             f"{ou.RNG.getSeed()} is the random seed", f"{max_time_s} seconds per run", "0 MB per run",
             f"{runs} runs per planner",
             f"{elapsed} seconds spent to collect the data", "1 enum type", "status|" + "|".join(_STATUSES),
             f"{len(results)} planners"]
    for name, rows in results.items():
        names = list(rows[0])
        lines += [name, "0 common properties", f"{len(names)} properties for each run", *names, f"{len(rows)} runs"]
        lines += ["; ".join(str(row[key]) for key in names) + "; " for row in rows]
        lines.append(".")
    path.write_text("\n".join(lines) + "\n")
