"""The ``QuantumSearchBackend`` interface and its result type.

A backend Grover-searches a database of N = 2^n entries given its phase oracle (a ``SearchOracle``:
``LookupOracle(marks)`` or ``CircuitOracle(circuit, index_qubits)``, ``search/oracles.py``): it
prepares the uniform superposition, applies ``iterations`` Grover iterations and measures, once per
shot. Each shot is an independent preparation and measurement, so one call with ``shots = p`` stands
for p workers searching copies of one shared database (the simulation shortcut of Pq-RRT: on
hardware each worker would run its own circuit).

Oracle calls are counted as DESIGN §2 says: one per Grover iteration per preparation, so
``oracle_calls = iterations * shots``.

``search_sequence(oracle, sequence, shots, seed)`` runs generalized iterates G(alpha_j, beta_j)
instead (an ``IterateSequence``, ``search/iterate_sequence.py``: fixed-point amplitude amplification);
each iterate queries the oracle once, so ``oracle_calls = len(sequence) * shots`` as well.

Memory: a backend reports the peak a search adds (``peak_bytes``, a number). ``search``,
``search_many`` and ``search_sequence`` are direct searches: each call makes one memory check of
them before the search allocates anything, and words a ``MemoryError`` raised while it runs as a
one-line ``OutOfMemory`` (``memory.run_checked``). ``run`` and ``run_sequence`` are the same
searches without either, for a caller whose own check covers them (a plan's ``memory.PlanSize``,
``qrrt search``'s).
"""

from __future__ import annotations

import abc
import functools
from collections.abc import Sequence
from typing import TYPE_CHECKING, TypeAlias

import numpy as np

from ..._support import memory
from ..._support.validation import check_seed
from ..oracles import SearchOracle, check_oracle
from ..requests import (
    MAX_ITERATIONS,
    MAX_SHOTS,
    SearchRequest,
    SearchResult,
    check_measured,
    seed_stream,
    validate_iterations,
    validate_marks,
    validate_shots,
)

if TYPE_CHECKING:
    from ..iterate_sequence import IterateSequence

#: a validated request: (oracle, num_qubits, iterations, shots, seed)
_Prepared: TypeAlias = tuple[SearchOracle, int, int, int, "int | np.random.Generator | None"]
#: a validated sequence search: (oracle, num_qubits, shots, sequence, seed)
_PreparedSequence: TypeAlias = tuple[SearchOracle, int, int, "IterateSequence", "int | np.random.Generator | None"]

#: the request types and checks, importable from here as from ``requests``
__all__ = ["MAX_ITERATIONS", "MAX_SHOTS", "QuantumSearchBackend", "SearchRequest", "SearchResult", "check_measured",
           "seed_stream", "validate_iterations", "validate_marks", "validate_shots"]


class QuantumSearchBackend(abc.ABC):
    """Runs Grover search on a phase oracle; subclasses differ in how (gates, exact, hardware).

    The quantum part of the paper's Alg. 2 / 3 (lines 4-8 of the worker): prepare ``H^n|0>``, apply k
    Grover iterations and measure; a marked index comes out with probability sin^2((2k+1) theta),
    sin^2 theta = m / 2^n (Eq. 1, Lemma 1). Implementations: ``AerBackend`` (gate level on
    qiskit-aer), ``StatevectorBackend`` (exact), ``SamplerBackend`` (any ``SamplerV2``). A subclass
    implements ``max_qubits`` and ``_sample``, and reports its ``peak_bytes``.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits import LookupOracle, SearchRequest, StatevectorBackend
        >>> backend = StatevectorBackend(seed=0)
        >>> marks = np.zeros(8, dtype=bool)
        >>> marks[5] = True
        >>> result = backend.search(LookupOracle(marks), iterations=2, shots=4, seed=1)
        >>> result.shots, result.oracle_calls  # 2 iterations x 4 preparations
        (4, 8)
        >>> again, = backend.search_many([SearchRequest(LookupOracle(marks), 2, 4, seed=1)])
        >>> bool(np.array_equal(again.indices, result.indices))
        True
    """

    #: short name used in outputs and the CLI
    name: str = "backend"

    @property
    @abc.abstractmethod
    def max_qubits(self) -> int:
        """The largest n this backend accepts (memory-limited)."""

    def search(self, oracle: SearchOracle, iterations: int, shots: int = 1, seed: int | None = None) -> SearchResult:
        """Grover-search ``oracle`` with ``iterations`` iterations; measure ``shots`` times.

        Prepares W|0> = H^n|0> on the oracle's index register, applies Q^k with Q = (2|s><s| - I) O
        (paper Alg. 2, lines 4-8; ``qrrt_circuits.search.circuits``) and measures the index; a marked
        index comes out with probability sin^2((2k+1) theta), sin^2 theta = m / 2^n (paper Eq. 1,
        Lemma 1). Each shot is one worker's independent preparation.

        Args:
            oracle: The phase oracle: ``LookupOracle(marks)`` (the lookup of 2^n marks) or a
                ``CircuitOracle`` (a phase-oracle circuit; not every backend runs one).
            iterations: k, the Grover iterations (0 .. ``MAX_ITERATIONS``).
            shots: Independent preparations and measurements (1 .. ``MAX_SHOTS``).
            seed: Seeds this call only (planners pass one per round and worker, so their results
                do not depend on the order of calls); by default the backend's own stream.

        Returns:
            ``SearchResult`` with ``indices`` (one measured index per shot), ``iterations``,
            ``shots`` and ``oracle_calls = iterations * shots`` (DESIGN §2).

        Raises:
            ValueError: n above ``max_qubits``, an oracle this backend cannot run (the message
                names what runs it), an estimated peak memory that does not fit
                (``qrrt_circuits._support.memory``; checked once per call), or ``iterations`` /
                ``shots`` out of range, before any work.
            TypeError: Arguments of the wrong type (marks not wrapped in a ``LookupOracle``).
            qrrt_circuits._support.memory.OutOfMemory: A ``MemoryError`` while the search ran (one line:
                n, what the allocator reported, the largest smaller n whose estimate fits).
        """
        return self.search_many([SearchRequest(oracle, iterations, shots, seed)])[0]

    def search_many(self, requests: Sequence[SearchRequest]) -> tuple[SearchResult, ...]:
        """Independent searches: result i is exactly what ``search(oracle, iterations, shots,
        seed)`` of request i returns when the requests are searched one after the other (same
        seeds, same measured indices). Every request is validated, and the call's one memory check
        made, before any work.

        Args:
            requests: The ``SearchRequest`` objects.

        Returns:
            One ``SearchResult`` per request, in order.

        Raises:
            TypeError: An element that is not a ``SearchRequest``, or arguments of the wrong type.
            ValueError: Any request that ``search`` would refuse (checked for all before any runs;
                the available memory is read once for the call).
            qrrt_circuits._support.memory.OutOfMemory: A ``MemoryError`` while a search ran.
        """
        prepared = [self._prepare(request) for request in requests]
        return memory.run_checked([self._size(item, sequence=False) for item in prepared],
                                  [functools.partial(self._run_prepared, item) for item in prepared])

    def run(self, oracle: SearchOracle, iterations: int, shots: int = 1, seed: int | None = None) -> SearchResult:
        """``search`` without its memory check and without ``OutOfMemory``: for a caller whose own
        check covers this search (a plan's ``memory.PlanSize``, ``qrrt search``'s) and which words a
        ``MemoryError`` itself. Same arguments, results and other refusals as ``search``."""
        return self._run_prepared(self._prepare(SearchRequest(oracle, iterations, shots, seed)))

    def search_sequence(self, oracle: SearchOracle, sequence: IterateSequence, shots: int = 1,
                        seed: int | None = None) -> SearchResult:
        """Apply the generalized Grover iterates of ``sequence`` (an ``IterateSequence``) to the
        uniform state and measure ``shots`` times; ``iterations`` of the result = len(sequence).

        Fixed-point amplitude amplification (Yoder, Low and Chuang 2014): each generalized iterate
        queries the oracle once, so ``oracle_calls = len(sequence) * shots``.

        Args:
            oracle: The phase oracle (one that gives the phase e^{i beta}: a ``LookupOracle``).
            sequence: The ``IterateSequence``.
            shots: Preparations, 1 .. ``MAX_SHOTS`` (default 1).
            seed: This call's seed, or None (default) for the backend's own stream.

        Returns:
            The ``SearchResult``.

        Raises:
            ValueError: n above ``max_qubits``, ``shots`` out of range, an oracle that cannot give
                the iterates' phases, or an estimated peak memory that does not fit (checked once
                per call).
            TypeError: ``sequence`` not an ``IterateSequence``, or a non-integer ``shots``.
            NotImplementedError: A backend that does not run generalized iterates.
            qrrt_circuits._support.memory.OutOfMemory: A ``MemoryError`` while the search ran.
        """
        prepared = self._prepare_sequence(oracle, sequence, shots, seed)
        checked, num_qubits, counted, _, _ = prepared
        size = self._size((checked, num_qubits, len(sequence), counted, None), sequence=True)
        return memory.run_checked([size], [lambda: self._run_sequence(*prepared)])[0]

    def run_sequence(self, oracle: SearchOracle, sequence: IterateSequence, shots: int = 1,
                     seed: int | None = None) -> SearchResult:
        """``search_sequence`` without its memory check and without ``OutOfMemory`` (see ``run``)."""
        return self._run_sequence(*self._prepare_sequence(oracle, sequence, shots, seed))

    #: generic footprint of one search (subclasses report their own, calibrated): a complex128 state
    #: vector, the measured indices, and what a search adds whatever its size (its result, Python
    #: objects, allocator slack)
    BYTES_PER_ENTRY: int = 16
    BYTES_PER_SHOT: int = 64
    FIXED_BYTES: int = 1 << 20

    def peak_bytes(self, num_qubits: int, shots: int = 1, iterations: int = 1, marked: int | None = None, *,
                   sequence: bool = False) -> int:
        """A bound of the peak bytes one search of a 2^n-entry lookup oracle adds to the process,
        beyond the marks the caller holds: the size the memory checks compare with the available
        memory (``qrrt_circuits._support.memory``). It grows with n and is at least the 2^n
        complex128 amplitudes of the index register's state (16 * 2^n bytes). A circuit oracle's
        search is sized by its index register as a lookup's: its ancillas and its own gates are not
        counted (Aer refuses a state it cannot hold with an error of its own).

        Args:
            num_qubits: n.
            shots: Preparations (default 1).
            iterations: k, or the generalized iterates of a sequence (default 1).
            marked: m, the number of marked entries, or None (default) for a bound over every m.
            sequence: Whether the search runs generalized iterates (``search_sequence``; default
                False).

        Returns:
            ``FIXED_BYTES + BYTES_PER_ENTRY * 2^n + BYTES_PER_SHOT * shots`` here; subclasses report
            their own (``benchmarks/memory_peaks.py`` measures each against its peak).
        """
        return self.FIXED_BYTES + (self.BYTES_PER_ENTRY << num_qubits) + self.BYTES_PER_SHOT * shots

    def labels(self) -> tuple[str, ...]:
        """Caveats every result that depends on this backend must carry (none by default)."""
        return ()

    def describe(self) -> str:
        """The backend's settings in words (recorded in ``PlanResult.settings``)."""
        return self.name

    def check_qubits(self, num_qubits: int) -> None:
        """Refuse an n this backend does not support.

        Args:
            num_qubits: n.

        Raises:
            ValueError: n < 1 or n > ``max_qubits``.
        """
        if num_qubits < 1 or num_qubits > self.max_qubits:
            raise ValueError(
                f"num_qubits = {num_qubits} is outside the range this backend supports "
                f"({self.name}: 1..{self.max_qubits} qubits, set by available memory)"
            )

    _rng: np.random.Generator

    def _prepare(self, request: SearchRequest) -> _Prepared:
        """(oracle, n, iterations, shots, seed) of one validated request; the seed is None (the
        backend's own stream), a non-negative int or a ``numpy.random.Generator``."""
        if not isinstance(request, SearchRequest):
            raise TypeError(f"requests must be SearchRequest objects, got {type(request).__name__}")
        oracle = check_oracle(request.oracle)
        iterations = validate_iterations(request.iterations)
        shots = validate_shots(request.shots)
        self.check_qubits(oracle.num_qubits)
        seed = request.seed
        if not isinstance(seed, np.random.Generator):
            seed = check_seed(seed)
        return oracle, oracle.num_qubits, iterations, shots, seed

    def _size(self, prepared: _Prepared, sequence: bool) -> memory.SearchSize:
        """The ``SearchSize`` of one validated search (its ``peak_bytes`` at its shots and k)."""
        oracle, num_qubits, iterations, shots, _ = prepared

        def peak(width: int, marked: int | None) -> int:
            return self.peak_bytes(width, shots, iterations, marked, sequence=sequence)

        return memory.SearchSize(peak, num_qubits, self.name, shots, iterations, oracle.marked_count)

    def _run_prepared(self, prepared: _Prepared) -> SearchResult:
        """The ``SearchResult`` of one validated request, refused (``RuntimeError``) unless the
        measured indices are one integer index in [0, 2^n) per shot: a backend (a subclass, a
        sampler) that returns anything else would otherwise have the planners read outside the
        database."""
        oracle, num_qubits, iterations, shots, seed = prepared
        indices = self._sample_seeded(oracle, num_qubits, iterations, shots, seed)
        check_measured(indices, shots, 1 << num_qubits, self.name)
        return SearchResult(indices, iterations, shots, iterations * shots)

    def _generator(self, seed: int | np.random.Generator | None) -> np.random.Generator:
        """The generator of one search: the backend's own stream for None, else ``seed_stream``."""
        return self._rng if seed is None else seed_stream(seed)

    def _first_integer(self, seed: int | np.random.Generator | None, high: int) -> int:
        """``int(self._generator(seed).integers(0, high))``: a search's simulator seed."""
        return int(self._generator(seed).integers(0, high))

    def _sample_seeded(self, oracle: SearchOracle, num_qubits: int, iterations: int, shots: int,
                       seed: int | np.random.Generator | None) -> np.ndarray:
        """``_sample`` with the generator of ``seed``."""
        return self._sample(oracle, num_qubits, iterations, shots, self._generator(seed))

    @abc.abstractmethod
    def _sample(self, oracle: SearchOracle, num_qubits: int, iterations: int, shots: int,
                rng: np.random.Generator) -> np.ndarray:
        """Return ``shots`` measured indices (validated inputs), drawing randomness from ``rng``;
        ask ``oracle`` for what this backend runs (``lookup_marks``, ``grover_circuit``)."""

    def _prepare_sequence(self, oracle: SearchOracle, sequence: IterateSequence, shots: int,
                          seed: int | np.random.Generator | None) -> _PreparedSequence:
        """(oracle, n, shots, sequence, seed) of a validated ``search_sequence`` call."""
        from ..iterate_sequence import IterateSequence

        oracle = check_oracle(oracle)
        if not isinstance(sequence, IterateSequence):
            raise TypeError(f"sequence must be an IterateSequence, got {type(sequence).__name__}")
        shots = validate_shots(shots)
        self.check_qubits(oracle.num_qubits)
        if not isinstance(seed, np.random.Generator):
            seed = check_seed(seed)
        return oracle, oracle.num_qubits, shots, sequence, seed

    def _run_sequence(self, oracle: SearchOracle, num_qubits: int, shots: int, sequence: IterateSequence,
                      seed: int | np.random.Generator | None) -> SearchResult:
        indices = self._sample_sequence(oracle, num_qubits, sequence, shots, self._generator(seed))
        check_measured(indices, shots, 1 << num_qubits, self.name)
        return SearchResult(indices, len(sequence), shots, sequence.oracle_calls * shots)

    def _sample_sequence(self, oracle: SearchOracle, num_qubits: int, sequence: IterateSequence, shots: int,
                         rng: np.random.Generator) -> np.ndarray:
        """``shots`` measured indices after ``sequence`` (validated inputs); backends that can run
        generalized iterates override this."""
        raise NotImplementedError(f"backend {self.name!r} does not run generalized Grover iterates "
                                  "(search_sequence); use the aer, statevector or sampler backend")
