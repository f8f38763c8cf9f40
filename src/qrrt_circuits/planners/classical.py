"""Classical baselines: RRT and manager-worker parallel RRT (paper §V, Devaurs et al. 2013).

One round of ``ParallelRRT``: p workers each sample a point, find its nearest tree node and run
one reachability test against the same tree snapshot; the manager adds every valid result. RRT is
the case p = 1. Each test is one oracle call (counted as a ``verification_call``: a classical check
of one candidate); a round's critical path is 1 call. With an ``OracleErrorModel`` the test answer
is noisy and a positive answer is verified with the true predicate (one more call) before the node
is added, as the quantum planners' finalizer does.

Rounds tested ahead. The planners run the one round loop of ``Planner._run`` (the termination
condition checked before each round). A round's candidates depend only on its random streams
(keyed by round and worker: ``placement.keyed_samples``, the samples ``build_database(tree, 1,
...)`` draws), and the tree cannot change until a round adds a node, so a round that finds no
tests made ahead for it draws the candidates of the next B rounds at once, finds their nearest
nodes in one query and tests all B x p pairs in one call (``LookAhead``); the following rounds
take their tests from that batch while the tree is the one it was tested against. A round that
adds a node makes the batch's later tests stale: they are counted in ``Metrics.wasted_checks``
(tests made ahead and never used), never as oracle calls, and their rounds are tested again in
the next batch (the same candidates, kept from their draw, with their nearest nodes in the new
tree). The tree, the counters and the status are those of one round at a time. B is the expected
number of rounds up to the next success, ceil(1 / rate) with the Laplace estimate
rate = (rounds that added + 1) / (rounds recorded + 2), at most ``MAX_BATCH_ROUNDS`` and at most
``batch_round_limit(workers, d)`` (a batch's candidates take at most ``MAX_BATCH_BYTES``). On an
``executor``, or with ``look_ahead=False``, B = 1 (on an executor each worker's test is one task).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import ClassVar

import numpy as np

from .._support.randomness import Stream, round_keys
from ..reachability.predicate import check_answers
from .base import Planner
from .context import map_tasks
from .database import steer
from .options import ParallelOptions, PlannerOptions, RRTOptions
from .placement import keyed_samples
from .run_state import RunState
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


def batch_rounds(changed_rounds: int, recorded_rounds: int) -> int:
    """Rounds to test ahead in one batch: the expected number of rounds up to the next that adds a node.

    Args:
        changed_rounds: Rounds recorded so far that added a node (>= 0).
        recorded_rounds: Rounds recorded so far (>= ``changed_rounds``).

    Returns:
        ceil(1 / rate) with rate = (changed + 1) / (recorded + 2) (a Laplace estimate of the rate at
        which rounds add a node), clipped to [1, ``MAX_BATCH_ROUNDS``].
    """
    rate = (changed_rounds + 1) / (recorded_rounds + 2)
    return max(1, min(MAX_BATCH_ROUNDS, math.ceil(1.0 / rate)))


#: what ``LookAhead`` draws and tests with: the candidates of keys (K, 3), and (children, parents,
#: truth) of samples (K, d) against the plan's tree
Draw = Callable[[RunState, np.ndarray], np.ndarray]
Extend = Callable[[RunState, np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]


class LookAhead:
    """One plan's classical extensions, tested ahead of the rounds that use them (module docstring).

    ``round`` hands a round its p (children, parents, truth): from the batch tested last, if that
    batch holds the round and the tree is still the one it was tested against; else from a new
    batch, the next B rounds' candidates (kept from the draw of a batch before, or drawn now)
    tested in one call.

    ``RunState.wasted_checks`` counts the tests made ahead and not used: a batch of B rounds adds
    (B - 1) p, each round served from it takes p away.

    Args:
        workers: p, the extensions of one round.
        most: The most rounds one batch tests (``batch_round_limit``, or 1).
        tree: The plan's tree as the plan starts (its d and its nodes).
        draw: The candidates of keys (round, worker, stream) (K, 3), (K, d).
        extend: (children, parents, truth) of samples (K, d) against the plan's tree, in order.
    """

    def __init__(self, workers: int, most: int, tree: Tree, draw: Draw, extend: Extend) -> None:
        self.workers, self.most, self.draw, self.extend = workers, most, draw, extend
        self.changed = 0  # rounds that added a node, up to the last batch
        self.drawn = np.empty((0, tree.dim))  # the candidates of rounds drawn_from, drawn_from + 1, ...
        self.drawn_from = 0
        self.tested_from = self.tested_rounds = 0  # the rounds of the last batch
        self.tested_size = tree.size  # the tree's nodes when the last batch was tested
        self.tested = (np.empty(0), np.empty(0, dtype=np.int64), np.empty(0, dtype=bool))

    def round(self, state: RunState) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The current round's (children (p, d), parents (p,), truth (p,))."""
        workers = self.workers
        offset = state.rounds - self.tested_from
        if state.tree.size == self.tested_size and offset < self.tested_rounds:
            state.wasted_checks -= workers  # a test made ahead, used
        else:
            self.changed += state.tree.size != self.tested_size  # (the round before added)
            self._test_ahead(state)
            offset = 0
        children, parents, truth = self.tested
        rows = slice(offset * workers, (offset + 1) * workers)
        return children[rows], parents[rows], truth[rows]

    def _test_ahead(self, state: RunState) -> None:
        """Test rounds r .. r + B - 1 (r the current round) against the tree as it is."""
        workers, first = self.workers, state.rounds
        ahead = min(batch_rounds(self.changed, first), self.most)
        drawn = self.drawn[(first - self.drawn_from) * workers:]  # (the rounds used are dropped)
        kept = min(drawn.shape[0] // workers, ahead)  # a round's candidates depend on its key only
        if kept < ahead:
            keys = round_keys(first + kept, ahead - kept, workers, int(Stream.CANDIDATES))
            drawn = np.concatenate((drawn[:kept * workers], self.draw(state, keys)))
        self.drawn, self.drawn_from = drawn, first
        # the raw samples are kept: a round tested again is steered from its new parents
        self.tested = self.extend(state, drawn[:ahead * workers])
        self.tested_from, self.tested_rounds, self.tested_size = first, ahead, state.tree.size
        state.wasted_checks += (ahead - 1) * workers


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
        state.ahead = LookAhead(self.workers, most, state.tree, self._draw, self._extend)

    def _round(self, state: RunState) -> None:
        """One round of p extensions: its tests (``LookAhead.round``), then its counters and nodes."""
        children, parents, truth = state.tests_ahead.round(state)
        self._record(state, state.rounds, children, parents, truth)

    def _draw(self, state: RunState, keys: np.ndarray) -> np.ndarray:
        """The candidates of the keys (round, worker, ``Stream.CANDIDATES``) (K, 3): the samples
        ``build_database(tree, 1, ...)`` draws from each key's generator (``keyed_samples``)."""
        return keyed_samples(self.streams, keys, state.worker_context.env, state.goal, self.options.goal_bias)

    def _extend(self, state: RunState, samples: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Each sample's nearest node, the sample steered toward it, and the predicate's answer on
        the pair: (children, parents, truth)."""
        parents = state.neighbors.nearest(samples)
        origins = state.tree.nodes[parents]
        context = state.worker_context
        children = steer(context.space, origins, samples, context.max_extension)
        return children, parents, self._test(state, origins, children)

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

    def _record(self, state: RunState, round_index: int, children: np.ndarray, parents: np.ndarray,
                truth: np.ndarray) -> None:
        """One round's counters and nodes from its workers' tests (p of them)."""
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
            state.add_node(children[worker], int(parents[worker]))
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
