"""A quantum round in compiled calls around the predicate (q-RRT Alg. 2, Pq-RRT Alg. 3).

The generic round (``workers.make_database``, ``DatabaseSearch``, the policy's ``run``, the
backend's ``search``) spends most of its non-oracle time in Python: building the keyed generators'
seeds, the candidate draws, the nearest-node queries, the validated search request, the seeded
draw and the verification are each a call of their own. ``FusedRound`` does the same work in
compiled calls:

1. ``_candidates`` (every backend and policy): the seed words of stream (round, worker,
   ``Stream.CANDIDATES``), the 2^n x d uniform doubles, the samples low + (high - low) u, their
   nearest tree nodes (``tree.nearest_into``) and the parents' positions (Alg. 1 lines 4-8);
2. the predicate's own ``reachable`` on those pairs (the oracle; not fused, so it is timed and
   counted as before), and the error model's flips if there is one;
3. ``_measure``, where the backend's seeded search is the closed-form draw
   (``QuantumSearchBackend.draws_closed_form``: the ``StatevectorBackend``) and the policy state
   searches by default (``PolicyState.searches_by_default``: one search per database at the k of
   its ``iterations_for``, as for the paper's schedule, fixed k, ``KnownOptimal``, ``Adaptive``):
   P(G) of Eq. 1 from the database's marked count (``probability.compiled_good_probability``),
   the seed of stream (round, worker, ``Stream.SEARCH``), the backend's generator of
   that seed, the two-level closed-form draw of the workers' measured indices
   (``statevector._draw_two_level_seeded``, Eq. 1 / Lemma 1), the classical verification of each
   (the finalizer: 1 oracle call per worker), the entries the planner adds (each verified entry
   once, in worker order) and the database's reachable entries, returned as a
   ``ClosedFormOutcome`` whose ``tally`` the planner integrates. Where the policy state searches
   by default but the backend searches itself (``AerBackend``, the iterated statevector), the
   round hands the backend's ``search_many`` the requests the policy's ``run_many`` would (same
   marks, k, shots and seeds) and verifies the measured indices with ``_verify`` (the second half
   of ``_measure``), into the same kind of outcome. Otherwise (BBHT, fixed-point amplification,
   ``EstimatedOptimal``) the databases go to the policy's ``run_many`` as in the generic round.

Every number is the one the generic round produces, bit for bit: the same draws in the same order
from the same PCG64 states, the same nearest-node kernels, the same predicate calls in the same
order, the same k, the same counts for the planner's bookkeeping (``tally``) and the same
``SearchOutcome`` objects for a policy's ``learn``, built only when it learns (tested against the
generic round, and by the planner fingerprints). A plan uses
it unless it has an executor, annealing or goal bias (whose databases need the generator object)
or was built with ``fused_round=False``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from ..environment import Environment
from ..oracle_errors import OracleErrorModel
from ..predicate import ReachabilityPredicate, check_answers
from ..probability import compiled_good_probability
from ..randomness import RandomStreams, Stream, _next_double, _pcg_state, _seed_words, _small_seed_words, _stream_seed
from ..search.backend import MAX_ITERATIONS, QuantumSearchBackend, SearchRequest, validate_iterations
from ..search.policies import PolicyState
from ..search.problem import DatabaseSearch, SearchOutcome
from ..search.statevector import _draw_two_level_seeded
from ..tree import Tree, nearest_into
from .workers import DatabaseResult, Tally, database_outcome

_CANDIDATES = int(Stream.CANDIDATES)
_SEARCH = int(Stream.SEARCH)


@njit(cache=True, nogil=True, inline="always")
def _key(round_index: int, worker: int, stream: int) -> np.ndarray:
    """The spawn key (round, worker, stream) as the (1, 3) array ``_seed_words`` takes."""
    key = np.empty((1, 3), dtype=np.int64)
    key[0, 0], key[0, 1], key[0, 2] = round_index, worker, stream
    return key


@njit(cache=True, nogil=True)
def _candidates(run_entropy: np.ndarray, round_index: int, worker: int, size: int, low: np.ndarray,
                high: np.ndarray, nodes: np.ndarray, tree_size: int, built: int, start: np.ndarray,
                order: np.ndarray, ordered: np.ndarray, origin: np.ndarray, cell: float, shape: np.ndarray,
                box_low: np.ndarray, box_high: np.ndarray, children: np.ndarray, parents: np.ndarray,
                positions: np.ndarray) -> None:
    """``stream_database`` without goal bias or annealing, plus the parents' positions, into
    ``children`` (size, d), ``parents`` (size,) and ``positions`` (size, d).

    The samples are ``low + (high - low) * u`` with u the first ``size * d`` doubles of the
    generator of (``round_index``, ``worker``, ``Stream.CANDIDATES``) (row-major, as
    ``uniform_draws(...).reshape(size, d)``), the parents their nearest nodes (``nearest_into``: the
    kernels of ``Tree.nearest``), the positions the parents'. The caller allocates the three
    arrays: a compiled call that returns three arrays of these shapes took 1.36 us, the same call
    writing into three made by ``np.empty`` 0.94 us (numba builds each array it hands to Python,
    unpickling its dtype; ``benchmarks/bench_round_parts.py``).
    """
    state = _pcg_state(_seed_words(run_entropy, _key(round_index, worker, _CANDIDATES))[0])
    dim = low.shape[0]
    for row in range(size):
        for axis in range(dim):
            children[row, axis] = low[axis] + (high[axis] - low[axis]) * _next_double(state)
    nearest_into(children, nodes, tree_size, built, start, order, ordered, origin, cell, shape, box_low, box_high,
                 parents)
    for row in range(size):
        for axis in range(dim):
            positions[row, axis] = nodes[parents[row], axis]


@njit(cache=True, nogil=True)
def _measure(run_entropy: np.ndarray, round_index: int, worker: int, marks: np.ndarray, truth: np.ndarray,
             iterations: int, shots: int) -> tuple[np.ndarray, np.ndarray, int, int]:
    """The measured indices of one closed-form search, their verification, and the entries a
    planner adds.

    P(G) = sin^2((2k+1) theta), sin^2 theta = m/N with m the marked entries of ``marks`` (Eq. 1,
    ``compiled_good_probability``: the double ``good_probability`` gives). The search seed is
    ``RandomStreams.seed(round_index, worker, Stream.SEARCH)`` (``randomness._stream_seed``), the
    draw ``_draw_two_level_seeded`` with that seed's ``integer_seed_words``
    (``randomness._small_seed_words``, the seed being below 2^62): the same functions the generic
    round calls; the indices are verified by ``_verify``. Two arrays come back, not five (each array
    a compiled call returns costs time to hand to Python, see ``_candidates``): the workers'
    verifications and the added entries' positions are read from ``truth``, ``children`` and
    ``parents`` where needed (``ClosedFormOutcome``).

    Returns:
        (indices (shots,), then what ``_verify`` returns for them).
    """
    size = marks.shape[0]
    marked = 0
    for entry in range(size):
        marked += marks[entry]
    p_good = compiled_good_probability(size, marked, iterations)
    words = _small_seed_words(_stream_seed(run_entropy, _key(round_index, worker, _SEARCH)))
    indices = _draw_two_level_seeded(marks, p_good, shots, words)
    added, reachable, good = _verify(indices, truth)
    return indices, added, reachable, good


@njit(cache=True, nogil=True)
def _verify(indices: np.ndarray, truth: np.ndarray) -> tuple[np.ndarray, int, int]:
    """Each worker's classical verification of its measured index (the finalizer, 1 oracle call
    per worker, against ``truth``) and the entries a planner adds.

    Returns:
        (added: the verified indices in worker order, each entry once (its first verification),
        the candidates Alg. 3 adds; the reachable entries of ``truth``; the verified shots).
    """
    size = truth.shape[0]
    shots = indices.shape[0]
    seen = np.zeros(size, dtype=np.bool_)
    added = np.empty(shots, dtype=np.int64)
    count = good = 0
    for shot in range(shots):
        index = indices[shot]
        if truth[index]:
            good += 1
            if not seen[index]:
                seen[index] = True
                added[count] = index
                count += 1
    reachable = 0
    for entry in range(size):
        reachable += truth[entry]
    return added[:count], reachable, good


class ClosedFormOutcome(NamedTuple):
    """One database searched by ``FusedRound`` at one k for all its workers (its closed-form draw,
    or the backend's search verified by ``_verify``): what ``DatabaseOutcome`` holds, as arrays
    (the ``SearchOutcome`` objects and found candidates are built only when asked for).
    Immutable: a named tuple, made once per database per round at about a third of a frozen
    dataclass's cost.

    Each of the ``len(indices)`` workers ran k = ``iterations`` Grover iterations and verified its
    measured index (DESIGN §2: k quantum calls + 1 verification per worker).

    Args:
        entries: N, the database's entries.
        reachable_entries: Its truly reachable entries.
        iterations: k.
        indices: The workers' measured indices, in worker order.
        truth: The database's true answers (N,) bool: a worker verifies if ``truth[index]``.
        added: The verified indices in worker order, each entry once (the entries added).
        children: The database's child positions (N, d).
        parents: Their parent node indices (N,).
        missed: The (shared) outcome of a worker whose measurement did not verify.
        verified_count: The workers whose measurement verified.
    """

    entries: int
    reachable_entries: int
    iterations: int
    indices: np.ndarray
    truth: np.ndarray
    added: np.ndarray
    children: np.ndarray
    parents: np.ndarray
    missed: SearchOutcome
    verified_count: int

    @property
    def verified(self) -> np.ndarray:
        """Whether each worker's measurement verified, ``truth[indices]`` (shots,) bool."""
        return self.truth[self.indices]

    @property
    def added_children(self) -> np.ndarray:
        """The added entries' child positions, ``children[added]`` (count, d)."""
        return self.children.take(self.added, axis=0)

    @property
    def added_parents(self) -> np.ndarray:
        """Their parents, ``parents[added]`` (count,)."""
        return self.parents[self.added]

    @property
    def outcomes(self) -> tuple[SearchOutcome, ...]:
        """Per worker the ``SearchOutcome`` the default ``PolicyState.run`` gives (``policies._verified``)."""
        k = self.iterations
        return tuple(SearchOutcome(index, k, 1, ((k, True),)) if good else self.missed
                     for index, good in zip(self.indices.tolist(), self.verified.tolist(), strict=True))

    @property
    def found(self) -> tuple[tuple[np.ndarray, int] | None, ...]:
        """Per worker the verified candidate (child position, parent index), or None."""
        return tuple((self.children[index], int(self.parents[index])) if good else None
                     for index, good in zip(self.indices.tolist(), self.verified.tolist(), strict=True))

    def tally(self) -> Tally:
        """``DatabaseOutcome.tally`` from the compiled draw's counts: every worker k quantum calls
        and one verification, the longest k + 1, the first verification of each entry added in
        worker order and the later ones counted as duplicates."""
        workers = self.indices.shape[0]
        good = self.verified_count
        added = self.added
        # (most q-RRT rounds add nothing: empty slices then, cheaper than indexing by an empty
        # array; take: 0.27 us where children[added] took 0.96 for 3 of 256 rows, bench_round_parts.py)
        children, parents = ((self.children.take(added, axis=0), self.parents[added]) if added.shape[0] else
                             (self.children[:0], self.parents[:0]))
        return (self.iterations * workers, workers, workers - good, self.iterations + 1 if workers else 0,
                good - added.shape[0], children, parents)


def _iterations(k: int) -> int:
    """``validate_iterations(k)``, its checks skipped for a Python int in range (the usual k)."""
    return k if type(k) is int and 0 <= k <= MAX_ITERATIONS else validate_iterations(k)


class FusedRound:
    """The round of one plan in compiled calls (module docstring); built at the plan's start.

    Args:
        env: The plan's ``Environment`` (its bounds are sampled).
        predicate: The plan's predicate (called once per database, as in the generic round).
        streams: The plan's ``RandomStreams``.
        oracle_errors: The plan's ``OracleErrorModel``, or None.
        backend: The plan's backend (its searches are drawn here if ``draws_closed_form(n)``).
        num_qubits: n (databases of 2^n entries).
    """

    def __init__(self, env: Environment, predicate: ReachabilityPredicate, streams: RandomStreams,
                 oracle_errors: OracleErrorModel | None, backend: QuantumSearchBackend, num_qubits: int) -> None:
        self.predicate = predicate
        self.streams = streams
        self.oracle_errors = oracle_errors
        self.backend = backend
        self.num_qubits = num_qubits
        self.size = 1 << num_qubits
        self._low = np.ascontiguousarray(env.bounds[:, 0], dtype=float)
        self._high = np.ascontiguousarray(env.bounds[:, 1], dtype=float)
        self._entropy = streams._run_entropy
        self.closed_form = backend.draws_closed_form(num_qubits)
        self._checked: set[tuple[int, int]] = set()
        self._answers_of = f"the predicate {predicate.name!r}"  # (check_answers' name of the predicate)
        self._missed_outcomes: dict[int, SearchOutcome] = {}
        self._flags_of: PolicyState | None = None  # the policy state whose flags _flags holds
        self._flags = (False, False)  # its (searches_by_default(), reads_problem())

    def search(self, tree: Tree, round_index: int, groups: list[tuple[int, int]], policy_state: PolicyState,
               tree_nodes: int) -> list[DatabaseResult]:
        """What ``search_databases_together`` returns for these groups, bit for bit (as
        ``ClosedFormOutcome`` arrays where the policy state searches by default).

        Every database is built by ``_candidates`` and marked by the predicate (in group order, as
        the generic round does). If the policy state searches by default
        (``PolicyState.searches_by_default``), k is the state's ``iterations_for`` on each
        database, in order, as ``run_many`` asks it (its ``iterations_by_size`` where it
        ``reads_problem()`` no further than N); then, if the backend's seeded search is the
        closed-form draw, each database's workers are drawn and verified by ``_measure``, else the
        backend's ``search_many`` runs the searches ``run_many`` would ask for and ``_verify``
        verifies them (``_searched``). Otherwise the databases go to the state's ``run_many``, as
        in the generic round.

        Args:
            tree: The plan's tree (read only).
            round_index: The round.
            groups: (first worker, workers) per database, all with the same worker count.
            policy_state: The plan's ``PolicyState``.
            tree_nodes: Nodes in the tree so far.

        Returns:
            One ``DatabaseOutcome`` (``ClosedFormOutcome`` where the policy searches by default)
            per group, in order: the same outcomes, found candidates and counts (``tally``).

        Raises:
            ValueError: A predicate answer that is not a 0/1 array of 2^n entries, or a k or a shot
                count that the backend's ``search`` would refuse, before any search.
            RuntimeError: A backend whose search returned indices outside the database
                (``search.backend.check_measured``).
        """
        workers = groups[0][1]
        if len(groups) > 1 and any(count != workers for _, count in groups):
            raise ValueError("FusedRound.search needs groups of one size")
        if policy_state is not self._flags_of:  # (constant for a state: its class's methods decide them)
            self._flags = policy_state.searches_by_default(), policy_state.reads_problem()
            self._flags_of = policy_state
        by_default, reads_problem = self._flags
        if len(groups) == 1 and by_default and not reads_problem and self.closed_form:
            # one database drawn in closed form (q-RRT, shared Pq-RRT): the steps below, without their lists
            first = groups[0][0]
            children, parents, truth, marks = self._database(tree, round_index, first)
            k = _iterations(policy_state.iterations_by_size(tree_nodes))
            self._check_memory(k, workers)
            return [self._measured(children, parents, marks, truth, round_index, first, workers, k)]
        built = [self._database(tree, round_index, first) for first, _ in groups]
        if by_default and not reads_problem:  # k from N and the tree: no DatabaseSearch needed
            iterations = [_iterations(policy_state.iterations_by_size(tree_nodes)) for _ in groups]
        else:
            problems = [DatabaseSearch(marks, truth, self.backend, self.streams, round_index, first)
                        for (_, _, truth, marks), (first, _) in zip(built, groups, strict=True)]
            if not by_default:
                searched = policy_state.run_many(problems, workers, tree_nodes)
                return [database_outcome(children, parents, truth, outcomes)
                        for (children, parents, truth, _), outcomes in zip(built, searched, strict=True)]
            iterations = [_iterations(policy_state.iterations_for(problem, tree_nodes)) for problem in problems]
        if not self.closed_form:  # the backend searches (search_many checks every request before any runs)
            return self._searched(built, groups, iterations, round_index, workers)
        for k in iterations:
            self._check_memory(k, workers)  # every search checked before any runs, as search_many does
        return [self._measured(children, parents, marks, truth, round_index, first, workers, k)
                for (children, parents, truth, marks), (first, _), k in zip(built, groups, iterations, strict=True)]

    def _searched(self, built: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]],
                  groups: list[tuple[int, int]], iterations: list[int], round_index: int,
                  workers: int) -> list[DatabaseResult]:
        """The default ``PolicyState.run_many`` on a backend that searches itself (Aer, the
        iterated statevector): the same requests (the marks, k, one shot per worker, the seed of
        stream (round, first worker, ``Stream.SEARCH``)) handed to the backend's ``search_many``
        at once, each database's measured indices verified by ``_verify``."""
        requests = [SearchRequest(marks, k, workers, self.streams.seed(round_index, first, Stream.SEARCH))
                    for (_, _, _, marks), (first, _), k in zip(built, groups, iterations, strict=True)]
        results = self.backend.search_many(requests)
        return [self._outcome(children, parents, truth, k, result.indices, *_verify(result.indices, truth))
                for (children, parents, truth, _), k, result in zip(built, iterations, results, strict=True)]

    def _database(self, tree: Tree, round_index: int,
                  worker: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(children, parents, truth, marks) of worker ``worker``'s database (Alg. 1 lines 4-8)."""
        size, dim = self.size, self._low.shape[0]
        children, parents, positions = np.empty((size, dim)), np.empty(size, dtype=np.int64), np.empty((size, dim))
        _candidates(self._entropy, round_index, worker, size, self._low, self._high, *tree.search_arrays(), children,
                    parents, positions)
        truth = check_answers(self.predicate.reachable(positions, children), self.size, self._answers_of)
        marks = truth
        if self.oracle_errors is not None:
            marks = check_answers(self.oracle_errors.apply(
                truth, self.streams.generator(round_index, worker, Stream.ORACLE_ERRORS)), self.size,
                "the oracle error model")
        return children, parents, truth, marks

    def _measured(self, children: np.ndarray, parents: np.ndarray, marks: np.ndarray, truth: np.ndarray,
                  round_index: int, first: int, count: int, iterations: int) -> ClosedFormOutcome:
        """The outcome of the default ``PolicyState.run`` at k = ``iterations`` for ``count``
        workers (``policies._verified`` of the backend's ``search``), compiled."""
        indices, added, reachable, good = _measure(self._entropy, round_index, first, marks, truth, iterations, count)
        return ClosedFormOutcome(self.size, reachable, iterations, indices, truth, added, children, parents,
                                 self._missed(iterations), good)

    def _outcome(self, children: np.ndarray, parents: np.ndarray, truth: np.ndarray, iterations: int,
                 indices: np.ndarray, added: np.ndarray, reachable: int, good: int) -> ClosedFormOutcome:
        """The ``ClosedFormOutcome`` of a database's measured ``indices`` and what ``_verify`` made
        of them (``_measure`` returns the indices and those, in this order)."""
        return ClosedFormOutcome(self.size, reachable, iterations, indices, truth, added, children, parents,
                                 self._missed(iterations), good)

    def _missed(self, iterations: int) -> SearchOutcome:
        """The (frozen, shareable) outcome of a worker whose measurement did not verify."""
        outcome = self._missed_outcomes.get(iterations)
        if outcome is None:
            outcome = self._missed_outcomes[iterations] = SearchOutcome(None, iterations, 1, ((iterations, False),))
        return outcome

    def _check_memory(self, iterations: int, shots: int) -> None:
        """The backend's memory check of a search with this k and shot count (once per pair per
        plan: a closed-form search needs (24 * 2^n + 64 * shots) bytes, checked at construction)."""
        if (iterations, shots) not in self._checked:
            self.backend.check_memory(self.num_qubits, shots, iterations)
            self._checked.add((iterations, shots))
