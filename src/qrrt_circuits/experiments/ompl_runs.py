"""One OMPL planner run on a problem of the library, on the library's own motion check (needs the
``ompl`` extra): the run that ``qrrt reproduce problems`` sets beside the library's planners."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from ..problems.families import Problem

#: OMPL planners by the experiment's label: (``ompl.geometric`` class, whether it takes a goal bias, whether
#: it is anytime: it plans until the budget and reports its best cost as it goes, ``bestCost()``)
OMPL_PLANNERS = {"OMPL RRT": ("RRT", True, False), "OMPL RRTConnect": ("RRTConnect", False, False),
                 "OMPL RRTstar": ("RRTstar", True, True)}


@dataclass(frozen=True)
class OMPLRun:
    """What one OMPL run measured.

    Attributes:
        reached: Whether OMPL found an exact solution within the budget.
        motion_checks: ``checkMotion`` calls (each one evaluation of the library's predicate).
        path: Float (L, d), the solution path's states, or None.
        wall_time_s: Seconds in ``SimpleSetup.solve``.
        range: The planner's ``range`` (OMPL's default: 0.2 of the space's largest extent).
        anytime: An anytime planner's (motion checks, best path cost) each time its best cost fell
            (read from ``bestCost()`` as the termination condition is polled); empty for the others.
    """

    reached: bool
    motion_checks: int
    path: np.ndarray | None
    wall_time_s: float
    range: float
    anytime: tuple[tuple[int, float], ...] = ()


def ompl_run(problem: Problem, label: str, budget: int, seed: int, goal_bias: float) -> OMPLRun:
    """Plan ``problem`` with OMPL's planner ``label`` until it solves or has made ``budget`` motion
    checks (``SimpleSetup.solve`` with a ``PlannerTerminationCondition`` on the validator's count).

    The setup is ``adapters.ompl_planning.setup_from_problem``: a ``RealVectorStateSpace`` with the
    problem's bounds (an SE(2) problem's angle is one more real coordinate there: OMPL's
    steering and nearest neighbours ignore the wrap, the check itself moves along the shorter
    arc), the predicate as motion validator, the goal ball as OMPL's goal state and threshold.
    OMPL's generator is seeded with ``ompl.util.RNG.setSeed(seed)`` before the planner is made.

    Args:
        problem: The problem.
        label: A key of ``OMPL_PLANNERS``.
        budget: Motion checks allowed.
        seed: OMPL's seed (>= 1).
        goal_bias: The planner's goal bias (RRT only; RRTConnect has none).

    Returns:
        The ``OMPLRun``.
    """
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    from ..adapters.ompl_planning import setup_from_problem

    previous = ou.getLogLevel()
    ou.setLogLevel(ou.LOG_NONE)  # (setSeed after the first run logs that sampling "already started";
    ou.RNG.setSeed(int(seed))  # the planners made after it draw from the new seed all the same)
    ou.setLogLevel(ou.LOG_WARN)
    setup = setup_from_problem(problem)
    si = setup.getSpaceInformation()
    validator = si.getMotionValidator()
    name, takes_goal_bias, anytime = OMPL_PLANNERS[label]
    planner = getattr(og, name)(si)
    if takes_goal_bias:
        planner.setGoalBias(goal_bias)
    setup.setPlanner(planner)
    setup.setup()
    trace: list[tuple[int, float]] = []

    def ended() -> bool:
        if anytime:
            cost = float(planner.bestCost().value())
            if math.isfinite(cost) and (not trace or cost < trace[-1][1]):
                trace.append((int(validator.checks), cost))
        return bool(validator.checks >= budget)

    condition = ob.PlannerTerminationCondition(ended)
    began = time.perf_counter()
    setup.solve(condition)
    elapsed = time.perf_counter() - began
    path = None
    if setup.haveExactSolutionPath():
        states = setup.getSolutionPath().getStates()
        path = np.array([[state[axis] for axis in range(problem.env.dim)] for state in states])
    ou.setLogLevel(previous)
    return OMPLRun(path is not None, int(validator.checks), path, elapsed, float(planner.getRange()), tuple(trace))
