"""``ThompsonIterations``: its arguments, its per-database learning, what it learns on streams of
databases with a known best k (both backends), and a plan with it."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import BACKENDS, make_backend
from scipy.stats import poisson

import qrrt_circuits as qc
from qrrt_circuits._support.randomness import RandomStreams
from qrrt_circuits.probability import expected_distinct_found, optimal_iterations
from qrrt_circuits.problems.families import open_space


def _stream(policy: qc.IterationPolicy, backend: qc.QuantumSearchBackend, mean_marked: float, databases: int,
            workers: int = 1, seed: int = 0):
    """Feed ``databases`` databases of 256 entries, each with m ~ Poisson(``mean_marked``) marked
    ones, through the policy's own run and learn (as a planner's round does); returns the state,
    the k of each database and the calls per distinct entry found."""
    rng = np.random.default_rng(seed)
    streams = RandomStreams(seed)
    state = policy.start(256)
    chosen, spent, found = [], 0, 0
    for index in range(databases):
        marks = np.zeros(256, dtype=bool)
        marks[rng.choice(256, min(int(rng.poisson(mean_marked)), 256), replace=False)] = True
        outcomes = state.run(qc.DatabaseSearch(qc.LookupOracle(marks), marks, backend, streams, index), workers, index)
        chosen.append(outcomes[0].quantum_calls)
        spent += sum(o.oracle_calls for o in outcomes)
        found += len({o.index for o in outcomes if o.index is not None})
        state.learn([outcomes])
    return state, chosen, spent / max(found, 1)


def _best_fixed_cost(mean_marked: float, workers: int) -> float:
    """min over k of p (k + 1) / E[distinct found], m ~ Poisson(mean_marked), N = 256."""
    marked = np.arange(257)
    weights = poisson.pmf(marked, mean_marked)
    return min(workers * (k + 1) / sum(w * expected_distinct_found(256, int(m), k, workers)
                                       for m, w in zip(marked, weights, strict=True))
               for k in range(optimal_iterations(256, 1) + 1))


@pytest.mark.parametrize(("field", "value"), [("memory", 0.0), ("memory", 1.5), ("prior_strength", 0.0),
                                              ("prior_strength", 2000.0), ("prior", "flat"),
                                              ("max_iterations", -1)])
def test_bad_fields_are_refused_by_name(field, value):
    with pytest.raises((TypeError, ValueError), match=field):
        qc.ThompsonIterations(**{field: value})


def test_the_arms_run_to_the_optimal_k_for_one_marked_entry():
    state = qc.ThompsonIterations().start(256)
    assert state.arms.tolist() == list(range(optimal_iterations(256, 1) + 1))
    assert qc.ThompsonIterations(max_iterations=4).start(256).arms.tolist() == [0, 1, 2, 3, 4]
    # the uniform prior: every arm's prior mean near 1/2, so a plan starts at k = 0, the cheapest
    mean = state.prior_alpha / (state.prior_alpha + state.prior_beta)
    assert np.all(np.abs(mean - 0.5) < 0.02) and state.choose_iterations(0) == 0


@pytest.mark.parametrize("backend_name", BACKENDS)
@pytest.mark.parametrize("workers", [1, 8])
def test_sparse_databases_cost_within_twice_the_best_fixed_k(backend_name, workers):
    """m ~ Poisson(1) in 256 entries (a third of the databases empty, the case where BBHT spends its
    cap on each empty one): over 300 databases the calls per distinct entry found stay within
    twice the best fixed k's expected cost (``probability.expected_distinct_found``), and the
    searches use k > 0 most of the time (k = 0 costs 16x the best for one worker)."""
    backend = make_backend(backend_name, 3)
    _, chosen, cost = _stream(qc.ThompsonIterations(), backend, 1.0, 300, workers, seed=3)
    assert cost <= 2.0 * _best_fixed_cost(1.0, workers), cost
    assert sum(k > 0 for k in chosen[-100:]) >= 60


@pytest.mark.parametrize("backend_name", BACKENDS)
def test_dense_databases_teach_it_classical_sampling(backend_name):
    """About half the entries marked: k = 0 finds one with probability 1/2 for 1 call (k = 1: 1/2
    for 2), so at least 80 % of the last 30 of 60 searches run k = 0."""
    backend = make_backend(backend_name, 4)
    state, chosen, _ = _stream(qc.ThompsonIterations(), backend, 128.0, 60, seed=4)
    assert state.choose_iterations(0) == 0
    assert sum(k == 0 for k in chosen[-30:]) >= 24


def test_a_shared_database_is_one_observation_rewarded_by_distinct_entries():
    """Eight workers that all find the one marked entry add one node: the arm's reward is 1/8, and
    the eight measurements weigh as one database."""
    state = qc.ThompsonIterations(memory=1.0).start(256)
    before_alpha, before_beta = state.alpha.copy(), state.beta.copy()
    same = tuple(qc.SearchOutcome(7, 12, 1, ((12, True),)) for _ in range(8))
    state.learn([same])
    assert state.alpha[12] - before_alpha[12] == pytest.approx(1 / 8)
    assert state.beta[12] - before_beta[12] == pytest.approx(7 / 8)
    assert np.array_equal(np.delete(state.alpha, 12), np.delete(before_alpha, 12))


def test_evidence_fades_toward_the_prior_per_database():
    state = qc.ThompsonIterations(memory=0.5).start(256)
    state.learn([(qc.SearchOutcome(None, 3, 1, ((3, False),)),)])
    gained = state.beta[3] - state.prior_beta[3]
    state.learn([(qc.SearchOutcome(None, 5, 1, ((5, False),)),)])
    assert state.beta[3] - state.prior_beta[3] == pytest.approx(0.5 * gained)


def test_same_seed_same_choices():
    first = _stream(qc.ThompsonIterations(), qc.StatevectorBackend(seed=0), 3.0, 40, seed=5)[1]
    assert first == _stream(qc.ThompsonIterations(), qc.StatevectorBackend(seed=0), 3.0, 40, seed=5)[1]
    assert len(set(first)) > 1  # (it explores)


def test_q_rrt_and_pq_rrt_plan_with_it():
    """Open space: q-RRT and Pq-RRT with ThompsonIterations reach the goal in 8 of 8 seeds within
    2 000 oracle calls, and every tree edge passes the check again."""
    problem = open_space()
    for make in (qc.QRRT, qc.PQRRT):
        reached = 0
        for seed in range(8):
            planner = make(backend=qc.StatevectorBackend(seed=seed), num_qubits=8, seed=seed,
                           goal_bias=0.05, search_policy=qc.ThompsonIterations())
            result = planner.plan(problem, max_oracle_calls=2000)
            reached += int(result.reached)
            assert problem.predicate.reachable(result.nodes[result.parents[1:]], result.nodes[1:]).all()
            assert any("thompson" in str(value) for value in result.settings.values())
        assert reached == 8, make.__name__
