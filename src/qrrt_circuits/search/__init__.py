"""Grover search behind one ``QuantumSearchBackend`` interface, and the search policies.

The names below are imported on first use (PEP 562): the Aer and sampler backends, the circuits
and the amplitude estimation import Qiskit, so a plan on the exact statevector never pays for it.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from . import circuits
    from .backends.aer import AerBackend
    from .backends.base import QuantumSearchBackend, SearchRequest, SearchResult
    from .backends.sampler import SamplerBackend
    from .backends.statevector import StatevectorBackend
    from .iterate_sequence import IterateSequence
    from .oracles import CircuitOracle, LookupOracle, SearchOracle
    from .policies.estimated import EstimatedOptimal
    from .policies.fixed_point_amplification import FixedPointAmplification
    from .problem import DatabaseSearch, SearchOutcome
    from .synthesis import OracleSynthesis

#: public name -> the submodule that defines it ("" for a submodule itself)
_WHERE = {
    "AerBackend": ".backends.aer",
    "CircuitOracle": ".oracles",
    "LookupOracle": ".oracles",
    "SearchOracle": ".oracles",
    "DatabaseSearch": ".problem",
    "EstimatedOptimal": ".policies.estimated",
    "FixedPointAmplification": ".policies.fixed_point_amplification",
    "IterateSequence": ".iterate_sequence",
    "OracleSynthesis": ".synthesis",
    "QuantumSearchBackend": ".backends.base",
    "SamplerBackend": ".backends.sampler",
    "SearchOutcome": ".problem",
    "SearchRequest": ".backends.base",
    "SearchResult": ".backends.base",
    "StatevectorBackend": ".backends.statevector",
    "circuits": "",
}

__all__ = [
    "AerBackend",
    "CircuitOracle",
    "DatabaseSearch",
    "EstimatedOptimal",
    "FixedPointAmplification",
    "IterateSequence",
    "LookupOracle",
    "OracleSynthesis",
    "QuantumSearchBackend",
    "SamplerBackend",
    "SearchOracle",
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
