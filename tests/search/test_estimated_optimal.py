"""EstimatedOptimal: qiskit-algorithms' iterative amplitude estimation on our circuits, its
confidence intervals' coverage of the true m, its oracle-call count against the library's, and
the policy inside the planners with its oracle-call identities."""

import numpy as np
import pytest
from conftest import random_marks
from qiskit_algorithms import AlgorithmError
from scipy.stats import binom
from tolerances import TAIL

import qrrt_circuits as qc
from qrrt_circuits._support.randomness import RandomStreams
from qrrt_circuits.probability import optimal_iterations
from qrrt_circuits.registry import POLICIES
from qrrt_circuits.search.estimation import estimate_marked_fraction, estimation_problem, grover_iterate
from qrrt_circuits.search.iterate_sequence import IterateSequence, generalized_grover_circuit


def test_grover_operator_is_the_standard_iterate():
    from qiskit.quantum_info import Operator

    marks = random_marks(np.random.default_rng(2), 4, 5)
    iterate = Operator(grover_iterate(marks)).data
    circuit = generalized_grover_circuit(marks, IterateSequence.grover(1), measure=False)
    hadamards = Operator(generalized_grover_circuit(marks, IterateSequence.grover(0), measure=False)).data
    assert np.allclose(iterate @ hadamards, Operator(circuit).data, atol=1e-10)
    problem = estimation_problem(marks)
    assert problem.objective_qubits == [0, 1, 2, 3]
    assert [problem.is_good_state(format(i, "04b")) for i in range(16)] == marks.tolist()


@pytest.mark.parametrize("method", ["mlae", "iae"])
def test_interval_covers_the_true_count_at_the_stated_confidence(method):
    """Over many databases, the 1 - alpha interval on m = aN covers the true m in at least as many
    cases as the (1 - TAIL) lower binomial bound of Binomial(trials, 1 - alpha) allows."""
    alpha, trials = 0.2, 50
    rng = np.random.default_rng(2024)
    covered = 0
    for _ in range(trials):
        num_marked = int(rng.integers(1, 25))
        marks = random_marks(rng, 5, num_marked)
        # IAE needs enough shots per round to avoid qiskit-algorithms' endless loop (estimation.py)
        estimate = estimate_marked_fraction(marks, alpha=alpha, shots=16 if method == "mlae" else 100,
                                            rng=rng, method=method)
        low, high = estimate.count_interval(32)
        covered += low - 1e-9 <= num_marked <= high + 1e-9
        assert estimate.library_oracle_queries == estimate.shots * sum(estimate.powers)
        assert estimate.oracle_calls == estimate.shots * sum(k + 1 for k in estimate.powers)
    assert covered >= binom.ppf(TAIL / 2, trials, 1 - alpha)


def test_estimates_are_reproducible_from_the_seed_and_shared_across_workers():
    marks = random_marks(np.random.default_rng(5), 6, 11)
    first = estimate_marked_fraction(marks, alpha=0.05, shots=8, rng=np.random.default_rng(1))
    again = estimate_marked_fraction(marks, alpha=0.05, shots=8, rng=np.random.default_rng(1))
    assert first == again
    for workers in (1, 3, 8, 20):
        shares = first.calls_per_worker(workers)
        assert sum(shares) == first.oracle_calls and shares[0] == max(shares)
        assert shares[0] == sum(-(-first.shots // workers) * (k + 1) for k in first.powers)


def test_vectorized_interval_and_minimizer_agree_with_the_library():
    from qiskit_algorithms import MaximumLikelihoodAmplitudeEstimation

    from qrrt_circuits.search.estimation import SeededAerSampler, likelihood_ratio_interval

    for seed, num_marked in ((1, 3), (3, 40)):
        marks = random_marks(np.random.default_rng(seed), 6, num_marked)
        library = MaximumLikelihoodAmplitudeEstimation(3, sampler=SeededAerSampler(16, np.random.default_rng(seed)))
        result = library.estimate(estimation_problem(marks))
        ours = estimate_marked_fraction(marks, alpha=0.1, shots=16, rng=np.random.default_rng(seed))
        assert ours.estimate == pytest.approx(result.estimation, abs=2e-4)
        expected = library.compute_confidence_interval(result, alpha=0.1, kind="likelihood_ratio")
        interval = likelihood_ratio_interval(result.theta, result.evaluation_schedule, result.good_counts, 16, 0.1)
        assert interval == pytest.approx(tuple(expected), abs=1e-9)


def recording_policy(states: list, **options):
    """EstimatedOptimal whose states are kept so a test can read their per-database history."""

    class Recording(qc.EstimatedOptimal):
        def start(self, num_items):
            state = super().start(num_items)
            states.append(state)
            return state

    return Recording(**options)


@pytest.mark.parametrize("shared", [True, False])
@pytest.mark.parametrize("workers", [1, 5])
def test_policy_inside_the_planners_counts_the_estimation(workers, shared, clutter):
    """quantum calls = sum over databases of (estimation calls + p k); every worker verifies once;
    the critical path adds worker 0's share of the estimation to k + 1 each round."""
    states = []
    policy = recording_policy(states, shots=8)
    rounds = 6
    result = qc.PQRRT(backend=qc.StatevectorBackend(0), num_qubits=6, workers=workers,
                      shared_database=shared, search_policy=policy, seed=8).plan(clutter, max_rounds=rounds)
    m = result.metrics
    history = states[0].history
    per_database = workers if shared else 1
    assert len(history) == m.databases == rounds * (1 if shared else workers)
    assert m.quantum_oracle_calls == sum(est.oracle_calls + per_database * k for est, k in history)
    assert m.verification_calls == workers * rounds
    assert m.oracle_calls == m.quantum_oracle_calls + m.verification_calls
    if shared:
        assert m.critical_path_oracle_calls == sum(est.calls_per_worker(workers)[0] + k + 1 for est, k in history)
    for est, k in history:
        assert k == optimal_iterations(64, est.marked_count(64))
    assert any("amplitude-estimation shots are counted" in label for label in result.labels)


def test_policy_state_run_identities():
    marks = random_marks(np.random.default_rng(3), 6, 9)
    problem = qc.DatabaseSearch(qc.LookupOracle(marks), marks, qc.StatevectorBackend(), RandomStreams.from_seed(1), 0)
    state = qc.EstimatedOptimal(shots=8).start(64)
    outcomes = state.run(problem, 4, 10)
    (estimate, k), = state.history
    assert [o.quantum_calls for o in outcomes] == [share + k for share in estimate.calls_per_worker(4)]
    assert all(o.verifications == 1 for o in outcomes)
    with pytest.raises(TypeError, match="chooses k per database"):
        state.choose_iterations(3)


def test_registry_and_bad_settings():
    assert POLICIES.create("estimated") == qc.EstimatedOptimal()
    with pytest.raises(ValueError, match="epsilon must be"):
        qc.EstimatedOptimal(epsilon=0.0)
    with pytest.raises(ValueError, match="alpha must be in"):
        qc.EstimatedOptimal(alpha=1.0)
    with pytest.raises(ValueError, match="shots must be"):
        qc.EstimatedOptimal(shots=0)
    with pytest.raises(ValueError, match="method must be one of"):
        qc.EstimatedOptimal(method="qpe")


def test_iterative_estimation_loop_is_cut_off_not_endless():
    """The case where qiskit-algorithms' IAE loops forever (observed; see estimation.py) ends in a
    RuntimeError naming the cause."""
    rng = np.random.default_rng(2024)
    for _ in range(3):  # three databases that estimate normally, then the one that loops
        marks = random_marks(rng, 5, int(rng.integers(1, 25)))
        estimate_marked_fraction(marks, alpha=0.2, shots=16, rng=rng, method="iae")
    marks = random_marks(rng, 5, int(rng.integers(1, 25)))
    with pytest.raises(AlgorithmError) as error:
        estimate_marked_fraction(marks, alpha=0.2, shots=16, rng=rng, method="iae")
    assert "loops forever" in str(error.value.__cause__)
