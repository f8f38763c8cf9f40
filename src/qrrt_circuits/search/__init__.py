"""Grover search behind one ``QuantumSearchBackend`` interface, and the search policies."""

from . import circuits
from .aer import AerBackend
from .backend import QuantumSearchBackend, SearchRequest, SearchResult
from .estimated_policy import EstimatedOptimal
from .fixed_point import IterateSequence
from .fixed_point_policy import FixedPointAmplification
from .problem import DatabaseSearch, SearchOutcome
from .sampler import SamplerBackend
from .statevector import StatevectorBackend

__all__ = [
    "AerBackend",
    "DatabaseSearch",
    "EstimatedOptimal",
    "FixedPointAmplification",
    "IterateSequence",
    "QuantumSearchBackend",
    "SamplerBackend",
    "SearchOutcome",
    "SearchRequest",
    "SearchResult",
    "StatevectorBackend",
    "circuits",
]
