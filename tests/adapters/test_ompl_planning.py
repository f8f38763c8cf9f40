"""OMPL both ways: a SimpleSetup planned by the library's planners, the library's planners as OMPL
planners, and OMPL benchmark logs that OMPL's own statistics script reads."""

from __future__ import annotations

import sqlite3

import numpy as np
import pytest

ob = pytest.importorskip("ompl.base")
og = pytest.importorskip("ompl.geometric")

import qrrt_circuits as qc  # noqa: E402
from qrrt_circuits.adapters.ompl_planning import (  # noqa: E402
    LibraryPlanner,
    OMPLGoalRegion,
    benchmark_log,
    problem_from_setup,
)


def valid(state) -> bool:
    """A wall x in [4, 6] with a gap y in [4, 6]."""
    return not (4.0 <= state[0] <= 6.0 and not 4.0 <= state[1] <= 6.0)


def gap_setup(goal_threshold: float = 0.5) -> og.SimpleSetup:
    space = ob.RealVectorStateSpace(2)
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(0.0)
    bounds.setHigh(10.0)
    space.setBounds(bounds)
    setup = og.SimpleSetup(space)
    setup.setStateValidityChecker(valid)
    start, goal = space.allocState(), space.allocState()
    start[0], start[1], goal[0], goal[1] = 1.0, 1.0, 9.0, 9.0
    setup.setStartAndGoalStates(start, goal, goal_threshold)
    return setup


def test_a_setup_becomes_a_problem_the_planners_take():
    problem = problem_from_setup(gap_setup())
    assert problem.env.bounds.tolist() == [[0.0, 10.0], [0.0, 10.0]] and problem.start.tolist() == [1.0, 1.0]
    assert isinstance(problem.goal, OMPLGoalRegion) and problem.goal.describe()["threshold"] == 0.5
    assert problem.goal.describe()["state"] == [9.0, 9.0] and not problem.goal.has_volume
    assert problem.predicate.is_valid(np.array([[5.0, 1.0], [5.0, 5.0]])).tolist() == [False, True]
    for make in (lambda: qc.RRT(goal_bias=0.05, seed=0),
                 lambda: qc.QRRT(backend=qc.StatevectorBackend(seed=0), num_qubits=4, goal_bias=0.05,
                                 search_policy=qc.Adaptive(), seed=0)):
        result = make().plan(problem, max_oracle_calls=20000)
        assert result.reached and np.linalg.norm(result.path[-1] - [9, 9]) <= 0.5
        for parent, child in zip(result.path[:-1], result.path[1:], strict=True):  # every path edge, by OMPL
            assert problem.predicate.reachable(parent[None], child[None])[0]


def test_a_problem_with_two_start_states_is_refused():
    setup = gap_setup()
    space = setup.getStateSpace()
    second = space.allocState()
    second[0], second[1] = 1.0, 2.0
    setup.getProblemDefinition().addStartState(second)
    with pytest.raises(ValueError, match="2 start states.*exactly one start state"):
        problem_from_setup(setup)


def test_a_goal_region_is_asked_through_ompl():
    class RightStrip(ob.GoalRegion):
        def __init__(self, si):
            super().__init__(si)
            self.setThreshold(1e-9)  # OMPL: satisfied where distanceGoal < threshold

        def distanceGoal(self, state):
            return max(0.0, 9.0 - state[0])

    setup = gap_setup()
    setup.setGoal(RightStrip(setup.getSpaceInformation()))
    problem = problem_from_setup(setup)
    assert isinstance(problem.goal, OMPLGoalRegion) and not hasattr(problem.goal, "sample")
    assert problem.goal.is_satisfied(np.array([[9.5, 1.0], [8.0, 1.0]])).tolist() == [True, False]
    result = qc.RRT(seed=1).plan(problem, max_oracle_calls=20000)
    assert result.reached and result.path[-1][0] >= 9.0


def test_library_planners_solve_through_simple_setup():
    setup = gap_setup()
    planner = LibraryPlanner(setup.getSpaceInformation(), qc.RRT(goal_bias=0.05, seed=2), "RRT-lib")
    setup.setPlanner(planner)
    assert setup.solve(30.0) and setup.haveExactSolutionPath()
    path = setup.getSolutionPath()
    assert path.check() and planner.last_result.reached
    assert path.getStateCount() == len(planner.last_result.path)


def test_benchmark_logs_carry_oracle_calls_that_ompls_statistics_read(tmp_path):
    from ompl import _benchmark_statistics as statistics

    setup = gap_setup()

    def library(name, planner):
        return lambda si: LibraryPlanner(si, planner, name)

    planners = {
        "RRT (OMPL)": og.RRT,
        "q-RRT": library("q-RRT", qc.QRRT(backend=qc.StatevectorBackend(seed=0), num_qubits=4, goal_bias=0.05,
                                          search_policy=qc.Adaptive(), seed=0)),
    }
    log = tmp_path / "run.log"
    rows = benchmark_log(setup, planners, runs=2, max_time_s=20.0, path=log)
    assert all(row["solved BOOLEAN"] == 1 for row in rows["q-RRT"])
    assert all(row["oracle calls INTEGER"] >= 1 and row["motion checks INTEGER"] >= row["oracle calls INTEGER"]
               for row in rows["q-RRT"])
    database = tmp_path / "run.db"
    statistics.readBenchmarkLog(str(database), [str(log)], False)
    with sqlite3.connect(database) as connection:
        names = [row[0] for row in connection.execute("SELECT name FROM plannerConfigs ORDER BY id")]
        calls = connection.execute("SELECT oracle_calls FROM runs WHERE oracle_calls IS NOT NULL").fetchall()
    assert names == ["RRT (OMPL)", "q-RRT"]
    assert sorted(c for (c,) in calls) == sorted(row["oracle calls INTEGER"] for row in rows["q-RRT"])


def test_bad_benchmark_arguments_are_refused(tmp_path):
    with pytest.raises(ValueError, match="runs must be"):
        benchmark_log(gap_setup(), {"RRT": og.RRT}, runs=0, max_time_s=1.0, path=tmp_path / "x.log")
    with pytest.raises(ValueError, match="max_time_s must be a finite number > 0.0"):
        benchmark_log(gap_setup(), {"RRT": og.RRT}, runs=1, max_time_s=0.0, path=tmp_path / "x.log")
    with pytest.raises(ValueError, match="planners must name at least one"):
        benchmark_log(gap_setup(), {}, runs=1, max_time_s=1.0, path=tmp_path / "x.log")


def test_ompls_planners_plan_a_library_problem_on_the_same_checks(clutter):
    from qrrt_circuits.adapters.ompl_planning import setup_from_problem

    check = clutter.predicate
    setup = setup_from_problem(clutter)
    setup.setPlanner(og.RRTConnect(setup.getSpaceInformation()))
    assert setup.solve(30.0) and setup.haveExactSolutionPath()
    path = setup.getSolutionPath()
    points = np.array([[path.getState(i)[axis] for axis in range(2)] for i in range(path.getStateCount())])
    assert check.reachable(points[:-1], points[1:]).all()  # every edge OMPL kept, re-checked by ours
    assert setup.getSpaceInformation().getMotionValidator().checks >= len(points) - 1


def test_benchmark_logs_of_a_library_problem_count_every_planners_motion_checks(clutter, tmp_path):
    from qrrt_circuits.adapters.ompl_planning import setup_from_problem

    setup = setup_from_problem(clutter)
    rrt = qc.RRT(goal_bias=0.05, seed=0, look_ahead=False)
    rows = benchmark_log(setup, {"RRTConnect (OMPL)": og.RRTConnect,
                                 "RRT (library)": lambda si: LibraryPlanner(si, rrt, "RRT (library)")},
                         runs=2, max_time_s=30.0, path=tmp_path / "clutter.log")
    for name, runs in rows.items():
        for row in runs:
            assert row["solved BOOLEAN"] == 1 and row["motion checks INTEGER"] >= 1, name
    for row in rows["RRT (library)"]:  # without look-ahead, one motion check per oracle call
        assert row["motion checks INTEGER"] == row["oracle calls INTEGER"]


@pytest.mark.parametrize("planner", [
    qc.QRRTConnect(backend=qc.StatevectorBackend(seed=0), num_qubits=4, seed=1),
    qc.QRRTStar(backend=qc.StatevectorBackend(seed=0), num_qubits=4, goal_bias=0.05, seed=1),
], ids=["qrrt-connect", "qrrt-star"])
def test_quantum_connect_and_star_solve_inside_ompl(planner):
    """q-RRT-Connect (its goal tree rooted at OMPL's goal state) and q-RRT* (anytime: it plans until
    OMPL's condition ends it and returns its best path) as ``ompl.base.Planner`` objects."""
    setup = gap_setup()
    library = LibraryPlanner(setup.getSpaceInformation(), planner, planner.name)
    setup.setPlanner(library)
    assert setup.solve(ob.plannerOrTerminationCondition(ob.timedPlannerTerminationCondition(20.0),
                                                        ob.exactSolnPlannerTerminationCondition(
                                                            setup.getProblemDefinition()))
                       if planner.name == "QRRTConnect" else ob.timedPlannerTerminationCondition(3.0))
    assert setup.haveExactSolutionPath() and setup.getSolutionPath().check() and library.last_result.reached
