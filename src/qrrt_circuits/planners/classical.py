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
from ..oracle import OracleErrorModel, ReachabilityOracle
from .base import Planner, RunState, _check_count
from .workers import classical_extension


class ParallelRRT(Planner):
    """Manager-worker parallel RRT with ``workers`` synchronous extensions per round."""

    name = "ParallelRRT"

    def __init__(
        self,
        env: Environment,
        workers: int = 8,
        dynamics: LinearTrackingDynamics | None = None,
        oracle_errors: OracleErrorModel | None = None,
        goal_bias: float = 0.0,
        resolution: float = 0.01,
        executor: Executor | None = None,
        seed: int | None = None,
        oracle: ReachabilityOracle | None = None,
    ) -> None:
        self.workers = _check_count(workers, "workers")
        super().__init__(env, dynamics, oracle_errors, goal_bias, resolution, seed, oracle)
        self.executor = executor

    def _round(self, state: RunState) -> None:
        tree, r = state.tree, state.rounds
        args = [(self, tree, state.goal, state.goal_radius, r, w) for w in range(self.workers)]
        if self.executor is None:
            outcomes = [classical_extension(*a) for a in args]
        else:
            outcomes = list(self.executor.map(classical_extension, *zip(*args, strict=True)))
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
        dynamics: LinearTrackingDynamics | None = None,
        oracle_errors: OracleErrorModel | None = None,
        goal_bias: float = 0.0,
        resolution: float = 0.01,
        seed: int | None = None,
        oracle: ReachabilityOracle | None = None,
    ) -> None:
        super().__init__(env, 1, dynamics, oracle_errors, goal_bias, resolution, None, seed, oracle)
