"""Work one worker does in one round, as module-level functions so any executor (threads,
processes, Dask) can run them. Each takes ``(WorkerContext, RoundView, task)`` and draws its
randomness from the streams keyed by (round, worker), so results never depend on which executor
ran it or in what order.

- ``classical_extension``: one RRT step (Alg. 1 with a 1-entry database): sample, nearest node,
  one reachability test.
- ``search_database``: build one database of 2^n candidates, evaluate the predicate on all of them
  to build the phase oracle (``simulation_checks``), and let the search policy run the workers that
  share it (Alg. 1 lines 4-12; Alg. 2 for p workers).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from ..database import Database, stream_database
from ..predicate import check_answers
from ..randomness import Stream
from ..search.problem import DatabaseSearch, SearchOutcome
from .context import RoundView, WorkerContext


@dataclass(frozen=True)
class ExtensionOutcome:
    """One classical RRT extension: the candidate, its parent, the test's answer and the truth."""

    child: np.ndarray
    parent: int
    answer: bool
    truth: bool


def classical_extension(context: WorkerContext, view: RoundView, worker: int) -> ExtensionOutcome:
    """Sample (with goal bias), nearest node, one reachability test."""
    db = stream_database(view.tree, 1, context.env, context.streams, view.round_index, worker, view.goal,
                         view.goal_radius, context.goal_bias)
    child, parent = db.children[0], int(db.parents[0])
    truth = bool(check_answers(context.predicate.reachable(view.tree.nodes[parent][None], child[None]), 1,
                               f"the predicate {context.predicate.name!r}")[0])
    answer = truth
    if context.oracle_errors is not None:
        flips = context.streams.generator(view.round_index, worker, Stream.ORACLE_ERRORS)
        answer = bool(context.oracle_errors.apply(np.array([truth]), flips)[0])
    return ExtensionOutcome(child, parent, answer, truth)


#: what ``DatabaseResult.tally`` returns: (quantum oracle calls, verification calls, rejected
#: measurements, the largest oracle calls of one worker, duplicates, and the candidates to add, in
#: worker order, each distinct entry once: their child positions (m, d) and parent indices (m,))
Tally = tuple[int, int, int, int, int, np.ndarray, np.ndarray]


class DatabaseResult(Protocol):
    """What a quantum planner integrates of one searched database (``DatabaseOutcome``, or the
    fused round's ``ClosedFormOutcome``): its size, its reachable entries, per worker its
    ``SearchOutcome`` and found candidate, and the round's counts (``tally``)."""

    @property
    def entries(self) -> int: ...

    @property
    def reachable_entries(self) -> int: ...

    @property
    def outcomes(self) -> tuple[SearchOutcome, ...]: ...

    @property
    def found(self) -> tuple[tuple[np.ndarray, int] | None, ...]: ...

    def tally(self) -> Tally: ...


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
    """Alg. 1 lines 4-8: the database, the true predicate on it, and the oracle's marks."""
    db = stream_database(view.tree, context.database_size, context.env, context.streams, view.round_index,
                         worker, view.goal, view.goal_radius, context.goal_bias, context.annealing,
                         view.temperature_index)
    size = db.parents.shape[0]
    truth = check_answers(context.predicate.reachable(view.tree.nodes[db.parents], db.children), size,
                          f"the predicate {context.predicate.name!r}")
    marks = truth
    if context.oracle_errors is not None:
        marks = check_answers(context.oracle_errors.apply(
            truth, context.streams.generator(view.round_index, worker, Stream.ORACLE_ERRORS)), size,
            "the oracle error model")
    return db, truth, marks


def search_database(context: WorkerContext, view: RoundView, group: tuple[int, int]) -> DatabaseOutcome:
    """Workers ``first, ..., first + count - 1`` search one database built by worker ``first``."""
    first, count = group
    db, truth, marks = make_database(context, view, first)
    problem = DatabaseSearch(marks, truth, context.search_backend, context.streams, view.round_index, first)
    return database_outcome(db.children, db.parents, truth, view.search_policy_state.run(problem, count,
                                                                                        view.tree_nodes))
