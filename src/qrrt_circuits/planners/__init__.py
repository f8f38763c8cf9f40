"""The planners: RRT, ParallelRRT, QRRT, PQRRT (DESIGN §1), and beyond the paper QRRTConnect and
QRRTStar."""

from .base import Planner
from .classical import RRT, ParallelRRT
from .connect import QRRTConnect
from .quantum import PQRRT, QRRT
from .result import Metrics, PlanResult
from .star import QRRTStar

__all__ = ["PQRRT", "QRRT", "RRT", "Metrics", "ParallelRRT", "PlanResult", "Planner", "QRRTConnect", "QRRTStar"]
