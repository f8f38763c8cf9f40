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

from collections.abc import Callable
from concurrent.futures import Executor

from .._support.memory import MemoryEstimate, database_bytes, database_resident_bytes
from .._support.validation import check_bool, check_instance, check_int
from ..reachability.dynamics import LinearTrackingDynamics
from ..reachability.oracle_errors import OracleErrorModel
from ..reachability.predicate import ReachabilityPredicate
from ..search.backends.base import QuantumSearchBackend
from ..search.policies.adaptive import Adaptive
from ..search.policies.base import IterationPolicy, PolicyState
from ..search.policies.thompson import ThompsonIterations
from ..world.environment import Environment
from ..world.spaces import StateSpace
from .base import Planner
from .candidates import Candidates, NearestParents
from .classical import MAX_WORKERS
from .context import WorkerContext, map_tasks
from .database import AnnealingSchedule
from .run_state import RunState
from .workers import DatabaseOutcome, search_database

ORACLE_LOOKUP_LABEL = (
    "simulation: the phase oracle is built from a classical lookup of all 2^n database entries "
    "(reported as simulation_checks, not as oracle calls)"
)


class PQRRT(Planner):
    """Parallel q-RRT (paper Algorithm 3) with ``workers`` quantum workers on a shared or unshared database.

    Each round builds 2^n (sample, nearest parent) databases, marks their reachable entries in a
    phase oracle, lets every worker run Grover search as ``search_policy`` decides, measure and
    verify its measured entry classically (the finalizer), and adds every verified candidate. Oracle
    calls follow DESIGN §2: per worker, 1 per Grover iteration plus 1 per verification; building the
    phase oracle in simulation is reported as ``simulation_checks``. With ``annealing`` this is
    Quantum Database Annealing (Alg. 4). ``QRRT`` is the case p = 1 (Alg. 2).

    The arguments every planner takes (``env``, ``predicate``, ``dynamics``, ``oracle_errors``,
    ``goal_bias``, ``max_extension``, ``space``, ``resolution``, ``seed`` and ``executor``) are
    documented on ``Planner``. On an ``executor`` each database's search is one task; without one
    the round's databases are searched in turn, with the same results.

    Args:
        backend: The ``QuantumSearchBackend`` that simulates each Grover search (its ``max_qubits``
            must allow ``num_qubits``). Default: a new ``AerBackend()`` (qiskit-aer statevector
            sampling).
        num_qubits: Qubits n per database, so each database holds N = 2^n (sample, nearest parent)
            entries; an integer >= 1 and at most the backend's ``max_qubits``. ``plan`` refuses
            an n whose round, with the tree, does not fit in the available memory. Default 8.
        workers: Number p of quantum workers per round, in [1, ``MAX_WORKERS``] (4096). Default 8.
        shared_database: True (default): the manager builds one database per round and its p workers
            all search it (Alg. 3 as printed; a solution measured by several workers is added once,
            the extra copies counted as ``duplicates``). False: each worker builds and searches its
            own database. Must be a ``bool``.
        search_policy: The ``IterationPolicy`` that decides how each worker searches a database:
            None (default) for ``default_search_policy()``, ``PaperIterations()`` (the paper's
            schedule: 5 Grover iterations, 3 once the tree has more than 10 nodes),
            ``FixedIterations(k)``, ``KnownOptimal()`` (Eq. 1 with the true m), ``BBHT()``,
            ``Adaptive()``, ``ThompsonIterations()``, ``FixedPointAmplification()``,
            ``EstimatedOptimal()`` or any other ``IterationPolicy``.
        annealing: An ``AnnealingSchedule`` for Quantum Database Annealing (Alg. 4: samples are
            drawn in distance bands around the tree that shrink with the temperature index h), or
            None (default) for uniform databases.
        database: How each round's database is built and searched (``planners.candidates``):
            ``NearestParents()`` (the default: the paper's samples with their nearest nodes,
            searched by lookup) or ``LatticeCandidates(cell_bits, ..., coherent=...)`` (lattice
            cells paired with drawn nodes, searched by lookup or by the coherent circuit on Aer).

    Raises:
        TypeError: A non-integer ``num_qubits`` or ``workers``, a ``backend`` that is not a
            ``QuantumSearchBackend``, a ``search_policy`` that is not an ``IterationPolicy``, an
            ``annealing`` that is not an ``AnnealingSchedule``, a non-bool ``shared_database``, or
            an argument ``Planner`` refuses.
        ValueError: ``num_qubits`` < 1 or above the backend's ``max_qubits``, ``workers`` outside
            [1, 4096], or an argument ``Planner`` refuses.
    """

    name = "PQRRT"

    @staticmethod
    def default_search_policy() -> IterationPolicy:
        """Pq-RRT's default policy, ``Adaptive()``: the candidate with the smallest worst ratio to
        the best candidate over the problem families of ``qrrt reproduce problems`` (its pre-stated
        rule, on critical-path calls per solution; ``docs/results/problems.md``)."""
        return Adaptive()

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
        database: Candidates | None = None,
        predicate: ReachabilityPredicate | None = None,
        dynamics: LinearTrackingDynamics | None = None,
        oracle_errors: OracleErrorModel | None = None,
        goal_bias: float = 0.0,
        max_extension: float | None = None,
        space: StateSpace | None = None,
        resolution: float = 0.01,
        executor: Executor | None = None,
        seed: int | None = None,
    ) -> None:
        self.num_qubits = check_int(num_qubits, "num_qubits", 1)
        self.workers = check_int(workers, "workers", 1, MAX_WORKERS)
        if backend is None:
            from ..search.backends.aer import AerBackend  # qiskit and Aer are imported only when used

            backend = AerBackend()
        check_instance(backend, "backend", QuantumSearchBackend, "a QuantumSearchBackend")
        backend.check_qubits(self.num_qubits)
        policy = self.default_search_policy() if search_policy is None else search_policy
        check_instance(policy, "search_policy", IterationPolicy,
                       "a search policy (PaperIterations(), FixedIterations(k), KnownOptimal(), BBHT(), Adaptive(), "
                       "ThompsonIterations())")
        if annealing is not None:
            check_instance(annealing, "annealing", AnnealingSchedule, "an AnnealingSchedule or None")
        candidates = NearestParents() if database is None else check_instance(
            database, "database", Candidates, "NearestParents() (the paper's), LatticeCandidates(...) or None")
        if annealing is not None and database is not None:
            raise ValueError("annealing draws the paper's database in bands: give annealing or database, not both")
        candidates.check(env, self.num_qubits, oracle_errors is not None)
        super().__init__(env, predicate=predicate, dynamics=dynamics, oracle_errors=oracle_errors,
                         goal_bias=goal_bias, max_extension=max_extension, space=space, resolution=resolution,
                         seed=seed, executor=executor)
        self.backend = backend
        self.shared_database = check_bool(shared_database, "shared_database")
        self.search_policy = policy
        self.annealing = annealing
        self.candidates = candidates

    def memory_estimate(self, num_qubits: int | None = None) -> MemoryEstimate:
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
            database_bytes=concurrent * database_bytes(n, self.env.dim, self.annealing is not None),
            resident_bytes=concurrent * database_resident_bytes(n, self.env.dim),
            search_bytes=concurrent * search,
            policy_bytes=self.search_policy.state_bytes(size),
        )

    @property
    def database_size(self) -> int:
        """N = 2^n, the entries of each database."""
        return 1 << self.num_qubits

    def _start_policy(self) -> PolicyState:
        return self.search_policy.start(self.database_size)

    def _max_new_nodes_per_round(self) -> int:
        """p: each worker adds at most one node a round."""
        return self.workers

    def _round_memory(self) -> tuple[Callable[[int], MemoryEstimate] | None, int]:
        """One round's ``memory_estimate`` as a function of n, and the plan's n."""
        return self.memory_estimate, self.num_qubits

    def _context(self) -> WorkerContext:
        return WorkerContext(self.env, self.predicate, self.streams, self.goal_bias, self.oracle_errors,
                             self.backend, self.annealing, self.database_size, self.max_extension, self.space,
                             self.candidates)

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
        """Count one database's work and add its verified candidates (``DatabaseResult.tally``);
        returns the largest oracle calls of one of its workers."""
        quantum, verifications, rejected, longest, duplicates, children, parents = result.tally()
        state.databases += 1
        state.simulation_checks += result.entries
        state.round_entries += result.entries
        state.round_reachable += result.reachable_entries
        state.quantum_calls += quantum
        state.verification_calls += verifications
        state.rejected += rejected
        state.duplicates += duplicates
        state.add_nodes(children, parents)
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
            "database": self.candidates.describe(),
        }

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

    The arguments every planner takes (``env``, ``predicate``, ``dynamics``, ``oracle_errors``,
    ``goal_bias``, ``max_extension``, ``space``, ``resolution`` and ``seed``; not ``executor``) are
    documented on ``Planner``; the others are ``PQRRT``'s, with the same meaning and defaults.

    Args:
        backend: The ``QuantumSearchBackend`` of the searches. Default: a new ``AerBackend()``.
        num_qubits: Qubits n per database (N = 2^n entries), 1 .. the backend's ``max_qubits``.
            Default 8.
        search_policy: The ``IterationPolicy`` of the searches, or None (default) for
            ``default_search_policy()``.
        annealing: An ``AnnealingSchedule`` (Quantum Database Annealing), or None (default).
        database: ``NearestParents()`` (default) or ``LatticeCandidates(...)``, as for ``PQRRT``.

    Raises:
        TypeError: An argument of the wrong type, as for ``PQRRT``.
        ValueError: An argument out of range, as for ``PQRRT``.
    """

    name = "QRRT"

    @staticmethod
    def default_search_policy() -> IterationPolicy:
        """q-RRT's default policy, ``ThompsonIterations()``: the candidate with the smallest worst
        ratio to the best candidate over the problem families of ``qrrt reproduce problems`` (its
        pre-stated rule, on calls per solution; ``docs/results/problems.md``)."""
        return ThompsonIterations()

    def __init__(
        self,
        env: Environment,
        *,
        backend: QuantumSearchBackend | None = None,
        num_qubits: int = 8,
        search_policy: IterationPolicy | None = None,
        annealing: AnnealingSchedule | None = None,
        database: Candidates | None = None,
        predicate: ReachabilityPredicate | None = None,
        dynamics: LinearTrackingDynamics | None = None,
        oracle_errors: OracleErrorModel | None = None,
        goal_bias: float = 0.0,
        max_extension: float | None = None,
        space: StateSpace | None = None,
        resolution: float = 0.01,
        seed: int | None = None,
    ) -> None:
        super().__init__(env, backend=backend, num_qubits=num_qubits, workers=1, shared_database=True,
                         search_policy=search_policy, annealing=annealing, database=database, predicate=predicate,
                         dynamics=dynamics, oracle_errors=oracle_errors, goal_bias=goal_bias,
                         max_extension=max_extension, space=space, resolution=resolution, seed=seed)
