"""Grover search behind one ``QuantumSearchBackend`` interface."""

from . import circuits
from .aer import AerBackend
from .backend import QuantumSearchBackend, SearchResult
from .sampler import SamplerBackend
from .statevector import StatevectorBackend

__all__ = [
    "AerBackend",
    "QuantumSearchBackend",
    "SamplerBackend",
    "SearchResult",
    "StatevectorBackend",
    "circuits",
]
