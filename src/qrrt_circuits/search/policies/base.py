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

The policies: ``schedules`` (``PaperIterations``, ``FixedIterations``, ``KnownOptimal``), ``bbht``,
``adaptive``, ``thompson``, ``fixed_point_amplification``, ``estimated``.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np

from ...probability import optimal_iterations
from ..problem import DatabaseSearch, SearchOutcome
from ..requests import validate_iterations

__all__ = ["IterationPolicy", "PolicyState", "verified_outcomes"]


class IterationPolicy:
    """Base class of the search policies: how a worker searches one database (frozen configurations).

    A policy picks the Grover iteration count k of the amplitude amplification loop of Alg. 2 / 3
    (the paper fixes k by a schedule; Eq. 1 gives the optimal k for a known m). Subclasses implement
    ``_iterations`` (policies that pick k before measuring) or return their own ``PolicyState``
    from ``start`` with its own ``run``.

    The class attribute ``uses_true_m`` is True if the policy reads the database's true marked
    count m (simulation knowledge a quantum device does not have, labelled in every output that
    depends on it); ``name`` is the policy's short name. A plan's memory check sizes the policy by
    numbers it reports: its largest search (``iterations_bound``, ``runs_sequences``) and its
    state (``state_bytes``).

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits import DatabaseSearch, KnownOptimal, LookupOracle, PaperIterations, StatevectorBackend
        >>> from qrrt_circuits._support.randomness import RandomStreams
        >>> marks = np.zeros(64, dtype=bool)
        >>> marks[:2] = True
        >>> problem = DatabaseSearch(LookupOracle(marks), marks, StatevectorBackend(seed=0), RandomStreams(0), 0)
        >>> PaperIterations().iterations_for(problem, 0), PaperIterations().iterations_for(problem, 11)
        (5, 3)
        >>> KnownOptimal().iterations_for(problem, 0)  # floor(pi / (4 asin(sqrt(2/64))))
        4
    """

    uses_true_m: bool = False
    name: str = "policy"
    #: whether the policy's searches run generalized iterates (``search_sequence``) rather than Grover
    #: iterations: a plan sizes its largest search as such a sequence of ``iterations_bound(N)`` iterates
    runs_sequences: bool = False

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

    def miss_reason(self) -> str:
        """Why a measurement of this policy can fail verification, in one clause (``qrrt plan``
        prints it when most measured candidates failed).

        Returns:
            By default: a measurement after k iterations is marked only with probability
            sin^2((2k+1) theta), sin^2 theta = m/N (the success probability behind Eq. 1).
        """
        return ("a measurement after k Grover iterations is a reachable entry only with probability "
                "sin^2((2k+1) theta), sin^2 theta = m/N (Eq. 1)")

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
        """The most Grover iterations (or generalized iterates, ``runs_sequences``) one search (one
        circuit) of this policy can run.

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
