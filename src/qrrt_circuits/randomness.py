"""The planners' random streams: one ``numpy.random.Generator`` per (round, worker, purpose).

A plan's randomness comes only from its ``seed``: ``SeedSequence(seed)`` is spawned at the key
``(round, worker, stream)``, so each draw depends on where it is used, never on the order in which
workers ran or on the executor that ran them. The stream numbers are part of the reproducibility
contract (changing one changes every published result), so they are named here once.

Speed. Building ``SeedSequence(entropy, spawn_key=key)`` and seeding ``PCG64`` from it costs about
60 us in Python, more than a round of RRT's other work. ``RandomStreams`` computes the same four
64-bit seed words with a compiled copy of numpy's ``SeedSequence`` algorithm (``_seed_words``:
entropy pool mixing, then ``generate_state(4, uint64)``, as numpy's ``bit_generator.pyx``), for
many keys in one call, and hands them to ``PCG64`` through a fixed-words seed sequence
(``_SeedWords``). The generators are therefore bit for bit the ones ``np.random.default_rng(
SeedSequence(entropy, spawn_key=key))`` gives (tested against numpy on many keys), at about
3 us each.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum
from functools import cached_property
from typing import TYPE_CHECKING, cast

import numpy as np
from numba import njit
from numpy.random.bit_generator import ISeedSequence

if TYPE_CHECKING:
    from numpy.typing import DTypeLike


class Stream(IntEnum):
    """What a generator is used for (the third element of its spawn key)."""

    #: candidate samples, goal bias and annealing distances of a database (or of one RRT step)
    CANDIDATES = 1
    #: the oracle error model's flips of the marks
    ORACLE_ERRORS = 2
    #: a search policy's own draws (BBHT's random iteration counts and its per-search seeds)
    POLICY = 3
    #: the seed of one backend search shared by a group of workers
    SEARCH = 7


# numpy's SeedSequence constants (numpy/random/bit_generator.pyx); the compiled code keeps every
# 32-bit value in a uint64 and masks after each product, as numpy's uint32 arithmetic wraps
_POOL_SIZE = 4
_INIT_A = 0x43B0D7E5
_MULT_A = 0x931E8875
_INIT_B = 0x8B51F9DD
_MULT_B = 0x58F38DED
_MIX_MULT_L = 0xCA01F9DD
_MIX_MULT_R = 0x4973F715
_MASK = 0xFFFFFFFF


def _uint32_words(value: int) -> list[int]:
    """numpy's ``_coerce_to_uint32_array`` for one non-negative int: little-endian 32-bit words."""
    if value < 0:
        raise ValueError(f"seed entropy must be non-negative, got {value}")
    words = []
    while value > 0:
        words.append(value & _MASK)
        value >>= 32
    return words or [0]


@njit(cache=True, nogil=True)
def _hashmix(value: np.uint64, hash_const: np.ndarray) -> np.uint64:
    """numpy's ``hashmix``; ``hash_const`` is a 1-element uint64 array (its state)."""
    mask = np.uint64(_MASK)
    value = value ^ hash_const[0]
    hash_const[0] = (hash_const[0] * np.uint64(_MULT_A)) & mask
    value = (value * hash_const[0]) & mask
    return value ^ (value >> np.uint64(16))


@njit(cache=True, nogil=True)
def _mix(x: np.uint64, y: np.uint64) -> np.uint64:
    mask = np.uint64(_MASK)
    result = (np.uint64(_MIX_MULT_L) * x - np.uint64(_MIX_MULT_R) * y) & mask
    return result ^ (result >> np.uint64(16))


@njit(cache=True, nogil=True)
def _seed_words(run_entropy: np.ndarray, keys: np.ndarray) -> np.ndarray:
    """For each row of ``keys`` (K, c) non-negative int64: the 4 uint64 words that
    ``SeedSequence(entropy, spawn_key=tuple(row)).generate_state(4, np.uint64)`` returns, where
    ``run_entropy`` (uint64 holding 32-bit words) is the entropy's words padded to the pool size."""
    mask = np.uint64(_MASK)
    count = keys.shape[0]
    out = np.empty((count, 4), dtype=np.uint64)
    entropy = np.empty(run_entropy.shape[0] + 2 * keys.shape[1], dtype=np.uint64)
    entropy[: run_entropy.shape[0]] = run_entropy
    hash_const = np.empty(1, dtype=np.uint64)
    mixer = np.empty(_POOL_SIZE, dtype=np.uint64)
    state = np.empty(8, dtype=np.uint64)
    for row in range(count):
        size = run_entropy.shape[0]
        for column in range(keys.shape[1]):
            value = np.uint64(keys[row, column])
            entropy[size] = value & mask
            size += 1
            high = value >> np.uint64(32)
            if high:
                entropy[size] = high
                size += 1
        # mix_entropy
        hash_const[0] = np.uint64(_INIT_A)
        for i in range(_POOL_SIZE):
            word = entropy[i] if i < size else np.uint64(0)
            mixer[i] = _hashmix(word, hash_const)
        for i_src in range(_POOL_SIZE):
            for i_dst in range(_POOL_SIZE):
                if i_src != i_dst:
                    mixer[i_dst] = _mix(mixer[i_dst], _hashmix(mixer[i_src], hash_const))
        for i_src in range(_POOL_SIZE, size):
            for i_dst in range(_POOL_SIZE):
                mixer[i_dst] = _mix(mixer[i_dst], _hashmix(entropy[i_src], hash_const))
        # generate_state(4, uint64): 8 uint32 words, read as 4 little-endian uint64
        const = np.uint64(_INIT_B)
        for i_dst in range(8):
            value = mixer[i_dst % _POOL_SIZE] ^ const
            const = (const * np.uint64(_MULT_B)) & mask
            value = (value * const) & mask
            state[i_dst] = value ^ (value >> np.uint64(16))
        for word in range(4):
            out[row, word] = state[2 * word] | (state[2 * word + 1] << np.uint64(32))
    return out


class _SeedWords(ISeedSequence):
    """A seed sequence that hands ``PCG64`` four precomputed uint64 words."""

    __slots__ = ("words",)

    def __init__(self, words: np.ndarray) -> None:
        self.words = words

    def generate_state(self, n_words: int, dtype: DTypeLike = np.uint32) -> np.ndarray:
        if n_words != 4 or np.dtype(dtype) != np.uint64:
            raise ValueError("_SeedWords only seeds PCG64 (4 uint64 words)")
        return self.words


@dataclass(frozen=True)
class RandomStreams:
    """The plan's root entropy; hands out one generator per (round, worker, stream).

    ``generator(r, w, s)`` is bit for bit
    ``np.random.default_rng(SeedSequence(entropy, spawn_key=(r, w, s)))``, built faster (module
    docstring).

    Args:
        entropy: The root entropy, a non-negative integer (``from_seed`` derives it from a seed).

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits.randomness import RandomStreams, Stream
        >>> streams = RandomStreams.from_seed(7)
        >>> ours = streams.generator(3, 1, Stream.CANDIDATES)
        >>> numpys = np.random.default_rng(np.random.SeedSequence(7, spawn_key=(3, 1, 1)))
        >>> bool(ours.random() == numpys.random())
        True
    """

    entropy: int

    @classmethod
    def from_seed(cls, seed: int | None) -> RandomStreams:
        """The streams of a plan's ``seed``.

        Args:
            seed: A non-negative integer, or None for fresh entropy (``SeedSequence(None)``).

        Returns:
            ``RandomStreams(SeedSequence(seed).entropy)``.
        """
        entropy = np.random.SeedSequence(seed).entropy  # an int for an int or None seed
        return cls(int(cast(int, entropy)))

    @cached_property
    def _run_entropy(self) -> np.ndarray:
        words = _uint32_words(int(self.entropy))
        words += [0] * max(0, _POOL_SIZE - len(words))  # numpy pads when a spawn key follows
        return np.asarray(words, dtype=np.uint64)

    def seed_words(self, keys: np.ndarray) -> np.ndarray:
        """(K, 4) uint64: the PCG64 seed words of the keys (K, 3) = (round, worker, stream).

        Args:
            keys: Non-negative int array, reshaped to (K, 3).

        Returns:
            Uint64 array (K, 4).

        Raises:
            ValueError: A negative key.
        """
        keys = np.ascontiguousarray(keys, dtype=np.int64).reshape(-1, 3)
        if keys.size and keys.min() < 0:
            raise ValueError("spawn keys must be non-negative")
        return _seed_words(self._run_entropy, keys)

    def generator(self, round_index: int, worker: int, stream: Stream) -> np.random.Generator:
        """The generator of one (round, worker, stream) key.

        Args:
            round_index: The round (>= 0).
            worker: The worker (>= 0).
            stream: The ``Stream`` (what the draws are for).

        Returns:
            A ``numpy.random.Generator`` on ``PCG64``.

        Raises:
            ValueError: A negative key.
        """
        key = (int(round_index), int(worker), int(stream))
        if min(key) < 0:
            raise ValueError(f"spawn keys must be non-negative, got {key}")
        words = _seed_words(self._run_entropy, np.array([key], dtype=np.int64))
        return np.random.Generator(np.random.PCG64(_SeedWords(words[0])))  # type: ignore[arg-type]  # an ISeedSequence

    def generators(self, rounds: np.ndarray, workers: np.ndarray, stream: Stream) -> list[np.random.Generator]:
        """The generators of many (round, worker) pairs of one stream, seeded in one compiled call.

        Args:
            rounds: Int array of rounds (>= 0).
            workers: Int array of workers (>= 0), broadcast against ``rounds``.
            stream: The ``Stream``.

        Returns:
            One generator per pair, in order.

        Raises:
            ValueError: A negative key.
        """
        rounds = np.asarray(rounds, dtype=np.int64).reshape(-1)
        keys = np.empty((rounds.shape[0], 3), dtype=np.int64)
        keys[:, 0] = rounds
        keys[:, 1] = workers
        keys[:, 2] = int(stream)
        return [np.random.Generator(np.random.PCG64(_SeedWords(words)))  # type: ignore[arg-type]
                for words in self.seed_words(keys)]

    def seed(self, round_index: int, worker: int, stream: Stream = Stream.SEARCH) -> int:
        """One integer seed (for a backend call) drawn from that generator: its
        ``integers(0, 2**62)``, which for this range is the first 64-bit output shifted right by
        2 (Lemire's bounded method with a power-of-two range never rejects), computed without
        building the generator (tested against numpy).

        Args:
            round_index: The round (>= 0).
            worker: The worker (>= 0).
            stream: The ``Stream`` (default ``Stream.SEARCH``).

        Returns:
            An integer in [0, 2^62).

        Raises:
            ValueError: A negative key.
        """
        key = (int(round_index), int(worker), int(stream))
        if min(key) < 0:
            raise ValueError(f"spawn keys must be non-negative, got {key}")
        return int(_stream_seed(self._run_entropy, np.array([key], dtype=np.int64)))


# PCG64 (numpy's default bit generator, O'Neill 2014: 128-bit LCG, XSL-RR output) for the first
# few doubles of many generators at once: numpy's pcg64.h, seeded as PCG64(seed_sequence) seeds it
_PCG_MULT_HIGH = 0x2360ED051FC65DA4
_PCG_MULT_LOW = 0x4385DF649FCCF645


@njit(cache=True, nogil=True)
def _mul64(a: np.uint64, b: np.uint64) -> tuple[np.uint64, np.uint64]:
    """The 128-bit product of two uint64 as (high, low)."""
    mask = np.uint64(0xFFFFFFFF)
    shift = np.uint64(32)
    a_lo, a_hi = a & mask, a >> shift
    b_lo, b_hi = b & mask, b >> shift
    lo_lo = a_lo * b_lo
    hi_lo = a_hi * b_lo
    lo_hi = a_lo * b_hi
    hi_hi = a_hi * b_hi
    cross = (lo_lo >> shift) + (hi_lo & mask) + lo_hi
    return hi_hi + (hi_lo >> shift) + (cross >> shift), (cross << shift) | (lo_lo & mask)


@njit(cache=True, nogil=True)
def _pcg_step(state_hi: np.uint64, state_lo: np.uint64, inc_hi: np.uint64,
              inc_lo: np.uint64) -> tuple[np.uint64, np.uint64]:
    """state * MULT + inc (mod 2^128)."""
    mult_hi, mult_lo = np.uint64(_PCG_MULT_HIGH), np.uint64(_PCG_MULT_LOW)
    high, low = _mul64(state_lo, mult_lo)
    high = high + state_hi * mult_lo + state_lo * mult_hi
    new_lo = low + inc_lo
    carry = np.uint64(1) if new_lo < low else np.uint64(0)
    return high + inc_hi + carry, new_lo


# The state of one generator is a uint64 array [state_hi, state_lo, inc_hi, inc_lo, has_uint32,
# uinteger] that mirrors numpy's pcg64_state (``pcg64.h``: the buffered upper half of a 64-bit
# output serves the next 32-bit draw).
@njit(cache=True, nogil=True)
def _pcg_state(words: np.ndarray) -> np.ndarray:
    """numpy's ``pcg64_set_seed`` from the four seed words: the generator state array."""
    one = np.uint64(1)
    state = np.zeros(6, dtype=np.uint64)
    inc_hi = (words[2] << one) | (words[3] >> np.uint64(63))
    inc_lo = (words[3] << one) | one
    state_hi, state_lo = _pcg_step(np.uint64(0), np.uint64(0), inc_hi, inc_lo)
    state_lo_sum = state_lo + words[1]
    carry = one if state_lo_sum < state_lo else np.uint64(0)
    state_hi, state_lo = _pcg_step(state_hi + words[0] + carry, state_lo_sum, inc_hi, inc_lo)
    state[0], state[1], state[2], state[3] = state_hi, state_lo, inc_hi, inc_lo
    return state


@njit(cache=True, nogil=True)
def _next64(state: np.ndarray) -> np.uint64:
    """``pcg64_next64``: advance, then the XSL-RR output of the new state."""
    state_hi, state_lo = _pcg_step(state[0], state[1], state[2], state[3])
    state[0], state[1] = state_hi, state_lo
    rotation = state_hi >> np.uint64(58)
    value = state_hi ^ state_lo
    return (value >> rotation) | (value << ((np.uint64(64) - rotation) & np.uint64(63)))


@njit(cache=True, nogil=True)
def _stream_seed(run_entropy: np.ndarray, key: np.ndarray) -> np.uint64:
    """``RandomStreams.seed`` of one (1, 3) key: the first 64-bit output of its generator >> 2."""
    return _next64(_pcg_state(_seed_words(run_entropy, key)[0])) >> np.uint64(2)


@njit(cache=True, nogil=True)
def _small_seed_words(seed: np.uint64) -> np.ndarray:
    """``integer_seed_words`` of a seed below 2^64: its two 32-bit words (the high one 0 or not,
    as numpy's zero padding to the pool of four makes them the same), mixed with no spawn key."""
    entropy = np.zeros(_POOL_SIZE, dtype=np.uint64)
    entropy[0] = seed & np.uint64(_MASK)
    entropy[1] = seed >> np.uint64(32)
    return _seed_words(entropy, np.empty((1, 0), dtype=np.int64))[0]


@njit(cache=True, nogil=True)
def _next_double(state: np.ndarray) -> float:
    """``Generator.random()``: the top 53 bits of one 64-bit output."""
    return np.float64(_next64(state) >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@njit(cache=True, nogil=True)
def _uniform_draws(words: np.ndarray, count: int) -> np.ndarray:
    """(K, count): the first ``count`` values of ``Generator(PCG64(seed words)).random()``."""
    out = np.empty((words.shape[0], count))
    for row in range(words.shape[0]):
        state = _pcg_state(words[row])
        for column in range(count):
            out[row, column] = _next_double(state)
    return out


def uniform_draws(streams: RandomStreams, keys: np.ndarray, count: int) -> np.ndarray:
    """(K, count): the first ``count`` doubles ``generator(*key).random()`` would return, for each
    key (round, worker, stream) of ``keys`` (K, 3), computed without building the generators.

    Args:
        streams: The plan's ``RandomStreams``.
        keys: Non-negative int array (K, 3).
        count: Doubles per key.

    Returns:
        Float array (K, count) in [0, 1).

    Raises:
        ValueError: A negative key.
    """
    return _uniform_draws(streams.seed_words(keys), int(count))


# ``np.random.default_rng(seed)`` for one integer seed, compiled: the backends' per-search
# generators. A search needs only a handful of draws, yet building the Generator costs more than
# the draws (``bench_search.py``: "statevector-seeded" against "statevector"); the functions below
# give the same numbers from the seed's words directly.
_NO_KEYS = np.empty((1, 0), dtype=np.int64)


def integer_seed_words(seed: int) -> np.ndarray:
    """(4,) uint64: the words ``SeedSequence(seed).generate_state(4, np.uint64)`` returns, i.e.
    the seed of ``np.random.default_rng(seed)``'s PCG64, for any non-negative int (an entropy of at
    most four 32-bit words is mixed exactly as when it is zero-padded to the pool size)."""
    seed = int(seed)
    if 0 <= seed < 1 << 64:
        return _small_seed_words(np.uint64(seed))
    words = _uint32_words(seed)
    words += [0] * max(0, _POOL_SIZE - len(words))  # longer entropy is mixed in after the pool
    return _seed_words(np.asarray(words, dtype=np.uint64), _NO_KEYS)[0]


@njit(cache=True, nogil=True)
def _next32(state: np.ndarray) -> np.uint64:
    """``pcg64_next32``: the buffered upper half of the last output, else the lower half of a new one."""
    if state[4]:
        state[4] = np.uint64(0)
        return state[5]
    value = _next64(state)
    state[4] = np.uint64(1)
    state[5] = value >> np.uint64(32)
    return value & np.uint64(0xFFFFFFFF)


@njit(cache=True, nogil=True)
def _bounded_below(state: np.ndarray, high: int) -> np.int64:
    """One ``Generator.integers(0, high)`` draw for 1 <= high <= 2**32 (numpy's
    ``random_bounded_uint64_fill``: nothing drawn for high = 1, Lemire's method on 32-bit draws)."""
    span = np.uint64(high - 1)  # numpy's inclusive range ``rng``
    if span == 0:
        return np.int64(0)
    mask = np.uint64(0xFFFFFFFF)
    if span == mask:
        return np.int64(_next32(state))
    span_excl = span + np.uint64(1)
    product = _next32(state) * span_excl
    leftover = product & mask
    if leftover < span_excl:
        threshold = (mask - span) % span_excl
        while leftover < threshold:
            product = _next32(state) * span_excl
            leftover = product & mask
    return np.int64(product >> np.uint64(32))


def first_integer_below(seed: int, high: int) -> int:
    """``int(np.random.default_rng(seed).integers(0, high))`` for 1 <= high <= 2**32, compiled."""
    if not 1 <= high <= 1 << 32:
        raise ValueError(f"high must be in [1, 2**32], got {high}")
    return int(_bounded_below(_pcg_state(integer_seed_words(seed)), high))
