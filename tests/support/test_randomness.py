"""The plan's random streams are numpy's SeedSequence generators: keyed ones at (round, worker,
stream), sequential ones at (stream,), never the same generator."""

from __future__ import annotations

import numpy as np
import pytest

from qrrt_circuits._support.randomness import RandomStreams, Stream


@pytest.mark.parametrize("seed", [0, 1, 7, 2**32 + 5, 2**70 + 3, 12345678901234567890123, None])
def test_keyed_generators_are_numpys_spawned_generators(seed):
    streams = RandomStreams.from_seed(seed)
    for key in [(0, 0, 1), (2**33, 1, 7), (2**40 + 1, 2**35, 3), (1, 2**32, 1), (4000, 3, 2)]:
        reference = np.random.default_rng(np.random.SeedSequence(streams.entropy, spawn_key=key))
        assert np.array_equal(streams.generator(*key).random(5), reference.random(5)), key


def test_sequential_generators_are_numpys_one_element_keys():
    streams = RandomStreams.from_seed(42)
    for stream in (Stream.EXTENSION_SAMPLES, Stream.GOAL_SAMPLES):
        reference = np.random.default_rng(np.random.SeedSequence(42, spawn_key=(int(stream),)))
        assert np.array_equal(streams.sequence(stream).random(9), reference.random(9))


def test_sequential_and_keyed_generators_differ():
    """(4,) and (4, 0, 0), or (r, w, 4): a one-element key never gives a keyed generator's draws."""
    streams = RandomStreams.from_seed(3)
    sequential = streams.sequence(Stream.EXTENSION_SAMPLES).random(4)
    for key in [(4, 0, 0), (0, 0, 4), (0, 4, 0), (0, 0, 5)]:
        assert not np.array_equal(np.random.default_rng(np.random.SeedSequence(3, spawn_key=key)).random(4),
                                  sequential), key
    assert not np.array_equal(streams.sequence(Stream.GOAL_SAMPLES).random(4), sequential)


def test_stream_numbers_are_distinct():
    # (__members__ keeps aliases: two names given one number would show up here, not in iter(Stream))
    assert len({int(stream) for stream in Stream.__members__.values()}) == len(Stream.__members__)


def test_negative_keys_refused():
    streams = RandomStreams.from_seed(1)
    with pytest.raises(ValueError, match="non-negative"):
        streams.generator(-1, 0, Stream.CANDIDATES)
    with pytest.raises(ValueError, match="non-negative"):
        streams.generator(0, -2, Stream.CANDIDATES)


@pytest.mark.parametrize("seed", [0, 99, None])
def test_search_seeds_equal_numpy_integers(seed):
    streams = RandomStreams.from_seed(seed)
    for round_index in range(0, 4000, 13):
        key = (round_index, round_index % 5, int(Stream.SEARCH))
        expected = np.random.default_rng(np.random.SeedSequence(streams.entropy, spawn_key=key)).integers(0, 2**62)
        assert streams.seed(*key) == int(expected)
