"""qrrt_circuits: quantum-search sampling-based motion planners.

q-RRT, parallel Pq-RRT (shared and unshared databases) and Quantum Database Annealing from
Lathrop, Boardman and Martinez, "Parallel Quantum Rapidly-Exploring Random Trees" (IEEE Access
2024), with Grover search as real Qiskit circuits on Aer or on an exact statevector.
"""

from importlib import metadata as _metadata
from typing import TYPE_CHECKING, Any

from . import probability, registry
from .planners import PQRRT, QRRT, RRT, Metrics, ParallelRRT, PlanResult, termination
from .planners.database import AnnealingSchedule
from .planners.termination import (
    AnyOf,
    MaxCriticalPathCalls,
    MaxNodes,
    MaxOracleCalls,
    MaxRounds,
    MaxWallTime,
    PlanStatus,
    Stall,
    TerminationCondition,
)
from .reachability.authors_check import AuthorsCheck
from .reachability.dynamics import LinearTrackingDynamics
from .reachability.exact import ExactCheck
from .reachability.oracle_errors import OracleErrorModel
from .reachability.predicate import ReachabilityPredicate
from .reachability.time_sampled import TimeSampledCheck
from .search.backend import QuantumSearchBackend, SearchRequest, SearchResult
from .search.policies.iteration import (
    BBHT,
    Adaptive,
    FixedIterations,
    IterationPolicy,
    KnownOptimal,
    PaperIterations,
)
from .search.problem import DatabaseSearch, SearchOutcome
from .world import scenarios
from .world.environment import Environment

if TYPE_CHECKING:
    from .search import circuits
    from .search.backends.aer import AerBackend
    from .search.backends.sampler import SamplerBackend
    from .search.backends.statevector import StatevectorBackend
    from .search.fixed_point import IterateSequence
    from .search.policies.estimated import EstimatedOptimal
    from .search.policies.fixed_point import FixedPointAmplification

#: the names imported on first use (PEP 562): their modules import Qiskit (the circuits, Aer, the
#: sampler, amplitude estimation) or its circuit types, which a plan on the statevector never needs
_LAZY = ("AerBackend", "EstimatedOptimal", "FixedPointAmplification", "IterateSequence", "SamplerBackend",
         "StatevectorBackend", "circuits")


#: deprecated name -> (its replacement, the object)
_DEPRECATED: dict[str, tuple[str, Any]] = {
    "SearchPolicy": ("IterationPolicy", IterationPolicy),
    "PaperSchedule": ("PaperIterations", PaperIterations),
    "ReachabilityOracle": ("ExactCheck", ExactCheck),
}


def __getattr__(name: str) -> Any:
    """``qrrt_circuits.search``'s lazily imported names, cached here on first use; deprecated names."""
    if name in _DEPRECATED:
        from ._support.deprecation import warn_deprecated

        new, value = _DEPRECATED[name]
        warn_deprecated(f"qrrt_circuits.{name}", f"qrrt_circuits.{new}")
        return value
    if name in _LAZY:
        from . import search

        value = getattr(search, name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))

try:  # one source of the version: ``version`` in pyproject.toml, read from the installed metadata
    __version__ = _metadata.version("qrrt-circuits")
except _metadata.PackageNotFoundError:  # a source tree on sys.path that was never installed
    __version__ = "0+unknown"

__all__ = [
    "BBHT",
    "PQRRT",
    "QRRT",
    "RRT",
    "Adaptive",
    "AerBackend",
    "AnnealingSchedule",
    "AnyOf",
    "AuthorsCheck",
    "DatabaseSearch",
    "Environment",
    "EstimatedOptimal",
    "FixedIterations",
    "FixedPointAmplification",
    "IterationPolicy",
    "KnownOptimal",
    "IterateSequence",
    "LinearTrackingDynamics",
    "MaxCriticalPathCalls",
    "MaxNodes",
    "MaxOracleCalls",
    "MaxRounds",
    "MaxWallTime",
    "Metrics",
    "OracleErrorModel",
    "PaperIterations",
    "ParallelRRT",
    "PlanResult",
    "PlanStatus",
    "QuantumSearchBackend",
    "ExactCheck",
    "ReachabilityPredicate",
    "SamplerBackend",
    "SearchOutcome",
    "SearchRequest",
    "SearchResult",
    "Stall",
    "StatevectorBackend",
    "TerminationCondition",
    "TimeSampledCheck",
    "circuits",
    "probability",
    "registry",
    "scenarios",
    "termination",
]
