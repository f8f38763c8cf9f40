"""The library's planners behave as OMPL's inside OMPL: ``solve(seconds)``, OMPL's statuses for an
invalid start and an unreached goal, OMPL's strict goal test, a fresh seed per solve drawn from
OMPL's generator, budgets, SE(2) and compound spaces, and OMPL's own demo flows and benchmark tool
(``OptimalPlanning.py``, ``Point2DPlanning.py`` and ``ompl.tools.Benchmark``, rewritten here) with
only the planner line changed. Every returned path is checked by OMPL's ``checkMotion``."""

from __future__ import annotations

import math
from functools import partial

import numpy as np
import pytest

ob = pytest.importorskip("ompl.base")
og = pytest.importorskip("ompl.geometric")
ou = pytest.importorskip("ompl.util")
ot = pytest.importorskip("ompl.tools")

import qrrt_circuits as qc  # noqa: E402
from qrrt_circuits.adapters.ompl_planning import LibraryPlanner, benchmark_log, problem_from_setup  # noqa: E402


def _path_is_valid_by_ompl(si, path) -> bool:
    states = [path.getState(i) for i in range(path.getStateCount())]
    return all(si.isValid(state) for state in states) and all(
        si.checkMotion(first, second) for first, second in zip(states[:-1], states[1:], strict=True))


def gap_setup(threshold: float = 0.5, start=(1.0, 1.0), goal=(9.0, 9.0)) -> og.SimpleSetup:
    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 10.0)
    setup = og.SimpleSetup(space)
    setup.setStateValidityChecker(lambda s: not (4.0 <= s[0] <= 6.0 and not 4.0 <= s[1] <= 6.0))
    first, last = space.allocState(), space.allocState()
    first[0], first[1], last[0], last[1] = *start, *goal
    setup.setStartAndGoalStates(first, last, threshold)
    return setup


def library(name: str, planner, **budgets):
    return lambda si: LibraryPlanner(si, planner, name, **budgets)


# --------------------------------------------------------------------------- OptimalPlanning.py's flow
class _Clearance(ob.StateValidityChecker):
    def isValid(self, state):  # noqa: N802 - OMPL's name
        return math.hypot(state[0] - 0.5, state[1] - 0.5) - 0.25 > 0.0


def optimal_planning_flow(allocate, run_time: float = 5.0):
    """The demo's steps: a ProblemDefinition with an objective, setProblemDefinition, setup, and
    ``solve(runTime)`` with a float."""
    space = ob.RealVectorStateSpace(2)
    space.setBounds(0.0, 1.0)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(_Clearance(si))
    si.setup()
    start, goal = space.allocState(), space.allocState()
    start[0], start[1], goal[0], goal[1] = 0.0, 0.0, 1.0, 1.0
    pdef = ob.ProblemDefinition(si)
    pdef.setStartAndGoalStates(start, goal)
    pdef.setOptimizationObjective(ob.PathLengthOptimizationObjective(si))
    planner = allocate(si)
    planner.setProblemDefinition(pdef)
    planner.setup()
    return planner, pdef, si, planner.solve(run_time)


@pytest.mark.parametrize("make", [lambda: qc.RRT(goal_bias=0.05),
                                  lambda: qc.QRRT(num_qubits=5, goal_bias=0.05,
                                                  backend=qc.StatevectorBackend())])
def test_the_optimal_planning_flow_solves_with_a_float_time(make):
    planner, pdef, si, status = optimal_planning_flow(library("lib", make()))
    assert status and status.asString() == "Exact solution" and pdef.hasExactSolution()
    path = pdef.getSolutionPath()
    assert path.length() >= 2 * math.sqrt(2) * 0.25 and _path_is_valid_by_ompl(si, path)
    assert path.cost(pdef.getOptimizationObjective()).value() == pytest.approx(path.length())


# --------------------------------------------------------------------------- Point2DPlanning.py's flow
def _maze(width: int = 60, height: int = 40) -> np.ndarray:
    free = np.ones((height, width), dtype=bool)
    free[:30, 20:22] = False   # a wall from the bottom, open at the top
    free[10:, 40:42] = False   # a wall from the top, open at the bottom
    return free


class Plane2D:
    """The demo's class, on an occupancy array instead of a PPM file: addDimension, a callable
    validity checker through ``functools.partial``, the checking resolution, the planner line."""

    def __init__(self, free: np.ndarray, allocate) -> None:
        self.free = free
        space = ob.RealVectorStateSpace()
        space.addDimension(0.0, float(free.shape[1]))
        space.addDimension(0.0, float(free.shape[0]))
        self.setup = og.SimpleSetup(space)
        self.setup.setStateValidityChecker(partial(Plane2D.is_valid, self))
        space.setup()
        self.setup.getSpaceInformation().setStateValidityCheckingResolution(1.0 / space.getMaximumExtent())
        self.setup.setPlanner(allocate(self.setup.getSpaceInformation()))  # the planner line

    def is_valid(self, state) -> bool:
        column = min(int(state[0]), self.free.shape[1] - 1)
        row = min(int(state[1]), self.free.shape[0] - 1)
        return bool(self.free[row, column])

    def plan(self, start, goal, solves: int = 3) -> int:
        space = self.setup.getStateSpace()
        first, last = space.allocState(), space.allocState()
        first[0], first[1], last[0], last[1] = *start, *goal
        self.setup.setStartAndGoalStates(first, last)
        for _ in range(solves):
            self.setup.getPlanner().clear()
            self.setup.solve(10.0)
        return self.setup.getProblemDefinition().getSolutionCount()


def test_the_point2d_flow_finds_a_solution_per_solve_simplifies_and_smooths():
    seen = []
    planner = qc.QRRT(num_qubits=5, goal_bias=0.05, max_extension=8.0, backend=qc.StatevectorBackend())

    def allocate(si):
        made = LibraryPlanner(si, planner, "q-RRT")
        seen.append(made)
        return made

    world = Plane2D(_maze(), allocate)
    assert world.plan((5.0, 5.0), (55.0, 35.0)) == 3
    setup = world.setup
    assert setup.haveExactSolutionPath()
    assert _path_is_valid_by_ompl(setup.getSpaceInformation(), setup.getSolutionPath())  # as planned
    setup.simplifySolution()  # OMPL's own post-processing of the demo runs on it
    path = setup.getSolutionPath()
    simplifier = og.PathSimplifier(setup.getSpaceInformation())
    simplifier.simplifyMax(path)
    simplifier.smoothBSpline(path)
    path.interpolate()
    assert path.getStateCount() >= 2 and seen[0].last_seed is not None


# --------------------------------------------------------------------------- OMPL's statuses and goal test
def test_an_invalid_start_returns_ompls_status_and_a_benchmark_goes_on(tmp_path):
    setup = gap_setup(start=(5.0, 1.0))  # inside the wall
    rows = benchmark_log(setup, {"RRT (OMPL)": og.RRT, "RRT (library)": library("RRT (library)", qc.RRT())},
                         runs=2, max_time_s=0.5, path=tmp_path / "x.log")
    for runs in rows.values():
        assert [row["status ENUM"] for row in runs] == [1, 1]  # "Invalid start", as OMPL's RRT says


def test_an_invalid_goal_ends_in_an_approximate_solution_as_ompls_rrt():
    setup = gap_setup(goal=(5.0, 9.0))  # inside the wall
    planner = LibraryPlanner(setup.getSpaceInformation(), qc.RRT(goal_bias=0.05), "RRT (library)")
    setup.setPlanner(planner)
    status = setup.solve(0.5)
    assert status.asString() == "Approximate solution" and not setup.haveExactSolutionPath()
    path = setup.getSolutionPath()
    assert _path_is_valid_by_ompl(setup.getSpaceInformation(), path)
    difference = setup.getProblemDefinition().getSolutionDifference()
    assert difference == pytest.approx(math.dist(planner.last_result.nodes[
        np.argmin(np.hypot(*(planner.last_result.nodes - [5.0, 9.0]).T))], (5.0, 9.0)))


def test_the_goal_test_is_ompls_strict_one():
    """With threshold 0 no state satisfies OMPL's goal (distance < 0): no exact solution, as with
    OMPL's RRT, where a closed ball would call the sampled goal state reached."""
    setup = gap_setup(threshold=0.0)
    problem = problem_from_setup(setup)
    assert problem.goal.is_satisfied(np.array([[9.0, 9.0]])).tolist() == [False]
    planner = LibraryPlanner(setup.getSpaceInformation(), qc.RRT(goal_bias=0.2), "RRT (library)")
    setup.setPlanner(planner)
    assert setup.solve(0.3).asString() == "Approximate solution"
    assert problem_from_setup(gap_setup(threshold=0.5)).goal.is_satisfied(
        np.array([[9.0, 9.5], [9.0, 9.4]])).tolist() == [False, True]


# --------------------------------------------------------------------------- seeds and budgets
def test_each_solve_draws_its_seed_from_ompls_generator():
    setup = gap_setup()
    planner = LibraryPlanner(setup.getSpaceInformation(), qc.RRT(goal_bias=0.05, seed=0), "RRT (library)")
    setup.setPlanner(planner)
    found = []
    for _ in range(3):
        setup.clear()
        assert setup.solve(10.0)
        found.append((planner.last_seed, planner.last_result.settings["seed"], planner.last_result.metrics.nodes))
    assert len({seed for seed, _, _ in found}) == 3 and all(seed == recorded for seed, recorded, _ in found)
    assert len({nodes for _, _, nodes in found}) > 1  # different seeds, different trees


SEEDED = """
from ompl import base as ob, util as ou
ou.RNG.setSeed(12345)
import qrrt_circuits as qc
from qrrt_circuits.adapters.ompl_planning import LibraryPlanner
space = ob.RealVectorStateSpace(2)
space.setBounds(0.0, 10.0)
planner = LibraryPlanner(ob.SpaceInformation(space), qc.RRT(), "RRT")
print([int(planner.rng.uniformInt(0, 2**31 - 2)) for _ in range(3)])
"""


def test_ompls_seed_fixes_every_solves_seed():
    """``ou.RNG.setSeed`` before the planner is made gives the same seeds in every process."""
    import subprocess
    import sys

    runs = [subprocess.run([sys.executable, "-c", SEEDED], capture_output=True, text=True, timeout=120)
            for _ in range(2)]
    assert all(run.returncode == 0 for run in runs), runs[0].stderr
    assert runs[0].stdout.splitlines()[-1] == runs[1].stdout.splitlines()[-1]


def test_benchmark_runs_differ_and_record_their_seeds(tmp_path):
    rows = benchmark_log(gap_setup(), {"RRT (library)": library("RRT (library)", qc.RRT(goal_bias=0.05, seed=0))},
                         runs=4, max_time_s=10.0, path=tmp_path / "x.log")["RRT (library)"]
    assert len({row["seed INTEGER"] for row in rows}) == 4
    assert len({row["nodes INTEGER"] for row in rows}) > 1
    assert "seed INTEGER" in (tmp_path / "x.log").read_text()


def test_a_budget_ends_the_plan_inside_ompl_and_ompls_end_is_named():
    setup = gap_setup(threshold=0.0)
    planner = LibraryPlanner(setup.getSpaceInformation(), qc.RRT(goal_bias=0.05), "RRT", max_oracle_calls=40)
    setup.setPlanner(planner)
    setup.solve(30.0)
    result = planner.last_result
    assert result.status == "max_oracle_calls" and result.metrics.oracle_calls <= 40 + 1
    timed = LibraryPlanner(setup.getSpaceInformation(), qc.RRT(goal_bias=0.05), "RRT")
    setup.setPlanner(timed)
    setup.solve(0.2)
    assert timed.last_result.status == "max_time_s" and "None" not in timed.last_result.status_text
    assert "OMPL's termination condition" in timed.last_result.status_text
    with pytest.raises(TypeError, match="max_oracle_calls"):
        LibraryPlanner(setup.getSpaceInformation(), qc.RRT(), "RRT", max_calls=3)


# --------------------------------------------------------------------------- spaces
def test_an_se2_setup_is_planned_on_the_library_se2_space():
    space = ob.SE2StateSpace()
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0.0)
    bounds.setHigh(10.0)
    space.setBounds(bounds)
    setup = og.SimpleSetup(space)
    setup.setStateValidityChecker(lambda s: not (4.0 <= s.getX() <= 6.0 and not 4.0 <= s.getY() <= 6.0))
    start, goal = space.allocState(), space.allocState()
    start.setXY(1.0, 1.0)
    start.setYaw(0.0)
    goal.setXY(9.0, 9.0)
    goal.setYaw(math.pi / 2)
    setup.setStartAndGoalStates(start, goal, 0.5)
    problem = problem_from_setup(setup)
    assert isinstance(problem.space, qc.SE2Space) and problem.space.angle_weight == 0.5
    assert problem.env.bounds[2].tolist() == [-math.pi, math.pi] and problem.start.tolist() == [1.0, 1.0, 0.0]
    planner = LibraryPlanner(setup.getSpaceInformation(), qc.RRT(goal_bias=0.05, max_extension=2.0), "RRT")
    setup.setPlanner(planner)
    assert setup.solve(20.0) and setup.haveExactSolutionPath()
    path = setup.getSolutionPath()
    assert _path_is_valid_by_ompl(setup.getSpaceInformation(), path)
    last = path.getState(path.getStateCount() - 1)
    assert space.distance(last, goal) < 0.5


def test_a_compound_of_real_vector_spaces_reads_as_one_vector():
    space = ob.CompoundStateSpace()
    for low, high, dim in ((0.0, 10.0, 2), (-1.0, 1.0, 1)):
        part = ob.RealVectorStateSpace(dim)
        part.setBounds(low, high)
        space.addSubspace(part, 1.0)
    setup = og.SimpleSetup(space)
    setup.setStateValidityChecker(lambda s: True)
    start, goal = space.allocState(), space.allocState()
    for state, values in ((start, (1.0, 1.0, 0.5)), (goal, (9.0, 9.0, -0.5))):
        state[0][0], state[0][1], state[1][0] = values
    setup.setStartAndGoalStates(start, goal, 0.5)
    problem = problem_from_setup(setup)
    assert problem.dim == 3 and problem.env.bounds.tolist() == [[0, 10], [0, 10], [-1, 1]]
    setup.setPlanner(LibraryPlanner(setup.getSpaceInformation(), qc.RRT(goal_bias=0.1, max_extension=3.0), "RRT"))
    assert setup.solve(20.0) and setup.haveExactSolutionPath()
    assert _path_is_valid_by_ompl(setup.getSpaceInformation(), setup.getSolutionPath())


def test_a_space_the_library_cannot_read_is_refused_naming_the_accepted_ones():
    from qrrt_circuits.adapters.ompl_states import coordinates_for

    mixed = ob.CompoundStateSpace()
    mixed.addSubspace(ob.RealVectorStateSpace(2), 1.0)
    mixed.addSubspace(ob.SO2StateSpace(), 0.5)
    for space in (ob.SO2StateSpace(), mixed):
        with pytest.raises(ValueError, match="RealVectorStateSpace, an SE2StateSpace, or a CompoundStateSpace"):
            coordinates_for(space)


# --------------------------------------------------------------------------- ompl.tools.Benchmark
def test_ompls_benchmark_tool_runs_the_library_planners(tmp_path):
    setup = gap_setup()
    benchmark = ot.Benchmark(setup, "gap")
    benchmark.addPlanner(og.RRT(setup.getSpaceInformation()))
    benchmark.addPlannerAllocator(library("q-RRT", qc.QRRT(num_qubits=5, goal_bias=0.05,
                                                           backend=qc.StatevectorBackend())))
    request = ot.Benchmark.Request() if hasattr(ot.Benchmark, "Request") else ot.Request()
    request.maxTime, request.runCount, request.displayProgress = 5.0, 3, False
    benchmark.benchmark(request)
    log = tmp_path / "gap.log"
    benchmark.saveResultsToFile(str(log))
    text = log.read_text()
    assert "q-RRT" in text and "2 planners" in text
