"""The planners' random streams: numpy generators spawned from the plan's seed, one per use.

A plan's randomness comes only from its ``seed``. Two layouts, both through numpy's documented
``SeedSequence(entropy, spawn_key=...)``:

- keyed, ``generator(round, worker, stream)``: the generator of the key (round, worker, stream), so
  a draw depends on where it is used, never on the order in which workers ran or on the executor
  that ran them (the quantum planners' databases, searches and policies, the oracle error model);
- sequential, ``sequence(stream)``: one generator for the whole plan at the key (stream,), drawn
  from in round order by the planner's own loop (the classical planners' extension samples, a
  fixed number of doubles per (round, worker), so a batch of rounds drawn at once draws what the
  rounds drawn one by one would).

A one-element key never equals a three-element one, so the two layouts never share a generator.
The stream numbers are part of the reproducibility contract (changing one changes every published
result), so they are named here once.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum
from typing import cast

import numpy as np


class Stream(IntEnum):
    """What a generator is used for (the last element of its spawn key)."""

    #: candidate samples, goal bias and annealing distances of a database (keyed)
    CANDIDATES = 1
    #: the oracle error model's flips of the marks (keyed)
    ORACLE_ERRORS = 2
    #: a search policy's own draws (BBHT's random iteration counts and its per-search seeds) (keyed)
    POLICY = 3
    #: the classical planners' extension samples: d doubles for the point and, with goal bias, one
    #: more for the bias, per (round, worker) in order (sequential)
    EXTENSION_SAMPLES = 4
    #: the points drawn in the goal for the goal-biased extension samples, in order (sequential)
    GOAL_SAMPLES = 5
    #: the seed of one backend search shared by a group of workers (keyed)
    SEARCH = 7


@dataclass(frozen=True)
class RandomStreams:
    """The plan's root entropy; hands out its generators (module docstring).

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

    def generator(self, round_index: int, worker: int, stream: Stream) -> np.random.Generator:
        """The generator of one (round, worker, stream) key:
        ``np.random.default_rng(SeedSequence(entropy, spawn_key=(round_index, worker, stream)))``.

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
        return np.random.default_rng(np.random.SeedSequence(self.entropy, spawn_key=key))

    def sequence(self, stream: Stream) -> np.random.Generator:
        """The plan's one sequential generator of ``stream``:
        ``np.random.default_rng(SeedSequence(entropy, spawn_key=(stream,)))``, a new one at each
        call (the caller keeps it for the plan and draws from it in round order).

        Example:
            >>> from qrrt_circuits._support.randomness import RandomStreams, Stream
            >>> streams = RandomStreams.from_seed(7)
            >>> first, again = streams.sequence(Stream.EXTENSION_SAMPLES), streams.sequence(Stream.EXTENSION_SAMPLES)
            >>> bool(first.random() == again.random())
            True
        """
        return np.random.default_rng(np.random.SeedSequence(self.entropy, spawn_key=(int(stream),)))

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
