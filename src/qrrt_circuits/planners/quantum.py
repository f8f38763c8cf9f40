"""q-RRT and Pq-RRT (paper Alg. 1, 2 and 4).

One round of q-RRT: build a database of 2^n (sample, nearest parent) pairs, evaluate the predicate
on all of them to build the phase oracle (``simulation_checks``; with an ``OracleErrorModel`` the
marks are corrupted), let the search policy run Grover search and measure, verify the measured
entry classically (the finalizer, 1 oracle call) and add it if it verifies.

Pq-RRT, shared database: the manager builds one database per round and its p workers search it
(for the policies that pick k before measuring, one search with ``shots = p`` stands for p
independent preparations; on hardware every worker would run its own circuit; counted as p x k
quantum oracle calls and p verifications). A solution measured by more than one worker is added
once; the extra copies are counted as ``duplicates``.

Pq-RRT, unshared: each of the p workers builds and searches its own database (optionally on an
``executor``); all verified candidates are added.

Both are one function, ``workers.search_database``, applied to groups of workers: one group of p
for a shared database, p groups of one for unshared ones. Without an executor, a round's databases
are built in turn and their searches handed to the backend together
(``search_databases_together``: ``PolicyState.run_many``, ``backend.search_many``), with the same
outcomes. The critical path of a round is the
largest number of oracle calls one worker made in it: the time of p parallel quantum devices.
"""

from __future__ import annotations

from concurrent.futures import Executor

import numpy as np

from ..database import AnnealingSchedule
from ..dynamics import LinearTrackingDynamics
from ..environment import Environment
from ..memory import MemoryEstimate, check_fits, database_bytes, database_resident_bytes
from ..oracle_errors import OracleErrorModel
from ..predicate import ReachabilityPredicate
from ..search.aer import AerBackend
from ..search.backend import QuantumSearchBackend
from ..search.policies import IterationPolicy, PaperSchedule
from ..search.problem import DatabaseSearch
from ..validation import check_bool, check_instance, check_int
from .base import Planner
from .classical import MAX_WORKERS
from .context import RoundView, WorkerContext, map_tasks
from .run_state import RunState
from .workers import DatabaseOutcome, make_database, search_database

ORACLE_LOOKUP_LABEL = (
    "simulation: the phase oracle is built from a classical lookup of all 2^n database entries "
    "(reported as simulation_checks, not as oracle calls)"
)


def search_databases_together(context: WorkerContext, view: RoundView,
                              groups: list[tuple[int, int]]) -> list[DatabaseOutcome]:
    """``search_database`` for every group of one round, with the databases' searches handed to
    the search policy at once (``PolicyState.run_many``, hence ``backend.search_many``): the same
    outcomes as searching them one by one, since every search draws its seed from the streams
    keyed by (round, worker). Groups are (first worker, workers) with one worker count."""
    if not groups:
        return []
    built = [make_database(context, view, first) for first, _ in groups]
    problems = [DatabaseSearch(marks, truth, context.search_backend, context.streams, view.round_index, first)
                for (_, truth, marks), (first, _) in zip(built, groups, strict=True)]
    workers = groups[0][1]
    if any(count != workers for _, count in groups):
        raise ValueError("search_databases_together needs groups of one size")
    outcomes = view.search_policy_state.run_many(problems, workers, view.tree_nodes)
    results = []
    for (db, truth, _), found_by in zip(built, outcomes, strict=True):
        found = tuple(None if outcome.index is None else (db.children[outcome.index], int(db.parents[outcome.index]))
                      for outcome in found_by)
        results.append(DatabaseOutcome(int(truth.shape[0]), int(np.count_nonzero(truth)), found_by, found))
    return results


class PQRRT(Planner):
    """Parallel q-RRT with ``workers`` quantum workers on a shared or unshared database.

    ``search_policy`` (alias ``iterations``, kept from 0.1) decides how each worker searches: a
    ``PaperSchedule``, ``FixedIterations``, ``KnownOptimal``, ``BBHT`` or ``Adaptive`` (or any
    ``IterationPolicy``)."""

    name = "PQRRT"

    def __init__(
        self,
        env: Environment,
        *,
        backend: QuantumSearchBackend | None = None,
        num_qubits: int = 8,
        workers: int = 8,
        shared_database: bool = True,
        search_policy: IterationPolicy | None = None,
        annealing: AnnealingSchedule | None = None,
        predicate: ReachabilityPredicate | None = None,
        dynamics: LinearTrackingDynamics | None = None,
        oracle_errors: OracleErrorModel | None = None,
        goal_bias: float = 0.0,
        resolution: float = 0.01,
        executor: Executor | None = None,
        seed: int | None = None,
        oracle: ReachabilityPredicate | None = None,
        iterations: IterationPolicy | None = None,
    ) -> None:
        self.num_qubits = check_int(num_qubits, "num_qubits", 1)
        self.workers = check_int(workers, "workers", 1, MAX_WORKERS)
        backend = AerBackend() if backend is None else backend
        check_instance(backend, "backend", QuantumSearchBackend, "a QuantumSearchBackend")
        backend.check_qubits(self.num_qubits)
        if search_policy is not None and iterations is not None and search_policy is not iterations:
            raise ValueError("give search_policy= or its alias iterations=, not both")
        policy = search_policy if search_policy is not None else iterations
        policy = PaperSchedule() if policy is None else policy
        check_instance(policy, "search_policy", IterationPolicy,
                       "a search policy (PaperSchedule(), FixedIterations(k), KnownOptimal(), BBHT(), Adaptive())")
        if annealing is not None:
            check_instance(annealing, "annealing", AnnealingSchedule, "an AnnealingSchedule or None")
        super().__init__(env, predicate=predicate, dynamics=dynamics, oracle_errors=oracle_errors,
                         goal_bias=goal_bias, resolution=resolution, seed=seed, oracle=oracle,
                         executor=executor)
        self.backend = backend
        self.shared_database = check_bool(shared_database, "shared_database")
        self.search_policy = policy
        self.annealing = annealing
        check_fits(self.memory_estimate, self.num_qubits, "this plan")

    def memory_estimate(self, num_qubits: int | None = None) -> MemoryEstimate:
        """Estimated peak memory of one round (``qrrt_circuits.memory``), for this planner's
        settings at ``num_qubits`` (default its own): the databases alive at once (one, or one per
        worker when unshared databases run on an executor), each with its backend search at the
        policy's largest iteration count, plus the policy's state. Checked at construction."""
        n = self.num_qubits if num_qubits is None else num_qubits
        size = 1 << n
        concurrent = self.workers if (self.executor is not None and not self.shared_database) else 1
        shots = self.workers if self.shared_database else 1
        search = self.backend.peak_bytes(n, shots, self.search_policy.iterations_bound(size))
        return MemoryEstimate(
            n,
            database_bytes=concurrent * database_bytes(n, self.env.dim, self.annealing is not None),
            resident_bytes=concurrent * database_resident_bytes(n, self.env.dim),
            search_bytes=concurrent * search,
            policy_bytes=self.search_policy.state_bytes(size),
        )

    @property
    def iterations_policy(self) -> IterationPolicy:
        """Alias of ``search_policy`` (0.1's attribute name)."""
        return self.search_policy

    @property
    def database_size(self) -> int:
        return 1 << self.num_qubits

    def _start_policy(self):
        return self.search_policy.start(self.database_size)

    def _context(self) -> WorkerContext:
        return WorkerContext(self.env, self.predicate, self.streams, self.goal_bias, self.oracle_errors,
                             self.backend, self.annealing, self.database_size)

    def _worker_groups(self) -> list[tuple[int, int]]:
        """(first worker, workers) per database: one group of p on a shared database, p of one."""
        if self.shared_database:
            return [(0, self.workers)]
        return [(worker, 1) for worker in range(self.workers)]

    def _temperature_index(self, state: RunState) -> int:
        """QDA's temperature index h (Alg. 4): databases built so far or nodes in the tree."""
        if self.annealing is None:
            return 0
        return self.annealing.temperature_index(state.rounds, state.nodes)

    def _round(self, state: RunState) -> None:
        view = self._view(state, self._temperature_index(state))
        if self.executor is None:  # the round's searches go to the backend together (same outcomes)
            results = search_databases_together(state.worker_context, view, self._worker_groups())
        else:
            results = map_tasks(self.executor, search_database, state.worker_context, view,
                                self._worker_groups())
        longest = 0
        for result in results:
            longest = max(longest, self._integrate(state, result))
        state.search_policy_state.learn(outcome for result in results for outcome in result.outcomes)
        state.critical_path += longest

    @staticmethod
    def _integrate(state: RunState, result: DatabaseOutcome) -> int:
        """Count one database's work and add its verified candidates; returns the largest oracle
        calls of one of its workers."""
        state.databases += 1
        state.simulation_checks += result.entries
        state.round_entries += result.entries
        state.round_reachable += result.reachable_entries
        added: set[int] = set()
        longest = 0
        for outcome, found in zip(result.outcomes, result.found, strict=True):
            state.quantum_calls += outcome.quantum_calls
            state.verification_calls += outcome.verifications
            state.rejected += outcome.rejected
            longest = max(longest, outcome.oracle_calls)
            if found is None or outcome.index is None:
                continue
            if outcome.index in added:
                state.duplicates += 1
                continue
            added.add(outcome.index)
            state.add_node(found[0], found[1])
        return longest

    # ------------------------------------------------------------------ reporting
    def settings(self) -> dict:
        return super().settings() | {
            "backend": self.backend.describe(),
            "num_qubits": self.num_qubits,
            "workers": self.workers,
            "shared_database": self.shared_database,
            "search_policy": self.search_policy.describe(),
            "annealing": None if self.annealing is None else self.annealing.describe(),
        }

    def labels(self) -> tuple[str, ...]:
        labels = [ORACLE_LOOKUP_LABEL]
        if self.shared_database and self.workers > 1:
            labels.append(
                f"simulation: one search with {self.workers} shots stands for {self.workers} workers "
                "measuring copies of the shared database (counted as p x k quantum oracle calls "
                "and p verifications)")
        labels.extend(self.search_policy.labels())
        labels.extend(self.backend.labels())
        return tuple(labels)


class QRRT(PQRRT):
    """q-RRT: one database, one search and one measurement per round (Pq-RRT with p = 1)."""

    name = "QRRT"

    def __init__(
        self,
        env: Environment,
        *,
        backend: QuantumSearchBackend | None = None,
        num_qubits: int = 8,
        search_policy: IterationPolicy | None = None,
        annealing: AnnealingSchedule | None = None,
        predicate: ReachabilityPredicate | None = None,
        dynamics: LinearTrackingDynamics | None = None,
        oracle_errors: OracleErrorModel | None = None,
        goal_bias: float = 0.0,
        resolution: float = 0.01,
        seed: int | None = None,
        oracle: ReachabilityPredicate | None = None,
        iterations: IterationPolicy | None = None,
    ) -> None:
        super().__init__(env, backend=backend, num_qubits=num_qubits, workers=1, shared_database=True,
                         search_policy=search_policy, annealing=annealing, predicate=predicate,
                         dynamics=dynamics, oracle_errors=oracle_errors, goal_bias=goal_bias,
                         resolution=resolution, seed=seed, oracle=oracle, iterations=iterations)
