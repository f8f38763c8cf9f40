"""qrrt_circuits: quantum-search sampling-based motion planners.

q-RRT, parallel Pq-RRT (shared and unshared databases) and Quantum Database Annealing from
Lathrop, Boardman and Martinez, "Parallel Quantum Rapidly-Exploring Random Trees" (IEEE Access
2024), with Grover search as real Qiskit circuits on Aer or on an exact statevector.
"""

import importlib as _importlib
from importlib import util as _importlib_util
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from . import probability, registry
    from .planners import PQRRT, QRRT, RRT, Metrics, ParallelRRT, Planner, PlanResult, QRRTConnect, QRRTStar
    from .planners.candidates import Candidates, LatticeCandidates, NearestParents
    from .planners.database import AnnealingSchedule
    from .planners.options import (
        ParallelOptions,
        ParallelQuantumOptions,
        PlannerOptions,
        QuantumOptions,
        RRTOptions,
    )
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
    from .problems.families import grid_problem, image_problem, load_problem
    from .problems.goals import Goal, GoalBall, GoalState
    from .problems.problem import Problem
    from .problems.scenarios import annealing_field, lattice, narrow_corridor, paper_clutter
    from .reachability.authors_check import AuthorsCheck
    from .reachability.dynamics import LinearTrackingDynamics
    from .reachability.exact import ExactCheck
    from .reachability.grid_check import GridCheck, grid_world, image_world
    from .reachability.oracle_errors import OracleErrorModel
    from .reachability.predicate import ReachabilityPredicate
    from .reachability.time_sampled import TimeSampledCheck
    from .search.backends.aer import AerBackend
    from .search.backends.base import QuantumSearchBackend, SearchRequest, SearchResult
    from .search.backends.sampler import SamplerBackend
    from .search.backends.statevector import StatevectorBackend
    from .search.iterate_sequence import IterateSequence
    from .search.oracles import CircuitOracle, LookupOracle, SearchOracle
    from .search.policies.adaptive import Adaptive
    from .search.policies.base import IterationPolicy
    from .search.policies.bbht import BBHT
    from .search.policies.estimated import EstimatedOptimal
    from .search.policies.fixed_point_amplification import FixedPointAmplification
    from .search.policies.schedules import FixedIterations, KnownOptimal, PaperIterations
    from .search.policies.thompson import ThompsonIterations
    from .search.problem import DatabaseSearch, SearchOutcome
    from .world.environment import Environment
    from .world.image import OccupancyGrid
    from .world.nearest import GridNearest, LinearNearest, NearestNeighbors, SE2Nearest
    from .world.spaces import RealVectorSpace, SE2Space, StateSpace

    __version__: str

#: every public name -> the module that defines it (or that is it, where the module's last part is the
#: name). Each is imported on first use (PEP 562) and then cached here, so ``import qrrt_circuits``
#: imports nothing heavy (no numpy, numba, scipy or Qiskit): a program such as the ``qrrt`` command
#: line can set itself up (install its signal handlers) before the heavy imports begin, and what a
#: program never uses it never imports (a plan on the statevector never imports Qiskit)
_WHERE = {
    "probability": ".probability",
    "registry": ".registry",
    **dict.fromkeys(["PQRRT", "QRRT", "RRT", "Metrics", "ParallelRRT", "PlanResult", "Planner", "QRRTConnect",
                     "QRRTStar"], ".planners"),
    **dict.fromkeys(["ParallelOptions", "ParallelQuantumOptions", "PlannerOptions", "QuantumOptions", "RRTOptions"],
                    ".planners.options"),
    "Problem": ".problems.problem",
    **dict.fromkeys(["grid_problem", "image_problem", "load_problem"], ".problems.families"),
    **dict.fromkeys(["annealing_field", "lattice", "narrow_corridor", "paper_clutter"], ".problems.scenarios"),
    "AnnealingSchedule": ".planners.database",
    **dict.fromkeys(["Candidates", "LatticeCandidates", "NearestParents"], ".planners.candidates"),
    **dict.fromkeys(["Goal", "GoalBall", "GoalState"], ".problems.goals"),
    **dict.fromkeys(["RealVectorSpace", "SE2Space", "StateSpace"], ".world.spaces"),
    **dict.fromkeys(["GridNearest", "LinearNearest", "NearestNeighbors", "SE2Nearest"], ".world.nearest"),
    **dict.fromkeys(["AnyOf", "MaxCriticalPathCalls", "MaxNodes", "MaxOracleCalls", "MaxRounds", "MaxWallTime",
                     "PlanStatus", "Stall", "TerminationCondition"], ".planners.termination"),
    "AuthorsCheck": ".reachability.authors_check",
    "LinearTrackingDynamics": ".reachability.dynamics",
    "ExactCheck": ".reachability.exact",
    **dict.fromkeys(["GridCheck", "grid_world", "image_world"], ".reachability.grid_check"),
    "OracleErrorModel": ".reachability.oracle_errors",
    "ReachabilityPredicate": ".reachability.predicate",
    "TimeSampledCheck": ".reachability.time_sampled",
    **dict.fromkeys(["QuantumSearchBackend", "SearchRequest", "SearchResult"], ".search.backends.base"),
    # (these import Qiskit: the circuits, Aer, the sampler, amplitude estimation, or its circuit types)
    **dict.fromkeys(["AerBackend", "EstimatedOptimal", "FixedPointAmplification", "IterateSequence",
                     "SamplerBackend", "StatevectorBackend"], ".search"),
    **dict.fromkeys(["CircuitOracle", "LookupOracle", "SearchOracle"], ".search.oracles"),
    "IterationPolicy": ".search.policies.base",
    **dict.fromkeys(["FixedIterations", "KnownOptimal", "PaperIterations"], ".search.policies.schedules"),
    "BBHT": ".search.policies.bbht",
    "Adaptive": ".search.policies.adaptive",
    "ThompsonIterations": ".search.policies.thompson",
    **dict.fromkeys(["DatabaseSearch", "SearchOutcome"], ".search.problem"),
    "Environment": ".world.environment",
    "OccupancyGrid": ".world.image",
}

def __getattr__(name: str) -> Any:
    """A public name, imported on first use (``_WHERE``) and cached in this module; ``__version__``."""
    if name == "__version__":
        value: Any = _version()
    elif name in _WHERE:
        where = _WHERE[name]
        value = _importlib.import_module(where, __name__)
        if where.rpartition(".")[2] != name:
            value = getattr(value, name)
    elif not name.startswith("_") and _importlib_util.find_spec(f"{__name__}.{name}") is not None:
        value = _importlib.import_module(f"{__name__}.{name}")  # a subpackage: qc.X is import qrrt_circuits.X
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__) | {"__version__"})


def _version() -> str:
    """One source of the version: ``version`` in pyproject.toml, read from the installed metadata."""
    from importlib import metadata

    try:
        return metadata.version("qrrt-circuits")
    except metadata.PackageNotFoundError:  # a source tree on sys.path that was never installed
        return "0+unknown"


__all__ = [
    "BBHT",
    "PQRRT",
    "QRRT",
    "QRRTConnect",
    "QRRTStar",
    "RRT",
    "Adaptive",
    "ThompsonIterations",
    "AerBackend",
    "AnnealingSchedule",
    "Candidates",
    "AnyOf",
    "AuthorsCheck",
    "DatabaseSearch",
    "Environment",
    "CircuitOracle",
    "EstimatedOptimal",
    "FixedIterations",
    "FixedPointAmplification",
    "Goal",
    "GoalBall",
    "GoalState",
    "GridCheck",
    "GridNearest",
    "LinearNearest",
    "SE2Nearest",
    "NearestNeighbors",
    "RealVectorSpace",
    "SE2Space",
    "StateSpace",
    "IterationPolicy",
    "KnownOptimal",
    "IterateSequence",
    "LatticeCandidates",
    "LinearTrackingDynamics",
    "LookupOracle",
    "MaxCriticalPathCalls",
    "MaxNodes",
    "MaxOracleCalls",
    "MaxRounds",
    "MaxWallTime",
    "Metrics",
    "NearestParents",
    "OccupancyGrid",
    "OracleErrorModel",
    "PaperIterations",
    "ParallelRRT",
    "PlanResult",
    "Planner",
    "PlannerOptions",
    "ParallelOptions",
    "ParallelQuantumOptions",
    "Problem",
    "QuantumOptions",
    "RRTOptions",
    "annealing_field",
    "grid_problem",
    "image_problem",
    "lattice",
    "load_problem",
    "narrow_corridor",
    "paper_clutter",
    "PlanStatus",
    "QuantumSearchBackend",
    "ExactCheck",
    "ReachabilityPredicate",
    "SamplerBackend",
    "SearchOracle",
    "SearchOutcome",
    "SearchRequest",
    "SearchResult",
    "Stall",
    "StatevectorBackend",
    "TerminationCondition",
    "TimeSampledCheck",
    "grid_world",
    "image_world",
    "probability",
    "registry",
]
