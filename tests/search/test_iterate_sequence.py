"""Fixed-point amplitude amplification (Yoder, Low, Chuang 2014): phases against the paper's
success-probability formula, circuits against exact operators, sampled success rates on every
backend, and the policy inside the planners with its oracle-call identities."""

import math

import numpy as np
import pytest
from conftest import ALL_BACKENDS, make_backend, random_marks
from qiskit.quantum_info import Operator, Statevector
from tolerances import binomial_counts, within_binomial

import qrrt_circuits as qc
from qrrt_circuits.probability import good_probability
from qrrt_circuits.registry import POLICIES
from qrrt_circuits.search.iterate_sequence import (
    IterateSequence,
    fixed_point_iterates,
    fixed_point_phases,
    fixed_point_success_probability,
    gamma,
    generalized_grover_circuit,
    statevector_after,
)

DELTAS = [0.05, 0.2, 0.5, 0.8]
FRACTIONS = np.linspace(0.0, 1.0, 41)


def numpy_operator(marks: np.ndarray, sequence: IterateSequence) -> np.ndarray:
    """prod_j -S_s(alpha_j) S_t(beta_j) times H^n, built from dense matrices (Yoder et al.)."""
    size = marks.shape[0]
    n = size.bit_length() - 1
    hadamard = np.array([[1.0, 1.0], [1.0, -1.0]]) / math.sqrt(2)
    walsh = np.array([[1.0]])
    for _ in range(n):
        walsh = np.kron(walsh, hadamard)
    s = np.full(size, 1.0 / math.sqrt(size))
    operator = walsh.astype(complex)
    for alpha, beta in zip(sequence.alphas, sequence.betas, strict=True):
        oracle = np.diag(np.where(marks, np.exp(1j * beta), 1.0))
        reflection = np.eye(size) - (1.0 - np.exp(-1j * alpha)) * np.outer(s, s)
        operator = -reflection @ oracle @ operator
    return operator


@pytest.mark.parametrize("delta", DELTAS)
@pytest.mark.parametrize("iterates", [0, 1, 2, 5, 9])
def test_two_dimensional_evolution_equals_the_papers_formula(delta, iterates):
    """The sign conventions (S_s with e^{-i alpha}, the oracle with e^{+i beta}) reproduce P_L(f)."""
    sequence = IterateSequence.fixed_point(delta, iterates)
    for f in FRACTIONS:
        assert sequence.good_probability(f) == pytest.approx(
            fixed_point_success_probability(delta, iterates, f), abs=1e-10)


def test_flipping_one_sign_convention_breaks_the_formula():
    """The check above can fail: the conjugate convention for alpha alone gives other numbers."""
    alphas, betas = fixed_point_phases(0.3, 4)
    flipped = IterateSequence(-alphas, betas)
    worst = max(abs(flipped.good_probability(f) - fixed_point_success_probability(0.3, 4, f)) for f in FRACTIONS)
    assert worst > 0.1


@pytest.mark.parametrize("delta", DELTAS)
@pytest.mark.parametrize("min_fraction", [1 / 256, 0.01, 0.05, 0.2, 0.6])
@pytest.mark.parametrize("rule", ["paper", "tight"])
def test_success_at_least_one_minus_delta_squared_for_every_fraction_above_w(delta, min_fraction, rule):
    iterates = fixed_point_iterates(delta, min_fraction, rule)
    length = 2 * iterates + 1
    assert 1 - gamma(delta, length) ** 2 <= min_fraction + 1e-12  # the exact condition of the guarantee
    if rule == "paper":
        assert length >= math.log(2 / delta) / math.sqrt(min_fraction)
        assert length - 2 < math.log(2 / delta) / math.sqrt(min_fraction)  # the smallest such L
    else:
        assert iterates <= fixed_point_iterates(delta, min_fraction, "paper")
    sequence = IterateSequence.fixed_point(delta, iterates)
    for f in np.linspace(min_fraction, 1.0, 60):
        assert sequence.good_probability(f) >= 1 - delta**2 - 1e-12


def test_standard_grover_is_the_special_case_alpha_beta_pi():
    for k in range(6):
        sequence = IterateSequence.grover(k)
        for m in (1, 3, 40, 200):
            assert sequence.good_probability(m / 256) == pytest.approx(good_probability(256, m, k), abs=1e-12)


@pytest.mark.parametrize("num_qubits", [1, 2, 3, 4, 5])
@pytest.mark.parametrize("delta", [0.1, 0.4, 0.7])
@pytest.mark.parametrize("synthesis", ["diagonal", "mcz"])
def test_circuit_operator_equals_the_formula(num_qubits, delta, synthesis):
    rng = np.random.default_rng(num_qubits * 10 + int(delta * 10))
    marks = random_marks(rng, num_qubits, int(rng.integers(1, 1 << num_qubits)))
    sequence = IterateSequence.fixed_point(delta, 3)
    circuit = generalized_grover_circuit(marks, sequence, measure=False, synthesis=synthesis)
    expected = numpy_operator(marks, sequence)
    assert np.allclose(Operator(circuit).data, expected, atol=1e-9)
    # and the iterated statevector and the 2-dimensional closed form agree with it
    state = expected[:, 0]
    assert np.allclose(statevector_after(marks, sequence), state, atol=1e-12)
    assert np.allclose(Statevector(circuit).data, state, atol=1e-9)
    fraction = marks.mean()
    marked_amplitude, unmarked_amplitude = sequence.marked_amplitude(fraction)
    assert np.allclose(state[marks], marked_amplitude / math.sqrt(marks.sum()), atol=1e-12)
    if fraction < 1:
        assert np.allclose(state[~marks], unmarked_amplitude / math.sqrt((~marks).sum()), atol=1e-12)


@pytest.mark.parametrize("backend_name", ALL_BACKENDS)
@pytest.mark.parametrize("delta, num_marked", [(0.5, 2), (0.5, 9), (0.3, 5), (0.3, 30)])
def test_sampled_success_within_binomial_bounds(backend_name, delta, num_marked):
    """5 qubits, w = 1/16: the measured marked rate matches P_L(f) and is >= 1 - delta^2."""
    marks = random_marks(np.random.default_rng(num_marked), 5, num_marked)
    policy = qc.FixedPointAmplification(delta=delta, min_fraction=1 / 16)
    shots = 3000
    result = make_backend(backend_name, 11).search_sequence(qc.LookupOracle(marks), policy.sequence(), shots, seed=5)
    successes = int(np.count_nonzero(marks[result.indices]))
    exact = policy.success_probability(num_marked / 32)
    assert exact >= 1 - delta**2
    assert within_binomial(successes, shots, exact)
    assert successes >= binomial_counts(shots, 1 - delta**2)[0]
    assert result.oracle_calls == policy.iterates * shots and result.iterations == policy.iterates


def test_search_sequence_is_reproducible_and_checks_its_input():
    marks = random_marks(np.random.default_rng(0), 4, 3)
    sequence = IterateSequence.fixed_point(0.4, 2)
    backend = qc.AerBackend()
    first = backend.search_sequence(qc.LookupOracle(marks), sequence, 50, seed=3).indices
    assert np.array_equal(first, backend.search_sequence(qc.LookupOracle(marks), sequence, 50, seed=3).indices)
    with pytest.raises(TypeError, match="sequence must be an IterateSequence"):
        backend.search_sequence(qc.LookupOracle(marks), [0.1, 0.2], 5)
    with pytest.raises(ValueError, match="shots must be an integer"):
        backend.search_sequence(qc.LookupOracle(marks), sequence, 0)
    with pytest.raises(ValueError, match="same length"):
        IterateSequence([1.0, 2.0], [1.0])


@pytest.mark.parametrize("shared", [True, False])
@pytest.mark.parametrize("workers", [1, 4])
def test_policy_inside_the_planners_costs_l_plus_one_per_worker(workers, shared, clutter):
    """quantum calls = l per worker per database, 1 verification each; the critical path is l + 1
    per round."""
    policy = qc.FixedPointAmplification(delta=0.4, min_fraction=0.1)
    rounds = 15
    result = qc.PQRRT(backend=qc.StatevectorBackend(0), workers=workers, shared_database=shared,
                      search_policy=policy, seed=4).plan(clutter, max_rounds=rounds)
    m = result.metrics
    searches = workers * rounds
    assert m.databases == rounds * (1 if shared else workers)
    assert m.quantum_oracle_calls == policy.iterates * searches
    assert m.verification_calls == searches
    assert m.oracle_calls == m.quantum_oracle_calls + m.verification_calls
    assert m.critical_path_oracle_calls == (policy.iterates + 1) * rounds
    assert m.nodes + m.duplicates + m.rejected == m.verification_calls
    assert m.nodes > 0


def test_qrrt_with_fixed_point_on_aer(clutter):
    policy = qc.FixedPointAmplification(delta=0.5, min_fraction=0.1)
    result = qc.QRRT(backend=qc.AerBackend(seed=1), num_qubits=6, search_policy=policy,
                     seed=3).plan(clutter, max_rounds=6)
    m = result.metrics
    assert m.quantum_oracle_calls == policy.iterates * m.rounds
    assert m.oracle_calls == (policy.iterates + 1) * m.rounds == m.critical_path_oracle_calls


def test_registry_names_and_bad_settings():
    assert POLICIES.create("fixed-point") == qc.FixedPointAmplification()
    assert POLICIES.create("fixed-point:0.3") == qc.FixedPointAmplification(delta=0.3)
    with pytest.raises(ValueError, match="fixed-point:DELTA needs a number"):
        POLICIES.create("fixed-point:abc")
    with pytest.raises(ValueError, match="delta must be in"):
        POLICIES.create("fixed-point:1")
    with pytest.raises(ValueError, match="delta must be"):
        qc.FixedPointAmplification(delta=0.0)
    with pytest.raises(TypeError, match="delta must be"):
        qc.FixedPointAmplification(delta="0.3")
    with pytest.raises(ValueError, match="min_fraction must be"):
        qc.FixedPointAmplification(min_fraction=1.5)
    with pytest.raises(ValueError, match="length_rule must be one of"):
        qc.FixedPointAmplification(length_rule="short")


@pytest.mark.parametrize("length_rule", ["paper", "tight"])
@pytest.mark.parametrize("delta, min_fraction", [(0.5, 1e-12), (1e-300, 1e-6), (0.5, 1e-300)])
def test_more_iterates_than_a_search_runs_are_refused_at_construction(delta, min_fraction, length_rule):
    """Refused when the policy is made, not at the plan's first search (where it was)."""
    with pytest.raises(ValueError, match=rf"delta = {delta} and min_fraction = {min_fraction} need l = \d+ "
                                         r"iterates per search, more than the 100000"):
        qc.FixedPointAmplification(delta, min_fraction, length_rule=length_rule)
