"""qrrt_circuits: quantum-search sampling-based motion planners.

q-RRT, parallel Pq-RRT (shared and unshared databases) and Quantum Database Annealing from
Lathrop, Boardman and Martinez, "Parallel Quantum Rapidly-Exploring Random Trees" (IEEE Access
2024), with Grover search as real Qiskit circuits on Aer or on an exact statevector.
"""

from . import probability, scenarios
from .database import AnnealingSchedule
from .dynamics import LinearTrackingDynamics
from .environment import Environment
from .oracle import OracleErrorModel, ReachabilityOracle
from .planners import PQRRT, QRRT, RRT, Metrics, ParallelRRT, PlanResult
from .search import (
    AerBackend,
    QuantumSearchBackend,
    SamplerBackend,
    SearchResult,
    StatevectorBackend,
    circuits,
)
from .search.schedules import BBHT, Adaptive, FixedIterations, KnownOptimal, PaperSchedule

__version__ = "0.1.0"

__all__ = [
    "BBHT",
    "PQRRT",
    "QRRT",
    "RRT",
    "Adaptive",
    "AerBackend",
    "AnnealingSchedule",
    "FixedIterations",
    "KnownOptimal",
    "Metrics",
    "PaperSchedule",
    "ParallelRRT",
    "PlanResult",
    "Environment",
    "LinearTrackingDynamics",
    "OracleErrorModel",
    "QuantumSearchBackend",
    "ReachabilityOracle",
    "SamplerBackend",
    "SearchResult",
    "StatevectorBackend",
    "circuits",
    "probability",
    "scenarios",
]
