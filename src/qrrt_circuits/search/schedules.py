"""Iteration policies: how many Grover iterations a worker applies before it measures (DESIGN §2).

A policy is a frozen configuration; ``policy.start(num_items)`` gives the mutable state one plan
uses, so a policy object can be shared between planners and runs.

- ``PaperSchedule()``: 5 iterations, 3 once the tree has more than 10 nodes (the authors' code).
- ``FixedIterations(k)``: always k (Alg. 4 / QDA uses k = 2).
- ``KnownOptimal()``: floor(pi / (4 theta)), sin^2 theta = m/N, with the database's true marked
  count m. This is simulation knowledge a quantum device does not have: every output says so.
- ``BBHT()``: Boyer-Brassard-Hoyer-Tapp search for unknown m. Per worker: draw j uniformly in
  [0, M), run j iterations, measure, verify; on failure M <- min(lambda M, sqrt(N)). Stops at the
  first verified success or when the iterations spent reach ``cap_factor * sqrt(N)`` (so m = 0
  terminates). Expected cost O(sqrt(N/m)).
- ``Adaptive()``: a Bayesian estimate of the marked fraction f = m/N from the planner's own
  verified outcomes only: each measurement after k iterations succeeded with probability
  sin^2((2k+1) asin(sqrt f)); a grid posterior over f (flat prior, with forgetting, since f drifts
  as the tree grows) picks the k with the largest expected success per oracle call, P(k) / (k + 1).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..probability import optimal_iterations


class IterationPolicy:
    """Base class. ``uses_true_m``: needs the database's true marked count (simulation only)."""

    uses_true_m: bool = False
    name: str = "policy"

    def start(self, num_items: int) -> PolicyState:
        return PolicyState(self, num_items)

    def describe(self) -> str:
        return self.name


class PolicyState:
    """Per-plan state; the default is stateless."""

    def __init__(self, policy: IterationPolicy, num_items: int) -> None:
        self.policy = policy
        self.num_items = int(num_items)

    def iterations(self, tree_nodes: int, num_marked: int | None = None) -> int:
        return self.policy._iterations(self.num_items, tree_nodes, num_marked)

    def observe(self, iterations: int, success: bool) -> None:
        """Record that a measurement after ``iterations`` iterations verified (or not)."""


@dataclass(frozen=True)
class PaperSchedule(IterationPolicy):
    """5 iterations, then ``late`` (3) once the tree has more than ``switch_nodes`` (10) nodes."""

    early: int = 5
    late: int = 3
    switch_nodes: int = 10
    name = "paper"

    def __post_init__(self) -> None:
        for key in ("early", "late", "switch_nodes"):
            value = getattr(self, key)
            if int(value) != value or value < 0:
                raise ValueError(f"{key} must be an integer >= 0, got {value!r}")

    def _iterations(self, num_items: int, tree_nodes: int, num_marked: int | None) -> int:
        return self.late if tree_nodes > self.switch_nodes else self.early

    def describe(self) -> str:
        return f"paper ({self.early} iterations, {self.late} after {self.switch_nodes} nodes)"


@dataclass(frozen=True)
class FixedIterations(IterationPolicy):
    """Always ``k`` iterations."""

    k: int = 2
    name = "fixed"

    def __post_init__(self) -> None:
        if isinstance(self.k, bool) or int(self.k) != self.k or self.k < 0:
            raise ValueError(f"k must be an integer >= 0, got {self.k!r}")

    def _iterations(self, num_items: int, tree_nodes: int, num_marked: int | None) -> int:
        return int(self.k)

    def describe(self) -> str:
        return f"fixed:{self.k}"


@dataclass(frozen=True)
class KnownOptimal(IterationPolicy):
    """floor(pi/(4 theta)) for the database's true m (simulation knowledge; labelled as such)."""

    name = "optimal"
    uses_true_m = True

    def _iterations(self, num_items: int, tree_nodes: int, num_marked: int | None) -> int:
        if num_marked is None:
            raise ValueError("KnownOptimal needs the database's marked count")
        return optimal_iterations(num_items, num_marked)

    def describe(self) -> str:
        return "optimal (uses the true m of each database: simulation knowledge)"


@dataclass(frozen=True)
class BBHT(IterationPolicy):
    """Boyer-Brassard-Hoyer-Tapp search for unknown m (the planner runs its loop per worker)."""

    growth: float = 6 / 5
    cap_factor: float = 4.5
    name = "bbht"

    def __post_init__(self) -> None:
        if not (1.0 < self.growth < 4.0 / 3.0 + 1e-12):
            raise ValueError(f"growth must be in (1, 4/3], got {self.growth}")
        if not self.cap_factor > 0:
            raise ValueError(f"cap_factor must be > 0, got {self.cap_factor}")

    def cap(self, num_items: int) -> int:
        """Iteration budget of one BBHT search: ``cap_factor * sqrt(N)``."""
        return max(1, int(math.ceil(self.cap_factor * math.sqrt(num_items))))

    def run(self, search, verify, num_items: int, rng: np.random.Generator) -> BBHTOutcome:
        """One worker's BBHT search. ``search(j)`` measures an index after j iterations and
        ``verify(index)`` is the classical check (1 oracle call each)."""
        bound = 1.0
        spent = 0
        verifications = 0
        cap = self.cap(num_items)
        limit = math.sqrt(num_items)
        while True:
            j = int(rng.integers(0, max(1, int(math.floor(bound)))))
            if spent + j > cap:
                return BBHTOutcome(None, spent, verifications)
            index = search(j)
            spent += j
            verifications += 1
            if verify(index):
                return BBHTOutcome(index, spent, verifications)
            bound = min(self.growth * bound, limit)
            if spent >= cap:
                return BBHTOutcome(None, spent, verifications)

    def _iterations(self, num_items: int, tree_nodes: int, num_marked: int | None) -> int:
        raise TypeError("BBHT chooses its iterations inside its own loop (BBHT.run)")

    def describe(self) -> str:
        return f"bbht (unknown m, cap {self.cap_factor} sqrt(N) iterations)"


@dataclass(frozen=True)
class BBHTOutcome:
    index: int | None
    iterations: int
    verifications: int


@dataclass(frozen=True)
class Adaptive(IterationPolicy):
    """Chooses k from a posterior over the marked fraction built from verified outcomes only.

    ``prior``: ``"uniform"`` (flat in f on [1/N, 1], the default) or ``"log-uniform"`` (flat in
    log f). ``forgetting``: each new observation multiplies the old log-likelihood by this factor
    (an effective memory of about 1 / (1 - forgetting) measurements, as f drifts with the tree).
    The defaults (uniform, 0.9) were chosen on 20 paper_clutter worlds plus sparse (100 boxes) and
    dense (1000 boxes) ones, against log-uniform and 0.97.
    """

    grid_size: int = 200
    forgetting: float = 0.9
    prior: str = "uniform"
    max_iterations: int | None = None
    name = "adaptive"

    def __post_init__(self) -> None:
        if int(self.grid_size) != self.grid_size or self.grid_size < 10:
            raise ValueError(f"grid_size must be an integer >= 10, got {self.grid_size}")
        if not (0.0 < self.forgetting <= 1.0):
            raise ValueError(f"forgetting must be in (0, 1], got {self.forgetting}")
        if self.prior not in ("uniform", "log-uniform"):
            raise ValueError(f"prior must be 'uniform' or 'log-uniform', got {self.prior!r}")

    def start(self, num_items: int) -> AdaptiveState:
        return AdaptiveState(self, num_items)

    def describe(self) -> str:
        return "adaptive (estimates m/N from verified outcomes; no access to the true m)"


class AdaptiveState(PolicyState):
    def __init__(self, policy: Adaptive, num_items: int) -> None:
        super().__init__(policy, num_items)
        self.fractions = np.geomspace(1.0 / num_items, 1.0, policy.grid_size)
        # the grid is geometric: weight f per point is a flat density in f, weight 1 flat in log f
        self.log_prior = np.log(self.fractions) if policy.prior == "uniform" else np.zeros(policy.grid_size)
        self.log_likelihood = np.zeros(policy.grid_size)
        top = policy.max_iterations or optimal_iterations(num_items, 1)
        self.candidates = np.arange(0, top + 1)
        theta = np.arcsin(np.sqrt(self.fractions))
        # success[k, f] = sin^2((2k+1) theta(f))
        self.success = np.sin(np.outer(2 * self.candidates + 1, theta)) ** 2

    @property
    def log_posterior(self) -> np.ndarray:
        return self.log_prior + self.log_likelihood

    def iterations(self, tree_nodes: int, num_marked: int | None = None) -> int:
        log_posterior = self.log_posterior
        weights = np.exp(log_posterior - log_posterior.max())
        weights /= weights.sum()
        expected = self.success @ weights
        return int(self.candidates[np.argmax(expected / (self.candidates + 1))])

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


POLICIES = {"paper": PaperSchedule, "optimal": KnownOptimal, "bbht": BBHT, "adaptive": Adaptive}


def parse_policy(text: str) -> IterationPolicy:
    """``paper``, ``optimal``, ``bbht``, ``adaptive`` or ``fixed:K``."""
    if text.startswith("fixed:"):
        try:
            return FixedIterations(int(text.split(":", 1)[1]))
        except ValueError as exc:
            raise ValueError(f"schedule fixed:K needs an integer K >= 0, got {text!r}") from exc
    if text not in POLICIES:
        raise ValueError(f"schedule must be one of {sorted(POLICIES)} or fixed:K, got {text!r}")
    return POLICIES[text]()
