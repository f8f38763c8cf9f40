"""The compiled seed derivation gives numpy's SeedSequence generators bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from qrrt_circuits._support.randomness import RandomStreams, Stream, seeded_generator


@pytest.mark.parametrize("seed", [0, 1, 7, 2**32 + 5, 2**70 + 3, 12345678901234567890123, None])
def test_seed_words_equal_numpy_seed_sequence(seed):
    streams = RandomStreams.from_seed(seed)
    rng = np.random.default_rng(0 if seed is None else seed % 1000)
    keys = np.column_stack([rng.integers(0, 10**6, 60), rng.integers(0, 5000, 60), rng.choice([1, 2, 3, 7], 60)])
    keys[:5] = [[0, 0, 1], [0, 0, 0], [2**33, 1, 7], [2**40 + 1, 2**35, 3], [1, 2**32, 1]]
    words = streams.seed_words(keys)
    for key, got in zip(keys, words, strict=True):
        expected = np.random.SeedSequence(streams.entropy, spawn_key=tuple(int(k) for k in key))
        assert np.array_equal(got, expected.generate_state(4, np.uint64)), key


def test_generators_draw_what_default_rng_draws():
    streams = RandomStreams.from_seed(42)
    batch = streams.generators(np.arange(10, 20), 3, Stream.CANDIDATES)
    for round_index, generator in zip(range(10, 20), batch, strict=True):
        single = streams.generator(round_index, 3, Stream.CANDIDATES)
        reference = np.random.default_rng(np.random.SeedSequence(42, spawn_key=(round_index, 3, 1)))
        expected = reference.random(5)
        assert np.array_equal(generator.random(5), expected)
        assert np.array_equal(single.random(5), expected)
        assert streams.seed(round_index, 3) == int(
            np.random.default_rng(np.random.SeedSequence(42, spawn_key=(round_index, 3, 7))).integers(0, 2**62))


@pytest.mark.parametrize("seed", [0, 1, 255, 2**32 - 1, 2**32, 2**62 - 1, 2**64 + 9, 2**128 + 1, 2**200 + 77])
def test_seeded_generator_is_default_rng(seed):
    ours, numpys = seeded_generator(seed), np.random.default_rng(seed)
    assert np.array_equal(ours.random(7), numpys.random(7))
    assert np.array_equal(ours.integers(0, 2**62, 5), numpys.integers(0, 2**62, 5))
    assert np.array_equal(ours.normal(size=3), numpys.normal(size=3))


def test_seeded_generator_refuses_a_negative_seed():
    with pytest.raises(ValueError, match="non-negative"):
        seeded_generator(-1)


def test_negative_keys_refused():
    streams = RandomStreams.from_seed(1)
    with pytest.raises(ValueError, match="non-negative"):
        streams.generator(-1, 0, Stream.CANDIDATES)
    with pytest.raises(ValueError, match="non-negative"):
        streams.seed_words(np.array([[0, -2, 1]]))


@pytest.mark.parametrize("seed", [0, 99, None])
def test_search_seeds_equal_numpy_integers(seed):
    streams = RandomStreams.from_seed(seed)
    for round_index in range(0, 4000, 13):
        key = (round_index, round_index % 5, int(Stream.SEARCH))
        expected = np.random.default_rng(np.random.SeedSequence(streams.entropy, spawn_key=key)).integers(0, 2**62)
        assert streams.seed(*key) == int(expected)


def test_uniform_draws_equal_the_generators_doubles():
    from qrrt_circuits._support.randomness import uniform_draws

    streams = RandomStreams.from_seed(4)
    keys = np.array([[r, w, int(Stream.CANDIDATES)] for r in (0, 7, 3000) for w in (0, 5)])
    draws = uniform_draws(streams, keys, 5)
    for row, key in enumerate(keys):
        expected = np.random.default_rng(np.random.SeedSequence(streams.entropy, spawn_key=tuple(key))).random(5)
        assert np.array_equal(draws[row], expected)


@pytest.mark.parametrize("seed", [0, 4, 2**70 + 3, None])
def test_compiled_pcg64_doubles_equal_numpys_on_many_keys(seed):
    """``uniform_draws`` runs PCG64 compiled (128-bit steps in 64-bit words, carries included):
    2 000 random keys, up to 2^40, and 9 doubles each, against ``Generator.random``."""
    from qrrt_circuits._support.randomness import uniform_draws

    streams = RandomStreams.from_seed(seed)
    rng = np.random.default_rng(17)
    keys = np.column_stack([rng.integers(0, 2**40, 2000), rng.integers(0, 5000, 2000), rng.choice([1, 2, 3, 7], 2000)])
    draws = uniform_draws(streams, keys, 9)
    assert draws.shape == (2000, 9) and uniform_draws(streams, keys[:0], 9).shape == (0, 9)
    for key, row in zip(keys, draws, strict=True):
        expected = np.random.default_rng(np.random.SeedSequence(streams.entropy, spawn_key=tuple(int(k) for k in key)))
        assert np.array_equal(row, expected.random(9)), key


def test_round_keys_list_each_rounds_workers_in_turn():
    from qrrt_circuits._support.randomness import round_keys

    keys = round_keys(7, 3, 4, int(Stream.ORACLE_ERRORS))
    assert keys.dtype == np.int64 and keys.tolist() == [[r, w, 2] for r in (7, 8, 9) for w in range(4)]
    assert round_keys(7, 0, 4, 1).shape == (0, 3)
