"""Every search policy through the one polymorphic path, ``state.run(problem, workers, tree_nodes)``,
with its oracle-call identities, its statistics against Grover theory on both backends, and inside
the planners."""

import math

import numpy as np
import pytest
from conftest import BACKENDS, make_backend, random_marks
from tolerances import within_binomial

import qrrt_circuits as qc
from qrrt_circuits._support.randomness import RandomStreams
from qrrt_circuits.probability import optimal_iterations, success_probability
from qrrt_circuits.registry import POLICIES

POLICY_NAMES = ["paper", "fixed:2", "optimal", "bbht", "adaptive", "thompson"]


def problem(marks, backend, round_index=0, first_worker=0, truth=None):
    truth = marks if truth is None else truth
    return qc.DatabaseSearch(qc.LookupOracle(np.asarray(marks)), np.asarray(truth), backend, RandomStreams.from_seed(7),
                             round_index, first_worker)


def expected_k(name: str, num_items: int, num_marked: int, tree_nodes: int) -> int | None:
    return {"paper": 5 if tree_nodes <= 10 else 3, "fixed:2": 2,
            "optimal": optimal_iterations(num_items, num_marked)}.get(name)


@pytest.mark.parametrize("tree_nodes", [3, 40])
@pytest.mark.parametrize("name", POLICY_NAMES)
def test_outcome_identities_for_every_policy(name, tree_nodes):
    marks = random_marks(np.random.default_rng(1), 8, 6)
    workers = 5
    state = POLICIES.create(name).start(256)
    outcomes = state.run(problem(marks, qc.StatevectorBackend()), workers, tree_nodes)
    assert len(outcomes) == workers
    k = expected_k(name, 256, 6, tree_nodes)
    for outcome in outcomes:
        assert isinstance(outcome, qc.SearchOutcome)
        assert outcome.oracle_calls == outcome.quantum_calls + outcome.verifications
        assert outcome.verifications == len(outcome.observations) >= 1
        assert outcome.rejected == outcome.verifications - int(outcome.verified)
        assert outcome.verified == (outcome.index is not None)
        if outcome.verified:
            assert marks[outcome.index] and outcome.observations[-1][1]
        assert all(not good for _, good in outcome.observations[:-1])  # only the last can verify
        if name == "bbht":
            assert outcome.quantum_calls == sum(j for j, _ in outcome.observations)
            assert outcome.quantum_calls <= qc.BBHT().cap(256)
        else:
            if name == "adaptive":
                k = state.choose_iterations(tree_nodes)
            if name == "thompson":  # a sampled k, one for all the workers of the database
                k = outcomes[0].quantum_calls
                assert 0 <= k <= optimal_iterations(256, 1)
            assert outcome.quantum_calls == k and outcome.verifications == 1


@pytest.mark.parametrize("backend_name", BACKENDS)
@pytest.mark.parametrize("name", ["paper", "fixed:2", "optimal"])
def test_workers_find_a_marked_entry_at_the_grover_rate(name, backend_name):
    """p workers on one database: each verifies with probability sin^2((2k+1) theta)."""
    marks = random_marks(np.random.default_rng(3), 6, 3)
    state = POLICIES.create(name).start(64)
    backend = make_backend(backend_name, 0)
    found, total = 0, 0
    for round_index in range(25):
        outcomes = state.run(problem(marks, backend, round_index), 40, tree_nodes=20)
        found += sum(outcome.verified for outcome in outcomes)
        total += len(outcomes)
    k = expected_k(name, 64, 3, 20)
    assert within_binomial(found, total, success_probability(64, 3, k))


@pytest.mark.parametrize("backend_name", BACKENDS)
def test_bbht_finds_a_solution_within_its_expected_cost(backend_name):
    """BBHT (Thm. 3 of Boyer et al.): expected iterations <= (9/4) sqrt(N/m) for m <= 3N/4; with
    m = 0 every worker gives up within the cap."""
    backend = make_backend(backend_name, 0)
    state = qc.BBHT().start(256)
    none = state.run(problem(np.zeros(256, bool), backend), 6, 10)
    assert all(not o.verified and o.quantum_calls <= qc.BBHT().cap(256) for o in none)
    marks = random_marks(np.random.default_rng(4), 8, 4)
    costs = [o.quantum_calls for r in range(15) for o in state.run(problem(marks, backend, r), 8, 10)]
    costs = np.array(costs)
    bound = 9 / 4 * math.sqrt(256 / 4)
    assert costs.mean() <= bound + 5 * costs.std(ddof=1) / math.sqrt(costs.size)


def test_known_optimal_reads_the_marks_and_is_labelled():
    assert qc.KnownOptimal().labels() and not qc.Adaptive().labels() and not qc.BBHT().labels()
    marks = random_marks(np.random.default_rng(5), 8, 20)
    (outcome,) = qc.KnownOptimal().start(256).run(problem(marks, qc.StatevectorBackend()), 1, 0)
    assert outcome.quantum_calls == optimal_iterations(256, 20) == 2


def test_verification_uses_the_truth_not_the_marks():
    """With oracle errors the marks lie; a worker's measured entry verifies only if truly good."""
    rng = np.random.default_rng(6)
    truth = random_marks(rng, 6, 4)
    marks = truth.copy()
    marks[np.flatnonzero(~truth)[:8]] = True  # 8 false positives
    outcomes = qc.FixedIterations(1).start(64).run(problem(marks, qc.StatevectorBackend(), truth=truth), 200, 5)
    assert all(truth[o.index] for o in outcomes if o.verified)
    p_marked = success_probability(64, 12, 1)
    assert within_binomial(sum(o.verified for o in outcomes), 200, p_marked * 4 / 12)


def test_adaptive_learns_from_outcomes_and_others_ignore_them():
    adaptive = qc.Adaptive().start(256)
    before = adaptive.choose_iterations(10)
    adaptive.learn([(qc.SearchOutcome(None, before, 1, ((before, False),)),)] * 30)
    assert adaptive.choose_iterations(10) != before
    paper = qc.PaperIterations().start(256)
    paper.learn([(qc.SearchOutcome(None, 5, 1, ((5, False),)),)] * 30)
    assert paper.choose_iterations(3) == 5


@pytest.mark.parametrize("shared", [True, False])
@pytest.mark.parametrize("name", POLICY_NAMES)
def test_every_policy_inside_the_planners(name, shared, clutter):
    """The planners use every policy through the same path: metric identities hold, the critical
    path is the largest worker's calls per round, and fixed-k policies cost exactly p (k + 1)."""
    workers, rounds = 4, 12
    result = qc.PQRRT(backend=qc.StatevectorBackend(0), workers=workers, shared_database=shared,
                      search_policy=POLICIES.create(name), seed=2).plan(clutter, max_rounds=rounds)
    m = result.metrics
    assert m.oracle_calls == m.quantum_oracle_calls + m.verification_calls
    assert m.nodes + m.duplicates + m.rejected == m.verification_calls
    assert m.critical_path_oracle_calls <= m.oracle_calls <= workers * m.critical_path_oracle_calls
    assert m.databases == rounds * (1 if shared else workers)
    if name in ("paper", "fixed:2"):
        k = [expected_k(name, 256, 0, nodes) for nodes in np.concatenate([[0], result.history["nodes"][:-1]])]
        assert m.quantum_oracle_calls == workers * sum(k) and m.verification_calls == workers * rounds
        assert m.critical_path_oracle_calls == sum(k) + rounds


@pytest.mark.parametrize("build, error, message", [
    (lambda: qc.Adaptive(max_iterations=-3), ValueError, r"max_iterations must be an integer in \[0, 1000000\]"),
    (lambda: qc.Adaptive(grid_size=10**9), ValueError, r"grid_size must be an integer in \[10, 100000\]"),
    (lambda: qc.Adaptive(grid_size=float("nan")), TypeError, "grid_size must be an integer"),
    (lambda: qc.BBHT(cap_factor=float("inf")), ValueError, "cap_factor must be a finite number"),
    (lambda: qc.FixedIterations(True), TypeError, "k must be an integer"),
    (lambda: qc.PaperIterations(early=2.5), TypeError, "early must be an integer"),
    (lambda: qc.AnnealingSchedule(bands=[(2.7, 4.2), (0.8, 2.0)], switch_at=[2.5]), TypeError,
     r"switch_at\[0\] must be an integer"),
])
def test_policy_settings_are_checked_at_construction(build, error, message):
    with pytest.raises(error, match=message):
        build()


@pytest.mark.parametrize("make", [lambda: qc.FixedIterations(100_001), lambda: qc.PaperIterations(early=100_001),
                                  lambda: qc.PaperIterations(late=100_001)])
def test_iteration_counts_beyond_what_a_search_runs_are_refused_at_construction(make):
    """A plan with k = 200 000 was refused at its first search with that k, after the work before it."""
    with pytest.raises(ValueError, match=r"must be an integer in \[0, 100000\], got 100001"):
        make()
    assert qc.PaperIterations(switch_nodes=1_000_000).switch_nodes == 1_000_000  # a node count, not k
