"""One database as a search policy sees it, and what one worker's search of it produced.

A ``DatabaseSearch`` gives a policy three things and nothing else: ``search(iterations, shots,
seed)`` (prepare the uniform superposition, apply Grover iterations with the database's oracle,
measure ``shots`` times: each shot one worker's independent preparation; ``search_sequence(sequence,
shots, seed)`` applies generalized iterates instead, for fixed-point amplification),
``verify(index)`` (the classical finalizer: the true predicate on one entry, 1 oracle call), and the
database size. ``marked_count()`` is simulation knowledge a quantum device does not have (only
``KnownOptimal`` uses it, and it is labelled). Seeds come from the plan's random streams, keyed by
round and worker, so a search never depends on the executor or the order of workers.

A database is a part of a plan, whose one memory check (``memory.PlanSize``) covers its searches:
they run without a check of their own (``QuantumSearchBackend.run``), and a ``MemoryError`` is left
to the plan, which words it.

A ``SearchOutcome`` is what one worker's search of one database returns to the planner: the
verified index (or None), the quantum oracle calls and verifications it spent (DESIGN §2), and
observations ``(iterations, verified)`` for learning policies.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .._support.randomness import RandomStreams, Stream
from .backends.base import QuantumSearchBackend
from .oracles import SearchOracle

if TYPE_CHECKING:
    from .iterate_sequence import IterateSequence


@dataclass(frozen=True)
class SearchOutcome:
    """One worker's search: ``index`` is the measured entry that verified, or None.

    Oracle calls as DESIGN §2 counts them: ``quantum_calls`` (one per Grover iteration, or per
    generalized iterate, of every preparation this worker ran) plus ``verifications`` (the
    classical finalizer of Alg. 2 / 3, one per measured entry checked).

    Args:
        index: The measured database entry that verified, or None if none did.
        quantum_calls: Quantum oracle calls this worker spent.
        verifications: Verification calls this worker spent.
        observations: ``(iterations, verified)`` per measurement, for learning policies.

    Example:
        >>> from qrrt_circuits import SearchOutcome
        >>> outcome = SearchOutcome(index=5, quantum_calls=6, verifications=2,
        ...                         observations=((3, False), (3, True)))
        >>> outcome.verified, outcome.oracle_calls, outcome.rejected
        (True, 8, 1)
    """

    index: int | None
    quantum_calls: int
    verifications: int
    observations: tuple[tuple[int, bool], ...] = ()

    @property
    def verified(self) -> bool:
        """Whether a measured entry verified (``index is not None``)."""
        return self.index is not None

    @property
    def oracle_calls(self) -> int:
        """quantum calls + verifications: this worker's share of the round's critical path."""
        return self.quantum_calls + self.verifications

    @property
    def rejected(self) -> int:
        """Measurements that failed verification."""
        return self.verifications - int(self.verified)


@dataclass(frozen=True, eq=False)
class DatabaseSearch:
    """A database of 2^n entries searched by workers ``first_worker, first_worker + 1, ...`` in round
    ``round_index``. ``oracle`` is its phase oracle (a ``LookupOracle`` of the possibly erroneous
    marks, or a ``CircuitOracle``); ``truth`` the true predicate used by ``verify``.

    What a search policy sees of one database of Alg. 2 / 3: Grover search (``search``),
    generalized iterates (``search_sequence``), the classical finalizer (``verify``, 1 oracle call)
    and the size N. ``marked_count`` is simulation knowledge (``KnownOptimal`` only, labelled). Its
    searches make no memory check of their own (module docstring).

    Args:
        oracle: The database's phase oracle (``SearchOracle``) on n index qubits.
        truth: Boolean array of length N = 2^n, the true reachability used by ``verify``.
        backend: The ``QuantumSearchBackend`` that runs the searches.
        streams: The plan's ``RandomStreams`` (seeds keyed by round and worker).
        round_index: The planner's round.
        first_worker: The first worker searching this database (default 0).

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits import DatabaseSearch, LookupOracle, StatevectorBackend
        >>> from qrrt_circuits._support.randomness import RandomStreams
        >>> marks = np.zeros(8, dtype=bool)
        >>> marks[5] = True
        >>> problem = DatabaseSearch(LookupOracle(marks), marks, StatevectorBackend(seed=0), RandomStreams(0),
        ...                          round_index=0)
        >>> problem.num_items, problem.marked_count(), problem.verify(5), problem.verify(0)
        (8, 1, True, False)
    """

    oracle: SearchOracle
    truth: np.ndarray
    backend: QuantumSearchBackend
    streams: RandomStreams
    round_index: int
    first_worker: int = 0

    @property
    def num_items(self) -> int:
        """N, the database's entries."""
        return 1 << self.oracle.num_qubits

    def search(self, iterations: int, shots: int, seed: int) -> np.ndarray:
        """Measured indices (one per shot) after ``iterations`` Grover iterations.

        Args:
            iterations: k, the Grover iterations of each preparation (k quantum oracle calls).
            shots: Independent preparations and measurements (one per worker).
            seed: The backend's sampling seed.

        Returns:
            Int array of ``shots`` measured indices.

        Raises:
            ValueError: k or ``shots`` out of the backend's range, or an oracle the backend cannot run.
            TypeError: A non-integer k or ``shots``.
        """
        return self.backend.run(self.oracle, iterations, shots, seed=seed).indices

    def search_sequence(self, sequence: IterateSequence, shots: int, seed: int) -> np.ndarray:
        """Measured indices (one per shot) after the generalized iterates of ``sequence`` (an
        ``IterateSequence``: fixed-point amplification), len(sequence) oracle calls per shot.

        Args:
            sequence: The ``IterateSequence``.
            shots: Independent preparations and measurements.
            seed: The backend's sampling seed.

        Returns:
            Int array of ``shots`` measured indices.
        """
        return self.backend.run_sequence(self.oracle, sequence, shots, seed=seed).indices

    def verify(self, index: int) -> bool:
        """The classical finalizer: is entry ``index`` truly reachable? (1 oracle call.)

        Args:
            index: A database entry, 0 .. N - 1.

        Returns:
            ``truth[index]``.
        """
        return bool(self.truth[index])

    def marked_count(self) -> int:
        """The number of marked entries: simulation knowledge (KnownOptimal only, labelled).

        Raises:
            ValueError: A circuit oracle given without its marks (its count is unknown).
        """
        count = self.oracle.marked_count()
        if count is None:
            raise ValueError("the marked count of this database's oracle is unknown (a CircuitOracle given "
                             "without its marks): a policy that reads the true m cannot search it")
        return count

    def shared_seed(self) -> int:
        """The seed of one search serving all the workers of this database.

        Returns:
            The seed of stream (``round_index``, ``first_worker``, ``Stream.SEARCH``).
        """
        return self.streams.seed(self.round_index, self.first_worker, Stream.SEARCH)

    def worker_generator(self, offset: int) -> np.random.Generator:
        """The policy's own generator for worker ``first_worker + offset``.

        Args:
            offset: The worker's offset from ``first_worker`` (>= 0).

        Returns:
            The generator of stream (``round_index``, worker, ``Stream.POLICY``).
        """
        return self.streams.generator(self.round_index, self.first_worker + offset, Stream.POLICY)
