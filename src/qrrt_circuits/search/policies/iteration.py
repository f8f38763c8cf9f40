"""Search policies: how a worker searches one database (DESIGN §2, "Iterations").

A policy is a frozen configuration; ``policy.start(num_items)`` gives the mutable ``PolicyState``
that one plan uses, so a policy object can be shared between planners and runs. Every state
answers one question, polymorphically::

    state.run(problem: DatabaseSearch, workers: int, tree_nodes: int) -> tuple[SearchOutcome, ...]

given a database (its search, its verification and its size), run ``workers`` workers' searches
and return one frozen outcome per worker: the verified index or None, the quantum oracle calls and
verifications spent, and observations for learning policies. After the round the planner hands
the outcomes back, grouped by database, with ``state.learn(databases)``. The planner never asks which policy it has.
``state.run_many(problems, workers, tree_nodes)`` answers the same for several independent
databases of one round: ``run`` on each, in order.

Policies that pick one k before measuring (``PaperIterations``, ``FixedIterations``,
``KnownOptimal``, ``Adaptive``) share the default ``run``: one backend search with ``shots =
workers`` (each shot is one worker's independent preparation: the simulation shortcut of Pq-RRT),
k quantum calls and 1 verification per worker. ``BBHT`` overrides ``run`` with its own loop per
worker. A policy that needs several circuits per worker, or one estimate shared by all the workers
of a shared database, overrides ``run`` the same way.

- ``PaperIterations()``: 5 iterations, 3 once the tree has more than 10 nodes (the authors' code).
- ``FixedIterations(k)``: always k (Alg. 4 / QDA uses k = 2).
- ``KnownOptimal()``: floor(pi / (4 theta)), sin^2 theta = m/N (Eq. 1), with the database's true
  marked count m. This is simulation knowledge a quantum device does not have: outputs say so.
- ``BBHT()``: Boyer-Brassard-Hoyer-Tapp search for unknown m (Boyer, Brassard, Hoyer and Tapp,
  "Tight bounds on quantum searching", Fortschr. Phys. 46, 493 (1998), Thm. 3). Per worker: draw
  j uniformly in [0, M), run j iterations, measure, verify; on failure M <- min(lambda M, sqrt(N)).
  Stops at the first verified success or when the iterations spent reach ``cap_factor * sqrt(N)``
  (so m = 0 terminates). Expected cost O(sqrt(N/m)).
- ``Adaptive()``: a Bayesian estimate of the marked fraction f = m/N from the planner's own
  verified outcomes only: each measurement after k iterations succeeded with probability
  sin^2((2k+1) asin(sqrt f)); a grid posterior over f (flat prior, with forgetting, since f drifts
  as the tree grows) picks the k with the largest expected success per oracle call, P(k) / (k + 1).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..._support.validation import check_choice, check_float, check_int, check_optional_int
from ...probability import optimal_iterations
from ..backend import QuantumSearchBackend
from ..problem import DatabaseSearch, SearchOutcome
from ..requests import MAX_ITERATIONS, validate_iterations

__all__ = [
    "BBHT",
    "Adaptive",
    "AdaptiveState",
    "BBHTOutcome",
    "FixedIterations",
    "IterationPolicy",
    "KnownOptimal",
    "PaperIterations",
    "PolicyState",
]


class IterationPolicy:
    """Base class of the search policies: how a worker searches one database (frozen configurations).

    A policy picks the Grover iteration count k of the amplitude amplification loop of Alg. 2 / 3
    (the paper fixes k by a schedule; Eq. 1 gives the optimal k for a known m). Subclasses implement
    ``_iterations`` (policies that pick k before measuring) or return their own ``PolicyState``
    from ``start`` with its own ``run``.

    The class attribute ``uses_true_m`` is True if the policy reads the database's true marked
    count m (simulation knowledge a quantum device does not have, labelled in every output that
    depends on it); ``name`` is the policy's short name.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits import DatabaseSearch, KnownOptimal, PaperIterations, StatevectorBackend
        >>> from qrrt_circuits._support.randomness import RandomStreams
        >>> marks = np.zeros(64, dtype=bool)
        >>> marks[:2] = True
        >>> problem = DatabaseSearch(marks, marks, StatevectorBackend(seed=0), RandomStreams(0), 0)
        >>> PaperIterations().iterations_for(problem, 0), PaperIterations().iterations_for(problem, 11)
        (5, 3)
        >>> KnownOptimal().iterations_for(problem, 0)  # floor(pi / (4 asin(sqrt(2/64))))
        4
    """

    uses_true_m: bool = False
    name: str = "policy"

    def start(self, num_items: int) -> PolicyState:
        """The mutable per-plan state of this policy.

        Args:
            num_items: N, the entries of each database the plan searches (2^n).

        Returns:
            A fresh ``PolicyState`` (or the subclass this policy needs).
        """
        return PolicyState(self, num_items)

    def describe(self) -> str:
        """The policy in words (recorded in ``PlanResult.settings``)."""
        return self.name

    def labels(self) -> tuple[str, ...]:
        """Caveats every result planned with this policy must carry (none by default)."""
        return ()

    def iterations_for(self, problem: DatabaseSearch, tree_nodes: int) -> int:
        """The Grover iteration count k for one database (policies that pick k before measuring).

        Args:
            problem: The database search (its size N, and for ``KnownOptimal`` its marked count).
            tree_nodes: Nodes in the tree so far.

        Returns:
            k >= 0.
        """
        return self._iterations(problem.num_items, tree_nodes, None)

    def iterations_bound(self, num_items: int) -> int:
        """The most Grover iterations one search (one circuit) of this policy can run.

        The memory guard sizes a search by it.

        Args:
            num_items: N, the database size.

        Returns:
            By default the optimal k for one marked entry, floor(pi / (4 asin(1/sqrt(N)))) (Eq. 1).
        """
        return optimal_iterations(num_items, 1)

    def state_bytes(self, num_items: int) -> int:
        """Bytes the policy's per-plan state holds (the memory guard adds them).

        Args:
            num_items: N, the database size.

        Returns:
            The bytes (0 by default).
        """
        return 0

    def search_peak_bytes(self, backend: QuantumSearchBackend, num_qubits: int, shots: int) -> int:
        """The backend's peak for the largest search of one database this policy runs (a plan's
        memory check counts it; the plan's searches make no check of their own).

        Args:
            backend: The plan's ``QuantumSearchBackend``.
            num_qubits: n, the database's qubits.
            shots: The shots of one search (p workers on a shared database).

        Returns:
            By default ``backend.peak_bytes(n, shots, iterations_bound(2^n))``, a bound over every
            marked count.
        """
        return backend.peak_bytes(num_qubits, shots, self.iterations_bound(1 << num_qubits))

    def _iterations(self, num_items: int, tree_nodes: int, num_marked: int | None) -> int:
        raise NotImplementedError


class PolicyState:
    """Per-plan mutable state of a policy; the default runs one search with ``shots = workers``.

    Args:
        policy: The frozen ``IterationPolicy`` this state belongs to.
        num_items: N, the entries of each database the plan searches.

    Attributes:
        policy: The policy.
        num_items: N.
    """

    def __init__(self, policy: IterationPolicy, num_items: int) -> None:
        self.policy = policy
        self.num_items = int(num_items)

    def choose_iterations(self, tree_nodes: int, num_marked: int | None = None) -> int:
        """The Grover iterations for the next database.

        Args:
            tree_nodes: Nodes in the tree so far.
            num_marked: The database's true marked count m (only ``KnownOptimal`` reads it).

        Returns:
            k >= 0.

        Raises:
            ValueError: ``KnownOptimal`` without ``num_marked``.
            TypeError: Policies that choose k inside their own loop (``BBHT``, ``EstimatedOptimal``).
        """
        return self.policy._iterations(self.num_items, tree_nodes, num_marked)

    def iterations_for(self, problem: DatabaseSearch, tree_nodes: int) -> int:
        """The policy's k for ``problem`` (``IterationPolicy.iterations_for``).

        Args:
            problem: The database search.
            tree_nodes: Nodes in the tree so far.

        Returns:
            k >= 0.
        """
        return self.policy.iterations_for(problem, tree_nodes)

    def run(self, problem: DatabaseSearch, workers: int, tree_nodes: int) -> tuple[SearchOutcome, ...]:
        """``workers`` workers search one database (paper Algorithm 3's worker loop; Algorithm 2 for one).

        The default: one backend search at the policy's k with ``shots = workers`` (each shot
        stands for one worker's independent preparation), then each worker verifies its own
        measurement classically. Cost per worker (DESIGN §2): k quantum oracle calls + 1
        verification.

        Args:
            problem: The database search (marks, classical verification, size N, seeded streams).
            workers: Number p of workers searching this database (>= 1).
            tree_nodes: Nodes in the tree so far (for schedules that depend on it).

        Returns:
            One ``SearchOutcome`` per worker, in worker order: the verified index or None, the
            quantum calls and verifications spent, and the (k, success) observations.
        """
        k = validate_iterations(self.iterations_for(problem, tree_nodes))
        return verified_outcomes(problem, k, problem.search(k, workers, problem.shared_seed()))

    def run_many(self, problems: Sequence[DatabaseSearch], workers: int,
                 tree_nodes: int) -> tuple[tuple[SearchOutcome, ...], ...]:
        """``run`` on each of several independent databases of one round, in order.

        Args:
            problems: The round's database searches.
            workers: Workers per database (>= 1).
            tree_nodes: Nodes in the tree so far.

        Returns:
            Per database, the outcomes ``run`` returns for it.
        """
        return tuple(self.run(problem, workers, tree_nodes) for problem in problems)

    def observe(self, iterations: int, success: bool) -> None:
        """Record that a measurement after ``iterations`` iterations verified (or not).

        Nothing by default; learning policies (``Adaptive``) update their posterior.

        Args:
            iterations: k of the measured preparation.
            success: Whether the measured entry verified.
        """

    def learn(self, databases: Iterable[Sequence[SearchOutcome]]) -> None:
        """Feed a round's outcomes back, one group per database, in worker order.

        By default each observation goes to ``observe``; a policy that learns per database
        (``ThompsonIterations``) overrides this.

        Args:
            databases: Per database searched this round, its workers' ``SearchOutcome`` objects.
        """
        for outcomes in databases:
            for outcome in outcomes:
                for iterations, success in outcome.observations:
                    self.observe(iterations, success)


def verified_outcomes(problem: DatabaseSearch, k: int, measured: np.ndarray) -> tuple[SearchOutcome, ...]:
    """Each worker verifies its own measured index (k quantum calls + 1 verification each).

    Args:
        problem: The database search.
        k: The iterations of the search that measured ``measured``.
        measured: One measured index per worker.

    Returns:
        One ``SearchOutcome`` per worker.
    """
    outcomes = []
    for index in measured:
        good = problem.verify(int(index))
        outcomes.append(SearchOutcome(int(index) if good else None, k, 1, ((k, good),)))
    return tuple(outcomes)


def _check_iteration_count(value: Any, name: str) -> int:
    """A Grover iteration count k a backend's search accepts: 0 .. ``MAX_ITERATIONS`` (so a plan is
    not refused halfway through, at the first search with that k)."""
    return check_int(value, name, 0, MAX_ITERATIONS)


@dataclass(frozen=True)
class PaperIterations(IterationPolicy):
    """The authors' schedule: ``early`` iterations, then ``late`` once the tree is larger.

    The paper's q-RRT / Pq-RRT experiments (Alg. 2 / 3) use k = 5, then k = 3 once the tree has more
    than 10 nodes (the authors' code), not the optimal k of Eq. 1.

    Args:
        early: k while the tree has at most ``switch_nodes`` nodes (default 5).
        late: k once the tree has more than ``switch_nodes`` nodes (default 3).
        switch_nodes: The tree size at which the schedule switches (default 10).

    Raises:
        TypeError: A non-integer field.
        ValueError: ``early`` or ``late`` outside [0, 100000] (``MAX_ITERATIONS``, what a search
            accepts), or ``switch_nodes`` outside [0, 1000000].
    """

    early: int = 5
    late: int = 3
    switch_nodes: int = 10
    name = "paper"

    def __post_init__(self) -> None:
        for key in ("early", "late"):
            _check_iteration_count(getattr(self, key), key)
        check_int(self.switch_nodes, "switch_nodes", 0, 1_000_000)

    def _iterations(self, num_items: int, tree_nodes: int, num_marked: int | None) -> int:
        return self.late if tree_nodes > self.switch_nodes else self.early

    def iterations_bound(self, num_items: int) -> int:
        return max(self.early, self.late)

    def describe(self) -> str:
        return f"paper ({self.early} iterations, {self.late} after {self.switch_nodes} nodes)"


@dataclass(frozen=True)
class FixedIterations(IterationPolicy):
    """Always ``k`` Grover iterations (paper Algorithm 4, QDA, uses k = 2).

    Args:
        k: The iteration count (default 2).

    Raises:
        TypeError: A non-integer ``k``.
        ValueError: ``k`` outside [0, 100000] (``MAX_ITERATIONS``, what a search accepts).
    """

    k: int = 2
    name = "fixed"

    def __post_init__(self) -> None:
        _check_iteration_count(self.k, "k")

    def _iterations(self, num_items: int, tree_nodes: int, num_marked: int | None) -> int:
        return int(self.k)

    def iterations_bound(self, num_items: int) -> int:
        return int(self.k)

    def describe(self) -> str:
        return f"fixed:{self.k}"


@dataclass(frozen=True)
class KnownOptimal(IterationPolicy):
    """The optimal k (paper Equation 1) for each database's true marked count m.

    k = floor(pi / (4 theta)) with sin^2 theta = m/N, and 0 for m = 0. Reading m is simulation
    knowledge a quantum device does not have; every output planned with it is labelled so.

    Example:
        >>> from qrrt_circuits import KnownOptimal
        >>> KnownOptimal.uses_true_m, KnownOptimal().describe()
        (True, 'optimal (uses the true m of each database: simulation knowledge)')
    """

    name = "optimal"
    uses_true_m = True

    def _iterations(self, num_items: int, tree_nodes: int, num_marked: int | None) -> int:
        if num_marked is None:
            raise ValueError("KnownOptimal needs the database's marked count")
        return optimal_iterations(num_items, num_marked)

    def iterations_for(self, problem: DatabaseSearch, tree_nodes: int) -> int:
        return self._iterations(problem.num_items, tree_nodes, problem.marked_count())

    def describe(self) -> str:
        return "optimal (uses the true m of each database: simulation knowledge)"

    def labels(self) -> tuple[str, ...]:
        return ("simulation knowledge: iterations use the true marked count m of each database "
                "(KnownOptimal)",)


@dataclass(frozen=True)
class BBHTOutcome:
    """One BBHT search: the verified index or None, iterations and verifications spent.

    Args:
        index: The verified database entry, or None if the loop gave up.
        iterations: Grover iterations spent over all attempts (quantum oracle calls).
        verifications: Measured entries verified (one per attempt).
        attempts: ``(iterations, verified)`` per attempt.
    """

    index: int | None
    iterations: int
    verifications: int
    attempts: tuple[tuple[int, bool], ...] = ()


@dataclass(frozen=True)
class BBHT(IterationPolicy):
    """Boyer-Brassard-Hoyer-Tapp search for an unknown m, one loop per worker.

    Boyer, Brassard, Hoyer and Tapp, "Tight bounds on quantum searching", Fortschr. Phys. 46, 493
    (1998), Thm. 3. Per worker: draw j uniformly in [0, M), run j iterations, measure, verify; on
    failure M <- min(lambda M, sqrt(N)), starting from M = 1. The loop stops at the first verified
    success or once the iterations spent reach ``cap_factor * sqrt(N)`` (so m = 0 terminates; for
    N = 2, where M < 2 and every j is 0, after that many attempts).
    Expected cost O(sqrt(N/m)) oracle calls. Each circuit costs j quantum calls + 1 verification.

    Args:
        growth: lambda, the growth factor of M, in (1, 4/3] (default 6/5; BBHT prove the bound for
            1 < lambda < 4/3).
        cap_factor: The iteration budget of one search as a multiple of sqrt(N), in (0, 1000]
            (default 4.5).

    Raises:
        TypeError: A non-real field.
        ValueError: A field outside its range.
    """

    growth: float = 6 / 5
    cap_factor: float = 4.5
    name = "bbht"

    def __post_init__(self) -> None:
        check_float(self.growth, "growth", 1.0, 4.0 / 3.0 + 1e-12, open_minimum=True)
        check_float(self.cap_factor, "cap_factor", 0.0, 1000.0, open_minimum=True)

    def start(self, num_items: int) -> BBHTState:
        return BBHTState(self, num_items)

    def iterations_bound(self, num_items: int) -> int:
        """The most iterations one BBHT circuit runs: j < M <= sqrt(N) (the cap bounds their sum).

        Args:
            num_items: N, the database size.

        Returns:
            min(isqrt(N), ``cap(N)``).
        """
        return min(math.isqrt(num_items), self.cap(num_items))

    def cap(self, num_items: int) -> int:
        """Iteration budget of one BBHT search.

        Args:
            num_items: N, the database size.

        Returns:
            ceil(``cap_factor`` * sqrt(N)), at least 1.
        """
        return max(1, int(math.ceil(self.cap_factor * math.sqrt(num_items))))

    def run(self, search: Callable[[int], int], verify: Callable[[int], bool], num_items: int,
            rng: np.random.Generator) -> BBHTOutcome:
        """One worker's BBHT search (Theorem 3 of BBHT 1998, with an iteration cap).

        Args:
            search: ``search(j)`` prepares the database, runs j Grover iterations (j quantum oracle
                calls) and returns the measured index.
            verify: ``verify(index)`` is the classical check of a measured index (1 oracle call).
            num_items: N, the database size.
            rng: The generator that draws each j.

        Returns:
            A ``BBHTOutcome``: the verified index or None (cap reached), the iterations and
            verifications spent, and the (j, success) attempts.
        """
        bound = 1.0
        spent = 0
        attempts: list[tuple[int, bool]] = []
        cap = self.cap(num_items)
        limit = math.sqrt(num_items)
        while True:
            j = int(rng.integers(0, max(1, int(math.floor(bound)))))
            if spent + j > cap:
                return BBHTOutcome(None, spent, len(attempts), tuple(attempts))
            index = search(j)
            spent += j
            good = verify(index)
            attempts.append((j, good))
            if good:
                return BBHTOutcome(index, spent, len(attempts), tuple(attempts))
            bound = min(self.growth * bound, limit)
            if spent >= cap or (limit < 2.0 and len(attempts) >= cap):
                # (N = 2: M never reaches 2, every j is 0 and spends nothing; stop after cap attempts)
                return BBHTOutcome(None, spent, len(attempts), tuple(attempts))

    def describe(self) -> str:
        return f"bbht (unknown m, cap {self.cap_factor} sqrt(N) iterations)"


class BBHTState(PolicyState):
    """Each worker runs its own BBHT loop (its own random iteration counts and searches)."""

    policy: BBHT

    def choose_iterations(self, tree_nodes: int, num_marked: int | None = None) -> int:
        raise TypeError("BBHT chooses its iterations inside its own loop (BBHT.run)")


    def run(self, problem: DatabaseSearch, workers: int, tree_nodes: int) -> tuple[SearchOutcome, ...]:
        outcomes = []
        for offset in range(workers):
            rng = problem.worker_generator(offset)

            def search(j: int, rng: np.random.Generator = rng) -> int:
                return int(problem.search(j, 1, int(rng.integers(2**62)))[0])

            found = self.policy.run(search, problem.verify, problem.num_items, rng)
            outcomes.append(SearchOutcome(found.index, found.iterations, found.verifications, found.attempts))
        return tuple(outcomes)


@dataclass(frozen=True)
class Adaptive(IterationPolicy):
    """Chooses k from a posterior over the marked fraction built from verified outcomes only.

    Each measurement after k iterations succeeds with probability sin^2((2k+1) asin(sqrt f)) for
    the marked fraction f = m/N (the success probability behind Eq. 1); a grid posterior over f
    picks the k with the largest expected success per oracle call, P(k) / (k + 1). It never reads
    the true m. The defaults (a uniform prior, forgetting 0.9) are calibrated on cluttered, sparse
    and dense worlds.

    Args:
        grid_size: Points of the geometric grid over f in [1/N, 1], in [10, 100000] (default 200).
        forgetting: Each new observation multiplies the old log-likelihood by this factor, in (0, 1]
            (default 0.9): an effective memory of about 1 / (1 - forgetting) measurements, as f
            drifts with the tree.
        prior: ``"uniform"`` (flat in f on [1/N, 1], the default) or ``"log-uniform"`` (flat in
            log f).
        max_iterations: The largest k considered, in [0, 1000000], or None (default) for the optimal
            k for one marked entry (Eq. 1).

    Raises:
        TypeError: A field of the wrong type.
        ValueError: A field outside its range, or an unknown ``prior``.
    """

    grid_size: int = 200
    forgetting: float = 0.9
    prior: str = "uniform"
    max_iterations: int | None = None
    name = "adaptive"

    def __post_init__(self) -> None:
        check_int(self.grid_size, "grid_size", 10, 100_000)
        check_float(self.forgetting, "forgetting", 0.0, 1.0, open_minimum=True)
        check_choice(self.prior, "prior", ("uniform", "log-uniform"))
        check_optional_int(self.max_iterations, "max_iterations", 0, 1_000_000)

    def start(self, num_items: int) -> AdaptiveState:
        return AdaptiveState(self, num_items)

    def iterations_bound(self, num_items: int) -> int:
        return optimal_iterations(num_items, 1) if self.max_iterations is None else int(self.max_iterations)

    def state_bytes(self, num_items: int) -> int:
        """The success table sin^2((2k+1) theta(f)), (k_max + 1) x grid_size float64, and the
        temporaries that build it (3 tables).

        Args:
            num_items: N, the database size.

        Returns:
            3 x 8 x (k_max + 1) x ``grid_size`` bytes.
        """
        return 3 * 8 * (self.iterations_bound(num_items) + 1) * int(self.grid_size)

    def describe(self) -> str:
        return "adaptive (estimates m/N from verified outcomes; no access to the true m)"


class AdaptiveState(PolicyState):
    """Per-plan state of ``Adaptive``: a posterior over the marked fraction f on a geometric grid.

    k is chosen to maximise E[sin^2((2k+1) theta(f))] / (k + 1), sin^2 theta = f (Eq. 1; the
    expected successes per oracle call), the expectation under the posterior; each verified or
    refuted measurement multiplies the likelihood by sin^2((2k+1) theta) or its complement (the old
    log-likelihood discounted by ``forgetting``).

    Args:
        policy: The ``Adaptive`` policy.
        num_items: N, the entries of each database.
    """

    policy: Adaptive

    def __init__(self, policy: Adaptive, num_items: int) -> None:
        super().__init__(policy, num_items)
        self.fractions = np.geomspace(1.0 / num_items, 1.0, policy.grid_size)
        # the grid is geometric: weight f per point is a flat density in f, weight 1 flat in log f
        self.log_prior = np.log(self.fractions) if policy.prior == "uniform" else np.zeros(policy.grid_size)
        self.log_likelihood = np.zeros(policy.grid_size)
        top = optimal_iterations(num_items, 1) if policy.max_iterations is None else policy.max_iterations
        self.candidates = np.arange(0, top + 1)
        theta = np.arcsin(np.sqrt(self.fractions))
        # success[k, f] = sin^2((2k+1) theta(f))
        self.success = np.sin(np.outer(2 * self.candidates + 1, theta)) ** 2

    @property
    def log_posterior(self) -> np.ndarray:
        """Log prior + log likelihood on the grid of fractions (unnormalised)."""
        return self.log_prior + self.log_likelihood

    def choose_iterations(self, tree_nodes: int, num_marked: int | None = None) -> int:
        log_posterior = self.log_posterior
        weights = np.exp(log_posterior - log_posterior.max())
        weights /= weights.sum()
        expected = self.success @ weights
        return int(self.candidates[np.argmax(expected / (self.candidates + 1))])


    def iterations_for(self, problem: DatabaseSearch, tree_nodes: int) -> int:
        """The posterior's k (``choose_iterations``); the problem's true m is never read.

        Args:
            problem: The database search (unused but for its type).
            tree_nodes: Nodes in the tree so far.

        Returns:
            k >= 0.
        """
        return self.choose_iterations(tree_nodes)

    def observe(self, iterations: int, success: bool) -> None:
        theta = np.arcsin(np.sqrt(self.fractions))
        p = np.clip(np.sin((2 * iterations + 1) * theta) ** 2, 1e-9, 1 - 1e-9)
        self.log_likelihood *= self.policy.forgetting
        self.log_likelihood += np.log(p if success else 1 - p)

    def estimate(self) -> float:
        """Posterior mean of the marked fraction."""
        log_posterior = self.log_posterior
        weights = np.exp(log_posterior - log_posterior.max())
        return float(np.sum(weights * self.fractions) / weights.sum())
