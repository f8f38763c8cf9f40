"""q-RRT and Pq-RRT (paper Alg. 1, 2 and 4).

One round of q-RRT: build a database of 2^n (sample, nearest parent) pairs, evaluate the predicate
on all of them to build the phase oracle (``simulation_checks``; with an ``OracleErrorModel`` the
marks are corrupted), run Grover search with the policy's k iterations, measure one index, verify
it classically (the finalizer, 1 oracle call) and add it if it verifies.

Pq-RRT, shared database: the manager builds one database per round; p workers search it and each
measures one index. The simulation runs one search with ``shots = p`` (each shot is an independent
preparation; on hardware every worker would run its own circuit) and counts p x k quantum oracle
calls and p verifications. A solution measured by more than one worker is added once; the extra
copies are counted as ``duplicates``.

Pq-RRT, unshared: each of the p workers builds and searches its own database (optionally on an
``executor``); all verified candidates are added.

The critical path of a round is the largest number of oracle calls one worker made in it: the
time of p parallel quantum devices.
"""

from __future__ import annotations

from concurrent.futures import Executor

import numpy as np

from ..database import AnnealingSchedule, Tree, build_database
from ..dynamics import LinearTrackingDynamics
from ..environment import Environment
from ..oracle import OracleErrorModel, ReachabilityOracle
from ..probability import optimal_iterations
from ..search.aer import AerBackend
from ..search.backend import QuantumSearchBackend
from ..search.schedules import BBHT, IterationPolicy, PaperSchedule
from .base import Planner, RunState, _check_count
from .workers import unshared_worker

ORACLE_LOOKUP_LABEL = (
    "simulation: the phase oracle is built from a classical lookup of all 2^n database entries "
    "(reported as simulation_checks, not as oracle calls)"
)


class PQRRT(Planner):
    """Parallel q-RRT with ``workers`` quantum workers on a shared or unshared database."""

    name = "PQRRT"

    def __init__(
        self,
        env: Environment,
        backend: QuantumSearchBackend | None = None,
        num_qubits: int = 8,
        workers: int = 8,
        shared_database: bool = True,
        iterations: IterationPolicy | None = None,
        annealing: AnnealingSchedule | None = None,
        dynamics: LinearTrackingDynamics | None = None,
        oracle_errors: OracleErrorModel | None = None,
        goal_bias: float = 0.0,
        resolution: float = 0.01,
        executor: Executor | None = None,
        seed: int | None = None,
        oracle: ReachabilityOracle | None = None,
    ) -> None:
        self.num_qubits = _check_count(num_qubits, "num_qubits")
        self.workers = _check_count(workers, "workers")
        backend = AerBackend() if backend is None else backend
        if not isinstance(backend, QuantumSearchBackend):
            raise ValueError(f"backend must be a QuantumSearchBackend, got {type(backend).__name__}")
        backend.check_qubits(self.num_qubits)
        iterations = PaperSchedule() if iterations is None else iterations
        if not isinstance(iterations, IterationPolicy):
            raise ValueError("iterations must be an iteration policy (PaperSchedule(), "
                             "FixedIterations(k), KnownOptimal(), BBHT(), Adaptive())")
        if annealing is not None and not isinstance(annealing, AnnealingSchedule):
            raise ValueError("annealing must be an AnnealingSchedule or None")
        super().__init__(env, dynamics, oracle_errors, goal_bias, resolution, seed, oracle)
        self.backend = backend
        self.shared_database = bool(shared_database)
        self.iterations_policy = iterations
        self.annealing = annealing
        self.executor = executor

    @property
    def database_size(self) -> int:
        return 1 << self.num_qubits

    def _start_policy(self):
        return self.iterations_policy.start(self.database_size)

    # ------------------------------------------------------------------ steps
    def make_database(self, tree: Tree, goal, goal_radius, round_index: int, worker: int, h: int):
        """Alg. 1 lines 4-8: the database, the true predicate on it, and the oracle's marks."""
        db = build_database(tree, self.database_size, self.env, self.rng(round_index, worker, 1),
                            goal, goal_radius, self.goal_bias, self.annealing, h)
        truth = self.oracle.reachable(tree.nodes[db.parents], db.children)
        marks = truth
        if self.oracle_errors is not None:
            marks = self.oracle_errors.apply(truth, self.rng(round_index, worker, 2))
        return db, truth, marks

    def search_database(self, marks, truth, round_index: int, first_worker: int, shots: int,
                        iterations: int | None):
        """Search one database for ``shots`` workers. Returns per worker
        (index or None, quantum oracle calls, verifications, observations, iterations used)."""
        size = marks.shape[0]
        policy = self.iterations_policy
        if isinstance(policy, BBHT):
            outcomes = []
            for worker in range(first_worker, first_worker + shots):
                rng = self.rng(round_index, worker, 3)
                attempts: list[tuple[int, bool]] = []

                def search(j, rng=rng):
                    return int(self.backend.search(marks, j, 1, seed=int(rng.integers(2**62))).indices[0])

                def verify(index, attempts=attempts):
                    good = bool(truth[index])
                    attempts.append((-1, good))
                    return good

                result = policy.run(search, verify, size, rng)
                outcomes.append((result.index, result.iterations, result.verifications,
                                 tuple(attempts), result.iterations))
            return outcomes
        k = optimal_iterations(size, int(np.count_nonzero(marks))) if iterations is None else iterations
        found = self.backend.search(marks, k, shots, seed=self.call_seed(round_index, first_worker))
        return [(int(i), k, 1, ((k, bool(truth[i])),), k) for i in found.indices]

    def _round_iterations(self, state: RunState) -> int | None:
        policy = self.iterations_policy
        if policy.uses_true_m or isinstance(policy, BBHT):
            return None
        return state.policy_state.iterations(state.tree.size - 1)

    def _temperature_index(self, state: RunState) -> int:
        """QDA's h: databases built so far (= rounds) or nodes in the tree, per the schedule."""
        if self.annealing is not None and self.annealing.counter == "nodes":
            return state.tree.size - 1
        return state.rounds

    def _round(self, state: RunState) -> None:
        if self.shared_database:
            self._shared_round(state)
        else:
            self._unshared_round(state)

    def _shared_round(self, state: RunState) -> None:
        tree, r = state.tree, state.rounds
        db, truth, marks = self.make_database(tree, state.goal, state.goal_radius, r, 0, self._temperature_index(state))
        state.databases += 1
        state.simulation_checks += truth.shape[0]
        state.round_entries += truth.shape[0]
        state.round_reachable += int(np.count_nonzero(truth))
        outcomes = self.search_database(marks, truth, r, 0, self.workers, self._round_iterations(state))
        added: set[int] = set()
        longest = 0
        for index, spent, verifications, observations, _ in outcomes:
            state.quantum_calls += spent
            state.verification_calls += verifications
            longest = max(longest, spent + verifications)
            for k, good in observations:
                if k >= 0:
                    state.policy_state.observe(k, good)
            verified = index is not None and bool(truth[index])
            state.rejected += verifications - int(verified)
            if not verified:
                continue
            if index in added:
                state.duplicates += 1
                continue
            added.add(index)
            state.add_node(db.children[index], int(db.parents[index]))
        state.critical_path += longest

    def _unshared_round(self, state: RunState) -> None:
        tree, r = state.tree, state.rounds
        k = self._round_iterations(state)
        h = self._temperature_index(state)
        args = [(self, tree, state.goal, state.goal_radius, r, w, k, h) for w in range(self.workers)]
        if self.executor is None:
            outcomes = [unshared_worker(*a) for a in args]
        else:
            outcomes = list(self.executor.map(unshared_worker, *zip(*args, strict=True)))
        longest = 0
        for outcome in outcomes:
            state.databases += 1
            state.simulation_checks += outcome.simulation_checks
            state.round_entries += outcome.simulation_checks
            state.round_reachable += outcome.reachable_entries
            state.quantum_calls += outcome.quantum_calls
            state.verification_calls += outcome.verifications
            longest = max(longest, outcome.quantum_calls + outcome.verifications)
            for it, good in outcome.observations:
                if it >= 0:
                    state.policy_state.observe(it, good)
            state.rejected += outcome.verifications - int(outcome.verified)
            if outcome.verified:
                state.add_node(outcome.child, outcome.parent)
        state.critical_path += longest

    # ------------------------------------------------------------------ reporting
    def settings(self) -> dict:
        return super().settings() | {
            "backend": self.backend.name,
            "num_qubits": self.num_qubits,
            "workers": self.workers,
            "shared_database": self.shared_database,
            "iterations": self.iterations_policy.describe(),
            "annealing": None if self.annealing is None else {
                "bands": [list(b) for b in self.annealing.bands],
                "switch_at": list(self.annealing.switch_at), "counter": self.annealing.counter},
        }

    def labels(self) -> tuple[str, ...]:
        labels = [ORACLE_LOOKUP_LABEL]
        if self.shared_database and self.workers > 1:
            labels.append(
                f"simulation: one search with {self.workers} shots stands for {self.workers} workers "
                "measuring copies of the shared database (counted as p x k quantum oracle calls "
                "and p verifications)")
        if self.iterations_policy.uses_true_m:
            labels.append("simulation knowledge: iterations use the true marked count m of each "
                          "database (KnownOptimal)")
        return tuple(labels)


class QRRT(PQRRT):
    """q-RRT: one database, one search and one measurement per round (Pq-RRT with p = 1)."""

    name = "QRRT"

    def __init__(
        self,
        env: Environment,
        backend: QuantumSearchBackend | None = None,
        num_qubits: int = 8,
        iterations: IterationPolicy | None = None,
        annealing: AnnealingSchedule | None = None,
        dynamics: LinearTrackingDynamics | None = None,
        oracle_errors: OracleErrorModel | None = None,
        goal_bias: float = 0.0,
        resolution: float = 0.01,
        seed: int | None = None,
        oracle: ReachabilityOracle | None = None,
    ) -> None:
        super().__init__(env, backend, num_qubits, 1, True, iterations, annealing, dynamics,
                         oracle_errors, goal_bias, resolution, None, seed, oracle)
