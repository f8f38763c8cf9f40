"""Backends: ``base`` holds the ``QuantumSearchBackend`` interface every backend implements (with
its request and result types); ``statevector``, ``aer``, ``sampler`` and ``noisy`` the
implementations, each imported on its own (the last three import Qiskit)."""

from .base import QuantumSearchBackend, SearchRequest, SearchResult

__all__ = ["QuantumSearchBackend", "SearchRequest", "SearchResult"]
