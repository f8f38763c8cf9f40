"""The ``QuantumSearchBackend`` interface and its result type.

A backend Grover-searches a database of N = 2^n entries given the oracle's marks (a bool array of
length N): it prepares the uniform superposition, applies ``iterations`` Grover iterations and
measures, once per shot. Each shot is an independent preparation and measurement, so one call with
``shots = p`` stands for p workers searching copies of one shared database (the simulation
shortcut of Pq-RRT: on hardware each worker would run its own circuit).

Oracle calls are counted as DESIGN §2 says: one per Grover iteration per preparation, so
``oracle_calls = iterations * shots``.

``search_sequence(marks, sequence, shots, seed)`` runs generalized iterates G(alpha_j, beta_j)
instead (an ``IterateSequence``, ``search/fixed_point.py``: fixed-point amplitude amplification);
each iterate queries the oracle once, so ``oracle_calls = len(sequence) * shots`` as well.
"""

from __future__ import annotations

import abc
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, TypeAlias

import numpy as np

from ..memory import MemoryEstimate, check_fits
from ..validation import check_int, check_seed

if TYPE_CHECKING:
    from .fixed_point import IterateSequence

#: a validated request: (marks, num_qubits, iterations, shots, rng)
_Prepared: TypeAlias = tuple[np.ndarray, int, int, int, np.random.Generator]


@dataclass(frozen=True)
class SearchResult:
    """Measured database indices (one per shot) and the oracle calls they cost."""

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
    """One search of ``QuantumSearchBackend.search_many``: the arguments of one ``search`` call."""

    marks: np.ndarray
    iterations: int
    shots: int = 1
    seed: int | None = None


def validate_marks(marks: np.ndarray) -> tuple[np.ndarray, int]:
    """Return (marks as bool array, n) or raise a ValueError naming the problem."""
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


#: generous upper limits: far beyond any useful search (the optimal k for N = 2^30 and m = 1 is
#: 25 735), small enough that a circuit or a result never exhausts memory
MAX_ITERATIONS = 100_000
MAX_SHOTS = 10_000_000


def validate_iterations(iterations: int) -> int:
    return check_int(iterations, "iterations", 0, MAX_ITERATIONS)


def validate_shots(shots: int) -> int:
    return check_int(shots, "shots", 1, MAX_SHOTS)


def seed_stream(seed: int | np.random.Generator | None) -> np.random.Generator:
    """A numpy Generator from a seed, a Generator (used as is) or None (fresh entropy)."""
    if isinstance(seed, np.random.Generator):
        return seed
    return np.random.default_rng(check_seed(seed))


class QuantumSearchBackend(abc.ABC):
    """Runs Grover search on a marked database; subclasses differ in how (gates, exact, hardware)."""

    #: short name used in outputs and the CLI
    name: str = "backend"

    @property
    @abc.abstractmethod
    def max_qubits(self) -> int:
        """The largest n this backend accepts (memory-limited)."""

    def search(
        self, marks: np.ndarray, iterations: int, shots: int = 1, seed: int | None = None
    ) -> SearchResult:
        """Grover-search ``marks`` with ``iterations`` iterations; measure ``shots`` times.

        Prepares W|0> = H^n|0>, applies Q^k with Q = ``grover_operator(phase_oracle(marks), W)``
        (paper Alg. 2, lines 4-8; ``qrrt_circuits.search.circuits``) and measures; a marked index
        comes out with probability sin^2((2k+1) theta), sin^2 theta = m / 2^n (paper Eq. 1,
        Lemma 1). Each shot is one worker's independent
        preparation.

        Args:
            marks: Boolean array of length 2^n: the phase oracle's marked entries.
            iterations: k, the Grover iterations (0 .. ``MAX_ITERATIONS``).
            shots: Independent preparations and measurements (1 .. ``MAX_SHOTS``).
            seed: Seeds this call only (planners pass one per round and worker, so their results
                do not depend on the order of calls); by default the backend's own stream.

        Returns:
            ``SearchResult`` with ``indices`` (one measured index per shot), ``iterations``,
            ``shots`` and ``oracle_calls = iterations * shots`` (DESIGN §2).

        Raises:
            ValueError: ``marks`` not of length 2^n (n >= 1), n above ``max_qubits``, an estimated
                peak memory that does not fit (``qrrt_circuits.memory``), or ``iterations`` /
                ``shots`` out of range, before any work.
            TypeError: Arguments of the wrong type.
        """
        prepared = self._prepare(SearchRequest(marks, iterations, shots, seed))
        return self._finish(prepared, self._sample(*prepared))

    def search_many(self, requests: Sequence[SearchRequest]) -> tuple[SearchResult, ...]:
        """Independent searches (the p databases of one unshared Pq-RRT round): result i is exactly
        what ``search(marks, iterations, shots, seed)`` of request i returns when the requests are
        searched one after the other (same seeds, same measured indices). Every request is
        validated before any search runs. A backend may run them together (``AerBackend``)."""
        prepared = [self._prepare(request) for request in requests]
        return tuple(self._finish(item, self._sample(*item)) for item in prepared)

    def _prepare(self, request: SearchRequest) -> _Prepared:
        """(marks, n, iterations, shots, rng) of one validated request."""
        if not isinstance(request, SearchRequest):
            raise TypeError(f"requests must be SearchRequest objects, got {type(request).__name__}")
        marks, num_qubits = validate_marks(request.marks)
        iterations = validate_iterations(request.iterations)
        shots = validate_shots(request.shots)
        self.check_qubits(num_qubits)
        self.check_memory(num_qubits, shots, iterations)
        return marks, num_qubits, iterations, shots, self._rng if request.seed is None else seed_stream(request.seed)

    @staticmethod
    def _finish(prepared: _Prepared, indices: np.ndarray) -> SearchResult:
        _, _, iterations, shots, _ = prepared
        return SearchResult(indices, iterations, shots, iterations * shots)

    #: generic footprint of one search (subclasses report their own, calibrated): a complex128 state
    #: vector and the measured indices
    BYTES_PER_ENTRY: int = 16
    BYTES_PER_SHOT: int = 64

    def peak_bytes(self, num_qubits: int, shots: int = 1, iterations: int = 1) -> int:
        """Peak bytes one ``search`` of a 2^n-entry database adds to the process, beyond the marks
        the caller holds (used by the memory guard, ``qrrt_circuits.memory``)."""
        return (self.BYTES_PER_ENTRY << num_qubits) + self.BYTES_PER_SHOT * shots

    def memory_estimate(self, num_qubits: int, shots: int = 1, iterations: int = 1) -> MemoryEstimate:
        """This backend's search alone, as a ``MemoryEstimate``."""
        return MemoryEstimate(num_qubits, search_bytes=self.peak_bytes(num_qubits, shots, iterations),
                              scratch_bytes=0)

    def check_memory(self, num_qubits: int, shots: int = 1, iterations: int = 1) -> None:
        """Refuse a search whose estimated peak exceeds the available memory (before allocating)."""
        check_fits(lambda n: self.memory_estimate(n, shots, iterations), num_qubits,
                   f"this {self.name} search ({shots} shots, {iterations} iterations)")

    def search_sequence(self, marks: np.ndarray, sequence: IterateSequence, shots: int = 1,
                        seed: int | None = None) -> SearchResult:
        """Apply the generalized Grover iterates of ``sequence`` (an ``IterateSequence``) to the
        uniform state and measure ``shots`` times; ``iterations`` of the result = len(sequence)."""
        from .fixed_point import IterateSequence

        marks, num_qubits = validate_marks(marks)
        if not isinstance(sequence, IterateSequence):
            raise TypeError(f"sequence must be an IterateSequence, got {type(sequence).__name__}")
        shots = validate_shots(shots)
        self.check_qubits(num_qubits)
        self.check_memory(num_qubits, shots, len(sequence))
        rng = self._rng if seed is None else seed_stream(seed)
        indices = self._sample_sequence(marks, num_qubits, sequence, shots, rng)
        return SearchResult(indices, len(sequence), shots, sequence.oracle_calls * shots)

    def _sample_sequence(self, marks: np.ndarray, num_qubits: int, sequence: IterateSequence, shots: int,
                         rng: np.random.Generator) -> np.ndarray:
        """``shots`` measured indices after ``sequence`` (validated inputs); backends that can run
        generalized iterates override this."""
        raise NotImplementedError(f"backend {self.name!r} does not run generalized Grover iterates "
                                  "(search_sequence); use the aer, statevector or sampler backend")

    def labels(self) -> tuple[str, ...]:
        """Caveats every result that depends on this backend must carry (none by default)."""
        return ()

    def describe(self) -> str:
        return self.name

    def check_qubits(self, num_qubits: int) -> None:
        if num_qubits < 1 or num_qubits > self.max_qubits:
            raise ValueError(
                f"num_qubits = {num_qubits} is outside the range this backend supports "
                f"({self.name}: 1..{self.max_qubits} qubits, set by available memory)"
            )

    _rng: np.random.Generator

    @abc.abstractmethod
    def _sample(
        self, marks: np.ndarray, num_qubits: int, iterations: int, shots: int, rng: np.random.Generator
    ) -> np.ndarray:
        """Return ``shots`` measured indices (validated inputs), drawing randomness from ``rng``."""
