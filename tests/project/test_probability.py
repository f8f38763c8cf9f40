import math

import numpy as np
import pytest
from conftest import BACKENDS, make_backend, random_marks

from qrrt_circuits import LookupOracle, OracleErrorModel
from qrrt_circuits import probability as pr


def test_success_probability_and_optimal_iterations():
    assert pr.success_probability(4, 1, 1) == pytest.approx(1.0)
    assert pr.optimal_iterations(256, 1) == 12
    assert pr.optimal_iterations(256, 0) == 0
    assert pr.optimal_iterations(256, 256) == 0
    for n_items, m in ((256, 3), (1024, 10), (64, 20)):
        k = pr.optimal_iterations(n_items, m)
        assert pr.success_probability(n_items, m, k) > 1 - m / n_items - 1e-9


def _groups(backend, marks, k, workers, repeats):
    indices = backend.search(LookupOracle(marks), k, shots=workers * repeats).indices.reshape(repeats, workers)
    good = marks[indices].all(axis=1)
    same = good & (indices == indices[:, :1]).all(axis=1)
    distinct = good & np.array([len(set(row)) == workers for row in indices])
    return same, distinct


def _within(freq, p, n):
    sigma = math.sqrt(max(p * (1 - p), 1e-12) / n)
    return abs(freq - p) <= 5 * sigma + 1e-9


@pytest.mark.parametrize("backend_name", BACKENDS)
@pytest.mark.parametrize("n, m, workers, k", [(4, 2, 2, 1), (4, 3, 3, 1), (5, 4, 2, 2),
                                              (3, 1, 4, 1)])
def test_lemmas_1_and_2_against_shot_frequencies(backend_name, n, m, workers, k):
    backend = make_backend(backend_name, seed=n * 10 + workers)
    marks = random_marks(np.random.default_rng(m), n, m)
    repeats = 3000
    same, distinct = _groups(backend, marks, k, workers, repeats)
    p_good = pr.success_probability(2**n, m, k)
    assert _within(same.mean(), pr.prob_all_same(workers, m, p_good), repeats)
    assert _within(distinct.mean(), pr.prob_all_different(workers, m, p_good), repeats)


def test_lemma_3_against_simulated_coupon_collection():
    rng = np.random.default_rng(0)
    for m, p_good in ((3, 0.9), (6, 0.7), (1, 0.4)):
        draws = []
        for _ in range(4000):
            seen, count = set(), 0
            while len(seen) < m:
                count += 1
                if rng.random() < p_good:
                    seen.add(int(rng.integers(m)))
            draws.append(count)
        draws = np.array(draws)
        expected = pr.expected_workers_all_found(m, p_good)
        assert abs(draws.mean() - expected) <= 5 * draws.std() / math.sqrt(len(draws))


@pytest.mark.parametrize("backend_name", BACKENDS)
def test_lemmas_4_and_5_with_oracle_errors(backend_name):
    rng = np.random.default_rng(7)
    n, workers, k = 5, 2, 1
    truth = random_marks(rng, n, 6)
    errors = OracleErrorModel(false_positive=0.1, false_negative=0.3, seed=3)
    marks = errors.apply(truth)
    m = int(marks.sum())
    m1 = int((marks & truth).sum())
    m2 = int((~marks & truth).sum())
    assert m > m1 and m2 > 0  # the draw has both kinds of mistakes
    p_good = pr.success_probability(2**n, m, k)
    backend = make_backend(backend_name, seed=11)
    repeats = 4000
    indices = backend.search(LookupOracle(marks), k, shots=workers * repeats).indices.reshape(repeats, workers)
    true_hit = truth[indices[:, 0]].mean()
    assert _within(true_hit, pr.prob_true_solution(2**n, m, m1, m2, p_good), repeats)
    same_true = (truth[indices].all(axis=1) & (indices == indices[:, :1]).all(axis=1)).mean()
    expected = pr.prob_all_same_with_errors(workers, 2**n, m, m1, m2, p_good)
    assert _within(same_true, expected, repeats)


def test_lemma_6_against_simulated_collection():
    rng = np.random.default_rng(1)
    m, m1, p_good = 5, 3, 0.8
    draws = []
    for _ in range(4000):
        seen, count = set(), 0
        while len(seen) < m1:
            count += 1
            if rng.random() < p_good:
                hit = int(rng.integers(m))
                if hit < m1:
                    seen.add(hit)
        draws.append(count)
    draws = np.array(draws)
    expected = pr.expected_workers_with_errors(m, m1, p_good)
    assert abs(draws.mean() - expected) <= 5 * draws.std() / math.sqrt(len(draws))


def test_lemma_limits():
    assert pr.prob_all_same(1, 5, 0.7) == pytest.approx(0.7)
    assert pr.prob_all_different(1, 5, 0.7) == pytest.approx(0.7)
    assert pr.prob_all_different(4, 3, 1.0) == 0.0
    assert pr.prob_all_different(2, 10**6, 0.5) == pytest.approx(0.25, rel=1e-5)
    assert pr.expected_workers_all_found(1, 1.0) == 1.0
    assert pr.harmonic(3) == pytest.approx(1 + 1 / 2 + 1 / 3)
    assert pr.expected_workers_with_errors(4, 4, 0.5) == pytest.approx(
        pr.expected_workers_all_found(4, 0.5))


@pytest.mark.parametrize("call, message", [
    (lambda: pr.prob_all_same(0, 2, 0.5), "workers"),
    (lambda: pr.prob_all_same(2, 2, 1.5), "p_good"),
    (lambda: pr.success_probability(8, 9, 1), "num_marked"),
    (lambda: pr.optimal_iterations(0, 0), "num_items"),
    (lambda: pr.prob_true_solution(8, 2, 3, 0, 0.5), "true_marked"),
    (lambda: pr.prob_true_solution(8, 2, 1, 7, 0.5), "missed_good"),
    (lambda: pr.expected_workers_all_found(-1, 0.5), "num_marked"),
])
def test_bad_arguments(call, message):
    with pytest.raises(ValueError, match=message):
        call()
