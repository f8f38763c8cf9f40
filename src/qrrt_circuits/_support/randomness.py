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
spawn_key=key))`` gives (tested against numpy on many keys). ``seeded_generator(seed)`` does the
same for a plain integer seed (no spawn key): ``np.random.default_rng(seed)``, bit for bit, as the
backends build one per search from its seed.

Where only a key's first few doubles are wanted (``uniform_draws``: one classical extension per
key), building a ``Generator`` per key is again the larger cost. ``_pcg64_doubles`` runs numpy's
``PCG64`` itself, compiled: the 128-bit state s and increment c from the four seed words (w0 w1 and
w2 w3, high word first; c = 2 (w2 w3) + 1, s = 0, one step, s += w0 w1, one step, as numpy's
``pcg64_set_seed``), each draw a step s = s a + c mod 2^128 (a = numpy's 128-bit multiplier) and
the output XSL-RR: the 64-bit xor of the halves of s rotated right by the top 6 bits of s; a
double is (output >> 11) 2^-53, numpy's ``next_double``. Tested equal to ``Generator.random``.
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
    ``run_entropy`` (uint64 holding 32-bit words) is the entropy's words padded to the pool size.
    A negative key raises ``ValueError``."""
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
            if keys[row, column] < 0:
                raise ValueError("spawn keys must be non-negative")
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


#: numpy's PCG64 multiplier (``PCG_DEFAULT_MULTIPLIER_128``), high and low 64-bit words
_PCG_MULTIPLIER_HIGH = 2549297995355413924
_PCG_MULTIPLIER_LOW = 4865540595714422341
#: 2^-53: the double of an output's top 53 bits (numpy's ``next_double``)
_DOUBLE_UNIT = 1.0 / 9007199254740992.0


@njit(cache=True, nogil=True, inline="always")
def _multiply_64(a: np.uint64, b: np.uint64) -> tuple[np.uint64, np.uint64]:
    """The 128-bit product of two 64-bit words: (high, low)."""
    mask = np.uint64(_MASK)
    thirty_two = np.uint64(32)
    a_low, a_high = a & mask, a >> thirty_two
    b_low, b_high = b & mask, b >> thirty_two
    low_low = a_low * b_low
    low_high = a_low * b_high
    high_low = a_high * b_low
    middle = (low_low >> thirty_two) + (low_high & mask) + (high_low & mask)
    low = (low_low & mask) | (middle << thirty_two)
    high = a_high * b_high + (low_high >> thirty_two) + (high_low >> thirty_two) + (middle >> thirty_two)
    return high, low


@njit(cache=True, nogil=True, inline="always")
def _pcg_step(high: np.uint64, low: np.uint64, inc_high: np.uint64,
              inc_low: np.uint64) -> tuple[np.uint64, np.uint64]:
    """One PCG64 step of the 128-bit state (high, low): state * multiplier + increment mod 2^128."""
    multiplier_high, multiplier_low = np.uint64(_PCG_MULTIPLIER_HIGH), np.uint64(_PCG_MULTIPLIER_LOW)
    product_high, product_low = _multiply_64(low, multiplier_low)
    product_high += high * multiplier_low + low * multiplier_high
    new_low = product_low + inc_low
    carry = np.uint64(1) if new_low < product_low else np.uint64(0)
    return product_high + inc_high + carry, new_low


@njit(cache=True, nogil=True)
def _pcg64_doubles(words: np.ndarray, count: int) -> np.ndarray:
    """For each row of ``words`` (K, 4) uint64 seed words: the first ``count`` doubles of
    ``Generator(PCG64)`` seeded with them (module docstring), (K, count)."""
    out = np.empty((words.shape[0], count))
    one, sixty_three = np.uint64(1), np.uint64(63)
    for row in range(words.shape[0]):
        inc_high = (words[row, 2] << one) | (words[row, 3] >> sixty_three)
        inc_low = (words[row, 3] << one) | one
        high, low = _pcg_step(np.uint64(0), np.uint64(0), inc_high, inc_low)
        low_sum = low + words[row, 1]
        carry = np.uint64(1) if low_sum < low else np.uint64(0)
        high, low = _pcg_step(high + words[row, 0] + carry, low_sum, inc_high, inc_low)
        for column in range(count):
            high, low = _pcg_step(high, low, inc_high, inc_low)
            folded = high ^ low
            rotation = high >> np.uint64(58)
            output = (folded >> rotation) | (folded << ((np.uint64(64) - rotation) & sixty_three))
            out[row, column] = np.float64(output >> np.uint64(11)) * _DOUBLE_UNIT
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
        return _seed_words(self._run_entropy, np.ascontiguousarray(keys, dtype=np.int64).reshape(-1, 3))

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


@njit(cache=True, nogil=True)
def round_keys(first: int, rounds: int, workers: int, stream: int) -> np.ndarray:
    """The keys (round, worker, stream) of rounds ``first .. first + rounds - 1``, each round's
    workers ``0 .. workers - 1`` in turn: int64 (rounds * workers, 3).

    Example:
        >>> from qrrt_circuits._support.randomness import round_keys
        >>> round_keys(5, 2, 2, 1).tolist()
        [[5, 0, 1], [5, 1, 1], [6, 0, 1], [6, 1, 1]]
    """
    keys = np.empty((max(rounds, 0) * workers, 3), dtype=np.int64)
    row = 0
    for round_index in range(first, first + rounds):
        for worker in range(workers):
            keys[row, 0] = round_index
            keys[row, 1] = worker
            keys[row, 2] = stream
            row += 1
    return keys


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
    return _pcg64_doubles(streams.seed_words(keys), int(count))


def seeded_generator(seed: int) -> np.random.Generator:
    """``np.random.default_rng(seed)`` for a non-negative integer ``seed``, bit for bit: the seed
    words of ``SeedSequence(seed)`` (no spawn key) from the compiled ``_seed_words``, handed to
    ``PCG64`` (a backend builds one per search from its seed).

    Args:
        seed: A non-negative integer (any size).

    Returns:
        A ``numpy.random.Generator`` on ``PCG64``.

    Raises:
        ValueError: A negative seed.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits._support.randomness import seeded_generator
        >>> bool(seeded_generator(42).random() == np.random.default_rng(42).random())
        True
    """
    words = np.asarray(_uint32_words(int(seed)), dtype=np.uint64)
    state = _seed_words(words, np.empty((1, 0), dtype=np.int64))[0]
    return np.random.Generator(np.random.PCG64(_SeedWords(state)))  # type: ignore[arg-type]  # an ISeedSequence
