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
    result = backend.search(qc.LookupOracle(marks), k, shots=shots)
    assert result.indices.shape == (shots,)
    assert result.oracle_calls == k * shots
    p = success_probability(2**n, m, k)
    sigma = math.sqrt(p * (1 - p) / shots)
    assert abs(marks[result.indices].mean() - p) <= 5 * sigma + 1e-12


@pytest.mark.parametrize("backend_name", ALL_BACKENDS)
def test_marked_outcomes_are_uniform(backend_name):
    backend = make_backend(backend_name, seed=5)
    marks = random_marks(np.random.default_rng(1), 6, 8)
    result = backend.search(qc.LookupOracle(marks), 2, shots=4000)
    hits = result.indices[marks[result.indices]]
    counts = np.bincount(hits, minlength=64)[marks]
    assert stats.chisquare(counts).pvalue > 1e-4


@pytest.mark.parametrize("backend_name", ALL_BACKENDS)
def test_no_marked_and_all_marked(backend_name):
    backend = make_backend(backend_name, seed=2)
    none = np.zeros(16, dtype=bool)
    result = backend.search(qc.LookupOracle(none), 3, shots=1600)
    counts = np.bincount(result.indices, minlength=16)
    assert stats.chisquare(counts).pvalue > 1e-4  # uniform: Grover does nothing when m = 0
    every = np.ones(16, dtype=bool)
    assert every[backend.search(qc.LookupOracle(every), 3, shots=200).indices].all()


@pytest.mark.parametrize("backend_name", BACKENDS + ["statevector-iterated"])
def test_same_seed_same_indices(backend_name):
    marks = random_marks(np.random.default_rng(0), 5, 4)
    a = make_backend(backend_name, seed=42)
    b = make_backend(backend_name, seed=42)
    c = make_backend(backend_name, seed=43)
    first = [a.search(qc.LookupOracle(marks), 1, shots=64).indices for _ in range(3)]
    second = [b.search(qc.LookupOracle(marks), 1, shots=64).indices for _ in range(3)]
    assert all(np.array_equal(x, y) for x, y in zip(first, second, strict=True))
    assert not np.array_equal(first[0], c.search(qc.LookupOracle(marks), 1, shots=64).indices)


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


def test_ranked_indices_name_each_class_rank():
    """Every rank of each class maps to that class's entry of that rank, shots in order."""
    from qrrt_circuits.search.backends.statevector import _ranked_indices

    marks = np.zeros(32, dtype=bool)
    marks[[0, 3, 4, 5, 20, 31]] = True
    marked, unmarked = np.flatnonzero(marks), np.flatnonzero(~marks)
    rng = np.random.default_rng(3)
    good = rng.random(200) < 0.4
    good_ranks = rng.integers(0, marked.size, int(good.sum()))
    other_ranks = rng.integers(0, unmarked.size, int((~good).sum()))
    expected = np.empty(200, dtype=np.int64)
    expected[good], expected[~good] = marked[good_ranks], unmarked[other_ranks]
    assert np.array_equal(_ranked_indices(marks, good, good_ranks, other_ranks), expected)
    every = np.arange(unmarked.size)
    assert np.array_equal(_ranked_indices(marks, np.zeros(every.size, bool), every[:0], every), unmarked)
    every = np.arange(marked.size)
    assert np.array_equal(_ranked_indices(marks, np.ones(every.size, bool), every, every[:0]), marked)


@pytest.mark.parametrize("backend_name", ALL_BACKENDS)
def test_bad_input(backend_name):
    backend = make_backend(backend_name, seed=0)
    with pytest.raises(ValueError, match="power of two"):
        backend.search(qc.LookupOracle(np.zeros(12, bool)), 1, 1)
    with pytest.raises(ValueError, match="iterations"):
        backend.search(qc.LookupOracle(np.zeros(8, bool)), -1, 1)
    with pytest.raises(ValueError, match="shots"):
        backend.search(qc.LookupOracle(np.zeros(8, bool)), 1, 0)
    with pytest.raises(ValueError, match="num_qubits"):
        backend.check_qubits(backend.max_qubits + 1)


def test_statevector_memory_limit_is_checked_before_allocating():
    backend = qc.StatevectorBackend(seed=0, max_qubits=10)
    assert backend.max_qubits == 10
    with pytest.raises(ValueError, match=r"num_qubits = 11 .*1\.\.10"):
        backend.search(qc.LookupOracle(np.zeros(2**11, bool)), 1, 1)


def test_twenty_qubit_ideal_search():
    backend = qc.StatevectorBackend(seed=1)
    marks = random_marks(np.random.default_rng(0), 20, 50)
    k = qc.probability.optimal_iterations(2**20, 50)
    result = backend.search(qc.LookupOracle(marks), k, shots=400)
    p = success_probability(2**20, 50, k)
    assert within_binomial(int(marks[result.indices].sum()), 400, p)


def test_noisy_aer_backend_loses_amplification():
    from qiskit_aer.noise import NoiseModel, depolarizing_error

    noise = NoiseModel()
    noise.add_all_qubit_quantum_error(depolarizing_error(0.05, 1), ["h", "x"])
    marks = random_marks(np.random.default_rng(2), 5, 1)
    ideal = marks[qc.AerBackend(seed=1).search(qc.LookupOracle(marks), 4, shots=2000).indices].mean()
    noisy = marks[qc.AerBackend(seed=1, noise_model=noise).search(qc.LookupOracle(marks), 4, shots=2000).indices].mean()
    # the ideal rate is sin^2(9 theta) for N = 32, m = 1; the noisy one must fall below it by more
    # than the binomial noise of the two estimates allows
    assert within_binomial(int(round(ideal * 2000)), 2000, success_probability(32, 1, 4))
    assert ideal - noisy > z_bound() * difference_sigma(ideal, 2000, noisy, 2000)


def test_sampler_backend_transpiles_once_per_shape():
    from qiskit_aer.primitives import SamplerV2

    backend = qc.SamplerBackend(SamplerV2(seed=1))
    marks = random_marks(np.random.default_rng(0), 4, 2)
    backend.search(qc.LookupOracle(marks), 1, 10)
    backend.search(qc.LookupOracle(marks), 1, 10)
    assert backend.transpile_count == 1
    backend.search(qc.LookupOracle(marks), 2, 10)
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
    compiled = backend.compiled(qc.LookupOracle(marks), 1)
    assert set(compiled.count_ops()) <= set(fake.operation_names) | {"measure", "barrier"}
    shots = 2000
    rate = marks[backend.search(qc.LookupOracle(marks), 1, shots=shots).indices].mean()
    assert 0.25 + 10 * math.sqrt(0.25 * 0.75 / shots) < rate < 1.0


def test_sampler_backend_is_seeded_per_search_when_the_sampler_allows_it(clutter):
    """Aer's SamplerV2 without a seed of its own takes each search's seed: two plans with one
    planner seed are identical. A sampler with a fixed seed seeds itself, and results say so."""
    from qiskit_aer.primitives import SamplerV2

    def plan(sampler):
        return qc.PQRRT(backend=qc.SamplerBackend(sampler), num_qubits=5, workers=3,
                        seed=11).plan(clutter, max_rounds=8)

    a, b = plan(SamplerV2()), plan(SamplerV2())
    assert np.array_equal(a.nodes, b.nodes) and a.metrics.oracle_calls == b.metrics.oracle_calls
    assert not any("seeds itself" in label for label in a.labels)
    fixed = plan(SamplerV2(seed=3))
    assert any("the sampler (SamplerV2) seeds itself" in label for label in fixed.labels)
    # the per-search seeds reach the simulator: two different planner seeds give different draws
    marks = random_marks(np.random.default_rng(0), 6, 20)
    backend = qc.SamplerBackend(SamplerV2())
    first = backend.search(qc.LookupOracle(marks), 1, shots=64, seed=1).indices
    assert np.array_equal(first, backend.search(qc.LookupOracle(marks), 1, shots=64, seed=1).indices)
    assert not np.array_equal(first, backend.search(qc.LookupOracle(marks), 1, shots=64, seed=2).indices)


def test_unsupported_aer_methods_are_refused_with_the_reason():
    with pytest.raises(ValueError, match="method='density_matrix' is not supported: .*mcphase"):
        qc.AerBackend(method="density_matrix")


def test_search_sizes_have_documented_limits():
    backend = qc.StatevectorBackend(seed=0)
    marks = np.zeros(16, dtype=bool)
    with pytest.raises(ValueError, match=r"shots must be an integer in \[1, 10000000\]"):
        backend.search(qc.LookupOracle(marks), 1, shots=10**9)
    with pytest.raises(ValueError, match=r"iterations must be an integer in \[0, 100000\]"):
        backend.search(qc.LookupOracle(marks), 10**6, shots=1)
    with pytest.raises(ValueError, match="device must be one of"):
        qc.AerBackend(device="TPU")


def _aer_random_marks(num_qubits: int, seed: int, fraction: float = 0.2) -> np.ndarray:
    rng = np.random.default_rng(seed)
    marks = rng.random(1 << num_qubits) < fraction
    marks[rng.integers(1 << num_qubits)] = True
    return marks


def _run_memory(simulator, circuit, shots: int, seed: int, threads: int = 1) -> list[int]:
    """The indices ``AerSimulator.run`` measures on ``circuit``, shot by shot."""
    result = simulator.run(circuit, shots=shots, seed_simulator=seed, memory=True,
                           max_parallel_threads=threads).result()
    return [int(word, 2) for word in result.get_memory(0)]


@pytest.mark.parametrize("num_qubits", [1, 2, 3, 5, 8, 13, 14])
@pytest.mark.parametrize("synthesis", ["diagonal", "mcz", "auto"])
def test_aer_search_measures_what_aersimulator_run_measures_on_its_circuit(num_qubits, synthesis):
    """``AerBackend.search`` is ``AerSimulator.run`` of ``aer_grover_circuit`` with the search's
    simulator seed (the first ``integers(0, 2**31 - 1)`` of its seed), word for word: k = 0 .. 4,
    shot counts 1 (Aer's single-shot measurement) to 64 (its sampler), both sides of Aer's
    parallel threshold (14 qubits)."""
    from qrrt_circuits.search.circuits import aer_grover_circuit

    backend = qc.AerBackend(seed=3, synthesis=synthesis, max_parallel_threads=0)  # (all cores from 14 qubits)
    rng = np.random.default_rng(num_qubits)
    fraction = 0.3 if synthesis != "mcz" or num_qubits < 6 else 4 / (1 << num_qubits)  # mcz: few marked
    for case in range(4 if num_qubits < 10 else 2):
        marks = _aer_random_marks(num_qubits, case, fraction)
        iterations, shots = case % 5, (1, 2, 64)[case % 3]
        seed = int(rng.integers(0, 2**31 - 1))
        measured = backend.search(qc.LookupOracle(marks), iterations, shots=shots, seed=seed).indices
        circuit = aer_grover_circuit(marks, iterations, synthesis=synthesis)
        expected = _run_memory(backend.simulator, circuit, shots, backend._first_integer(seed, 2**31 - 1),
                               backend.threads_for(num_qubits))
        assert measured.dtype == np.int64 and measured.tolist() == expected


def test_aer_mcz_form_global_phase_and_x_strings_measure_the_circuits_words():
    """Most entries marked: the mcz form flips the unmarked ones, with a global phase of pi per
    oracle call; a sparse oracle's X-strings and mcphase gates; both run as their circuit."""
    from qrrt_circuits.search.circuits import aer_grover_circuit

    backend = qc.AerBackend(seed=0, synthesis="mcz")
    many = np.ones(8, dtype=bool)
    many[[2, 5]] = False
    for marks in (many, ~many):
        for iterations in (1, 2, 3):
            circuit = aer_grover_circuit(marks, iterations, synthesis="mcz")
            assert {instruction.operation.name for instruction in circuit.data} >= {"pauli", "mcphase"}
            for seed in range(3):
                expected = _run_memory(backend.simulator, circuit, 32, backend._first_integer(seed, 2**31 - 1))
                measured = backend.search(qc.LookupOracle(marks), iterations, shots=32, seed=seed)
                assert measured.indices.tolist() == expected
    assert aer_grover_circuit(many, 1, synthesis="mcz").global_phase != 0


def test_aer_backend_uses_only_documented_aer_names():
    """The Aer backend reaches qiskit-aer through ``AerSimulator`` (its ``run``, options and
    configuration) only: no private module or name of qiskit-aer appears in its source."""
    import inspect
    import re

    from qrrt_circuits.search import aer_circuits
    from qrrt_circuits.search.backends import aer

    for module in (aer, aer_circuits):
        source = inspect.getsource(module)
        assert not re.search(r"controller_wrappers|AerCircuit|CircuitHeader|AerStateWrapper|aer_compiler"
                             r"|qiskit_aer\.backends|_execute_circuits", source), module.__name__
        assert not re.search(r"simulator\._", source), module.__name__


def test_a_noise_model_set_later_acts_on_the_compact_circuit():
    """With a noise model given to the constructor the gate-by-gate circuit runs; one set on the
    simulator later acts on the compact circuit, run through ``AerSimulator.run`` as it is."""
    from qiskit_aer.noise import NoiseModel, depolarizing_error

    from qrrt_circuits.search.circuits import aer_grover_circuit

    noise = NoiseModel()
    noise.add_all_qubit_quantum_error(depolarizing_error(0.9, 4), ["mcphase"])
    later = qc.AerBackend(seed=2, synthesis="mcz")
    later.simulator.set_options(noise_model=noise)
    marks = np.zeros(16, dtype=bool)
    marks[3] = True
    measured = later.search(qc.LookupOracle(marks), 3, shots=64, seed=1).indices
    expected = _run_memory(later.simulator, aer_grover_circuit(marks, 3, synthesis="mcz"), 64,
                           later._first_integer(1, 2**31 - 1))
    np.testing.assert_array_equal(measured, expected)
    assert marks[measured].mean() < 0.9  # the noise acts (noiseless: sin^2(7 theta) = 0.96)


def test_a_failed_aer_simulation_raises():
    backend = qc.AerBackend(seed=0)
    backend.simulator.set_options(max_memory_mb=1)
    with pytest.raises(RuntimeError, match="AerSimulator failed"):
        backend.search(qc.LookupOracle(np.ones(2**17, dtype=bool)), 0, 1, seed=1)  # a 2 MiB state
    assert backend.search(qc.LookupOracle(np.ones(2, dtype=bool)), 1, 3, seed=1).indices.shape == (3,)


def test_aer_max_qubits_follows_the_simulators_configuration():
    """``AerBackend.max_qubits`` is ``configuration().n_qubits`` after every way of changing it,
    and after a pickle round trip; a search above it is refused."""
    import pickle

    backend = qc.AerBackend()
    assert backend.max_qubits == backend.simulator.configuration().n_qubits
    backend.simulator.set_max_qubits(3)
    assert backend.max_qubits == 3
    marks = np.zeros(16, dtype=bool)
    marks[3] = True
    with pytest.raises(ValueError, match="1..3 qubits"):
        backend.search(qc.LookupOracle(marks), 1, 2, seed=1)
    again = pickle.loads(pickle.dumps(backend))
    assert again.max_qubits == 3
    backend.simulator.clear_options()
    assert backend.max_qubits == backend.simulator.configuration().n_qubits


def test_aer_threads_searching_at_once_measure_what_one_thread_does():
    from concurrent.futures import ThreadPoolExecutor

    backend = qc.AerBackend(seed=0)
    cases = [(_aer_random_marks(3 + seed % 5, seed), seed % 4, seed) for seed in range(16)]

    def one(case):
        marks, iterations, seed = case
        return backend.search(qc.LookupOracle(marks), iterations, shots=16, seed=seed).indices.tolist()

    alone = [one(case) for case in cases]
    with ThreadPoolExecutor(max_workers=4) as pool:
        assert list(pool.map(one, cases)) == alone


def test_aer_describe_records_method_device_and_synthesis():
    from qiskit_aer.noise import NoiseModel, depolarizing_error

    assert qc.AerBackend().describe() == "aer (method=statevector, device=CPU, synthesis=auto)"
    assert (qc.AerBackend(method="automatic", synthesis="mcz").describe()
            == "aer (method=automatic, device=CPU, synthesis=mcz)")
    noise = NoiseModel()
    noise.add_all_qubit_quantum_error(depolarizing_error(0.05, 1), ["h"])
    assert qc.AerBackend(noise_model=noise).describe() == (
        "aer (method=statevector, device=CPU, synthesis=auto, noise model, gate-by-gate circuit)")
    later = qc.AerBackend(synthesis="diagonal")
    later.simulator.set_options(noise_model=noise)
    assert later.describe() == "aer (method=statevector, device=CPU, synthesis=diagonal, noise model)"


def _aer_search_words(marks: np.ndarray, seed: int) -> list[int]:
    return qc.AerBackend(seed=0).search(qc.LookupOracle(marks), 2, shots=8, seed=seed).indices.tolist()


@pytest.mark.skipif("fork" not in __import__("multiprocessing").get_all_start_methods(), reason="no fork")
@pytest.mark.filterwarnings("ignore:This process .* is multi-threaded:DeprecationWarning")
def test_a_process_forked_after_aer_searches_searches_too():
    """``AerSimulator.run`` hands its work to a job thread, which a forked child does not inherit:
    a child forked after the parent's searches searches too, and measures what the parent does
    (this needs a qiskit-aer whose job executor is fork-safe)."""
    import multiprocessing

    marks = _aer_random_marks(6, 2)
    parent = _aer_search_words(marks, 11)
    with multiprocessing.get_context("fork").Pool(2) as pool:
        children = pool.starmap_async(_aer_search_words, [(marks, 11)] * 2).get(timeout=120)
    assert children == [parent, parent]


def test_aer_threads_follow_the_free_cores_from_14_qubits(monkeypatch):
    """By default a circuit of 14 qubits or more runs on the cores other work leaves free (usable
    cores less the load beyond this process's own thread where no CPU time has been measured, to
    the nearest core, at least 1); below 14 qubits on one thread; an explicit limit (0: all cores)
    is kept whatever the load."""
    import os

    from qrrt_circuits._support import free_cores

    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: set(range(8)))
    monkeypatch.setattr(free_cores, "_METER", free_cores.BusyMeter(lambda: None))  # (no counters: the load)
    monkeypatch.setattr(free_cores, "PROC_CGROUP", "/nonexistent/cgroup")  # (no CPU quota)
    auto, all_cores, two = qc.AerBackend(seed=0), qc.AerBackend(max_parallel_threads=0), qc.AerBackend(
        max_parallel_threads=2)
    for load, expected in ((0.3, 8), (1.0, 8), (1.49, 8), (1.51, 7), (3.5, 6), (3.6, 5), (7.2, 2), (7.6, 1), (40.0, 1)):
        monkeypatch.setattr(os, "getloadavg", lambda load=load: (load, load, load))
        assert free_cores.free_cores() == expected
        assert auto.threads_for(16) == expected and auto.threads_for(13) == 1
        assert all_cores.threads_for(16) == 0 and two.threads_for(16) == 2 and two.threads_for(8) == 1
    marks = np.zeros(1 << 14, dtype=bool)
    marks[[3, 999]] = True
    from qrrt_circuits.probability import optimal_iterations, success_probability

    k = optimal_iterations(marks.size, 2)
    found = auto.search(qc.LookupOracle(marks), k, shots=64, seed=1).indices  # one thread under this load
    p = success_probability(marks.size, 2, k)
    assert np.isin(found, [3, 999]).mean() >= p - 4 * np.sqrt(p * (1 - p) / 64) - 1e-9
