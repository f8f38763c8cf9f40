"""Work one worker does in one round, as module-level functions so any executor (threads,
processes, Dask) can run them. Each takes ``(WorkerContext, RoundView, task)`` and draws its
randomness from the streams keyed by (round, worker), so results never depend on which executor
ran it or in what order.

- ``check_extensions``: the reachability tests of classical RRT extensions (Alg. 1 line 7).
- ``search_database``: build one database of 2^n candidates, evaluate the predicate on all of them
  to build the phase oracle (``simulation_checks``), and let the search policy run the workers that
  share it (Alg. 1 lines 4-12; Alg. 2 for p workers).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._support.randomness import Stream
from ..reachability.predicate import check_answers
from ..search.problem import DatabaseSearch, SearchOutcome
from .context import RoundView, WorkerContext
from .database import Database


def check_extensions(context: WorkerContext, view: RoundView, pairs: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """The plan's predicate on (parent positions (M, d), children (M, d)): the reachability tests
    of classical extensions (paper Algorithm 1, line 7) handed to a worker."""
    origins, children = pairs
    return context.predicate.reachable(origins, children)


#: what ``DatabaseResult.tally`` returns: (quantum oracle calls, verification calls, rejected
#: measurements, the largest oracle calls of one worker, duplicates, and the candidates to add, in
#: worker order, each distinct entry once: their child positions (m, d) and parent indices (m,))
Tally = tuple[int, int, int, int, int, np.ndarray, np.ndarray]


@dataclass(frozen=True)
class DatabaseOutcome:
    """One database's statistics and, per worker that searched it, its outcome and the candidate
    it found (child position and parent index) or None. Only found candidates travel back."""

    entries: int
    reachable_entries: int
    outcomes: tuple[SearchOutcome, ...]
    found: tuple[tuple[np.ndarray, int] | None, ...]

    def tally(self) -> Tally:
        """The database's counts as DESIGN §2 counts them, worker by worker: each worker's quantum
        calls and verifications, its rejected measurements (verifications without a verified
        index), the largest oracle calls of one worker (the database's share of the round's
        critical path), and the verified candidates in worker order, a candidate measured by an
        earlier worker counted as a duplicate instead of added again.

        Returns:
            A ``Tally``: (quantum calls, verifications, rejected, longest, duplicates, children to
            add, their parents).
        """
        quantum = verifications = rejected = longest = duplicates = 0
        added: set[int] = set()
        additions: list[tuple[np.ndarray, int]] = []
        for outcome, found in zip(self.outcomes, self.found, strict=True):
            index = outcome.index
            quantum += outcome.quantum_calls
            verifications += outcome.verifications
            rejected += outcome.verifications - (index is not None)  # outcome.rejected
            longest = max(longest, outcome.quantum_calls + outcome.verifications)  # outcome.oracle_calls
            if found is None or index is None:
                continue
            if index in added:
                duplicates += 1
                continue
            added.add(index)
            additions.append(found)
        dim = additions[0][0].shape[0] if additions else 0
        children = np.array([child for child, _ in additions], dtype=float).reshape(len(additions), dim)
        parents = np.array([parent for _, parent in additions], dtype=np.int64)
        return quantum, verifications, rejected, longest, duplicates, children, parents


def database_outcome(children: np.ndarray, parents: np.ndarray, truth: np.ndarray,
                     outcomes: tuple[SearchOutcome, ...]) -> DatabaseOutcome:
    """One database's ``DatabaseOutcome``: its size, its reachable entries and, per worker, the
    candidate (child position, parent index) its verified index names, or None."""
    found = tuple(None if outcome.index is None else (children[outcome.index], int(parents[outcome.index]))
                  for outcome in outcomes)
    return DatabaseOutcome(int(truth.shape[0]), int(np.count_nonzero(truth)), outcomes, found)


def make_database(context: WorkerContext, view: RoundView, worker: int) -> tuple[Database, np.ndarray, np.ndarray]:
    """The database of paper Algorithm 1, lines 4-8, the true predicate on it, and the oracle's
    marks."""
    db = context.candidates.build(context, view, worker)
    size = db.parents.shape[0]
    truth = check_answers(context.predicate.reachable(view.tree.nodes.take(db.parents, axis=0), db.children), size,
                          f"the predicate {context.predicate.name!r}")
    marks = context.candidates.oracle_marks(context, db, truth)
    if context.oracle_errors is not None:
        marks = check_answers(context.oracle_errors.apply(
            truth, context.streams.generator(view.round_index, worker, Stream.ORACLE_ERRORS)), size,
            "the oracle error model")
    return db, truth, marks


def search_database(context: WorkerContext, view: RoundView, group: tuple[int, int]) -> DatabaseOutcome:
    """Workers ``first, ..., first + count - 1`` search one database built by worker ``first``."""
    first, count = group
    db, truth, marks = make_database(context, view, first)
    problem = DatabaseSearch(context.candidates.search_oracle(context, db, marks), truth, context.search_backend,
                             context.streams, view.round_index, first)
    return database_outcome(db.children, db.parents, truth, view.search_policy_state.run(problem, count,
                                                                                        view.tree_nodes))
