"""Classical baselines: RRT and manager-worker parallel RRT (paper §V, Devaurs et al. 2013).

One round of ``ParallelRRT``: p workers each sample a point, find its nearest tree node and run
one reachability test against the same tree snapshot; the manager adds every valid result. RRT is
the case p = 1. Each test is one oracle call (counted as a ``verification_call``: a classical check
of one candidate); a round's critical path is 1 call. With an ``OracleErrorModel`` the test answer
is noisy and a positive answer is verified with the true predicate (one more call) before the node
is added, as the quantum planners' finalizer does.

Rounds in batches. A round's candidates depend only on its random streams (keyed by round and
worker), and the tree cannot change until a round adds a node, so the planners draw the candidates
of the next B rounds at once (``randomness.uniform_draws``), find their nearest nodes in one query
and test all B x p pairs together. The rounds are then recorded one by one (the termination
condition checked before each, counters, history, error flips), up to and including the first round
that adds a node. The later rounds' tests were made against the tree without that node, so they
are counted in ``Metrics.wasted_checks``, never as oracle calls, and those rounds are tested again
in the next batch (the same candidates, kept from their draw, with their nearest nodes in the new
tree). The tree, the counters and the status are those of one round at a time. B is the expected
number of rounds up to the next success, ceil(1 / rate) with the Laplace estimate
rate = (rounds that added + 1) / (rounds recorded + 2), at most ``MAX_BATCH_ROUNDS`` and at most
``batch_round_limit(workers, d)`` (a batch's candidates take at most ``MAX_BATCH_BYTES``). On an
``executor`` B = 1 and each worker's test is one task.
"""

from __future__ import annotations

import math
import time
from concurrent.futures import Executor

import numpy as np

from .._support.randomness import Stream, uniform_draws
from .._support.validation import check_bool, check_int
from ..reachability.dynamics import LinearTrackingDynamics
from ..reachability.oracle_errors import OracleErrorModel
from ..reachability.predicate import ReachabilityPredicate, check_answers
from ..world.environment import Environment
from ..world.spaces import StateSpace
from .base import Planner
from .context import map_tasks
from .database import steer
from .goals import sample_goal
from .run_state import RunState
from .termination import PlanStatus, TerminationCondition
from .workers import check_extensions

MAX_WORKERS = 4096
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


class ParallelRRT(Planner):
    """Manager-worker parallel RRT (paper §V, Devaurs et al. 2013): the classical counterpart of Pq-RRT.

    Each round, ``workers`` workers each sample a point, find its nearest tree node and run one
    reachability test (the extension step of Alg. 1, RRT) against the same tree snapshot; the
    manager adds every valid result, as the Pq-RRT manager does (Alg. 3). Each test is one oracle
    call, counted as a ``verification_call`` (DESIGN §2); a round's critical path is 1 call (2 with
    ``oracle_errors``). ``RRT`` is the case p = 1.

    The arguments every planner takes (``env``, ``predicate``, ``dynamics``, ``oracle_errors``,
    ``goal_bias``, ``max_extension``, ``space``, ``resolution``, ``seed`` and ``executor``) are
    documented on ``Planner``. Without an ``executor`` the rounds are tested in batches (module
    docstring); with one, each worker's test is one task.

    Args:
        workers: Number p of workers, i.e. extensions per round, in [1, ``MAX_WORKERS``] (4096).
            Default 8.
        look_ahead: Whether rounds are tested in batches ahead of the tree (default True). The
            plan is the same either way; a batch tests rounds a node makes stale
            (``Metrics.wasted_checks``), which costs little with the compiled checks and much with
            an expensive user predicate: False tests one round at a time (B = 1), so the predicate
            is asked exactly once per oracle call.

    Raises:
        TypeError: A non-integer ``workers``, or an argument ``Planner`` refuses.
        ValueError: ``workers`` outside [1, 4096], or an argument ``Planner`` refuses.
    """

    name = "ParallelRRT"

    def __init__(
        self,
        env: Environment,
        *,
        workers: int = 8,
        predicate: ReachabilityPredicate | None = None,
        dynamics: LinearTrackingDynamics | None = None,
        oracle_errors: OracleErrorModel | None = None,
        goal_bias: float = 0.0,
        max_extension: float | None = None,
        space: StateSpace | None = None,
        resolution: float = 0.01,
        executor: Executor | None = None,
        seed: int | None = None,
        look_ahead: bool = True,
    ) -> None:
        self.workers = check_int(workers, "workers", 1, MAX_WORKERS)
        self.look_ahead = check_bool(look_ahead, "look_ahead")
        super().__init__(env, predicate=predicate, dynamics=dynamics, oracle_errors=oracle_errors,
                         goal_bias=goal_bias, max_extension=max_extension, space=space, resolution=resolution,
                         seed=seed, executor=executor)

    def _run(self, state: RunState, condition: TerminationCondition, began: float) -> PlanStatus:
        """Rounds in batches: the candidates of the next B rounds drawn and tested together, then
        recorded round by round (the condition checked before each) up to the first round that adds
        a node; the later rounds' tests are ``wasted_checks`` and those rounds are tested again, with
        the candidates already drawn (a round's candidates depend on its (round, worker) keys only).
        B is ``batch_rounds`` (at most ``batch_round_limit``) in-process, 1 on an executor."""
        workers = self.workers
        changed = recorded = 0
        most = batch_round_limit(workers, self.env.dim) if self.executor is None and self.look_ahead else 1
        drawn = np.empty((0, self.env.dim))  # candidates drawn for rounds first, first + 1, ... not yet recorded
        while state.goal_node is None:
            ended = condition.ended_by(state.progress(time.perf_counter() - began))
            if ended is not None:
                return ended
            ahead = min(batch_rounds(changed, recorded), most)
            first = state.rounds
            kept = min(drawn.shape[0] // workers, ahead)  # a round's candidates depend on its key only
            if kept < ahead:
                keys = np.empty(((ahead - kept) * workers, 3), dtype=np.int64)
                keys[:, 0] = np.repeat(np.arange(first + kept, first + ahead), workers)
                keys[:, 1] = np.tile(np.arange(workers), ahead - kept)
                keys[:, 2] = int(Stream.CANDIDATES)
                drawn = np.concatenate((drawn[:kept * workers], self._candidates(state, keys)))
            samples = drawn[:ahead * workers]  # kept raw: a round tested again is steered from its new parents
            parents = state.neighbors.nearest(samples)
            children = steer(self.space, state.tree.nodes[parents], samples, self.max_extension)
            truth = self._test(state, state.tree.nodes[parents], children)
            for offset in range(ahead):
                if offset:  # (the first round's check came before the draws)
                    ended = condition.ended_by(state.progress(time.perf_counter() - began))
                    if ended is not None:
                        state.wasted_checks += (ahead - offset) * workers
                        return ended
                nodes_before = state.nodes
                rows = slice(offset * workers, (offset + 1) * workers)
                self._record(state, first + offset, children[rows], parents[rows], truth[rows])
                state.end_round()
                recorded += 1
                if state.nodes != nodes_before:  # the tree changed: later tests are stale, their candidates not
                    changed += 1
                    state.wasted_checks += (ahead - offset - 1) * workers
                    break
            drawn = drawn[(offset + 1) * workers:]
        return PlanStatus.REACHED

    def _test(self, state: RunState, origins: np.ndarray, children: np.ndarray) -> np.ndarray:
        """The predicate on every (parent position, child) pair: one call in-process, one task per
        worker on an executor."""
        name = f"the predicate {self.predicate.name!r}"
        if self.executor is None or children.shape[0] <= 1:
            return check_answers(self.predicate.reachable(origins, children), children.shape[0], name)
        pairs = [(origins[row:row + 1], children[row:row + 1]) for row in range(children.shape[0])]
        answers = map_tasks(self.executor, check_extensions, state.worker_context, self._view(state), pairs)
        return np.concatenate([check_answers(answer, 1, name) for answer in answers])

    def _candidates(self, state: RunState, keys: np.ndarray) -> np.ndarray:
        """The samples ``build_database(tree, 1, ...)`` draws from each key's generator: uniform
        in the workspace (``Environment.sample_uniform``: low + (high - low) * u), and with goal
        bias the next double decides, a biased one redrawn in the goal ball by the generator."""
        dim = self.env.dim
        biased = self.goal_bias > 0
        draws = uniform_draws(self.streams, keys, dim + int(biased))
        low, high = self.env.bounds[:, 0], self.env.bounds[:, 1]
        children = low + (high - low) * draws[:, :dim]
        if biased:
            for row in np.flatnonzero(draws[:, dim] < self.goal_bias):
                rng = self.streams.generator(*keys[row])
                rng.random(dim + 1)  # the doubles used above
                children[row] = sample_goal(state.goal, 1, rng)[0]
        return children

    def _record(self, state: RunState, round_index: int, children: np.ndarray, parents: np.ndarray,
                truth: np.ndarray) -> None:
        """One round's counters and nodes from its workers' tests, as ``_round`` records them."""
        longest = 1
        errors = self.oracle_errors
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
    counted as a ``verification_call`` (DESIGN §2).

    The arguments every planner takes (``env``, ``predicate``, ``dynamics``, ``oracle_errors``,
    ``goal_bias``, ``max_extension``, ``space``, ``resolution`` and ``seed``; not ``executor``) are
    documented on ``Planner``, with what they raise; ``look_ahead`` on ``ParallelRRT``.
    """

    name = "RRT"

    def __init__(
        self,
        env: Environment,
        *,
        predicate: ReachabilityPredicate | None = None,
        dynamics: LinearTrackingDynamics | None = None,
        oracle_errors: OracleErrorModel | None = None,
        goal_bias: float = 0.0,
        max_extension: float | None = None,
        space: StateSpace | None = None,
        resolution: float = 0.01,
        seed: int | None = None,
        look_ahead: bool = True,
    ) -> None:
        super().__init__(env, workers=1, predicate=predicate, dynamics=dynamics, oracle_errors=oracle_errors,
                         goal_bias=goal_bias, max_extension=max_extension, space=space, resolution=resolution,
                         seed=seed, look_ahead=look_ahead)
