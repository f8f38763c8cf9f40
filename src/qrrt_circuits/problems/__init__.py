"""Planning problems as values: ``Problem`` (world, state space, motion check, start, goal), the
goals, the paper's seeded scenarios and the problem families and files."""

from .goals import Goal, GoalBall, GoalState
from .problem import Problem

__all__ = ["Goal", "GoalBall", "GoalState", "Problem"]
