"""The planners: RRT, ParallelRRT, QRRT, PQRRT (DESIGN §1)."""

from .base import DEFAULT_MAX_ROUNDS, Metrics, Planner, PlanResult
from .classical import RRT, ParallelRRT
from .quantum import PQRRT, QRRT

__all__ = ["DEFAULT_MAX_ROUNDS", "PQRRT", "QRRT", "RRT", "Metrics", "ParallelRRT", "PlanResult", "Planner"]
