"""Dürr-Høyer minimum finding and the search for all marked entries, on arrays with known answers,
on Aer and the statevector: the returned minimum's rank distribution and the oracle calls against
the published bounds (Dürr and Høyer 1996, Thm. 1 and Lemma 2; BBHT 1998, Thm. 3), over many seeds."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import BACKENDS, make_backend
from tolerances import TAIL, binomial_counts, z_bound

from qrrt_circuits.search.all_marked import all_marked_bound, find_all_marked
from qrrt_circuits.search.minimum_finding import (
    DurrHoyer,
    durr_hoyer_budget,
    durr_hoyer_expected_bound,
)
from qrrt_circuits.search.policies.bbht import BBHT

RUNS = 120


def _table(rng, size, feasible_share):
    values = rng.permutation(size).astype(float)  # distinct values: the rank is well defined
    feasible = rng.random(size) < feasible_share
    feasible[rng.integers(size)] = True
    return values, feasible


@pytest.mark.parametrize("backend_name", BACKENDS)
@pytest.mark.parametrize("below_threshold_only", [False, True])
def test_durr_hoyer_finds_the_minimum_within_the_published_bounds(backend_name, below_threshold_only):
    """Rank 0 (the feasible minimum) in at least half the runs less a binomial tail (Thm. 1: >= 1/2
    within 22.5 sqrt(N) + 1.4 lg^2 N calls); the mean calls until it is held below Lemma 2's
    45/4 sqrt(N) + 7/10 lg^2 N (with a normal bound on the mean over runs); every run's quantum calls
    within the budget plus one BBHT search's cap."""
    size = 32
    backend = make_backend(backend_name, 0)
    finder = DurrHoyer(below_threshold_only=below_threshold_only)
    rng = np.random.default_rng(7)
    ranks, to_final = [], []
    for run in range(RUNS):
        values, feasible = _table(rng, size, 0.5)
        outcome = finder.run(values, feasible, backend, np.random.default_rng(1000 + run))
        order = np.sort(values[feasible])
        assert outcome.index is not None and feasible[outcome.index]
        ranks.append(int(np.searchsorted(order, values[outcome.index])))
        to_final.append(outcome.calls_to_final)
        assert outcome.quantum_calls <= durr_hoyer_budget(size) + BBHT().cap(size)
        assert outcome.oracle_calls == outcome.quantum_calls + outcome.verifications
    low, _ = binomial_counts(RUNS, 0.5, TAIL)
    found = sum(rank == 0 for rank in ranks)
    assert found >= low, f"minimum held in {found}/{RUNS} runs"
    mean, spread = float(np.mean(to_final)), float(np.std(to_final, ddof=1))
    assert mean - z_bound() * spread / math.sqrt(RUNS) <= durr_hoyer_expected_bound(size), mean


def test_durr_hoyer_keeps_a_known_start_and_refuses_bad_tables(clutter):
    backend = make_backend("statevector", 0)
    values = np.arange(8, dtype=float)
    feasible = np.zeros(8, dtype=bool)
    feasible[5] = True
    outcome = DurrHoyer().run(values, feasible, backend, np.random.default_rng(0), start=5)
    assert outcome.index == 5 and outcome.improvements == 0 and outcome.verifications >= 1
    with pytest.raises(ValueError, match="N = 2\\^n >= 2"):
        DurrHoyer().run(np.arange(6.0), np.ones(6, dtype=bool), backend, np.random.default_rng(0))
    with pytest.raises(ValueError, match="start must be an index in \\[0, 8\\)"):
        DurrHoyer().run(values, feasible, backend, np.random.default_rng(0), start=8)
    with pytest.raises(ValueError, match="budget_factor"):
        DurrHoyer(budget_factor=0)


def bbht_give_up_probability(num_items: int, num_marked: int, search: BBHT, mass: float = 1e-15) -> float:
    """The probability that one ``BBHT.run`` with ``num_marked`` of ``num_items`` marked gives up,
    by exact dynamic programming over its schedule: attempt a draws j uniform in [0, floor(b_a)),
    b_0 = 1, b_{a+1} = min(growth b_a, sqrt N); a draw with spent + j > cap gives up; else j
    iterations are spent and the measurement is marked with probability sin^2((2j + 1) theta),
    sin^2 theta = M / N; a miss with spent >= cap gives up. (The still-running mass below ``mass``
    is counted as giving up, so the result is an upper bound within ``mass``.)"""
    theta = math.asin(math.sqrt(num_marked / num_items))
    cap, limit = search.cap(num_items), math.sqrt(num_items)
    running = {0: 1.0}  # spent -> probability of still searching before this attempt
    bound, given_up = 1.0, 0.0
    while sum(running.values()) > mass:
        draws = max(1, int(math.floor(bound)))
        following: dict[int, float] = {}
        for spent, weight in running.items():
            for j in range(draws):
                share = weight / draws
                if spent + j > cap:
                    given_up += share
                    continue
                miss = share * (1.0 - math.sin((2 * j + 1) * theta) ** 2)
                if spent + j >= cap:
                    given_up += miss
                else:
                    following[spent + j] = following.get(spent + j, 0.0) + miss
        running = following
        bound = min(search.growth * bound, limit)
    return given_up + sum(running.values())


@pytest.mark.parametrize("backend_name", BACKENDS)
@pytest.mark.parametrize("marked", [1, 3, 6])
def test_find_all_marked_finds_them_within_the_sqrt_n_m_bound(backend_name, marked):
    """All M marked entries found in as many runs as BBHT's exact give-up probability allows (the
    binomial interval of the product over the searches), never an unmarked one; mean quantum calls
    below sum_t 4.5 sqrt(N / t) + cap (BBHT Thm. 3 summed), which is of order sqrt(N M)."""
    size = 64
    backend = make_backend(backend_name, 0)
    rng = np.random.default_rng(3)
    complete, calls = 0, []
    for run in range(60):
        marks = np.zeros(size, dtype=bool)
        marks[rng.choice(size, marked, replace=False)] = True
        outcome = find_all_marked(marks, backend, np.random.default_rng(run))
        assert len(set(outcome.indices)) == len(outcome.indices) and marks[list(outcome.indices)].all()
        complete += len(outcome.indices) == marked
        calls.append(outcome.quantum_calls)
    # every search up to the last finds its entry unless it gives up: P(all M found) is the product
    # over t = M, ..., 1 of (1 - P(give up with t marked)), exact for BBHT's schedule
    low, _ = binomial_counts(60, math.prod(1.0 - bbht_give_up_probability(size, t, BBHT())
                                             for t in range(1, marked + 1)))
    assert complete >= low, complete
    mean, spread = float(np.mean(calls)), float(np.std(calls, ddof=1))
    assert mean - z_bound() * spread / math.sqrt(60) <= all_marked_bound(size, marked, BBHT()), mean
