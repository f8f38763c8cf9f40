"""Ideal Grover search on an exact numpy statevector.

Starting from the uniform state, k Grover iterations leave every marked index with amplitude
sin((2k+1)theta)/sqrt(m) and every unmarked one with cos((2k+1)theta)/sqrt(N-m), where
sin^2 theta = m/N (Boyer, Brassard, Hoyer, Tapp 1998). Sampling uses this closed form (fast path,
O(N) only to list the marked indices); ``amplitudes`` runs the O(N)-per-iteration statevector
update, which the tests check against the closed form.
"""

from __future__ import annotations

import math
import os

import numpy as np

from ..probability import good_probability
from ..validation import check_bool, check_int
from .backend import QuantumSearchBackend, seed_stream, validate_iterations, validate_marks

BYTES_PER_ENTRY = 32  # amplitudes (8) + probabilities (8) + index lists (8) + marks, with slack


def _memory_bytes() -> int:
    try:
        return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return 8 << 30


class StatevectorBackend(QuantumSearchBackend):
    """Exact (noise-free) Grover search; ``closed_form=False`` samples from the iterated vector."""

    name = "statevector"

    def __init__(
        self,
        seed: int | np.random.Generator | None = None,
        closed_form: bool = True,
        max_qubits: int | None = None,
    ) -> None:
        self._rng = seed_stream(seed)
        self.closed_form = check_bool(closed_form, "closed_form")
        memory_limit = int(math.log2(max(_memory_bytes() // 2 // BYTES_PER_ENTRY, 2)))
        if max_qubits is not None and check_int(max_qubits, "max_qubits", 1) > memory_limit:
            raise ValueError(f"max_qubits must be an integer in [1, {memory_limit}] (the largest n whose "
                             f"state fits in half of this machine's memory), got {max_qubits}")
        self._max_qubits = memory_limit if max_qubits is None else int(max_qubits)

    @property
    def max_qubits(self) -> int:
        return self._max_qubits

    #: per shot: the uniform draws, the good/unmarked split, the ranks and the measured indices
    BYTES_PER_SHOT = 64

    def peak_bytes(self, num_qubits: int, shots: int = 1, iterations: int = 1) -> int:
        """Closed form: the marked indices and their rank table (at most 8 + 16 bytes per entry
        when every entry is marked). ``closed_form=False``: the state, its update temporaries,
        the probabilities and their cumulative sum (5 float64 arrays)."""
        per_entry = 24 if self.closed_form else 40
        return (per_entry << num_qubits) + self.BYTES_PER_SHOT * shots

    @staticmethod
    def amplitudes(marks: np.ndarray, iterations: int) -> np.ndarray:
        """Real amplitudes after ``iterations`` x (oracle, then inversion about the mean)."""
        marks, _ = validate_marks(marks)
        iterations = validate_iterations(iterations)
        state = np.full(marks.shape[0], 1.0 / math.sqrt(marks.shape[0]))
        for _ in range(iterations):
            state[marks] *= -1.0
            state = 2.0 * state.mean() - state
        return state

    def _sample(self, marks, num_qubits, iterations, shots, rng) -> np.ndarray:
        if not self.closed_form:
            probabilities = self.amplitudes(marks, iterations) ** 2
            cumulative = np.cumsum(probabilities)
            draws = rng.random(shots) * cumulative[-1]
            return np.minimum(np.searchsorted(cumulative, draws, side="right"), marks.shape[0] - 1)
        size = marks.shape[0]
        marked = np.flatnonzero(marks)
        num_marked = marked.shape[0]
        p_good = good_probability(size, num_marked, iterations)
        good = rng.random(shots) < p_good
        out = np.empty(shots, dtype=np.int64)
        num_good = int(np.count_nonzero(good))
        if num_good:
            out[good] = marked[rng.integers(0, num_marked, num_good)]
        if num_good < shots:
            unmarked_count = size - num_marked
            # k-th unmarked index without listing them all: rank among the complement
            ranks = rng.integers(0, unmarked_count, shots - num_good)
            out[~good] = _kth_unmarked(marked, ranks)
        return out


def _kth_unmarked(marked_sorted: np.ndarray, ranks: np.ndarray) -> np.ndarray:
    """The ranks[j]-th index (0-based) not in ``marked_sorted``."""
    # index = rank + (number of marked indices <= index); solve by searching marked - arange
    shifted = marked_sorted - np.arange(marked_sorted.shape[0])
    return ranks + np.searchsorted(shifted, ranks, side="right")
