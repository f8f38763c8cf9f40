"""The ``QuantumSearchBackend`` interface and its result type.

A backend Grover-searches a database of N = 2^n entries given the oracle's marks (a bool array of
length N): it prepares the uniform superposition, applies ``iterations`` Grover iterations and
measures, once per shot. Each shot is an independent preparation and measurement, so one call with
``shots = p`` stands for p workers searching copies of one shared database (the simulation
shortcut of Pq-RRT: on hardware each worker would run its own circuit).

Oracle calls are counted as DESIGN §2 says: one per Grover iteration per preparation, so
``oracle_calls = iterations * shots``.

``search_sequence(marks, sequence, shots, seed)`` runs generalized iterates G(alpha_j, beta_j)
instead (an ``IterateSequence``, ``search/iterate_sequence.py``: fixed-point amplitude amplification);
each iterate queries the oracle once, so ``oracle_calls = len(sequence) * shots`` as well.

Memory: each call of ``search``, ``search_many`` and ``search_sequence`` checks its estimated peak
against the available memory once, before the search allocates anything, and a ``MemoryError``
raised while it runs becomes a one-line ``qrrt_circuits._support.memory.OutOfMemory``. A plan's searches
(``DatabaseSearch`` with ``memory_checked``) make neither: the plan's own check covers them.
"""

from __future__ import annotations

import abc
import functools
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, TypeAlias, TypeVar

import numpy as np

from ..._support import memory
from ..._support.memory import MemoryEstimate, OutOfMemory, check_fits, out_of_memory
from ..._support.validation import check_seed
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

#: a validated request: (marks, num_qubits, iterations, shots, rng)
_Prepared: TypeAlias = tuple[np.ndarray, int, int, int, "int | np.random.Generator | None"]
#: a peak-memory estimate: (num_qubits, shots, iterations, marked or None) -> bytes
_Peak: TypeAlias = Callable[[int, int, int, "int | None"], int]
#: what one search is sized by: (marks, num_qubits, iterations, shots)
_Sized: TypeAlias = tuple[np.ndarray, int, int, int]
_T = TypeVar("_T")

#: the request types and checks, importable from here as from ``requests``
__all__ = ["MAX_ITERATIONS", "MAX_SHOTS", "QuantumSearchBackend", "SearchRequest", "SearchResult", "check_measured",
           "seed_stream", "validate_iterations", "validate_marks", "validate_shots"]


class QuantumSearchBackend(abc.ABC):
    """Runs Grover search on a marked database; subclasses differ in how (gates, exact, hardware).

    The quantum part of the paper's Alg. 2 / 3 (lines 4-8 of the worker): prepare ``H^n|0>``, apply k
    Grover iterations and measure; a marked index comes out with probability sin^2((2k+1) theta),
    sin^2 theta = m / 2^n (Eq. 1, Lemma 1). Implementations: ``AerBackend`` (gate level on
    qiskit-aer), ``StatevectorBackend`` (exact), ``SamplerBackend`` (any ``SamplerV2``). A subclass
    implements ``max_qubits`` and ``_sample``.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits import SearchRequest, StatevectorBackend
        >>> backend = StatevectorBackend(seed=0)
        >>> marks = np.zeros(8, dtype=bool)
        >>> marks[5] = True
        >>> result = backend.search(marks, iterations=2, shots=4, seed=1)
        >>> result.shots, result.oracle_calls  # 2 iterations x 4 preparations
        (4, 8)
        >>> again, = backend.search_many([SearchRequest(marks, 2, 4, seed=1)])
        >>> bool(np.array_equal(again.indices, result.indices))
        True
    """

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
                peak memory that does not fit (``qrrt_circuits._support.memory``; checked once per call), or
                ``iterations`` / ``shots`` out of range, before any work.
            TypeError: Arguments of the wrong type.
            qrrt_circuits._support.memory.OutOfMemory: A ``MemoryError`` while the search ran (one line:
                n, what the allocator reported, the largest smaller n whose estimate fits).
        """
        prepared = self._prepare(SearchRequest(marks, iterations, shots, seed))
        measured = self._check_searches(self.peak_bytes, [prepared[:4]])
        return self._guarded(self.peak_bytes, prepared[:4], functools.partial(self._run_prepared, prepared),
                             measured)

    def _search_covered(self, marks: np.ndarray, iterations: int, shots: int = 1,
                        seed: int | None = None) -> SearchResult:
        """``search`` without its memory check and without ``OutOfMemory``: for a caller whose own
        check covered this search (a plan's ``PlanSize.check``, ``qrrt search``'s) and which words
        a ``MemoryError`` itself."""
        return self._run_prepared(self._prepare(SearchRequest(marks, iterations, shots, seed)))

    def search_many(self, requests: Sequence[SearchRequest]) -> tuple[SearchResult, ...]:
        """Independent searches: result i is exactly what ``search(marks, iterations, shots,
        seed)`` of request i returns when the requests are searched one after the other (same
        seeds, same measured indices). Every request is validated before any work. A backend may
        override this to run them together.

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
        measured = self._check_searches(self.peak_bytes, [item[:4] for item in prepared])
        return tuple(self._guarded(self.peak_bytes, item[:4], functools.partial(self._run_prepared, item), measured)
                     for item in prepared)

    def _run_prepared(self, prepared: _Prepared) -> SearchResult:
        """The ``SearchResult`` of one validated request."""
        return self._finish(prepared, self._sample_seeded(*prepared))

    def _prepare(self, request: SearchRequest) -> _Prepared:
        """(marks, n, iterations, shots, seed) of one validated request; the seed is None (the
        backend's own stream), a non-negative int or a ``numpy.random.Generator``."""
        if not isinstance(request, SearchRequest):
            raise TypeError(f"requests must be SearchRequest objects, got {type(request).__name__}")
        marks, num_qubits = validate_marks(request.marks)
        iterations = validate_iterations(request.iterations)
        shots = validate_shots(request.shots)
        self.check_qubits(num_qubits)
        seed = request.seed
        if not isinstance(seed, np.random.Generator):
            seed = check_seed(seed)
        return marks, num_qubits, iterations, shots, seed

    def _generator(self, seed: int | np.random.Generator | None) -> np.random.Generator:
        """The generator of one search: the backend's own stream for None, else ``seed_stream``."""
        return self._rng if seed is None else seed_stream(seed)

    def _first_integer(self, seed: int | np.random.Generator | None, high: int) -> int:
        """``int(self._generator(seed).integers(0, high))``: a search's simulator seed."""
        return int(self._generator(seed).integers(0, high))

    def _sample_seeded(self, marks: np.ndarray, num_qubits: int, iterations: int, shots: int,
                       seed: int | np.random.Generator | None) -> np.ndarray:
        """``_sample`` with the generator of ``seed``."""
        return self._sample(marks, num_qubits, iterations, shots, self._generator(seed))

    def _finish(self, prepared: _Prepared, indices: np.ndarray) -> SearchResult:
        """The ``SearchResult`` of a search's measured indices, refused (``RuntimeError``) unless
        they are one integer index in [0, 2^n) per shot: a backend (a subclass, a sampler) that
        returns anything else would otherwise have the planners read outside the database."""
        marks, _, iterations, shots, _ = prepared
        check_measured(indices, shots, marks.shape[0], self.name)
        return SearchResult(indices, iterations, shots, iterations * shots)

    #: generic footprint of one search (subclasses report their own, calibrated): a complex128 state
    #: vector and the measured indices
    BYTES_PER_ENTRY: int = 16
    BYTES_PER_SHOT: int = 64

    def peak_bytes(self, num_qubits: int, shots: int = 1, iterations: int = 1, marked: int | None = None) -> int:
        """Peak bytes one ``search`` of a 2^n-entry database adds to the process, beyond the marks
        the caller holds (used by the memory guard, ``qrrt_circuits._support.memory``).

        Args:
            num_qubits: n.
            shots: Preparations (default 1).
            iterations: k (default 1; the generic estimate ignores it).
            marked: m, the number of marked entries, or None (default) for a bound over every m
                (the generic estimate ignores it; ``AerBackend``'s depends on its oracle's form).

        Returns:
            ``BYTES_PER_ENTRY * 2^n + BYTES_PER_SHOT * shots`` here; subclasses report their own.
        """
        return (self.BYTES_PER_ENTRY << num_qubits) + self.BYTES_PER_SHOT * shots

    def memory_estimate(self, num_qubits: int, shots: int = 1, iterations: int = 1,
                        marked: int | None = None) -> MemoryEstimate:
        """This backend's search alone, as a ``MemoryEstimate``.

        Args:
            num_qubits: n.
            shots: Preparations (default 1).
            iterations: k (default 1).
            marked: m, or None (default) for a bound over every m.

        Returns:
            A ``MemoryEstimate`` with ``search_bytes = peak_bytes(n, shots, iterations, marked)``.
        """
        return MemoryEstimate(num_qubits, search_bytes=self.peak_bytes(num_qubits, shots, iterations, marked),
                              scratch_bytes=0)

    def check_memory(self, num_qubits: int, shots: int = 1, iterations: int = 1, marked: int | None = None) -> None:
        """Refuse a search whose estimated peak exceeds the available memory (before allocating).

        Args:
            num_qubits: n.
            shots: Preparations (default 1).
            iterations: k (default 1).
            marked: m, or None (default) for a bound over every m.

        Raises:
            ValueError: The estimate does not fit in the available memory.
        """
        self._check_peak(self.peak_bytes, num_qubits, shots, iterations, marked)

    def sequence_peak_bytes(self, num_qubits: int, shots: int = 1, iterations: int = 1,
                            marked: int | None = None) -> int:
        """``peak_bytes`` of a ``search_sequence`` of ``iterations`` generalized iterates (by
        default the same as a search's; ``AerBackend`` builds those circuits gate by gate).

        Args:
            num_qubits: n.
            shots: Preparations (default 1).
            iterations: The sequence's length.
            marked: m, or None (default) for a bound over every m.

        Returns:
            Bytes.
        """
        return self.peak_bytes(num_qubits, shots, iterations, marked)

    def check_search_memory(self, marks: np.ndarray, shots: int = 1, iterations: int = 1) -> None:
        """Refuse the search of these marks if its estimated peak exceeds the available memory
        (what ``search`` checks, once per call).

        First ``check_memory`` of their width with the bound over every m (no pass over the
        marks); only where that bound does not fit and the estimate for their count m is smaller
        (``AerBackend`` with its ``mcz`` oracle), again with m. The available memory is read at
        most once.

        Args:
            marks: The validated boolean array of length 2^n.
            shots: Preparations (default 1).
            iterations: k (default 1).

        Raises:
            ValueError: The estimate does not fit in the available memory.
        """
        self._check_searches(self.peak_bytes, [(marks, int(marks.shape[0]).bit_length() - 1, iterations, shots)])

    def _check_searches(self, peak: _Peak, searches: Sequence[_Sized]) -> tuple[int, str] | None:
        """One memory check of searches run one after the other: each held to ``peak``'s bound
        over every m and, where that does not fit and the estimate for its marks' count m is
        smaller, to that; the available memory read at most once (none of it where every bound is
        at most ``always_fits_bytes()``). Returns what was read (``available_memory()``), or None."""
        bounds = [peak(num_qubits, shots, iterations, None) for _, num_qubits, iterations, shots in searches]
        if not bounds or max(bounds) <= memory.always_fits_bytes():
            return None
        measured = memory.available_memory()
        if measured is None:
            return None
        for (marks, num_qubits, iterations, shots), bound in zip(searches, bounds, strict=True):
            if bound <= measured[0]:
                continue
            marked: int | None = int(np.count_nonzero(marks))
            if peak(num_qubits, shots, iterations, marked) >= bound:
                marked = None  # the count cannot lower the estimate: the message names none
            self._check_peak(peak, num_qubits, shots, iterations, marked, measured)
        return measured

    def _check_peak(self, peak: _Peak, num_qubits: int, shots: int, iterations: int, marked: int | None,
                    measured: tuple[int, str] | None = None) -> None:
        """``check_fits`` of ``peak(n, shots, iterations, marked)`` bytes (against ``measured``,
        ``(bytes, source)``, where given)."""
        marks_text = "" if marked is None else f", {marked} marked"

        def estimate(width: int) -> MemoryEstimate:
            return MemoryEstimate(width, search_bytes=peak(width, shots, iterations, marked), scratch_bytes=0)

        what = f"this {self.name} search ({shots} shots, {iterations} iterations{marks_text})"
        if measured is None:
            check_fits(estimate, num_qubits, what)
        else:
            check_fits(estimate, num_qubits, what, available=measured[0], source=measured[1])

    def _guarded(self, peak: _Peak, search: _Sized, run: Callable[[], _T], measured: tuple[int, str] | None) -> _T:
        """``run()``, a ``MemoryError`` raised again as a one-line ``OutOfMemory`` naming the
        search's n, what the allocator reported and the largest smaller n whose bound fits in
        ``measured`` (what the check read; None: read then)."""
        try:
            return run()
        except OutOfMemory:
            raise
        except MemoryError as error:
            _, num_qubits, iterations, shots = search

            def estimate(width: int) -> MemoryEstimate:
                return MemoryEstimate(width, search_bytes=peak(width, shots, iterations, None), scratch_bytes=0)

            what = f"this {self.name} search ({shots} shots, {iterations} iterations)"
            raise out_of_memory(error, estimate, num_qubits, what, measured) from error

    def search_sequence(self, marks: np.ndarray, sequence: IterateSequence, shots: int = 1,
                        seed: int | None = None) -> SearchResult:
        """Apply the generalized Grover iterates of ``sequence`` (an ``IterateSequence``) to the
        uniform state and measure ``shots`` times; ``iterations`` of the result = len(sequence).

        Fixed-point amplitude amplification (Yoder, Low and Chuang 2014): each generalized iterate
        queries the oracle once, so ``oracle_calls = len(sequence) * shots``.

        Args:
            marks: Boolean array of length 2^n.
            sequence: The ``IterateSequence``.
            shots: Preparations, 1 .. ``MAX_SHOTS`` (default 1).
            seed: This call's seed, or None (default) for the backend's own stream.

        Returns:
            The ``SearchResult``.

        Raises:
            ValueError: ``marks`` not of length 2^n, n above ``max_qubits``, ``shots`` out of
                range, or an estimated peak memory that does not fit (checked once per call).
            TypeError: ``sequence`` not an ``IterateSequence``, or a non-integer ``shots``.
            NotImplementedError: A backend that does not run generalized iterates.
            qrrt_circuits._support.memory.OutOfMemory: A ``MemoryError`` while the search ran.
        """
        marks, num_qubits, shots = self._prepare_sequence(marks, sequence, shots)
        sized = (marks, num_qubits, len(sequence), shots)
        measured = self._check_searches(self.sequence_peak_bytes, [sized])
        return self._guarded(self.sequence_peak_bytes, sized,
                             lambda: self._run_sequence(marks, num_qubits, sequence, shots, seed), measured)

    def _search_sequence_covered(self, marks: np.ndarray, sequence: IterateSequence, shots: int = 1,
                                 seed: int | None = None) -> SearchResult:
        """``search_sequence`` without its memory check and without ``OutOfMemory`` (see
        ``_search_covered``)."""
        marks, num_qubits, shots = self._prepare_sequence(marks, sequence, shots)
        return self._run_sequence(marks, num_qubits, sequence, shots, seed)

    def _prepare_sequence(self, marks: np.ndarray, sequence: IterateSequence,
                          shots: int) -> tuple[np.ndarray, int, int]:
        """(marks, n, shots) of a validated ``search_sequence`` call."""
        from ..iterate_sequence import IterateSequence

        marks, num_qubits = validate_marks(marks)
        if not isinstance(sequence, IterateSequence):
            raise TypeError(f"sequence must be an IterateSequence, got {type(sequence).__name__}")
        shots = validate_shots(shots)
        self.check_qubits(num_qubits)
        return marks, num_qubits, shots

    def _run_sequence(self, marks: np.ndarray, num_qubits: int, sequence: IterateSequence, shots: int,
                      seed: int | None) -> SearchResult:
        rng = self._rng if seed is None else seed_stream(seed)
        indices = self._sample_sequence(marks, num_qubits, sequence, shots, rng)
        check_measured(indices, shots, marks.shape[0], self.name)
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

    @abc.abstractmethod
    def _sample(
        self, marks: np.ndarray, num_qubits: int, iterations: int, shots: int, rng: np.random.Generator
    ) -> np.ndarray:
        """Return ``shots`` measured indices (validated inputs), drawing randomness from ``rng``."""
