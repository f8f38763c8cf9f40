"""``Adaptive()``: a Bayesian estimate of the marked fraction f = m/N from the planner's own
verified outcomes only.

Each measurement after k iterations succeeded with probability sin^2((2k+1) asin(sqrt f)); a grid
posterior over f (flat prior, with forgetting, since f drifts as the tree grows) picks the k with
the largest expected success per oracle call, P(k) / (k + 1).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._support.validation import check_choice, check_float, check_int, check_optional_int
from ...probability import optimal_iterations
from ..problem import DatabaseSearch
from .base import IterationPolicy, PolicyState

__all__ = ["Adaptive", "AdaptiveState"]


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
        """The success table sin^2((2k+1) theta(f)), (k_max + 1) x grid_size float64, the log
        likelihoods of a success and of a miss (2 more tables), and the temporaries that build them
        (3 tables).

        Args:
            num_items: N, the database size.

        Returns:
            6 x 8 x (k_max + 1) x ``grid_size`` bytes.
        """
        return 6 * 8 * (self.iterations_bound(num_items) + 1) * int(self.grid_size)

    def miss_reason(self) -> str:
        return ("the posterior over m/N learns from misses, and where m/N is large the k with the most successes "
                "per call is 0: a uniform draw, which misses with probability 1 - m/N")

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
        # the log likelihood of a success and of a miss at each candidate k (``observe``)
        clipped = np.clip(self.success, 1e-9, 1 - 1e-9)
        self.log_success, self.log_miss = np.log(clipped), np.log(1 - clipped)

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
        """Discount the log likelihood by ``forgetting`` and add log sin^2((2k+1) theta(f)) (a
        success) or log of its complement (a miss), clipped to [1e-9, 1 - 1e-9] (the candidates'
        rows are computed once, when the plan starts)."""
        if 0 <= iterations < self.candidates.shape[0]:
            row = (self.log_success if success else self.log_miss)[iterations]
        else:
            theta = np.arcsin(np.sqrt(self.fractions))
            p = np.clip(np.sin((2 * iterations + 1) * theta) ** 2, 1e-9, 1 - 1e-9)
            row = np.log(p if success else 1 - p)
        self.log_likelihood *= self.policy.forgetting
        self.log_likelihood += row

    def estimate(self) -> float:
        """Posterior mean of the marked fraction."""
        log_posterior = self.log_posterior
        weights = np.exp(log_posterior - log_posterior.max())
        return float(np.sum(weights * self.fractions) / weights.sum())
