"""The planners' random streams: one ``numpy.random.Generator`` per (round, worker, purpose).

A plan's randomness comes only from its ``seed``: ``SeedSequence(seed)`` is spawned at the key
``(round, worker, stream)``, so each draw depends on where it is used, never on the order in which
workers ran or on the executor that ran them. The stream numbers are part of the reproducibility
contract (changing one changes every published result), so they are named here once.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum
from typing import cast

import numpy as np


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


@dataclass(frozen=True)
class RandomStreams:
    """The plan's root entropy; hands out one generator per (round, worker, stream)."""

    entropy: int

    @classmethod
    def from_seed(cls, seed: int | None) -> RandomStreams:
        entropy = np.random.SeedSequence(seed).entropy  # an int for an int or None seed
        return cls(int(cast(int, entropy)))

    def generator(self, round_index: int, worker: int, stream: Stream) -> np.random.Generator:
        sequence = np.random.SeedSequence(self.entropy, spawn_key=(int(round_index), int(worker), int(stream)))
        return np.random.default_rng(sequence)

    def seed(self, round_index: int, worker: int, stream: Stream = Stream.SEARCH) -> int:
        """One integer seed (for a backend call) drawn from that generator."""
        return int(self.generator(round_index, worker, stream).integers(0, 2**62))
