"""The planners: RRT, ParallelRRT, QRRT, PQRRT (DESIGN §1)."""

from .base import Planner
from .classical import RRT, ParallelRRT
from .quantum import PQRRT, QRRT
from .result import Metrics, PlanResult

__all__ = ["PQRRT", "QRRT", "RRT", "Metrics", "ParallelRRT", "PlanResult", "Planner"]
