"""Grover search behind one ``QuantumSearchBackend`` interface, and the search policies."""

from . import circuits
from .aer import AerBackend
from .backend import QuantumSearchBackend, SearchRequest, SearchResult
from .problem import DatabaseSearch, SearchOutcome
from .sampler import SamplerBackend
from .statevector import StatevectorBackend

__all__ = [
    "AerBackend",
    "DatabaseSearch",
    "QuantumSearchBackend",
    "SamplerBackend",
    "SearchOutcome",
    "SearchRequest",
    "SearchResult",
    "StatevectorBackend",
    "circuits",
]
