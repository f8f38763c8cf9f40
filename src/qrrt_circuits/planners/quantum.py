"""q-RRT and Pq-RRT (paper Algorithms 2 and 3), with Quantum Database Annealing (Algorithm 4).

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
for a shared database, p groups of one for unshared ones, in turn or on an ``executor``. The
critical path of a round is the largest number of oracle calls one worker made in it: the time of
p parallel quantum devices.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any, ClassVar

from .._support.memory import MemoryEstimate, database_bytes, database_resident_bytes
from ..problems.problem import Problem
from ..search.policies.adaptive import Adaptive
from ..search.policies.base import IterationPolicy
from ..search.policies.thompson import ThompsonIterations
from .candidates import Candidates, NearestParents
from .context import WorkerContext, map_tasks
from .database import AnnealingSchedule
from .options import ParallelQuantumOptions, PlannerOptions, QuantumOptions
from .run_state import RunState
from .searching import SearchingPlanner
from .workers import DatabaseOutcome, search_database

#: the paper's database, which annealing draws in bands
PAPER_DATABASE = NearestParents()

ORACLE_LOOKUP_LABEL = (
    "simulation: the phase oracle is built from a classical lookup of all 2^n database entries "
    "(reported as simulation_checks, not as oracle calls)"
)


class PQRRT(SearchingPlanner):
    """Parallel q-RRT (paper Algorithm 3) with ``workers`` quantum workers on a shared or unshared database.

    Each round builds 2^n (sample, nearest parent) databases, marks their reachable entries in a
    phase oracle, lets every worker run Grover search as ``search_policy`` decides, measure and
    verify its measured entry classically (the finalizer), and adds every verified candidate. Oracle
    calls follow DESIGN §2: per worker, 1 per Grover iteration plus 1 per verification; building the
    phase oracle in simulation is reported as ``simulation_checks``. With ``annealing`` this is
    Quantum Database Annealing (Alg. 4). ``QRRT`` is the case p = 1 (Alg. 2).

    Its options are ``ParallelQuantumOptions`` (``backend``, ``num_qubits``, ``workers``,
    ``shared_database``, ``search_policy``, ``annealing``, ``database`` and what every planner
    takes); it takes an ``executor`` (``Planner``). On an ``executor`` each database's search is one
    task; without one the round's databases are searched in turn, with the same results.
    """

    name = "PQRRT"
    Options: ClassVar[type[PlannerOptions]] = ParallelQuantumOptions
    takes_executor = True

    @staticmethod
    def default_search_policy() -> IterationPolicy:
        """Pq-RRT's default policy, ``Adaptive()``: the candidate with the smallest worst ratio to
        the best candidate over the problem families of ``qrrt reproduce problems`` (its pre-stated
        rule, on critical-path calls per solution; ``docs/results/problems.md``)."""
        return Adaptive()

    def _complete(self, options: Any) -> Any:
        """The options with the planner's defaults: a new ``AerBackend()``, the planner's
        ``default_search_policy()`` and the paper's database, where none is given."""
        options = super()._complete(options)
        if options.database is None and options.annealing is None:  # (annealing draws the paper's in bands)
            options = options.replace(database=NearestParents())
        return options

    @property
    def workers(self) -> int:
        """p, the workers of a round."""
        return int(self.options.workers)

    @property
    def shared_database(self) -> bool:
        """Whether the workers search one shared database."""
        return bool(self.options.shared_database)

    @property
    def annealing(self) -> AnnealingSchedule | None:
        """Quantum Database Annealing's schedule, or None."""
        schedule: AnnealingSchedule | None = self.options.annealing
        return schedule

    @property
    def candidates(self) -> Candidates:
        """How each database is built and searched."""
        candidates: Candidates | None = self.options.database
        return PAPER_DATABASE if candidates is None else candidates

    def _check_serves(self, problem: Problem) -> None:
        """Refuse a database this problem cannot hold (``Candidates.check``)."""
        self.candidates.check(problem.env, self.num_qubits, self.options.oracle_errors is not None)

    def memory_estimate(self, num_qubits: int | None = None, *, dim: int) -> MemoryEstimate:
        """Estimated peak memory of one round (``qrrt_circuits._support.memory``); ``plan`` checks it, with
        the tree and the round history, once before the plan allocates anything.

        Counts the databases alive at once (one shared database, or one per worker when the
        databases are unshared: a round builds every worker's database before it searches them, on
        an executor or not), each with its backend search at the policy's largest iteration count
        (``QuantumSearchBackend.peak_bytes`` of ``IterationPolicy.iterations_bound``), plus the
        policy's state.

        Args:
            num_qubits: Qubits n to estimate for (databases of 2^n entries); default the planner's
                own ``num_qubits``.
            dim: The problem's dimension d (a database entry holds a sample and its parent).

        Returns:
            A ``MemoryEstimate`` with the database, resident, search and policy bytes.
        """
        n = self.num_qubits if num_qubits is None else num_qubits
        size = 1 << n
        concurrent = 1 if self.shared_database else self.workers
        shots = self.workers if self.shared_database else 1
        policy = self.search_policy
        search = self.backend.peak_bytes(n, shots, policy.iterations_bound(size), sequence=policy.runs_sequences)
        return MemoryEstimate(
            n,
            database_bytes=concurrent * database_bytes(n, dim, self.annealing is not None),
            resident_bytes=concurrent * database_resident_bytes(n, dim),
            search_bytes=concurrent * search,
            policy_bytes=self.search_policy.state_bytes(size),
        )

    @property
    def database_size(self) -> int:
        """N = 2^n, the entries of each database."""
        return 1 << self.num_qubits

    def _start_rounds(self, state: RunState) -> None:
        """The search policy's state of this plan."""
        state.policy_state = self.search_policy.start(self.database_size)

    def _max_new_nodes_per_round(self) -> int:
        """p: each worker adds at most one node a round."""
        return self.workers

    def _round_memory(self, dim: int) -> tuple[Callable[[int], MemoryEstimate] | None, int]:
        """One round's ``memory_estimate`` in dimension ``dim`` as a function of n, and the plan's n."""
        return functools.partial(self.memory_estimate, dim=dim), self.num_qubits

    def _context(self, problem: Problem) -> WorkerContext:
        options = self.options
        return WorkerContext(problem.env, problem.predicate, problem.space, self.streams, options.goal_bias,
                             options.oracle_errors, self.backend, self.annealing, self.database_size,
                             options.max_extension, self.candidates)

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
        results = map_tasks(self.executor, search_database, state.worker_context, view, self._worker_groups())
        longest = 0
        for result in results:
            longest = max(longest, self._integrate(state, result))
        state.search_policy_state.learn(result.outcomes for result in results)
        state.critical_path += longest

    @staticmethod
    def _integrate(state: RunState, result: DatabaseOutcome) -> int:
        """Count one database's work (``RunState.count_database``) and add its verified candidates;
        returns the largest oracle calls of one of its workers."""
        longest, children, parents = state.count_database(result)
        state.add_nodes(children, parents)
        return longest

    # ------------------------------------------------------------------ reporting
    def settings(self) -> dict:
        return super().settings() | {"workers": self.workers, "shared_database": self.shared_database}

    def miss_reason(self) -> str:
        """Why a measured candidate fails verification: its search policy's reason
        (``IterationPolicy.miss_reason``)."""
        return self.search_policy.miss_reason()

    def labels(self) -> tuple[str, ...]:
        """The simulation shortcuts of this planner: the classical lookup behind the phase oracle,
        the one search standing for p workers of a shared database (p > 1), and the search
        policy's and the backend's own labels.

        Returns:
            Label sentences, copied into every result.
        """
        labels = [ORACLE_LOOKUP_LABEL]
        if self.shared_database and self.workers > 1:
            labels.append(
                f"simulation: one search with {self.workers} shots stands for {self.workers} workers "
                "measuring copies of the shared database (counted as p x k quantum oracle calls "
                "and p verifications)")
        labels.extend(self.candidates.labels())
        labels.extend(self.search_policy.labels())
        labels.extend(self.backend.labels())
        return tuple(labels)


class QRRT(PQRRT):
    """q-RRT (paper Algorithm 2): one database, one search and one measurement per round.

    ``PQRRT`` with one worker on a shared database and no executor. Per round: build 2^n (sample,
    nearest parent) pairs, mark the reachable ones in the phase oracle, run Grover search as
    ``search_policy`` decides, measure, verify classically (1 oracle call) and add the entry if it
    verifies. With ``annealing`` this is Quantum Database Annealing (Alg. 4).

    Its options are ``QuantumOptions`` (``backend``, ``num_qubits``, ``search_policy``,
    ``annealing``, ``database`` and what every planner takes), with ``PQRRT``'s meaning and
    defaults; it takes no executor.
    """

    name = "QRRT"
    Options: ClassVar[type[PlannerOptions]] = QuantumOptions
    takes_executor = False

    @staticmethod
    def default_search_policy() -> IterationPolicy:
        """q-RRT's default policy, ``ThompsonIterations()``: the candidate with the smallest worst
        ratio to the best candidate over the problem families of ``qrrt reproduce problems`` (its
        pre-stated rule, on calls per solution; ``docs/results/problems.md``)."""
        return ThompsonIterations()

    @property
    def workers(self) -> int:
        """1: q-RRT's round is one worker's."""
        return 1

    @property
    def shared_database(self) -> bool:
        """True: one worker searches its one database."""
        return True
