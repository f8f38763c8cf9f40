import math

import numpy as np
import pytest
from conftest import ALL_BACKENDS, BACKENDS, make_backend, random_marks
from scipy import stats
from tolerances import difference_sigma, within_binomial, z_bound

import qrrt_circuits as qc
from qrrt_circuits.probability import success_probability


@pytest.mark.parametrize("backend_name", ALL_BACKENDS)
@pytest.mark.parametrize("n, m, k", [(5, 3, 1), (5, 3, 2), (6, 1, 6), (4, 5, 1)])
def test_success_frequency_matches_theory(backend_name, n, m, k):
    backend = make_backend(backend_name, seed=17)
    marks = random_marks(np.random.default_rng(n * 100 + m), n, m)
    shots = 3000
    result = backend.search(marks, k, shots=shots)
    assert result.indices.shape == (shots,)
    assert result.oracle_calls == k * shots
    p = success_probability(2**n, m, k)
    sigma = math.sqrt(p * (1 - p) / shots)
    assert abs(marks[result.indices].mean() - p) <= 5 * sigma + 1e-12


@pytest.mark.parametrize("backend_name", ALL_BACKENDS)
def test_marked_outcomes_are_uniform(backend_name):
    backend = make_backend(backend_name, seed=5)
    marks = random_marks(np.random.default_rng(1), 6, 8)
    result = backend.search(marks, 2, shots=4000)
    hits = result.indices[marks[result.indices]]
    counts = np.bincount(hits, minlength=64)[marks]
    assert stats.chisquare(counts).pvalue > 1e-4


@pytest.mark.parametrize("backend_name", ALL_BACKENDS)
def test_no_marked_and_all_marked(backend_name):
    backend = make_backend(backend_name, seed=2)
    none = np.zeros(16, dtype=bool)
    result = backend.search(none, 3, shots=1600)
    counts = np.bincount(result.indices, minlength=16)
    assert stats.chisquare(counts).pvalue > 1e-4  # uniform: Grover does nothing when m = 0
    every = np.ones(16, dtype=bool)
    assert every[backend.search(every, 3, shots=200).indices].all()


@pytest.mark.parametrize("backend_name", BACKENDS + ["statevector-iterated"])
def test_same_seed_same_indices(backend_name):
    marks = random_marks(np.random.default_rng(0), 5, 4)
    a = make_backend(backend_name, seed=42)
    b = make_backend(backend_name, seed=42)
    c = make_backend(backend_name, seed=43)
    first = [a.search(marks, 1, shots=64).indices for _ in range(3)]
    second = [b.search(marks, 1, shots=64).indices for _ in range(3)]
    assert all(np.array_equal(x, y) for x, y in zip(first, second, strict=True))
    assert not np.array_equal(first[0], c.search(marks, 1, shots=64).indices)


def test_statevector_closed_form_equals_iteration():
    rng = np.random.default_rng(9)
    for n in (1, 3, 7):
        for m in (0, 1, 2**n // 3, 2**n):
            marks = random_marks(rng, n, m)
            for k in (0, 1, 4):
                amps = qc.StatevectorBackend.amplitudes(marks, k)
                p = success_probability(2**n, m, k)
                assert np.sum(amps[marks] ** 2) == pytest.approx(p, abs=1e-12)
                assert np.sum(amps**2) == pytest.approx(1.0)


def test_kth_unmarked_ranks():
    from qrrt_circuits.search.statevector import _kth_unmarked

    marks = np.zeros(32, dtype=bool)
    marks[[0, 3, 4, 5, 20, 31]] = True
    unmarked = np.flatnonzero(~marks)
    ranks = np.arange(len(unmarked))
    assert np.array_equal(_kth_unmarked(np.flatnonzero(marks), ranks), unmarked)


@pytest.mark.parametrize("backend_name", ALL_BACKENDS)
def test_bad_input(backend_name):
    backend = make_backend(backend_name, seed=0)
    with pytest.raises(ValueError, match="power of two"):
        backend.search(np.zeros(12, bool), 1, 1)
    with pytest.raises(ValueError, match="iterations"):
        backend.search(np.zeros(8, bool), -1, 1)
    with pytest.raises(ValueError, match="shots"):
        backend.search(np.zeros(8, bool), 1, 0)
    with pytest.raises(ValueError, match="num_qubits"):
        backend.check_qubits(backend.max_qubits + 1)


def test_statevector_memory_limit_is_checked_before_allocating():
    backend = qc.StatevectorBackend(seed=0, max_qubits=10)
    assert backend.max_qubits == 10
    with pytest.raises(ValueError, match=r"num_qubits = 11 .*1\.\.10"):
        backend.search(np.zeros(2**11, bool), 1, 1)


def test_twenty_qubit_ideal_search():
    backend = qc.StatevectorBackend(seed=1)
    marks = random_marks(np.random.default_rng(0), 20, 50)
    k = qc.probability.optimal_iterations(2**20, 50)
    result = backend.search(marks, k, shots=400)
    p = success_probability(2**20, 50, k)
    assert within_binomial(int(marks[result.indices].sum()), 400, p)


def test_noisy_aer_backend_loses_amplification():
    from qiskit_aer.noise import NoiseModel, depolarizing_error

    noise = NoiseModel()
    noise.add_all_qubit_quantum_error(depolarizing_error(0.05, 1), ["h", "x"])
    marks = random_marks(np.random.default_rng(2), 5, 1)
    ideal = marks[qc.AerBackend(seed=1).search(marks, 4, shots=2000).indices].mean()
    noisy = marks[qc.AerBackend(seed=1, noise_model=noise).search(marks, 4, shots=2000).indices].mean()
    # the ideal rate is sin^2(9 theta) for N = 32, m = 1; the noisy one must fall below it by more
    # than the binomial noise of the two estimates allows
    assert within_binomial(int(round(ideal * 2000)), 2000, success_probability(32, 1, 4))
    assert ideal - noisy > z_bound() * difference_sigma(ideal, 2000, noisy, 2000)


def test_sampler_backend_transpiles_once_per_shape():
    from qiskit_aer.primitives import SamplerV2

    backend = qc.SamplerBackend(SamplerV2(seed=1))
    marks = random_marks(np.random.default_rng(0), 4, 2)
    backend.search(marks, 1, 10)
    backend.search(marks, 1, 10)
    assert backend.transpile_count == 1
    backend.search(marks, 2, 10)
    assert backend.transpile_count == 2


def test_sampler_backend_on_a_noisy_fake_backend():
    """A fake device (GenericBackendV2: its basis, coupling map and noise) through BackendSamplerV2:
    the circuit is transpiled to the device's basis and noise lowers, but does not erase, the
    amplification."""
    from qiskit.primitives import BackendSamplerV2
    from qiskit.providers.fake_provider import GenericBackendV2
    from qiskit_aer import AerSimulator

    fake = GenericBackendV2(num_qubits=5, seed=3)
    backend = qc.SamplerBackend(BackendSamplerV2(backend=AerSimulator.from_backend(fake, seed_simulator=5)),
                                backend=fake)
    marks = np.zeros(8, dtype=bool)
    marks[[2, 5]] = True  # k = 1 is exact here: sin^2(3 theta) = 1
    compiled = backend.compiled(marks, 1)
    assert set(compiled.count_ops()) <= set(fake.operation_names) | {"measure", "barrier"}
    shots = 2000
    rate = marks[backend.search(marks, 1, shots=shots).indices].mean()
    assert 0.25 + 10 * math.sqrt(0.25 * 0.75 / shots) < rate < 1.0


def test_sampler_backend_is_seeded_per_search_when_the_sampler_allows_it(clutter):
    """Aer's SamplerV2 without a seed of its own takes each search's seed: two plans with one
    planner seed are identical. A sampler with a fixed seed seeds itself, and results say so."""
    from qiskit_aer.primitives import SamplerV2

    def plan(sampler):
        return qc.PQRRT(clutter, backend=qc.SamplerBackend(sampler), num_qubits=5, workers=3,
                        seed=11).plan(max_rounds=8)

    a, b = plan(SamplerV2()), plan(SamplerV2())
    assert np.array_equal(a.nodes, b.nodes) and a.metrics.oracle_calls == b.metrics.oracle_calls
    assert not any("seeds itself" in label for label in a.labels)
    fixed = plan(SamplerV2(seed=3))
    assert any("the sampler (SamplerV2) seeds itself" in label for label in fixed.labels)
    # the per-search seeds reach the simulator: two different planner seeds give different draws
    marks = random_marks(np.random.default_rng(0), 6, 20)
    backend = qc.SamplerBackend(SamplerV2())
    first = backend.search(marks, 1, shots=64, seed=1).indices
    assert np.array_equal(first, backend.search(marks, 1, shots=64, seed=1).indices)
    assert not np.array_equal(first, backend.search(marks, 1, shots=64, seed=2).indices)


@pytest.mark.parametrize("method", ["density_matrix", "matrix_product_state"])
def test_unsupported_aer_methods_are_refused_with_the_reason(method):
    with pytest.raises(ValueError, match=f"method='{method}' is not supported: .*mcphase"):
        qc.AerBackend(method=method)


def test_search_sizes_have_documented_limits():
    backend = qc.StatevectorBackend(seed=0)
    marks = np.zeros(16, dtype=bool)
    with pytest.raises(ValueError, match=r"shots must be an integer in \[1, 10000000\]"):
        backend.search(marks, 1, shots=10**9)
    with pytest.raises(ValueError, match=r"iterations must be an integer in \[0, 100000\]"):
        backend.search(marks, 10**6, shots=1)
    with pytest.raises(ValueError, match="device must be one of"):
        qc.AerBackend(device="TPU")
