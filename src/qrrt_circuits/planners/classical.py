"""Classical baselines: RRT and manager-worker parallel RRT (paper §V, Devaurs et al. 2013).

One round of ``ParallelRRT``: p workers each sample a point, find its nearest tree node and run
one reachability test against the same tree snapshot; the manager adds every valid result. RRT is
the case p = 1. Each test is one oracle call (counted as a ``verification_call``: a classical check
of one candidate); a round's critical path is 1 call. With an ``OracleErrorModel`` the test answer
is noisy and a positive answer is verified with the true predicate (one more call) before the node
is added, as the quantum planners' finalizer does.

Rounds tested ahead. The planners run the one round loop of ``Planner._run`` (the termination
condition checked before each round). The candidates are the plan's extension samples, one per
(round, worker) in round order from its sequential streams (``ExtensionSamples``): they do not
depend on the tree, and a batch of rounds draws what the rounds drawn one by one would. So a round
that finds no tests made ahead for it draws the candidates of the next B rounds at once, finds
their nearest nodes in one query and tests all B x p pairs in one call (``LookAhead``). A test made
ahead holds as long as the candidate's nearest node is the one it was tested with: a node added
since takes that place only if it is at least as near to the raw sample as the parent (ties go to
the lower index, the older node), which one query of the nearest-neighbour structure tells
(``nearest_distance_from``). A round whose test no longer holds is stale: the batch's stale rounds
are tested again, the same candidates with their nearest nodes in the new tree, while the others
keep their tests. The rounds ready before the first that finds a reachable candidate run as one
block: they add no node, so their counters and history are written at once, as many as the
termination condition lets start (``termination.rounds_that_start``). The tree, the counters, the
history and the status are those of testing each round on its own; tests made ahead and never used
are counted in ``Metrics.wasted_checks``, never as oracle calls. B is the expected number of rounds
up to the next stale one, ceil(1 / rate) with the Laplace estimate rate = (stale rounds + 1) /
(rounds recorded + 2), at most floor(sqrt(r)) + 1 at round r (so the tests a plan's end leaves
unused are about the square root of its rounds), at most ``MAX_BATCH_ROUNDS`` and at most
``batch_round_limit(workers, d)`` (a batch's candidates take at most ``MAX_BATCH_BYTES``). On an
``executor``, or with ``look_ahead=False``, B = 1 (on an executor each worker's test is one task).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import ClassVar, NamedTuple

import numpy as np

from .._support.randomness import Stream
from ..problems.goals import satisfying
from ..reachability.predicate import check_answers
from .base import Planner
from .context import map_tasks
from .database import steer
from .extension_samples import ExtensionSamples
from .options import ParallelOptions, PlannerOptions, RRTOptions
from .run_state import RunState
from .termination import Progress, TerminationCondition, rounds_that_start
from .tree import Tree
from .workers import check_extensions

#: the most rounds one batch tests ahead
MAX_BATCH_ROUNDS = 256
#: the most memory one batch's candidates may take (at least one round is tested whatever its size):
#: with 4 096 workers, 256 rounds ahead are a million candidates, about 350 MiB at d = 6 and 3 GiB
#: at d = 64 at the bytes per candidate below, more than the plan's own limits allow for
MAX_BATCH_BYTES = 64 << 20
#: a batch's bytes per candidate, 64 + 48 d: its keys, the candidate and its parent's position, the
#: parent index, the answers and the predicate's scratch (a calibrated upper bound of the measured
#: peak of a batch whose predicate rejects everything)
BATCH_BYTES_PER_CANDIDATE = 64
BATCH_BYTES_PER_COORDINATE = 48


def batch_round_limit(workers: int, dim: int) -> int:
    """The most rounds one batch may test: ``MAX_BATCH_ROUNDS``, fewer where their candidates would
    take more than ``MAX_BATCH_BYTES`` (many workers in high d), at least 1.

    Example:
        >>> from qrrt_circuits.planners.classical import batch_round_limit
        >>> batch_round_limit(8, 2), batch_round_limit(4096, 6), batch_round_limit(4096, 1000)
        (256, 46, 1)
    """
    per_round = workers * (BATCH_BYTES_PER_CANDIDATE + BATCH_BYTES_PER_COORDINATE * dim)
    return max(1, min(MAX_BATCH_ROUNDS, MAX_BATCH_BYTES // per_round))


def batch_rounds(stale_rounds: int, recorded_rounds: int) -> int:
    """Rounds to test ahead in one batch: the expected number of rounds up to the next whose test
    a new node made stale.

    Args:
        stale_rounds: Rounds so far whose test made ahead was stale when they came (>= 0).
        recorded_rounds: Rounds recorded so far (>= ``stale_rounds``).

    Returns:
        ceil(1 / rate) with rate = (stale + 1) / (recorded + 2) (a Laplace estimate of the rate at
        which rounds find their test stale), clipped to [1, ``MAX_BATCH_ROUNDS``].
    """
    rate = (stale_rounds + 1) / (recorded_rounds + 2)
    return max(1, min(MAX_BATCH_ROUNDS, math.ceil(1.0 / rate)))


#: what ``LookAhead`` draws and tests with: the plan's next K candidates (K, d), and (children,
#: parents, truth, reach) of samples (K, d) against the plan's tree
Draw = Callable[[int], np.ndarray]
Extend = Callable[[RunState, np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]
#: a node counts as possibly nearer than a candidate's parent within this relative margin (the
#: structures round distances their own way; a false alarm only tests a round again)
NEARER_MARGIN = 1e-9


def first_true(flags: np.ndarray, start: int, stop: int) -> int:
    """The first index in [start, stop) where the bool array ``flags`` holds, else ``stop``.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits.planners.classical import first_true
        >>> flags = np.array([False, True, False, True])
        >>> first_true(flags, 0, 4), first_true(flags, 2, 4), first_true(flags, 2, 3), first_true(flags, 3, 3)
        (1, 3, 3, 3)
    """
    if start >= stop:
        return stop
    part = flags[start:stop]
    index = int(part.argmax())  # (the first True of a bool array, or 0 where none holds)
    return start + index if part[index] else stop


class RoundGate(NamedTuple):
    """Which of the rounds ready may start: ``termination.rounds_that_start`` of the plan's
    condition from the counters now, each round adding ``growth``."""

    condition: TerminationCondition
    progress: Progress
    growth: Progress

    def rounds(self, ready: int) -> int:
        """How many of ``ready`` rounds start (1 .. ready)."""
        return rounds_that_start(self.condition, self.progress, self.growth, ready)


class LookAhead:
    """One plan's classical extensions, tested ahead of the rounds that use them (module docstring).

    ``block`` hands the loop the next rounds' p (children, parents, truth) each: from the batch
    tested last while their tests still hold, else from a new batch, the next B rounds'
    candidates (kept from the draw of a batch before, or drawn now) tested in one call.

    A test holds while the candidate's nearest node is the one it was tested with: a node added
    since can only take that place by being at least as near to the raw sample as the parent was
    (``reach``); rounds with such a candidate are stale and are tested again against the tree as it
    is, the others keeping their tests. A block is the rounds from the current one up to the first
    that finds a reachable candidate or the first stale one, at most the rounds the caller allows.

    ``RunState.wasted_checks`` counts the tests made ahead and not used: a batch of B rounds adds
    B p, each round served from it takes p away.

    Args:
        workers: p, the extensions of one round.
        most: The most rounds one batch tests (``batch_round_limit``, or 1).
        tree: The plan's tree as the plan starts (its d and its nodes).
        draw: The plan's next K candidates (K, d), given K (``ExtensionSamples.next``).
        extend: (children, parents, truth, reach) of samples (K, d) against the plan's tree, in
            order; ``reach`` the distance from each parent to its raw sample.
    """

    def __init__(self, workers: int, most: int, tree: Tree, draw: Draw, extend: Extend) -> None:
        self.workers, self.most, self.draw, self.extend = workers, most, draw, extend
        self.stale_rounds = 0  # rounds found stale when they came (each tested again)
        self.drawn = np.empty((0, tree.dim))  # the candidates of rounds drawn_from, drawn_from + 1, ...
        self.drawn_from = 0
        self.tested_from = self.tested_rounds = 0  # the rounds of the last batch
        self.checked_size = tree.size  # the tree's nodes the batch's candidates were compared with
        empty = np.empty(0, dtype=bool)
        self.tested = (np.empty((0, tree.dim)), np.empty(0, dtype=np.int64), empty, empty)
        self.reach_limit = np.empty(0)  # per candidate, its parent's distance to its raw sample, widened
        self.idle_growth = Progress(workers, 1, 0, 1, 1, 0.0)  # what a round that adds no node adds
        self.hits = self.stale = empty  # per round of the batch: a reachable candidate; a stale test

    def block(self, state: RunState, gate: RoundGate | None) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The next k rounds' (children (k p, d), parents (k p,), truth (k p,), in_goal (k p,)): the
        rounds ready (up to the first that finds a reachable candidate, before the first stale one)
        that ``gate`` lets start, or k = 1 without a gate. Rounds 0 .. k - 2 find nothing
        reachable, so only the last can add nodes; ``in_goal`` says which reachable children
        satisfy the goal."""
        offset = state.rounds - self.tested_from
        if offset < self.tested_rounds and state.tree.size > self.checked_size:
            self._mark_stale(state, offset)
        if offset >= self.tested_rounds:
            self._test_ahead(state)
            offset = 0
        elif self.stale[offset]:
            self.stale_rounds += 1
            self._test_stale_again(state, offset)
        stop = offset + 1
        if gate is not None:
            stop = first_true(self.stale, offset + 1, self.tested_rounds)
            stop = min(stop, first_true(self.hits, offset, stop) + 1)
            stop = offset + gate.rounds(stop - offset)
        state.wasted_checks -= (stop - offset) * self.workers
        rows = slice(offset * self.workers, stop * self.workers)
        children, parents, truth, in_goal = self.tested
        return children[rows], parents[rows], truth[rows], in_goal[rows]

    def _per_round(self, flags: np.ndarray) -> np.ndarray:
        """Per round, whether any of its p workers' ``flags`` (K p,) holds: (K,)."""
        return flags if self.workers == 1 else np.asarray(flags.reshape(-1, self.workers).any(axis=1))

    def _mark_stale(self, state: RunState, offset: int) -> None:
        """Mark the batch's rounds from ``offset`` on whose candidates a node added since may be
        nearer to than their parents."""
        first = offset * self.workers
        samples = self.drawn[first:self.tested_rounds * self.workers]
        nearer = state.neighbors.nearest_distance_from(samples, self.checked_size) <= self.reach_limit[first:]
        self.stale[offset:] |= self._per_round(nearer)
        self.checked_size = state.tree.size

    def _test_stale_again(self, state: RunState, offset: int) -> None:
        """Test the batch's stale rounds from ``offset`` on again against the tree as it is (their
        raw samples steered from their new nearest nodes); the other rounds' tests still hold."""
        workers = self.workers
        rounds = offset + np.flatnonzero(self.stale[offset:])
        rows = (rounds[:, None] * workers + np.arange(workers)).reshape(-1)
        children, parents, truth, reach = self.extend(state, self.drawn[rows])
        tested_children, tested_parents, tested_truth, in_goal = self.tested
        tested_children[rows], tested_parents[rows], tested_truth[rows] = children, parents, truth
        self.reach_limit[rows] = reach * (1.0 + NEARER_MARGIN)
        in_goal[rows] = False
        reachable = np.flatnonzero(truth)
        if reachable.size:
            in_goal[rows[reachable]] = satisfying(state.goal, children.take(reachable, axis=0))
        self.hits[rounds] = self._per_round(truth)
        self.stale[rounds] = False
        state.wasted_checks += rows.shape[0]

    def _test_ahead(self, state: RunState) -> None:
        """Test rounds r .. r + B - 1 (r the current round) against the tree as it is."""
        workers, first = self.workers, state.rounds
        # at most floor(sqrt(r)) + 1 rounds from round r: the tests a plan's end leaves unused are
        # about the square root of its rounds (a share that vanishes as plans grow)
        ahead = min(batch_rounds(self.stale_rounds, first), math.isqrt(first) + 1, self.most)
        drawn = self.drawn[(first - self.drawn_from) * workers:]  # (the rounds used are dropped)
        kept = min(drawn.shape[0] // workers, ahead)  # (the rounds drawn before and not yet used)
        if kept < ahead:
            drawn = np.concatenate((drawn[:kept * workers], self.draw((ahead - kept) * workers)))
        self.drawn, self.drawn_from = drawn, first
        # the raw samples are kept: a round tested again is steered from its new parents
        children, parents, truth, reach = self.extend(state, drawn[:ahead * workers])
        self.reach_limit = reach * (1.0 + NEARER_MARGIN)
        in_goal = np.zeros(truth.shape[0], dtype=bool)
        reachable = np.flatnonzero(truth)
        if reachable.size:
            in_goal[reachable] = satisfying(state.goal, children.take(reachable, axis=0))
        self.tested = children, parents, truth, in_goal
        self.hits = self._per_round(truth)
        self.stale = np.zeros(ahead, dtype=bool)
        self.tested_from, self.tested_rounds, self.checked_size = first, ahead, state.tree.size
        state.wasted_checks += ahead * workers


class ParallelRRT(Planner):
    """Manager-worker parallel RRT (paper §V, Devaurs et al. 2013): the classical counterpart of Pq-RRT.

    Each round, ``workers`` workers each sample a point, find its nearest tree node and run one
    reachability test (the extension step of Alg. 1, RRT) against the same tree snapshot; the
    manager adds every valid result, as the Pq-RRT manager does (Alg. 3). Each test is one oracle
    call, counted as a ``verification_call`` (DESIGN §2); a round's critical path is 1 call (2 with
    ``oracle_errors``). ``RRT`` is the case p = 1.

    Its options are ``ParallelOptions`` (``workers``, ``look_ahead`` and what every planner takes);
    it takes an ``executor`` (``Planner``). Without an ``executor`` the rounds are tested ahead in
    batches (module docstring); with one, each worker's test is one task.
    """

    name = "ParallelRRT"
    Options: ClassVar[type[PlannerOptions]] = ParallelOptions
    takes_executor = True

    @property
    def workers(self) -> int:
        """p, the workers of a round."""
        return int(self.options.workers)

    def _start_rounds(self, state: RunState) -> None:
        """The plan's ``LookAhead``: B at most ``batch_round_limit`` in-process, 1 on an executor or
        without ``look_ahead``."""
        look_ahead = self.executor is None and self.options.look_ahead
        most = batch_round_limit(self.workers, state.tree.dim) if look_ahead else 1
        context = state.worker_context
        samples = ExtensionSamples(self.streams, context.env, state.goal, self.options.goal_bias)
        state.ahead = LookAhead(self.workers, most, state.tree, samples.next, self._extend)

    def _rounds(self, state: RunState, condition: TerminationCondition, progress: Progress) -> None:
        """A block of rounds from the tests made ahead (``LookAhead.block``): the rounds before the
        last found nothing reachable (p calls, critical path 1, no node each) and are recorded at
        once, the last worker by worker. With ``oracle_errors`` (answers drawn round by round) one
        round."""
        workers = self.workers
        ahead = state.tests_ahead
        gate = None if self.options.oracle_errors else RoundGate(condition, progress, ahead.idle_growth)
        children, parents, truth, in_goal = ahead.block(state, gate)
        last = children.shape[0] - workers
        state.end_idle_rounds(last // workers, workers)
        self._round_from(state, children[last:], parents[last:], truth[last:], in_goal[last:])
        state.end_round()

    def _extend(self, state: RunState,
                samples: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Each sample's nearest node, the sample steered toward it, the predicate's answer on the
        pair and the distance from the node to the sample: (children, parents, truth, reach)."""
        parents = state.neighbors.nearest(samples)
        origins = state.tree.nodes.take(parents, axis=0)
        context = state.worker_context
        reach = context.space.distance(origins, samples)
        children = steer(context.space, origins, samples, context.max_extension, reach)
        return children, parents, self._test(state, origins, children), reach

    def _test(self, state: RunState, origins: np.ndarray, children: np.ndarray) -> np.ndarray:
        """The predicate on every (parent position, child) pair: one call in-process, one task per
        worker on an executor."""
        predicate = state.worker_context.predicate
        name = f"the predicate {predicate.name!r}"
        if self.executor is None or children.shape[0] <= 1:
            return check_answers(predicate.reachable(origins, children), children.shape[0], name)
        pairs = [(origins[row:row + 1], children[row:row + 1]) for row in range(children.shape[0])]
        answers = map_tasks(self.executor, check_extensions, state.worker_context, self._view(state), pairs)
        return np.concatenate([check_answers(answer, 1, name) for answer in answers])

    def _round_from(self, state: RunState, children: np.ndarray, parents: np.ndarray, truth: np.ndarray,
                    in_goal: np.ndarray) -> None:
        """The current round's counters and nodes from its workers' tests (p of them)."""
        round_index = state.rounds
        longest = 1
        errors = self.options.oracle_errors
        for worker in range(children.shape[0]):
            true = bool(truth[worker])
            state.verification_calls += 1
            state.round_entries += 1
            state.round_reachable += int(true)
            answer = true
            if errors is not None:
                flips = self.streams.generator(round_index, worker, Stream.ORACLE_ERRORS)
                answer = bool(errors.apply(np.array([true]), flips)[0])
            if not answer:
                continue
            if errors is not None:
                state.verification_calls += 1
                longest = 2
                if not true:
                    state.rejected += 1
                    continue
            state.add_node(children[worker], int(parents[worker]), bool(in_goal[worker]))
        state.critical_path += longest

    def settings(self) -> dict:
        return super().settings() | {"workers": self.workers}

    def _max_new_nodes_per_round(self) -> int:
        """p: each worker adds at most one node a round."""
        return self.workers


class RRT(ParallelRRT):
    """Classical RRT (paper Algorithm 1): one sample, nearest node and reachability test per round.

    ``ParallelRRT`` with one worker and no executor. Each reachability test is one oracle call,
    counted as a ``verification_call`` (DESIGN §2). Its options are ``RRTOptions``.
    """

    name = "RRT"
    Options: ClassVar[type[PlannerOptions]] = RRTOptions
    takes_executor = False

    @property
    def workers(self) -> int:
        """1: RRT's round is one worker's."""
        return 1
