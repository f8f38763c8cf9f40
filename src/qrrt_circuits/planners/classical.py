"""Classical baselines: RRT and manager-worker parallel RRT (paper §V, Devaurs et al. 2013).

One round of ``ParallelRRT``: p workers each sample a point, find its nearest tree node and run
one reachability test against the same tree snapshot; the manager adds every valid result. RRT is
the case p = 1. Each test is one oracle call (counted as a ``verification_call``: a classical check
of one candidate); a round's critical path is 1 call. With an ``OracleErrorModel`` the test answer
is noisy and a positive answer is verified with the true predicate (one more call) before the node
is added, as the quantum planners' finalizer does.

Batched rounds (issue 11). A round's candidates depend only on its random streams, and the tree
cannot change until a round adds a node, so without an executor the planners draw the candidates of
the next B rounds at once (``randomness.uniform_draws``: the same doubles the round's own generator
gives), find their nearest nodes in one query and test all B x p pairs in one ``reachable`` call.
Then the rounds are recorded one by one exactly as the one-round loop records them (termination
checked before each, counters, history, error flips), up to and including the first round that adds
a node; the candidates of the later rounds were drawn against a tree that no longer exists and are
dropped: their tests are counted in ``Metrics.wasted_checks``, never as oracle calls, and those
rounds are drawn again next time. Trees, counters and statuses are therefore exactly the
sequential ones (tested bit for bit). B adapts to the observed rate at which rounds add a node:
B = ceil(1 / rate) with rate = (rounds that added + 1) / (rounds recorded + 2), at most
``MAX_BATCH_ROUNDS``, the expected number of rounds up to the next success, so about one batch per
node and, on average, about as many wasted tests as useful ones at worst. With an ``executor`` the
planners keep one task per worker per round.
"""

from __future__ import annotations

import math
import time
from concurrent.futures import Executor

import numpy as np

from ..database import sample_ball
from ..dynamics import LinearTrackingDynamics
from ..environment import Environment
from ..oracle_errors import OracleErrorModel
from ..predicate import ReachabilityPredicate
from ..randomness import Stream, uniform_draws
from ..termination import PlanStatus, TerminationCondition
from ..validation import check_int
from .base import Planner
from .context import map_tasks
from .run_state import RunState
from .workers import classical_extension

MAX_WORKERS = 4096
#: the most rounds one batch tests ahead
MAX_BATCH_ROUNDS = 256


def batch_rounds(changed_rounds: int, recorded_rounds: int) -> int:
    """Rounds to test ahead: ceil(1 / rate), rate = (changed + 1) / (recorded + 2), in
    [1, MAX_BATCH_ROUNDS] (the expected number of rounds up to the next that adds a node)."""
    rate = (changed_rounds + 1) / (recorded_rounds + 2)
    return max(1, min(MAX_BATCH_ROUNDS, math.ceil(1.0 / rate)))


class ParallelRRT(Planner):
    """Manager-worker parallel RRT with ``workers`` synchronous extensions per round."""

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
        resolution: float = 0.01,
        executor: Executor | None = None,
        seed: int | None = None,
        oracle: ReachabilityPredicate | None = None,
    ) -> None:
        self.workers = check_int(workers, "workers", 1, MAX_WORKERS)
        super().__init__(env, predicate=predicate, dynamics=dynamics, oracle_errors=oracle_errors,
                         goal_bias=goal_bias, resolution=resolution, seed=seed, oracle=oracle,
                         executor=executor)

    def _round(self, state: RunState) -> None:
        outcomes = map_tasks(self.executor, classical_extension, state.worker_context, self._view(state),
                             range(self.workers))
        longest = 1
        for outcome in outcomes:
            state.verification_calls += 1
            state.round_entries += 1
            state.round_reachable += int(outcome.truth)
            if not outcome.answer:
                continue
            if self.oracle_errors is not None:
                state.verification_calls += 1
                longest = 2
                if not outcome.truth:
                    state.rejected += 1
                    continue
            state.add_node(outcome.child, outcome.parent)
        state.critical_path += longest

    # ----------------------------------------------------------------- batched rounds
    def _run(self, state: RunState, condition: TerminationCondition, began: float) -> PlanStatus:
        if self.executor is not None:
            return super()._run(state, condition, began)
        workers = self.workers
        changed = recorded = 0
        while state.goal_node is None:
            ahead = batch_rounds(changed, recorded)
            first = state.rounds
            keys = np.empty((ahead * workers, 3), dtype=np.int64)
            keys[:, 0] = np.repeat(np.arange(first, first + ahead), workers)
            keys[:, 1] = np.tile(np.arange(workers), ahead)
            keys[:, 2] = int(Stream.CANDIDATES)
            children = self._candidates(state, keys)
            parents = state.tree.nearest(children)
            truth = np.asarray(self.predicate.reachable(state.tree.nodes[parents], children), dtype=bool)
            for offset in range(ahead):
                ended = condition.ended_by(state.progress(time.perf_counter() - began))
                if ended is not None:
                    state.wasted_checks += (ahead - offset) * workers
                    return ended
                nodes_before = state.nodes
                rows = slice(offset * workers, (offset + 1) * workers)
                self._record(state, first + offset, children[rows], parents[rows], truth[rows])
                state.end_round()
                recorded += 1
                if state.nodes != nodes_before:  # the tree changed: later candidates are stale
                    changed += 1
                    state.wasted_checks += (ahead - offset - 1) * workers
                    break
        return PlanStatus.REACHED

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
                children[row] = sample_ball(state.goal, state.goal_radius, 1, rng)[0]
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


class RRT(ParallelRRT):
    """Classical RRT: one sample, nearest node and reachability test per round."""

    name = "RRT"

    def __init__(
        self,
        env: Environment,
        *,
        predicate: ReachabilityPredicate | None = None,
        dynamics: LinearTrackingDynamics | None = None,
        oracle_errors: OracleErrorModel | None = None,
        goal_bias: float = 0.0,
        resolution: float = 0.01,
        seed: int | None = None,
        oracle: ReachabilityPredicate | None = None,
    ) -> None:
        super().__init__(env, workers=1, predicate=predicate, dynamics=dynamics, oracle_errors=oracle_errors,
                         goal_bias=goal_bias, resolution=resolution, seed=seed, oracle=oracle)
