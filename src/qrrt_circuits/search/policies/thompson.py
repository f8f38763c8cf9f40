"""``ThompsonIterations``: the iteration count k as a budgeted bandit over databases.

A plan searches one database after another, each with its own number m of reachable entries out
of N = 2^n, drawn from a distribution G that the plan does not know and that drifts as the tree
grows (most databases empty in a narrow passage, most entries reachable in open space). A policy
that measures each database once, after k Grover iterations, with p workers sharing it (p = 1 for
q-RRT), finds on average

    D(k) = E_G[ m (1 - (1 - P_k(m) / m)^p) ]   (``probability.expected_distinct_found``)

where P_k(m) = sin^2((2k + 1) theta), sin^2 theta = m / N (Eq. 1), and each worker measures a
given marked entry with probability P_k(m) / m (the multinomial behind Lemma 1; for p = 1,
D(k) = E_G[P_k(m)]). It spends k + 1 oracle calls per worker (k iterations and one verification,
DESIGN §2), so its critical-path calls per new node are

    C(k) = (k + 1) / D(k),

and its total calls per node p C(k). A mixture of several k is never better than the best single
k (C's reciprocal, a ratio of two linear functions of the mixture's weights, is largest at a
vertex), so the best one-measurement policy is k* = argmin C(k); the paper's schedule is the case
k = 5, then 3, and ``KnownOptimal`` would need each database's m.

Where many databases are empty (a share pi of G at m = 0), every k pays for them alike: C(k)
grows by 1 / (1 - pi) for all k, and k* does not move. A search that keeps going until it finds
an entry pays for an empty database up to its cap instead: BBHT's cap of 4.5 sqrt(N) iterations
(72 at N = 256) plus one verification per attempt, against k* + 1 here.

``ThompsonIterations`` learns D(k) from the plan's own databases as a budgeted multi-armed bandit
(Xia, Li, Qin, Yu and Liu, "Thompson sampling for budgeted multi-armed bandits", IJCAI 2015): arm
k in 0 .. K (K = the optimal k for m = 1, Eq. 1) has cost k + 1 and reward D(k) / p in [0, 1];
each arm's reward has a Beta posterior; every database draws one sample per arm and searches at
the arm with the largest sampled reward per cost. The unit of learning is the database, not the
measurement: the p measurements of one shared database are one observation (its share of distinct
verified entries), since they are not independent of each other. Each arm's prior is the mean of
P_k over f = m / N uniform on [1 / N, 1] (about 1/2 for every k), with the weight of
``prior_strength`` databases, so a plan starts at k = 0 (the cheapest arm) and moves to larger k as
classical draws fail; a prior log-uniform in f (mean 0.18 at k = 0) instead starts by exploring
k >= 1, which costs several times a short plan's calls in open space (on a synthetic model of
Poisson-distributed m, ``benchmarks/policy_synthetic.py`` measures both against the best fixed k);
after every database all arms forget toward their prior by the factor ``memory`` (an effective
memory of about 1 / (1 - memory) databases), as G drifts with the tree. An arm whose cost k + 1
already exceeds the sampled cost per node of a cheaper arm cannot win (a reward is at most 1), so
exploration stays below the plan's current cost per node. It never reads the true m.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from ..._support.validation import check_choice, check_float, check_optional_int
from ...probability import optimal_iterations
from ..problem import DatabaseSearch, SearchOutcome
from .base import IterationPolicy, PolicyState, verified_outcomes

__all__ = ["ThompsonIterations", "ThompsonState"]

#: salt of the policy's own draw, apart from the search's seed of the same database
_DRAW_SALT = 0x7A0B
#: grid points of the prior over the marked fraction
_PRIOR_GRID = 400


@dataclass(frozen=True)
class ThompsonIterations(IterationPolicy):
    """Grover iterations chosen per database by Thompson sampling of a budgeted bandit over k.

    The module docstring derives the cost per node C(k) = (k + 1) / D(k) and the rule. One search
    per database with ``shots = workers`` at the chosen k: k quantum calls and one verification per
    worker (DESIGN §2), as ``PaperIterations``.

    Args:
        memory: The factor by which every arm's evidence is kept after each database, in (0, 1]
            (default 0.95: about 20 databases).
        prior_strength: The prior's weight in databases, in (0, 1000] (default 1).
        prior: ``"uniform"`` (f uniform on [1/N, 1], the default) or ``"log-uniform"`` (flat in log f).
        max_iterations: The largest k, in [0, 1000000], or None (default) for the optimal k for one
            marked entry (Eq. 1).

    Raises:
        TypeError: A field of the wrong type.
        ValueError: A field outside its range.

    Example:
        >>> from qrrt_circuits import ThompsonIterations
        >>> state = ThompsonIterations().start(256)
        >>> int(state.arms[-1])  # floor(pi / (4 asin(1/16)))
        12
    """

    memory: float = 0.95
    prior_strength: float = 1.0
    prior: str = "uniform"
    max_iterations: int | None = None
    name = "thompson"

    def __post_init__(self) -> None:
        check_float(self.memory, "memory", 0.0, 1.0, open_minimum=True)
        check_float(self.prior_strength, "prior_strength", 0.0, 1000.0, open_minimum=True)
        check_choice(self.prior, "prior", ("uniform", "log-uniform"))
        check_optional_int(self.max_iterations, "max_iterations", 0, 1_000_000)

    def start(self, num_items: int) -> ThompsonState:
        return ThompsonState(self, num_items)

    def iterations_bound(self, num_items: int) -> int:
        return optimal_iterations(num_items, 1) if self.max_iterations is None else int(self.max_iterations)

    def state_bytes(self, num_items: int) -> int:
        """Four float64 arrays of one entry per arm, and the prior's (arms x grid) table.

        Args:
            num_items: N, the database size.

        Returns:
            8 x (arms x (4 + grid)) bytes.
        """
        return 8 * (self.iterations_bound(num_items) + 1) * (4 + _PRIOR_GRID)

    def miss_reason(self) -> str:
        return ("the bandit tries iteration counts to learn which verifies most entries per call, so its misses "
                "include that exploration")

    def describe(self) -> str:
        return (f"thompson (k per database from a bandit over verified outcomes, memory {self.memory}, "
                f"{self.prior} prior; no access to the true m)")


class ThompsonState(PolicyState):
    """Per-plan state of ``ThompsonIterations``: a Beta posterior per arm k.

    Args:
        policy: The ``ThompsonIterations`` policy.
        num_items: N, the entries of each database.

    Attributes:
        arms: The iteration counts 0 .. K.
        prior_alpha, prior_beta: Each arm's prior pseudo-counts.
        alpha, beta: Each arm's posterior pseudo-counts.
    """

    policy: ThompsonIterations

    def __init__(self, policy: ThompsonIterations, num_items: int) -> None:
        super().__init__(policy, num_items)
        self.arms = np.arange(policy.iterations_bound(num_items) + 1)
        spaced = np.linspace if policy.prior == "uniform" else np.geomspace
        theta = np.arcsin(np.sqrt(spaced(1.0 / num_items, 1.0, _PRIOR_GRID)))
        mean = np.clip(np.mean(np.sin(np.outer(2 * self.arms + 1, theta)) ** 2, axis=1), 1e-6, 1 - 1e-6)
        self.prior_alpha = policy.prior_strength * mean
        self.prior_beta = policy.prior_strength * (1.0 - mean)
        self.alpha = self.prior_alpha.copy()
        self.beta = self.prior_beta.copy()

    def choose_iterations(self, tree_nodes: int, num_marked: int | None = None) -> int:
        """The arm of largest posterior-mean reward per cost (a deterministic summary; a search
        draws its own sample in ``run``).

        Args:
            tree_nodes: Nodes in the tree so far (unused).
            num_marked: Unused: the true m is never read.

        Returns:
            k >= 0.
        """
        mean = self.alpha / (self.alpha + self.beta)
        return int(self.arms[np.argmax(mean / (self.arms + 1))])

    def sample_iterations(self, generator: np.random.Generator) -> int:
        """One Thompson draw: a reward per arm from its Beta posterior, the arm of largest reward
        per cost.

        Args:
            generator: The draw's generator.

        Returns:
            k >= 0.
        """
        rewards = generator.beta(self.alpha, self.beta)
        return int(self.arms[np.argmax(rewards / (self.arms + 1))])

    def run(self, problem: DatabaseSearch, workers: int, tree_nodes: int) -> tuple[SearchOutcome, ...]:
        """One search at a sampled k with ``shots = workers``; each worker verifies its measurement.

        Args:
            problem: The database search.
            workers: Workers p on this database.
            tree_nodes: Nodes in the tree so far (unused).

        Returns:
            One ``SearchOutcome`` per worker.
        """
        seed = problem.shared_seed()
        k = self.sample_iterations(np.random.default_rng([seed, _DRAW_SALT]))
        return verified_outcomes(problem, k, problem.search(k, workers, seed))

    def learn(self, databases: Iterable[Sequence[SearchOutcome]]) -> None:
        """Each database's share of distinct verified entries updates the arm it was searched at,
        after every arm forgets toward its prior by ``memory``.

        Args:
            databases: Per database, its workers' outcomes (one search at one k).
        """
        keep = self.policy.memory
        for outcomes in databases:
            if not outcomes or not outcomes[0].observations:
                continue
            k = outcomes[0].observations[0][0]
            reward = len({o.index for o in outcomes if o.index is not None}) / len(outcomes)
            self.alpha = self.prior_alpha + keep * (self.alpha - self.prior_alpha)
            self.beta = self.prior_beta + keep * (self.beta - self.prior_beta)
            arm = int(np.searchsorted(self.arms, k))
            self.alpha[arm] += reward
            self.beta[arm] += 1.0 - reward
