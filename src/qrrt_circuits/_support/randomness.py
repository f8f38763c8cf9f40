"""The planners' random streams: one ``numpy.random.Generator`` per (round, worker, purpose).

A plan's randomness comes only from its ``seed``: ``SeedSequence(seed)`` is spawned at the key
``(round, worker, stream)``, so each draw depends on where it is used, never on the order in which
workers ran or on the executor that ran them. The stream numbers are part of the reproducibility
contract (changing one changes every published result), so they are named here once.

Speed. Building ``SeedSequence(entropy, spawn_key=key)`` and seeding ``PCG64`` from it in Python
costs more than the rest of an RRT round. ``RandomStreams`` computes the same four 64-bit seed
words with a compiled copy of numpy's ``SeedSequence`` algorithm (``_seed_words``: entropy pool
mixing, then ``generate_state(4, uint64)``, as numpy's ``bit_generator.pyx``), for many keys in
one call, and hands them to ``PCG64`` through a fixed-words seed sequence (``_SeedWords``). The
generators are therefore bit for bit the ones ``np.random.default_rng(SeedSequence(entropy,
spawn_key=key))`` gives (tested against numpy on many keys).
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
    for i in range(run_entropy.shape[0]):  # (an element loop: a slice assignment compiles numba's shape-error text)
        entropy[i] = run_entropy[i]
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
        >>> from qrrt_circuits._support.randomness import RandomStreams, Stream
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
        """One integer seed (for a backend call): ``generator(round_index, worker, stream)``'s
        first ``integers(0, 2**62)``.

        Args:
            round_index: The round (>= 0).
            worker: The worker (>= 0).
            stream: The ``Stream`` (default ``Stream.SEARCH``).

        Returns:
            An integer in [0, 2^62).

        Raises:
            ValueError: A negative key.
        """
        return int(self.generator(round_index, worker, stream).integers(0, 2**62))


def uniform_draws(streams: RandomStreams, keys: np.ndarray, count: int) -> np.ndarray:
    """(K, count): the first ``count`` doubles ``generator(*key).random()`` returns, for each key
    (round, worker, stream) of ``keys`` (K, 3).

    Args:
        streams: The plan's ``RandomStreams``.
        keys: Non-negative int array (K, 3).
        count: Doubles per key.

    Returns:
        Float array (K, count) in [0, 1).

    Raises:
        ValueError: A negative key.
    """
    count = int(count)
    words = streams.seed_words(keys)
    if not words.shape[0]:
        return np.empty((0, count))
    return np.array([np.random.Generator(np.random.PCG64(_SeedWords(row))).random(count)  # type: ignore[arg-type]
                     for row in words])
