"""Grover search behind one ``QuantumSearchBackend`` interface, and the search policies.

The names below are imported on first use (PEP 562): the Aer and sampler backends, the circuits
and the amplitude estimation import Qiskit, so a plan on the exact statevector never pays for it.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from . import circuits
    from .aer import AerBackend
    from .backend import QuantumSearchBackend, SearchRequest, SearchResult
    from .estimated_policy import EstimatedOptimal
    from .fixed_point import IterateSequence
    from .fixed_point_policy import FixedPointAmplification
    from .problem import DatabaseSearch, SearchOutcome
    from .sampler import SamplerBackend
    from .statevector import StatevectorBackend

#: public name -> the submodule that defines it ("" for a submodule itself)
_WHERE = {
    "AerBackend": ".aer",
    "DatabaseSearch": ".problem",
    "EstimatedOptimal": ".estimated_policy",
    "FixedPointAmplification": ".fixed_point_policy",
    "IterateSequence": ".fixed_point",
    "QuantumSearchBackend": ".backend",
    "SamplerBackend": ".sampler",
    "SearchOutcome": ".problem",
    "SearchRequest": ".backend",
    "SearchResult": ".backend",
    "StatevectorBackend": ".statevector",
    "circuits": "",
}

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


def __getattr__(name: str) -> Any:
    """Import ``name``'s submodule on first use and cache the attribute in this module."""
    where = _WHERE.get(name)
    if where is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = importlib.import_module(f".{name}" if where == "" else where, __name__)
    if where:
        value = getattr(value, name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
