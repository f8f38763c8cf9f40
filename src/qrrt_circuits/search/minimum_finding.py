"""Dürr-Høyer quantum minimum finding (Dürr and Høyer, "A quantum algorithm for finding the
minimum", arXiv:quant-ph/9607014, 1996), on any backend's ``search(oracle, ...)``.

Over a table of N = 2^n values v (entries that are not ``feasible`` never qualify), keep a
threshold index y and repeat: search, with BBHT for an unknown number of marked entries (Boyer,
Brassard, Høyer and Tapp 1998, Thm. 3; ``policies.bbht``), for an index i with ``feasible[i]`` and
v[i] < v[y]; if one verifies, y <- i. Each search's phase oracle marks "feasible and below the
threshold": one Grover iteration is one oracle call, one classical check of a measured index
(feasible and below) one verification call (DESIGN §2, §9). The loop stops when a search gives up
(BBHT's cap, ``cap_factor`` sqrt(N) iterations) or when the quantum calls reach the published
budget 22.5 sqrt(N) + 1.4 log2(N)^2, within which Dürr and Høyer prove the minimum is held with
probability at least 1/2 (their Thm. 1; the expected calls until y holds the minimum are at most
45/4 sqrt(N) + 7/10 log2(N)^2, their Lemma 2).

The phase oracle of each search is a ``LookupOracle`` of the marks: a classical lookup of the
table behind it (a simulation shortcut the callers label).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._support.validation import check_float
from .backends.base import QuantumSearchBackend
from .oracles import LookupOracle
from .policies.bbht import BBHT

__all__ = ["DurrHoyer", "MinimumOutcome", "durr_hoyer_budget", "durr_hoyer_expected_bound"]


def durr_hoyer_budget(num_items: int) -> float:
    """22.5 sqrt(N) + 1.4 log2(N)^2: Dürr and Høyer's run length, after which the threshold holds
    the minimum with probability >= 1/2 (their Thm. 1)."""
    return 22.5 * math.sqrt(num_items) + 1.4 * math.log2(num_items) ** 2


def durr_hoyer_expected_bound(num_items: int) -> float:
    """45/4 sqrt(N) + 7/10 log2(N)^2: Dürr and Høyer's bound on the expected oracle calls until the
    threshold holds the minimum (their Lemma 2)."""
    return 11.25 * math.sqrt(num_items) + 0.7 * math.log2(num_items) ** 2


@dataclass(frozen=True)
class MinimumOutcome:
    """One minimum finding.

    Args:
        index: The threshold index at the end (the entry believed minimal), or None if no feasible
            entry was found.
        quantum_calls: Grover iterations of all searches (quantum oracle calls).
        verifications: Classical checks of measured indices (and of a drawn start index).
        calls_to_final: Oracle calls (quantum + verifications) spent when ``index`` was found.
        improvements: Searches that lowered the threshold.
    """

    index: int | None
    quantum_calls: int
    verifications: int
    calls_to_final: int
    improvements: int

    @property
    def oracle_calls(self) -> int:
        """quantum calls + verifications."""
        return self.quantum_calls + self.verifications


@dataclass(frozen=True)
class DurrHoyer:
    """Dürr-Høyer minimum finding with BBHT searches (module docstring).

    Args:
        search: The ``BBHT`` configuration of each threshold search (default ``BBHT()``).
        budget_factor: The quantum-call budget as a multiple of Dürr and Høyer's run length
            ``durr_hoyer_budget(N)``, in (0, 100] (default 1).
        below_threshold_only: False (default): every search runs over all N entries, as Dürr and
            Høyer's algorithm does. True: where the values are classical data (q-RRT*'s costs), each
            search runs over the entries whose value is below the threshold only (their lookup, not
            an oracle call), padded with unmarked entries to a power of two, and none runs when no
            entry is below it; the oracle's question is then the feasibility alone.

    Raises:
        TypeError: ``search`` not a ``BBHT``, or a non-real ``budget_factor``.
        ValueError: ``budget_factor`` outside (0, 100].
    """

    search: BBHT = field(default_factory=BBHT)
    budget_factor: float = 1.0
    below_threshold_only: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.search, BBHT):
            raise TypeError(f"search must be a BBHT, got {self.search!r}")
        check_float(self.budget_factor, "budget_factor", 0.0, 100.0, open_minimum=True)

    def run(self, values: np.ndarray, feasible: np.ndarray, backend: QuantumSearchBackend,
            rng: np.random.Generator, start: int | None = None) -> MinimumOutcome:
        """Find the feasible entry of least value.

        Args:
            values: Float (N,), N = 2^n >= 2, the table.
            feasible: Bool (N,), the entries that may qualify.
            backend: The backend that runs each search (``QuantumSearchBackend.run``).
            rng: The generator of the start index, BBHT's iteration counts and the backend seeds.
            start: A known feasible index to start the threshold at (no verification), or None
                (default) to draw one uniformly and verify it (1 verification call; an infeasible
                draw starts the threshold at +inf).

        Returns:
            The ``MinimumOutcome``.

        Raises:
            ValueError: N not a power of two >= 2, shapes that differ, or a ``start`` outside [0, N).
        """
        values = np.asarray(values, dtype=float)
        feasible = np.asarray(feasible, dtype=bool)
        size = values.shape[0]
        if values.ndim != 1 or size < 2 or size & (size - 1):
            raise ValueError(f"values must be a 1-D table of N = 2^n >= 2 entries, got shape {values.shape}")
        if feasible.shape != values.shape:
            raise ValueError(f"feasible must have the shape of values {values.shape}, got {feasible.shape}")
        verifications = 0
        if start is None:
            drawn = int(rng.integers(size))
            verifications += 1
            index: int | None = drawn if feasible[drawn] else None
        else:
            if not 0 <= int(start) < size:
                raise ValueError(f"start must be an index in [0, {size}), got {start}")
            index = int(start)
        threshold = math.inf if index is None else float(values[index])
        quantum = improvements = 0
        calls_to_final = verifications
        budget = self.budget_factor * durr_hoyer_budget(size)
        while quantum < budget:
            marks = feasible & (values < threshold)
            rows = np.arange(size)
            if self.below_threshold_only:
                rows = np.flatnonzero(values < threshold)
                if rows.shape[0] == 0:
                    break
                padded = np.zeros(1 << max(1, int(rows.shape[0] - 1).bit_length()), dtype=bool)
                padded[:rows.shape[0]] = marks[rows]
                marks = padded
            oracle = LookupOracle(marks)

            def search(j: int, oracle: LookupOracle = oracle) -> int:
                return int(backend.run(oracle, j, 1, seed=int(rng.integers(2**62))).indices[0])

            def verify(i: int, marks: np.ndarray = marks) -> bool:
                return bool(marks[i])

            found = self.search.run(search, verify, marks.shape[0], rng)
            quantum += found.iterations
            verifications += found.verifications
            if found.index is None:
                break
            index = int(rows[found.index])
            threshold = float(values[index])
            improvements += 1
            calls_to_final = quantum + verifications
        return MinimumOutcome(index, quantum, verifications, calls_to_final, improvements)

    def describe(self) -> dict:
        """JSON-able settings."""
        return {"kind": "durr-hoyer", "search": self.search.describe(), "budget_factor": self.budget_factor,
                "below_threshold_only": self.below_threshold_only}
