"""Classical baselines: RRT and manager-worker parallel RRT (paper §V, Devaurs et al. 2013).

One round of ``ParallelRRT``: p workers each sample a point, find its nearest tree node and run
one reachability test against the same tree snapshot; the manager adds every valid result. RRT is
the case p = 1. Each test is one oracle call (counted as a ``verification_call``: a classical check
of one candidate); a round's critical path is 1 call. With an ``OracleErrorModel`` the test answer
is noisy and a positive answer is verified with the true predicate (one more call) before the node
is added, as the quantum planners' finalizer does.
"""

from __future__ import annotations

from concurrent.futures import Executor

from ..dynamics import LinearTrackingDynamics
from ..environment import Environment
from ..oracle_errors import OracleErrorModel
from ..predicate import ReachabilityPredicate
from ..validation import check_int
from .base import Planner
from .context import map_tasks
from .run_state import RunState
from .workers import classical_extension

MAX_WORKERS = 4096


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
        outcomes = map_tasks(self.executor, classical_extension, state.context, self._view(state),
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
