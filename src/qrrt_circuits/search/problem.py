"""One database as a search policy sees it, and what one worker's search of it produced.

A ``DatabaseSearch`` gives a policy three things and nothing else: ``search(iterations, shots,
seed)`` (prepare the uniform superposition, apply Grover iterations, measure ``shots`` times: each
shot one worker's independent preparation; ``search_sequence(sequence, shots, seed)`` applies
generalized iterates instead, for fixed-point amplification), ``verify(index)`` (the classical finalizer: the true
predicate on one entry, 1 oracle call), and the database size. ``marked_count()`` is simulation
knowledge a quantum device does not have (only ``KnownOptimal`` uses it, and it is labelled).
Seeds come from the plan's random streams, keyed by round and worker, so a search never depends on
the executor or the order of workers.

A ``SearchOutcome`` is what one worker's search of one database returns to the planner: the
verified index (or None), the quantum oracle calls and verifications it spent (DESIGN §2), and
observations ``(iterations, verified)`` for learning policies.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..randomness import RandomStreams, Stream
from .backend import QuantumSearchBackend, SearchRequest, SearchResult

if TYPE_CHECKING:
    from .fixed_point import IterateSequence


@dataclass(frozen=True)
class SearchOutcome:
    """One worker's search: ``index`` is the measured entry that verified, or None."""

    index: int | None
    quantum_calls: int
    verifications: int
    observations: tuple[tuple[int, bool], ...] = ()

    @property
    def verified(self) -> bool:
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
    """A database of ``len(marks)`` entries searched by workers ``first_worker, first_worker + 1, ...``
    in round ``round_index``. ``marks`` are the phase oracle's (possibly erroneous) marks;
    ``truth`` the true predicate used by ``verify``."""

    marks: np.ndarray
    truth: np.ndarray
    backend: QuantumSearchBackend
    streams: RandomStreams
    round_index: int
    first_worker: int = 0

    @property
    def num_items(self) -> int:
        return int(self.marks.shape[0])

    def search(self, iterations: int, shots: int, seed: int) -> np.ndarray:
        """Measured indices (one per shot) after ``iterations`` Grover iterations."""
        return self.backend.search(self.marks, iterations, shots, seed=seed).indices

    def search_sequence(self, sequence: IterateSequence, shots: int, seed: int) -> np.ndarray:
        """Measured indices (one per shot) after the generalized iterates of ``sequence`` (an
        ``IterateSequence``: fixed-point amplification), len(sequence) oracle calls per shot."""
        return self.backend.search_sequence(self.marks, sequence, shots, seed=seed).indices

    def request(self, iterations: int, shots: int, seed: int) -> SearchRequest:
        """``search``'s arguments as a request for ``search_together``."""
        return SearchRequest(self.marks, iterations, shots, seed)

    def verify(self, index: int) -> bool:
        """The classical finalizer: is entry ``index`` truly reachable? (1 oracle call.)"""
        return bool(self.truth[index])

    def marked_count(self) -> int:
        """The number of marked entries: simulation knowledge (KnownOptimal only, labelled)."""
        return int(np.count_nonzero(self.marks))

    def shared_seed(self) -> int:
        """The seed of one search serving all the workers of this database."""
        return self.streams.seed(self.round_index, self.first_worker, Stream.SEARCH)

    def worker_generator(self, offset: int) -> np.random.Generator:
        """The policy's own generator for worker ``first_worker + offset``."""
        return self.streams.generator(self.round_index, self.first_worker + offset, Stream.POLICY)


def search_together(problems: Sequence[DatabaseSearch], requests: Sequence[SearchRequest]) -> tuple[SearchResult, ...]:
    """One request per database, all handed to their (common) backend's ``search_many``."""
    if not problems:
        return ()
    backend = problems[0].backend
    if any(problem.backend is not backend for problem in problems):
        raise ValueError("search_together needs databases searched by one backend")
    return backend.search_many(requests)
