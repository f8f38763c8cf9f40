"""The planners: RRT, ParallelRRT, QRRT, PQRRT (DESIGN §1)."""

from .base import DEFAULT_MAX_ROUNDS, Planner
from .classical import RRT, ParallelRRT
from .quantum import PQRRT, QRRT
from .result import Metrics, PlanResult

__all__ = ["DEFAULT_MAX_ROUNDS", "PQRRT", "QRRT", "RRT", "Metrics", "ParallelRRT", "PlanResult", "Planner"]
