"""Ideal Grover search on an exact numpy statevector.

Starting from the uniform state, k Grover iterations leave every marked index with amplitude
sin((2k+1)theta)/sqrt(m) and every unmarked one with cos((2k+1)theta)/sqrt(N-m), where
sin^2 theta = m/N (Boyer, Brassard, Hoyer, Tapp 1998). Sampling uses this closed form (fast path,
O(N) only to list the marked indices); ``amplitudes`` runs the O(N)-per-iteration statevector
update, which the tests check against the closed form. Both need the oracle's marks: the backend
searches a ``LookupOracle`` and refuses a ``CircuitOracle`` (its circuit must be simulated gate by
gate, by Aer or a sampler).
"""

from __future__ import annotations

import math
import os
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from ..._support.validation import check_bool, check_int
from ...probability import good_probability
from ..iterate_sequence import statevector_after
from ..requests import seed_stream, validate_iterations, validate_marks
from .base import QuantumSearchBackend

if TYPE_CHECKING:
    from ..iterate_sequence import IterateSequence
    from ..oracles import SearchOracle

BYTES_PER_ENTRY = 32  # amplitudes (8) + probabilities (8) + index lists (8) + marks, with slack


def _memory_bytes() -> int:
    try:
        return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return 8 << 30


class StatevectorBackend(QuantumSearchBackend):
    """Exact (noise-free) Grover search: the ideal machine of the paper (Algorithm 2, lines 4-8).

    After k iterations every marked index has amplitude sin((2k+1) theta)/sqrt(m) and every
    unmarked one cos((2k+1) theta)/sqrt(N - m), sin^2 theta = m/N (paper Eq. 1, Lemma 1). The
    default samples from this closed form; ``closed_form=False`` iterates the full statevector
    (O(N) per iteration) and samples from it. Oracle calls: ``iterations * shots`` (DESIGN §2).

    Args:
        seed: The backend's own stream for ``search`` calls without a seed: a non-negative
            integer, a ``numpy.random.Generator`` (used as is) or None (fresh entropy).
        closed_form: True (default) to sample from the two-level closed form, False to sample
            from the iterated vector.
        max_qubits: The largest n accepted, 1 .. the largest n whose state fits in half of this
            machine's memory (the default).

    Attributes:
        closed_form: Whether the closed form is sampled.

    Raises:
        TypeError: ``closed_form`` is not a bool, or ``max_qubits`` / ``seed`` not an integer.
        ValueError: ``max_qubits`` < 1 or above the memory limit, or a negative ``seed``.
    """

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
        """The largest n accepted (the constructor's ``max_qubits``, or the memory limit)."""
        return self._max_qubits

    #: per shot: the uniform draws, the good/unmarked split, the ranks and the measured indices
    BYTES_PER_SHOT = 64
    #: generalized iterates on the iterated vector: the complex128 state, its update temporaries
    #: and the probabilities with their cumulative sum
    SEQUENCE_BYTES_PER_ENTRY = 80

    def peak_bytes(self, num_qubits: int, shots: int = 1, iterations: int = 1, marked: int | None = None, *,
                   sequence: bool = False) -> int:
        """Upper bound of one search's peak memory (``QuantumSearchBackend.peak_bytes``).

        Closed form: the marked indices and their rank table (at most 8 + 16 bytes per entry
        when every entry is marked). ``closed_form=False``: the state, its update temporaries,
        the probabilities and their cumulative sum (5 float64 arrays); for generalized iterates the
        state is complex (``SEQUENCE_BYTES_PER_ENTRY``).

        Args:
            num_qubits: n, the index register's width.
            shots: Measurements of the search.
            iterations: k (unused: the footprint does not grow with k).
            marked: m (unused: the bound holds for every m).
            sequence: Whether the search runs generalized iterates.

        Returns:
            ``FIXED_BYTES + (24, 40 or SEQUENCE_BYTES_PER_ENTRY) * 2^n + BYTES_PER_SHOT * shots`` bytes.
        """
        if self.closed_form:
            per_entry = 24
        else:
            per_entry = self.SEQUENCE_BYTES_PER_ENTRY if sequence else 40
        return self.FIXED_BYTES + (per_entry << num_qubits) + self.BYTES_PER_SHOT * shots

    @staticmethod
    def amplitudes(marks: np.ndarray, iterations: int) -> np.ndarray:
        """Real amplitudes after ``iterations`` x (oracle, then inversion about the mean).

        Starts from the uniform state 1/sqrt(N) and applies k times the phase flip of the marked
        entries followed by the diffusion a -> 2 mean(a) - a (the Grover iteration Q of Alg. 2).

        Args:
            marks: Boolean (or 0/1) array of length N = 2^n, n >= 1.
            iterations: k, 0 .. ``MAX_ITERATIONS``.

        Returns:
            Float array (N,): the amplitudes; their squares are the measurement probabilities.

        Raises:
            ValueError: ``marks`` not of length 2^n or not boolean, or k out of range.
            TypeError: A non-integer k.
        """
        marks, _ = validate_marks(marks)
        iterations = validate_iterations(iterations)
        state = np.full(marks.shape[0], 1.0 / math.sqrt(marks.shape[0]))
        for _ in range(iterations):
            state[marks] *= -1.0
            state = 2.0 * state.mean() - state
        return state

    def _sample(self, oracle: SearchOracle, num_qubits: int, iterations: int, shots: int,
                rng: np.random.Generator) -> np.ndarray:
        """The lookup oracle's marks, sampled in closed form or from the iterated vector (a circuit
        oracle is refused: ``SearchOracle.lookup_marks``)."""
        marks = oracle.lookup_marks(f"the {self.name} backend")
        if not self.closed_form:
            return _draw(self.amplitudes(marks, iterations) ** 2, shots, rng)
        p_good = good_probability(marks.shape[0], int(np.count_nonzero(marks)), iterations)
        return _draw_two_level(marks, p_good, shots, rng)

    def _sample_sequence(self, oracle: SearchOracle, num_qubits: int, sequence: IterateSequence, shots: int,
                         rng: np.random.Generator) -> np.ndarray:
        """Generalized iterates: the exact 2-dimensional evolution (closed form; every marked index
        keeps the same amplitude) or, with ``closed_form=False``, the full iterated vector."""
        marks = oracle.lookup_marks(f"the {self.name} backend")
        if not self.closed_form:
            return _draw(np.abs(statevector_after(marks, sequence)) ** 2, shots, rng)
        num_marked = int(np.count_nonzero(marks))
        p_good = sequence.good_probability(num_marked / marks.shape[0]) if num_marked else 0.0
        return _draw_two_level(marks, min(max(p_good, 0.0), 1.0), shots, rng)


def _draw(probabilities: np.ndarray, shots: int, rng: np.random.Generator) -> np.ndarray:
    cumulative = np.cumsum(probabilities)
    draws = rng.random(shots) * cumulative[-1]
    return np.minimum(np.searchsorted(cumulative, draws, side="right"), probabilities.shape[0] - 1)


#: no ranks to draw (a class no shot landed in)
_NO_RANKS = np.empty(0, dtype=np.int64)


def _draw_two_level(marks: np.ndarray, p_good: float, shots: int, rng: np.random.Generator) -> np.ndarray:
    """``shots`` indices: marked (uniformly among the marked) with probability ``p_good``, else
    uniformly among the unmarked (Grover-type states are uniform within each class). The draws:
    ``shots`` doubles (u < p_good: marked), then the marked shots' ranks among the marked, then
    the others' ranks among the unmarked; ``_ranked_indices`` turns the ranks into indices."""
    size = marks.shape[0]
    num_marked = int(np.count_nonzero(marks))
    if num_marked in (0, size):  # nothing to amplify: the class probabilities are exact
        p_good = float(num_marked == size)
    good = rng.random(shots) < p_good
    num_good = int(np.count_nonzero(good))
    good_ranks = rng.integers(0, num_marked, num_good) if num_good else _NO_RANKS
    other_ranks = rng.integers(0, size - num_marked, shots - num_good) if num_good < shots else _NO_RANKS
    return _ranked_indices(marks, good, good_ranks, other_ranks)


@njit(cache=True, nogil=True)
def _ranked_indices(marks: np.ndarray, good: np.ndarray, good_ranks: np.ndarray,
                    other_ranks: np.ndarray) -> np.ndarray:
    """Per shot, the index of its rank: the ``good_ranks``-th marked index for the shots where
    ``good`` holds, the ``other_ranks``-th unmarked one for the rest, each in shot order."""
    marked = np.flatnonzero(marks)
    out = np.empty(good.shape[0], dtype=np.int64)
    taken_good = taken_other = 0
    for shot in range(good.shape[0]):
        if good[shot]:
            out[shot] = marked[good_ranks[taken_good]]
            taken_good += 1
        else:
            out[shot] = _kth_unmarked_one(marked, other_ranks[taken_other])
            taken_other += 1
    return out


@njit(cache=True, nogil=True)
def _kth_unmarked_one(marked_sorted: np.ndarray, rank: int) -> int:
    """The rank-th index (0-based) not in ``marked_sorted``: rank + the number j of marked
    indices below it, the count of ``marked_sorted[i] - i <= rank`` (a binary search)."""
    low, high = 0, marked_sorted.shape[0]
    while low < high:
        middle = (low + high) // 2
        if marked_sorted[middle] - middle <= rank:
            low = middle + 1
        else:
            high = middle
    return rank + low
