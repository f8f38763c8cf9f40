"""``EstimatedOptimal``: estimate the marked count of each database by amplitude estimation, then
let every worker run the optimal number of Grover iterations for the estimate.

For one database (shared by p workers in Pq-RRT), one amplitude estimation from qiskit-algorithms
(``MaximumLikelihoodAmplitudeEstimation`` by default, or ``IterativeAmplitudeEstimation``;
``search/estimation.py``) estimates a = m / N; every worker then runs
k = floor(pi / (4 theta)), sin^2 theta = m_hat / N with m_hat = max(1, round(a_hat N)) (Eq. 1),
measures once and verifies. The estimation is paid once per database and used by all p workers,
which is where it can pay for itself.

Oracle calls (DESIGN §2): the estimation costs sum_i shots_i (k_i + 1) quantum oracle calls (k_i
inside Q^{k_i}, 1 to decide whether the measured index is good: see ``search/estimation.py``);
its shots are shared by the p workers round by round (worker w takes shots // p, one more for
w < shots % p), so the estimation's critical path is worker 0's share. Each worker adds k quantum
calls and 1 verification. Estimation shots are labelled in every output as counted oracle calls.
The estimation runs on qiskit-aer's SamplerV2 whatever the planner's backend (labelled too).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..._support.validation import check_choice, check_float, check_int
from ...probability import optimal_iterations
from ..estimation import METHODS, AmplitudeEstimate, estimate_marked_fraction
from ..problem import DatabaseSearch, SearchOutcome
from .base import IterationPolicy, PolicyState

__all__ = ["EstimatedOptimal", "EstimatedOptimalState"]


@dataclass(frozen=True)
class EstimatedOptimal(IterationPolicy):
    """One amplitude estimation per database, then the optimal k (paper Equation 1) for the estimate.

    Every worker of the database (Alg. 3; one for Alg. 2) runs k = floor(pi / (4 theta)),
    sin^2 theta = m_hat / N with m_hat = max(1, round(a_hat N)), measures once and verifies. The
    estimation's shots are counted as quantum oracle calls (k_i + 1 per shot) and shared by the
    workers. Unlike ``KnownOptimal`` it never reads the true m.

    Args:
        method: ``"mlae"`` (default; maximum-likelihood amplitude estimation on the powers
            [0, 1, ..., 2^(schedule-1)] of the Grover operator, likelihood-ratio interval) or
            ``"iae"`` (iterative amplitude estimation to a half-width ``epsilon`` on m/N); see
            ``search/estimation.py`` for why MLAE is the default.
        schedule: Number of Grover powers of MLAE, in [0, 20] (default 3).
        shots: Shots per estimation circuit, in [1, 1000000] (default 16).
        alpha: The estimate's confidence is 1 - alpha, alpha in (0, 1) (default 0.05).
        epsilon: Target half-width of IAE on m/N, in (0, 0.5] (default 0.05).

    Raises:
        TypeError: A non-integer ``schedule`` or ``shots``, or a non-real ``alpha`` or ``epsilon``.
        ValueError: An unknown ``method`` or a field outside its range.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits import DatabaseSearch, EstimatedOptimal, LookupOracle, StatevectorBackend
        >>> from qrrt_circuits._support.randomness import RandomStreams
        >>> marks = np.zeros(16, dtype=bool)
        >>> marks[[1, 5, 9, 13]] = True
        >>> problem = DatabaseSearch(LookupOracle(marks), marks, StatevectorBackend(seed=0), RandomStreams(0), 0)
        >>> estimate = EstimatedOptimal(shots=64).estimate(problem)
        >>> estimate.powers, estimate.oracle_calls  # 64 shots x (1 + 2 + 3 + 5) calls
        ((0, 1, 2, 4), 704)
        >>> estimate.marked_count(16)
        4
    """

    method: str = "mlae"
    schedule: int = 3
    shots: int = 16
    alpha: float = 0.05
    epsilon: float = 0.05
    name = "estimated"

    def __post_init__(self) -> None:
        check_choice(self.method, "method", METHODS)
        check_int(self.schedule, "schedule", 0, 20)
        check_int(self.shots, "shots", 1, 1_000_000)
        check_float(self.alpha, "alpha", 0.0, 1.0, open_minimum=True)
        if self.alpha >= 1.0:
            raise ValueError(f"alpha must be in (0, 1), got {self.alpha}")
        check_float(self.epsilon, "epsilon", 0.0, 0.5, open_minimum=True)

    def start(self, num_items: int) -> EstimatedOptimalState:
        return EstimatedOptimalState(self, num_items)

    def estimate(self, problem: DatabaseSearch) -> AmplitudeEstimate:
        """One amplitude estimation of ``problem``'s marked fraction a = m/N.

        Seeded from the policy stream of the database's first worker.

        Args:
            problem: The database search (its lookup oracle's marks define the good states).

        Returns:
            The ``AmplitudeEstimate`` (estimate, interval and the quantum oracle calls it cost).

        Raises:
            ValueError: A database whose oracle is not a lookup (a ``CircuitOracle``).
            RuntimeError: IAE running more than ``MAX_IAE_ROUNDS`` circuits, or an oracle-query
                count that disagrees with qiskit-algorithms' (``estimate_marked_fraction``).
        """
        marks = problem.oracle.lookup_marks("EstimatedOptimal's amplitude estimation")
        return estimate_marked_fraction(marks, alpha=self.alpha, shots=self.shots,
                                        rng=problem.worker_generator(0), method=self.method,
                                        schedule=self.schedule, epsilon=self.epsilon)

    def miss_reason(self) -> str:
        return ("the optimal k for an estimated m misses more where the estimate is off, and a database with no "
                "reachable entry always misses")

    def describe(self) -> str:
        top = 2 ** (self.schedule - 1) if self.schedule else 0
        how = (f"maximum-likelihood amplitude estimation, powers 0..{top}" if self.method == "mlae"
               else f"iterative amplitude estimation to epsilon {self.epsilon}")
        return f"estimated ({how}, {self.shots} shots a circuit, then the optimal k for the estimate)"

    def labels(self) -> tuple[str, ...]:
        return ("EstimatedOptimal: amplitude-estimation shots are counted as quantum oracle calls "
                "(k + 1 per shot of Q^k A|0>), shared by the workers of a database; they run on "
                "qiskit-aer's SamplerV2 whatever the search backend",)


class EstimatedOptimalState(PolicyState):
    """Per-plan state: per database one estimation, then every worker searches with its optimal k.

    Args:
        policy: The ``EstimatedOptimal`` policy.
        num_items: N, the entries of each database.

    Attributes:
        history: (estimate, k) per database, in the order they were run.
    """

    policy: EstimatedOptimal

    def __init__(self, policy: EstimatedOptimal, num_items: int) -> None:
        super().__init__(policy, num_items)
        self.history: list[tuple[AmplitudeEstimate, int]] = []

    def choose_iterations(self, tree_nodes: int, num_marked: int | None = None) -> int:
        raise TypeError("EstimatedOptimal chooses k per database from its estimate (see run)")


    def run(self, problem: DatabaseSearch, workers: int, tree_nodes: int) -> tuple[SearchOutcome, ...]:
        """Estimate the database's m, then ``workers`` workers search it with the optimal k.

        Args:
            problem: The database search.
            workers: Number p of workers (>= 1).
            tree_nodes: Nodes in the tree so far (unused).

        Returns:
            One ``SearchOutcome`` per worker: the verified index or None, its share of the
            estimation's calls plus k quantum calls, and 1 verification.
        """
        estimate = self.policy.estimate(problem)
        k = optimal_iterations(problem.num_items, estimate.marked_count(problem.num_items))
        self.history.append((estimate, k))
        shares = estimate.calls_per_worker(workers)
        outcomes = []
        for share, measured in zip(shares, problem.search(k, workers, problem.shared_seed()), strict=True):
            good = problem.verify(int(measured))
            outcomes.append(SearchOutcome(int(measured) if good else None, share + k, 1, ((k, good),)))
        return tuple(outcomes)
