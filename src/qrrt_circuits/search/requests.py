"""What a Grover search is asked and what it returns, and the checks of its arguments.

A ``SearchRequest`` is one search (oracle, k, shots, seed); a ``SearchResult`` its measured indices
and oracle calls (DESIGN §2: one call per Grover iteration per preparation). ``validate_marks``,
``validate_iterations`` and ``validate_shots`` refuse bad arguments before any work; every backend
and circuit builder uses them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from .._support.validation import check_int, check_seed

if TYPE_CHECKING:
    from .oracles import SearchOracle


@dataclass(frozen=True)
class SearchResult:
    """Measured database indices (one per shot) and the oracle calls they cost.

    Args:
        indices: The measured indices, one per shot (stored as a read-only int64 array).
        iterations: k, the Grover iterations (or generalized iterates) of each preparation.
        shots: The preparations measured.
        oracle_calls: ``iterations * shots`` (DESIGN §2: one call per iteration per preparation).
    """

    indices: np.ndarray
    iterations: int
    shots: int
    oracle_calls: int

    def __post_init__(self) -> None:
        indices = np.asarray(self.indices, dtype=np.int64)
        indices.setflags(write=False)
        object.__setattr__(self, "indices", indices)


@dataclass(frozen=True, eq=False)
class SearchRequest:
    """One search of ``QuantumSearchBackend.search_many``: the arguments of one ``search`` call.

    Args:
        oracle: The phase oracle (``LookupOracle(marks)`` or a ``CircuitOracle``; ``search/oracles.py``).
        iterations: k, 0 .. ``MAX_ITERATIONS``.
        shots: Preparations, 1 .. ``MAX_SHOTS`` (default 1).
        seed: This search's seed, or None (default) for the backend's own stream.
    """

    oracle: SearchOracle
    iterations: int
    shots: int = 1
    seed: int | None = None


def validate_marks(marks: np.ndarray) -> tuple[np.ndarray, int]:
    """Return (marks as bool array, n) or raise a ValueError naming the problem.

    Args:
        marks: A 1-D array of length 2^n (n >= 1) of booleans or 0/1 values.

    Returns:
        (the marks as a bool array, n).

    Raises:
        ValueError: Not 1-D, a length that is not a power of two >= 2, or values other than 0/1.
    """
    array = np.asarray(marks)
    if array.ndim != 1:
        raise ValueError(f"marks must be a 1-D array of length 2**n, got shape {array.shape}")
    size = array.shape[0]
    if size < 2 or size & (size - 1):
        raise ValueError(
            f"marks must have length 2**n with n >= 1 (a power of two >= 2), got length {size}"
        )
    if array.dtype != np.bool_:
        if not np.all(np.isin(array, (0, 1))):
            raise ValueError("marks must be booleans (or 0/1)")
        array = array.astype(bool)
    return array, size.bit_length() - 1


def check_measured(indices: np.ndarray, shots: int, size: int, backend: str) -> None:
    """Refuse measured indices that are not ``shots`` integers in [0, ``size``).

    Args:
        indices: What a backend's sampling returned.
        shots: The shots asked for.
        size: N = 2^n, the database's entries.
        backend: The backend's name (for the message).

    Raises:
        RuntimeError: A shape other than (shots,), a non-integer dtype, or an index out of range.
    """
    if not (isinstance(indices, np.ndarray) and indices.shape == (shots,) and indices.dtype.kind in "iu"):
        raise RuntimeError(f"the {backend} backend returned {indices!r} for {shots} shots: expected an integer "
                           f"array of shape ({shots},)")
    if _any_outside(indices, size):
        raise RuntimeError(f"the {backend} backend measured an index outside [0, {size}): {indices.tolist()}")


@njit(cache=True, nogil=True)
def _any_outside(indices: np.ndarray, size: int) -> bool:
    """Whether any of the integer ``indices`` lies outside [0, ``size``) (one compiled pass)."""
    for index in indices:
        if index < 0 or index >= size:
            return True
    return False


#: generous upper limits: far beyond any useful search (the optimal k for N = 2^30 and m = 1 is
#: 25 735), small enough that a circuit or a result never exhausts memory
MAX_ITERATIONS = 100_000
MAX_SHOTS = 10_000_000


def validate_iterations(iterations: int) -> int:
    """k as an int in [0, ``MAX_ITERATIONS``].

    Args:
        iterations: k.

    Returns:
        k as a Python ``int``.

    Raises:
        TypeError: A non-integer k.
        ValueError: k out of range.
    """
    return check_int(iterations, "iterations", 0, MAX_ITERATIONS)


def validate_shots(shots: int) -> int:
    """``shots`` as an int in [1, ``MAX_SHOTS``].

    Args:
        shots: The preparations.

    Returns:
        ``shots`` as a Python ``int``.

    Raises:
        TypeError: A non-integer ``shots``.
        ValueError: ``shots`` out of range.
    """
    return check_int(shots, "shots", 1, MAX_SHOTS)


def seed_stream(seed: int | np.random.Generator | None) -> np.random.Generator:
    """A numpy Generator from a seed (``np.random.default_rng(seed)``), a Generator (used as is)
    or None (fresh entropy).

    Args:
        seed: A non-negative integer, a ``numpy.random.Generator`` or None.

    Returns:
        The generator.

    Raises:
        TypeError: A seed that is neither an integer, a Generator nor None.
        ValueError: A negative seed.
    """
    if isinstance(seed, np.random.Generator):
        return seed
    checked = check_seed(seed)
    return np.random.default_rng(checked)
