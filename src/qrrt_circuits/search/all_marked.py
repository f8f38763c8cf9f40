"""Finding all M marked entries of a database by repeated BBHT searches, each found entry
unmarked before the next search (Boyer, Brassard, Høyer and Tapp 1998, Thm. 3, applied M + 1
times).

The i-th search runs with M - i + 1 marked entries left, at an expected cost of order
sqrt(N / (M - i + 1)) oracle calls, so finding all of them costs of order
sum_{j=1}^{M} sqrt(N / j) <= 2 sqrt(N M) calls, and one more search that gives up at BBHT's cap
(``cap_factor`` sqrt(N) iterations) certifies, with bounded error, that none is left: about
2 c sqrt(N M) + cap sqrt(N) in all, against N classical checks. Each Grover iteration is one
quantum oracle call; each classical check of a measured index one verification call (DESIGN §2).
The phase oracle of each search is a ``LookupOracle`` (the classical lookup of the marks, a
simulation shortcut the callers label).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .backends.base import QuantumSearchBackend
from .oracles import LookupOracle
from .policies.bbht import BBHT

__all__ = ["AllMarkedOutcome", "all_marked_bound", "find_all_marked"]


def all_marked_bound(num_items: int, num_marked: int, search: BBHT) -> float:
    """An upper bound on the expected quantum calls of ``find_all_marked``: BBHT's expected-cost
    bound (9/2) sqrt(N / t) (their Thm. 3, for t <= 3N/4) summed over t = M, ..., 1, plus the cap of
    the last search, which finds none.

    Args:
        num_items: N.
        num_marked: M.
        search: The ``BBHT`` configuration (its cap).

    Returns:
        sum_{t=1}^{M} 4.5 sqrt(N / t) + cap(N).
    """
    return math.fsum(4.5 * math.sqrt(num_items / t) for t in range(1, num_marked + 1)) + search.cap(num_items)


@dataclass(frozen=True)
class AllMarkedOutcome:
    """What ``find_all_marked`` found: the marked ``indices`` in the order found, the quantum
    oracle calls and the verifications spent."""

    indices: tuple[int, ...]
    quantum_calls: int
    verifications: int

    @property
    def oracle_calls(self) -> int:
        """quantum calls + verifications."""
        return self.quantum_calls + self.verifications


def find_all_marked(marks: np.ndarray, backend: QuantumSearchBackend, rng: np.random.Generator,
                    search: BBHT | None = None) -> AllMarkedOutcome:
    """All marked entries of a database, by BBHT searches until one gives up (module docstring).

    Args:
        marks: Bool (N,), N = 2^n >= 2: the phase oracle's marks (each verified classically when
            measured).
        backend: The backend that runs each search (``QuantumSearchBackend.run``).
        rng: The generator of BBHT's iteration counts and the backend seeds.
        search: The ``BBHT`` configuration (default ``BBHT()``).

    Returns:
        The ``AllMarkedOutcome``; a marked entry a search gave up on before finding is missing.

    Raises:
        ValueError: N not a power of two >= 2.
    """
    remaining = np.array(marks, dtype=bool)
    size = remaining.shape[0]
    if remaining.ndim != 1 or size < 2 or size & (size - 1):
        raise ValueError(f"marks must be a 1-D array of N = 2^n >= 2 entries, got shape {remaining.shape}")
    search = BBHT() if search is None else search
    found: list[int] = []
    quantum = verifications = 0
    while True:
        left = remaining.copy()
        oracle = LookupOracle(left)

        def run(j: int, oracle: LookupOracle = oracle) -> int:
            return int(backend.run(oracle, j, 1, seed=int(rng.integers(2**62))).indices[0])

        def verify(i: int, left: np.ndarray = left) -> bool:
            return bool(left[i])

        outcome = search.run(run, verify, size, rng)
        quantum += outcome.iterations
        verifications += outcome.verifications
        if outcome.index is None:
            return AllMarkedOutcome(tuple(found), quantum, verifications)
        found.append(outcome.index)
        remaining[outcome.index] = False
