"""The compiled seed derivation gives numpy's SeedSequence generators bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from qrrt_circuits.randomness import RandomStreams, Stream


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


@pytest.mark.parametrize("seed", [0, 1, 2**31 - 1, 2**32 - 1, 2**32, 2**62 - 1, 2**64 - 1, 2**64, 2**100 + 17, 2**128,
                                  2**300 - 1])
def test_integer_seed_words_equal_default_rng(seed):
    from qrrt_circuits.randomness import integer_seed_words

    expected = np.random.SeedSequence(seed).generate_state(4, np.uint64)
    assert np.array_equal(integer_seed_words(seed), expected)


def test_first_integer_below_equals_default_rng_integers():
    from qrrt_circuits.randomness import first_integer_below

    rng = np.random.default_rng(5)
    highs = [1, 2, 3, 5, 2**31 - 1, 2**32 - 1, 2**32, *rng.integers(1, 2**32, 40).tolist()]
    for seed in rng.integers(0, 2**62, 60).tolist():
        for high in highs:
            assert first_integer_below(seed, high) == int(np.random.default_rng(seed).integers(0, high))
    assert first_integer_below(2**130 + 7, 1000) == int(np.random.default_rng(2**130 + 7).integers(0, 1000))
    with pytest.raises(ValueError, match="high"):
        first_integer_below(1, 2**32 + 1)


def test_compiled_two_level_draws_equal_the_numpy_ones():
    """The statevector backend's compiled sampler (integer seeds) draws what default_rng draws:
    same doubles, then the buffered 32-bit Lemire draws of the marked picks and unmarked ranks."""
    from qrrt_circuits.probability import good_probability
    from qrrt_circuits.randomness import integer_seed_words
    from qrrt_circuits.search.statevector import _draw_two_level, _draw_two_level_seeded

    rng = np.random.default_rng(11)
    for _ in range(400):
        size = 1 << int(rng.integers(1, 12))
        fraction = float(rng.choice([0.0, 1.0, rng.random(), 1.0 / size]))
        marks = rng.random(size) < fraction
        shots = int(rng.choice([1, 2, 3, 8, 33]))  # 1: the scan of the marks; more: the lists
        seed = int(rng.integers(0, 2**62))
        p_good = good_probability(size, int(marks.sum()), int(rng.integers(0, 6)))
        expected = _draw_two_level(marks, p_good, shots, np.random.default_rng(seed))
        assert np.array_equal(_draw_two_level_seeded(marks, p_good, shots, integer_seed_words(seed)), expected)


def test_the_scan_of_the_marks_draws_what_numpy_draws_at_any_shot_count():
    """``_draw_two_level_scanned`` (what one shot takes) is written for any shot count: the same
    indices as numpy's ``_draw_two_level`` at 1 to 9 shots, none marked and all marked included."""
    from qrrt_circuits.randomness import integer_seed_words
    from qrrt_circuits.search.statevector import _draw_two_level, _draw_two_level_scanned

    rng = np.random.default_rng(12)
    for case in range(300):
        size = 1 << int(rng.integers(1, 11))
        marks = rng.random(size) < float(rng.choice([0.0, 1.0, rng.random()]))
        shots, seed, p_good = int(rng.integers(1, 10)), int(rng.integers(0, 2**62)), float(rng.random())
        expected = _draw_two_level(marks, p_good, shots, np.random.default_rng(seed))
        assert np.array_equal(_draw_two_level_scanned(marks, p_good, shots, integer_seed_words(seed)), expected), case
