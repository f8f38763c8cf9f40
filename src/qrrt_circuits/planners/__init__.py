"""The planners: RRT, ParallelRRT, QRRT, PQRRT (DESIGN §1)."""

from typing import Any

from .base import Planner
from .classical import RRT, ParallelRRT
from .quantum import PQRRT, QRRT
from .result import Metrics, PlanResult

__all__ = ["PQRRT", "QRRT", "RRT", "Metrics", "ParallelRRT", "PlanResult", "Planner"]


def __getattr__(name: str) -> Any:
    """Deprecated names of this package."""
    if name == "DEFAULT_MAX_ROUNDS":
        from . import base

        return base.DEFAULT_MAX_ROUNDS
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
