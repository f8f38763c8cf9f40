"""``BBHT()``: Boyer-Brassard-Hoyer-Tapp search for unknown m (Boyer, Brassard, Hoyer and Tapp,
"Tight bounds on quantum searching", Fortschr. Phys. 46, 493 (1998), Thm. 3).

Per worker: draw j uniformly in [0, M), run j iterations, measure, verify; on failure
M <- min(lambda M, sqrt(N)). Stops at the first verified success or when the iterations spent
reach ``cap_factor * sqrt(N)`` (so m = 0 terminates). Expected cost O(sqrt(N/m)).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..._support.validation import check_float
from ..problem import DatabaseSearch, SearchOutcome
from .base import IterationPolicy, PolicyState

__all__ = ["BBHT", "BBHTOutcome", "BBHTState"]


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

    def miss_reason(self) -> str:
        return ("BBHT draws a random k below a bound that each miss raises, so misses are part of its schedule "
                "(Boyer et al., Thm. 3)")

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
