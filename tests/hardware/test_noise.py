"""Noisy Grover search: zero noise gives the ideal statistics, noisy shots agree with the exact
density matrix, and the white-noise and Lemma 4 mappings do what they say."""

import sys

import numpy as np
import pytest
from qiskit import QuantumCircuit
from qiskit.quantum_info import Statevector
from tolerances import binomial_counts, within_binomial

from qrrt_circuits import LookupOracle
from qrrt_circuits.hardware import noise
from qrrt_circuits.probability import good_probability, prob_true_solution
from qrrt_circuits.search.backends.noisy import depolarizing_backend
from qrrt_circuits.search.circuits import grover_circuit


def _marks(n, marked, seed=0):
    marks = np.zeros(1 << n, dtype=bool)
    marks[np.random.default_rng(seed).choice(1 << n, marked, replace=False)] = True
    return marks


@pytest.mark.parametrize("method", ["statevector", "density_matrix"])
def test_zero_noise_gives_the_ideal_success_rate(method):
    marks, k, shots = _marks(4, 2), 2, 2000
    backend = depolarizing_backend(0.0, 0.0, method=method)
    result = backend.search(LookupOracle(marks), k, shots=shots, seed=11)
    hits = int(marks[result.indices].sum())
    assert within_binomial(hits, shots, good_probability(16, 2, k))
    assert result.oracle_calls == k * shots
    assert any("noise: depolarizing p1=0 (sx, x), p2=0 (cx)" in label for label in backend.labels())


def test_zero_noise_density_matrix_equals_the_exact_statevector():
    marks, k = _marks(4, 3, seed=2), 1
    compiled = noise.transpiled_grover(marks, k)
    exact = Statevector(grover_circuit(marks, k, measure=False)).probabilities()
    noisy = noise.noisy_index_distribution(compiled, noise.depolarizing_noise_model(0.0, 0.0), 4)
    np.testing.assert_allclose(noisy, exact, atol=1e-9)


@pytest.mark.parametrize("method", ["statevector", "density_matrix"])
@pytest.mark.parametrize("n", [3, 4])
def test_noisy_shots_agree_with_the_density_matrix(n, method):
    marks, k, shots = _marks(n, 1, seed=n), 2 if n == 4 else 1, 1500
    p1, p2 = 0.003, 0.03
    exact = noise.noisy_index_distribution(noise.transpiled_grover(marks, k),
                                           noise.depolarizing_noise_model(p1, p2), n)
    expected = float(exact[marks].sum())
    ideal = good_probability(1 << n, 1, k)
    assert expected < ideal - 0.05  # the noise is large enough to matter
    result = depolarizing_backend(p1, p2, method=method).search(LookupOracle(marks), k, shots=shots, seed=5)
    hits = int(marks[result.indices].sum())
    assert within_binomial(hits, shots, expected)


def test_one_depolarized_cx_is_exactly_the_white_noise_mixture():
    # a single 2-qubit depolarizing channel on a 2-qubit register: (1 - p) rho + p I/4
    circuit = QuantumCircuit(2)
    circuit.cx(0, 1)
    circuit.x(0)
    p2 = 0.2
    distribution = noise.noisy_index_distribution(circuit, noise.depolarizing_noise_model(0.0, p2), 2)
    ideal = np.array([0.0, 1.0, 0.0, 0.0])  # |01>: index 1
    np.testing.assert_allclose(distribution, (1 - p2) * ideal + p2 / 4, atol=1e-12)
    assert noise.white_noise_fidelity(0, 1, 0.0, p2) == pytest.approx(1 - p2)
    assert noise.noisy_gate_counts(circuit) == (1, 1)


def test_white_noise_approximation_limits():
    assert noise.white_noise_success(64, 4, 1, 1.0) == pytest.approx(good_probability(64, 4, 1))
    assert noise.white_noise_success(64, 4, 1, 0.0) == pytest.approx(4 / 64)


def test_effective_false_positive_rate_recovers_a_false_positive_oracle():
    # an oracle with m = 4 true marks and f = 6 false ones over N = 64 entries (Lemma 4, m2 = 0)
    size, true_marked, false_marked, k = 64, 4, 6, 1
    marked = true_marked + false_marked
    measured = prob_true_solution(size, marked, true_marked, 0, good_probability(size, marked, k))
    q = noise.effective_false_positive_rate(size, true_marked, k, measured)
    assert q == pytest.approx(false_marked / (size - true_marked), abs=2e-3)
    assert noise.effective_false_positive_rate(size, true_marked, k, good_probability(size, true_marked, k)) == 0.0


def test_wrong_answer_collision_of_uniform_and_concentrated_errors():
    marks = _marks(5, 4)
    uniform = np.full(32, 1 / 32)
    assert noise.wrong_answer_collision(uniform, marks) == pytest.approx(1 / 28)
    concentrated = np.where(marks, 0.2, 0.0)
    wrong = np.flatnonzero(~marks)[:2]
    concentrated[wrong] = 0.1
    assert noise.wrong_answer_collision(concentrated, marks) == pytest.approx(0.5)


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="p1"):
        noise.depolarizing_noise_model(1.5, 0.0)
    with pytest.raises(ValueError, match="p2"):
        depolarizing_backend(0.0, -0.1)
    with pytest.raises(ValueError, match="method"):
        depolarizing_backend(0.0, 0.0, method="mps")


def test_unknown_fake_device_is_refused():
    pytest.importorskip("qiskit_ibm_runtime")
    with pytest.raises(ValueError, match="device"):
        noise.fake_device("FakeMelbourne")


def test_missing_extra_is_named(monkeypatch):
    monkeypatch.setitem(sys.modules, "qiskit_ibm_runtime", None)  # import fails as if not installed
    with pytest.raises(noise.MissingExtraError, match=r"pip install 'qrrt-circuits\[noise\]'"):
        noise.available_fake_device()
    assert not noise.has_fake_devices()


def test_fake_device_is_heavy_hex():
    pytest.importorskip("qiskit_ibm_runtime")
    device = noise.fake_device()
    degrees = np.bincount(np.array(list(device.coupling_map.get_edges())).ravel())
    assert device.num_qubits >= 100 and degrees.max() <= 6  # heavy hex: at most 3 neighbours (edges both ways)


def test_fake_device_backend_searches_on_the_device():
    pytest.importorskip("qiskit_ibm_runtime")
    from qrrt_circuits.search.backends.noisy import fake_device_backend

    backend = fake_device_backend()
    marks, shots = _marks(3, 1, seed=1), 200
    result = backend.search(LookupOracle(marks), 1, shots=shots, seed=3)
    compiled = backend.compiled(LookupOracle(marks), 1)
    assert set(compiled.count_ops()) <= set(noise.fake_device().operation_names) | {"barrier"}
    hits = int(marks[result.indices].sum())
    # the calibrated noise may lower the ideal sin^2(3 theta) = 0.78, not raise it, and a 3-qubit
    # search on the device still beats a uniform guess (1/8)
    assert binomial_counts(shots, 1 / 8)[1] < hits <= binomial_counts(shots, good_probability(8, 1, 1))[1]
    assert any("calibration snapshot" in label for label in backend.labels())
