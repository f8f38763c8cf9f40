"""``aer_direct``: running circuits on AerSimulator's controller directly measures exactly what
``AerSimulator.run`` measures (same words for the same seed), for every circuit form the package
runs, and falls back to Aer's own assembler for anything else."""

from __future__ import annotations

import numpy as np
import pytest
from qiskit import QuantumCircuit
from qiskit.circuit import Parameter
from qiskit_aer import AerSimulator

import qrrt_circuits as qc
from qrrt_circuits.search import aer_direct
from qrrt_circuits.search.aer_circuits import aer_grover_program
from qrrt_circuits.search.circuits import aer_grover_circuit, aer_literal_grover_circuit
from qrrt_circuits.search.fixed_point import IterateSequence, generalized_grover_circuit

pytestmark = pytest.mark.skipif(not aer_direct.DIRECT_AVAILABLE, reason="this qiskit-aer lacks the internals")

SIMULATOR = AerSimulator(method="statevector")


def job_memory(circuit: QuantumCircuit, shots: int, seed: int, threads: int = 1) -> list[str]:
    result = SIMULATOR.run(circuit, shots=shots, seed_simulator=seed, memory=True,
                           max_parallel_threads=threads).result()
    return list(result.results[0].data.memory)


def signature(circuit: QuantumCircuit) -> list:
    """Each instruction's name, qubit and clbit indices and parameters (as numbers), in order."""
    def value(param):
        return param if isinstance(param, str) else np.asarray(param, dtype=complex).round(12).tolist()
    return [(i.operation.name, [circuit.find_bit(q).index for q in i.qubits],
             [circuit.find_bit(c).index for c in i.clbits], [value(p) for p in i.operation.params])
            for i in circuit.data] + [circuit.global_phase]


def random_marks(num_qubits: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    marks = rng.random(1 << num_qubits) < 0.2
    marks[rng.integers(1 << num_qubits)] = True
    return marks


@pytest.mark.parametrize("num_qubits", [1, 2, 3, 5, 7])
@pytest.mark.parametrize("synthesis", ["diagonal", "mcz"])
@pytest.mark.parametrize("iterations", [0, 1, 3])
def test_grover_circuits_measure_the_same_words(num_qubits, synthesis, iterations):
    for seed in range(3):
        circuit = aer_grover_circuit(random_marks(num_qubits, seed), iterations, synthesis=synthesis)
        assert aer_direct.execute(SIMULATOR, circuit, 32, 1000 + seed, 1) == job_memory(circuit, 32, 1000 + seed)


@pytest.mark.parametrize("num_qubits", [1, 3, 5])
def test_literal_and_generalized_circuits_measure_the_same_words(num_qubits):
    marks = random_marks(num_qubits, 7)
    circuits = [aer_literal_grover_circuit(marks, 2),
                generalized_grover_circuit(marks, IterateSequence.fixed_point(delta=0.5, iterates=2)),
                generalized_grover_circuit(marks, IterateSequence.grover(2), synthesis="mcz")]
    for circuit in circuits:
        for seed in (3, 99):
            assert aer_direct.execute(SIMULATOR, circuit, 24, seed, 1) == job_memory(circuit, 24, seed)


def test_the_package_circuits_need_no_aer_assembler(monkeypatch):
    """Every circuit form the backends run is converted here (Aer's generic assembler is never
    called), barriers of the gate-by-gate and fixed-point circuits included."""
    def refuse(*args, **kwargs):
        raise AssertionError("Aer's assembler was called")

    monkeypatch.setattr(aer_direct, "assemble_circuits", refuse)
    marks = random_marks(5, 2)
    for circuit in (aer_grover_circuit(marks, 3, synthesis="diagonal"), aer_grover_circuit(marks, 3, synthesis="mcz"),
                    aer_literal_grover_circuit(marks, 2),
                    generalized_grover_circuit(marks, IterateSequence.fixed_point(delta=0.5, iterates=2))):
        aer_direct.assemble(circuit)
    aer_direct.assemble_program(aer_grover_program(marks, 3))


def test_other_circuits_fall_back_to_aers_assembler(monkeypatch):
    calls = []
    original = aer_direct.assemble_circuits

    def counted(circuits, *args, **kwargs):
        calls.append(len(circuits))
        return original(circuits, *args, **kwargs)

    monkeypatch.setattr(aer_direct, "assemble_circuits", counted)
    theta = Parameter("theta")
    parameterized = QuantumCircuit(1, 1)
    parameterized.h(0)
    parameterized.p(theta, 0)
    parameterized.h(0)
    parameterized.measure(0, 0)
    bound = parameterized.assign_parameters({theta: 0.3})
    assert aer_direct.execute(SIMULATOR, bound, 64, 3, 1) == job_memory(bound, 64, 3)  # converted here
    assert calls == []
    other = QuantumCircuit(3, 3)
    other.h(0)  # converted, then a gate that is not: the whole circuit goes to Aer's assembler
    other.ry(0.7, 0)
    other.cx(0, 1)
    other.ccx(0, 1, 2)
    other.measure(range(3), range(3))
    assert aer_direct.execute(SIMULATOR, other, 40, 5, 1) == job_memory(other, 40, 5)
    assert calls == [1]


def test_a_noisy_simulator_is_refused():
    from qiskit_aer.noise import NoiseModel, depolarizing_error

    noise = NoiseModel()
    noise.add_all_qubit_quantum_error(depolarizing_error(0.1, 1), ["h"])
    circuit = aer_grover_circuit(random_marks(3, 0), 1)
    with pytest.raises(ValueError, match="noise_model"):
        aer_direct.execute(AerSimulator(noise_model=noise), circuit, 4, 1, 1)


def test_aer_backend_results_equal_the_job_path():
    """``AerBackend.search`` through the controller equals the same backend through
    ``AerSimulator.run`` (the path it takes with a noise model), seed for seed."""
    direct = qc.AerBackend(seed=3)
    through_jobs = qc.AerBackend(seed=3)
    through_jobs._use_controller = False
    assert direct._direct
    for seed in range(6):
        marks = random_marks(6, seed)
        a = direct.search(marks, 2, shots=16, seed=seed)
        b = through_jobs.search(marks, 2, shots=16, seed=seed)
        np.testing.assert_array_equal(a.indices, b.indices)


def test_a_noise_model_runs_through_aersimulator_run():
    """With a noise model, given to the constructor or set on the simulator later, circuits go
    through ``AerSimulator.run`` (which prepares the model), so the noise acts."""
    from qiskit_aer.noise import NoiseModel, depolarizing_error

    noise = NoiseModel()
    noise.add_all_qubit_quantum_error(depolarizing_error(0.9, 4), ["mcphase"])
    assert not qc.AerBackend(noise_model=noise)._direct
    later = qc.AerBackend(seed=2, synthesis="mcz")
    assert later._direct
    later.simulator.set_options(noise_model=noise)
    assert not later._direct
    marks = np.zeros(16, dtype=bool)
    marks[3] = True
    measured = later.search(marks, 3, shots=64, seed=1).indices
    seed = later._first_integer(1, 2**31 - 1)
    expected = later.simulator.run(aer_grover_circuit(marks, 3, synthesis="mcz"), shots=64, seed_simulator=seed,
                                   memory=True, max_parallel_threads=1).result().get_memory(0)
    np.testing.assert_array_equal(measured, [int(word, 2) for word in expected])


def test_a_failed_simulation_raises():
    wide = QuantumCircuit(1, 1)
    wide.h(0)
    wide.measure(0, 0)
    simulator = AerSimulator(method="statevector", max_memory_mb=1)
    big = QuantumCircuit(26, 26)
    big.h(range(26))
    big.measure(range(26), range(26))
    with pytest.raises(RuntimeError, match="AerSimulator failed"):
        aer_direct.execute(simulator, big, 1, 1, 1)
    assert len(aer_direct.execute(simulator, wide, 3, 1, 1)) == 3


@pytest.mark.parametrize("num_qubits", [1, 2, 4, 6])
@pytest.mark.parametrize("synthesis", ["diagonal", "mcz"])
def test_a_grover_program_runs_as_its_circuit(num_qubits, synthesis):
    """``execute(program)`` (no QuantumCircuit built) measures what ``AerSimulator.run`` measures
    on ``aer_grover_circuit`` of the same marks, and ``program.circuit()`` is that circuit."""
    for iterations in (0, 1, 4):
        marks = random_marks(num_qubits, iterations)
        program = aer_grover_program(marks, iterations, synthesis)
        circuit = aer_grover_circuit(marks, iterations, synthesis=synthesis)
        assert signature(program.circuit()) == signature(circuit)
        for seed in (0, 17):
            assert aer_direct.execute(SIMULATOR, program, 32, seed, 1) == job_memory(circuit, 32, seed)


def test_the_run_configuration_follows_the_simulators_options():
    """The configuration is made once and reused with a new seed, but made again when the
    simulator's options change (so a changed option is never ignored)."""
    simulator = AerSimulator(method="statevector")
    width = aer_direct._Width(3, 3)
    first = aer_direct._configuration(simulator, width, 4, 11, 1)
    assert first.seed_simulator == 11 and first.precision == "double"
    again = aer_direct._configuration(simulator, width, 4, 12, 1)
    assert again is first and again.seed_simulator == 12
    simulator.set_options(precision="single")
    changed = aer_direct._configuration(simulator, width, 4, 13, 1)
    assert changed is not first and changed.precision == "single" and changed.seed_simulator == 13
    assert aer_direct._configuration(simulator, width, 8, 13, 1) is not changed  # other shots


def test_threads_searching_at_once_measure_what_one_thread_does():
    from concurrent.futures import ThreadPoolExecutor

    circuits = [aer_grover_circuit(random_marks(5, seed), 2) for seed in range(12)]
    alone = [aer_direct.execute(SIMULATOR, circuit, 16, seed, 1) for seed, circuit in enumerate(circuits)]
    with ThreadPoolExecutor(max_workers=4) as pool:
        together = list(pool.map(lambda item: aer_direct.execute(SIMULATOR, item[1], 16, item[0], 1),
                                 enumerate(circuits)))
    assert together == alone


@pytest.mark.parametrize("num_qubits", [1, 2, 3, 6, 8])
@pytest.mark.parametrize("synthesis", ["auto", "diagonal", "mcz"])
def test_assemble_grover_makes_the_programs_circuit(num_qubits, synthesis):
    """``execute_grover`` (the diagonal form assembled from cached call arguments, AerBackend's
    path) measures the words ``execute`` measures on ``aer_grover_program`` of the same marks, for
    every k, including k = 0 and k = 1 (one oracle phase list)."""
    for iterations in (0, 1, 2, 5):
        for seed in range(3):
            marks = random_marks(num_qubits, 10 * iterations + seed)
            program = aer_grover_program(marks, iterations, synthesis)
            assert (aer_direct.execute_grover(SIMULATOR, marks, iterations, synthesis, 48, seed, 1)
                    == aer_direct.execute(SIMULATOR, program, 48, seed, 1))


def test_assemble_grover_refuses_a_noisy_simulator():
    from qiskit_aer.noise import NoiseModel, depolarizing_error

    noise = NoiseModel()
    noise.add_all_qubit_quantum_error(depolarizing_error(0.1, 1), ["h"])
    with pytest.raises(ValueError, match="noise_model"):
        aer_direct.execute_grover(AerSimulator(noise_model=noise), random_marks(3, 0), 1, "diagonal", 4, 1, 1)


def test_max_qubits_follows_the_simulators_configuration():
    """``AerBackend.max_qubits`` (read without copying Aer's configuration) is
    ``configuration().n_qubits`` after every way of changing it, and after a pickle round trip;
    a search above it is refused."""
    import pickle

    backend = qc.AerBackend()
    assert backend.max_qubits == backend.simulator.configuration().n_qubits
    backend.simulator.set_options(method="density_matrix")
    assert backend.max_qubits == backend.simulator.configuration().n_qubits
    backend.simulator.set_options(method="statevector")
    backend.simulator.set_max_qubits(3)
    assert backend.max_qubits == backend.simulator.configuration().n_qubits == 3
    marks = np.zeros(16, dtype=bool)
    marks[3] = True
    with pytest.raises(ValueError, match="1..3 qubits"):
        backend.search(marks, 1, 2, seed=1)
    again = pickle.loads(pickle.dumps(backend))
    assert again.max_qubits == again.simulator.configuration().n_qubits == 3
    backend.simulator.clear_options()
    assert backend.max_qubits == backend.simulator.configuration().n_qubits


@pytest.mark.parametrize(("marks", "iterations"), [
    (np.array([0, 1, 0, 0], dtype=np.uint8), 1),  # not bool: 2 would have counted as marked
    (np.array([True, False, False]), 1),            # not a power of two
    (np.array([True]), 1),                          # n = 0
    (np.array([[True, False]]), 1),                 # not 1-D
    (np.array([True, False]), -1),
    (np.array([True, False]), np.int64(1)),         # not coerced
])
def test_execute_grover_refuses_what_the_backend_would_have_refused(marks, iterations):
    with pytest.raises(ValueError, match="marks|iterations"):
        aer_direct.execute_grover(SIMULATOR, marks, iterations, "diagonal", 4, 1, 1)


def _controller_output(aer, num_qubits: int, shots: int, seed: int) -> dict:
    """The controller's result for ``aer`` without its timings (header, data, shots, seed, status)."""
    config = aer_direct._configuration(SIMULATOR, aer_direct._Width(num_qubits, num_qubits), shots, seed, 1)
    result = SIMULATOR._execute_circuits([aer], None, config)["results"][0]
    return {key: value for key, value in result.items() if key not in ("time_taken", "metadata")}


def test_the_recycled_circuit_measures_what_a_new_one_does():
    """``execute_grover`` refills one ``AerCircuit`` per thread (``_recycled``); over a sequence of
    searches whose n, k, marks, shots and seeds all change from one to the next (so the recycled
    circuit switches header, length and phases), every search measures the words of a new circuit
    (``assemble_grover``) run with the same configuration, and the controller's whole result
    (header included, which the words do not show) is that of the program's circuit
    (``assemble_program``, assembled without ``_fill_grover``)."""
    assert aer_direct.RECYCLABLE  # with the installed qiskit-aer the recycled path is the one taken
    rng = np.random.default_rng(7)
    for case in range(60):
        num_qubits = int(rng.integers(1, 9))
        iterations = int(rng.integers(0, 6))
        shots = int(rng.integers(1, 33))
        marks = random_marks(num_qubits, case)
        seed = int(rng.integers(0, 2**31 - 1))
        fresh = aer_direct.assemble_grover(marks, iterations, "diagonal")
        words = aer_direct._run(SIMULATOR, fresh, aer_direct._Width(num_qubits, num_qubits), shots, seed, 1)
        assert aer_direct.execute_grover(SIMULATOR, marks, iterations, "diagonal", shots, seed, 1) == words
        if case % 3 == 0:
            recycled = aer_direct._recycled(marks, iterations, aer_direct.WALSH_HADAMARD_BLOCK)
            program = aer_direct.assemble_program(aer_grover_program(marks, iterations, "diagonal"))
            assert (_controller_output(recycled, num_qubits, shots, seed)
                    == _controller_output(program, num_qubits, shots, seed))
    # the recycled circuit is the same object from one search to the next (it is not rebuilt)
    first = aer_direct._recycled(random_marks(4, 0), 2, aer_direct.WALSH_HADAMARD_BLOCK)
    assert aer_direct._recycled(random_marks(5, 1), 1, aer_direct.WALSH_HADAMARD_BLOCK) is first


def test_the_recycled_circuit_is_emptied_after_each_search():
    """After ``execute_grover`` the thread's circuit holds no operations (its phases, k x 2^n
    complex numbers, are not kept until the next search): run as it is, it measures nothing."""
    marks = random_marks(6, 3)
    aer_direct.execute_grover(SIMULATOR, marks, 3, "diagonal", 4, 1, 1)
    output = _controller_output(aer_direct._RECYCLED.circuit, 6, 4, 1)
    assert "memory" not in output.get("data", {})


def test_without_recycling_execute_grover_builds_new_circuits(monkeypatch):
    """Where Aer does not let a circuit be emptied (``RECYCLABLE`` False), each search gets a new
    circuit and measures the same words."""
    rng = np.random.default_rng(11)
    cases = [(random_marks(int(rng.integers(1, 8)), case), int(rng.integers(0, 5)), int(rng.integers(0, 2**31 - 1)))
             for case in range(12)]
    recycled = [aer_direct.execute_grover(SIMULATOR, marks, k, "diagonal", 8, seed, 1) for marks, k, seed in cases]
    monkeypatch.setattr(aer_direct, "RECYCLABLE", False)
    assert [aer_direct.execute_grover(SIMULATOR, marks, k, "diagonal", 8, seed, 1)
            for marks, k, seed in cases] == recycled


def test_threads_each_refill_their_own_recycled_circuit():
    """Searches of several threads at once (each thread its own recycled circuit) measure what
    one thread measures alone; the interpreter switches threads every microsecond (Aer's run holds
    the GIL, so threads interleave only between Python steps: with the default 5 ms switch interval
    a circuit shared by the threads would rarely be caught), ten times over."""
    import sys
    from concurrent.futures import ThreadPoolExecutor

    cases = [(random_marks(3 + seed % 4, seed), seed % 4) for seed in range(24)]

    def one(item):
        seed, (marks, iterations) = item
        return aer_direct.execute_grover(SIMULATOR, marks, iterations, "diagonal", 16, seed, 1)

    alone = [one(item) for item in enumerate(cases)]
    interval = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)
    try:
        with ThreadPoolExecutor(max_workers=4) as pool:
            for _ in range(10):
                assert list(pool.map(one, enumerate(cases))) == alone
    finally:
        sys.setswitchinterval(interval)
