"""The policies that fix k by a rule before measuring: the paper's schedule, a fixed k, Eq. 1's k.

- ``PaperIterations()``: 5 iterations, 3 once the tree has more than 10 nodes (the authors' code).
- ``FixedIterations(k)``: always k (Alg. 4 / QDA uses k = 2).
- ``KnownOptimal()``: floor(pi / (4 theta)), sin^2 theta = m/N (Eq. 1), with the database's true
  marked count m. This is simulation knowledge a quantum device does not have: outputs say so.

Each shares ``PolicyState``'s default ``run`` (``base``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ..._support.validation import check_int
from ...probability import optimal_iterations
from ..problem import DatabaseSearch
from ..requests import MAX_ITERATIONS
from .base import IterationPolicy

__all__ = ["FixedIterations", "KnownOptimal", "PaperIterations"]


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

    def miss_reason(self) -> str:
        return ("the paper's fixed counts suit a small reachable share m/N and over-rotate past the peak of "
                "sin^2((2k+1) theta) once the share grows; --policy thompson or adaptive learn k from verified "
                "outcomes")

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

    def miss_reason(self) -> str:
        return ("a fixed k suits one reachable share m/N and over-rotates past the peak of sin^2((2k+1) theta) "
                "above it; --policy thompson or adaptive learn k from verified outcomes")

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

    def miss_reason(self) -> str:
        return ("even the optimal k for the true m misses with probability cos^2((2k+1) theta), and a database "
                "with no reachable entry always misses")

    def describe(self) -> str:
        return "optimal (uses the true m of each database: simulation knowledge)"

    def labels(self) -> tuple[str, ...]:
        return ("simulation knowledge: iterations use the true marked count m of each database "
                "(KnownOptimal)",)
