"""``aer_state``: the package's Grover circuits run on Aer's own statevector state measure exactly
the words ``AerSimulator.run`` measures for the same seed (every oracle form, n = 1 .. 13, shot
counts on both sides of Aer's single-shot and sampling paths), and ``AerBackend`` takes that path
only where it is the controller's simulation."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from qiskit_aer import AerSimulator

import qrrt_circuits as qc
from qrrt_circuits.search import aer_direct, aer_state
from qrrt_circuits.search.circuits import aer_grover_circuit

pytestmark = pytest.mark.skipif(not aer_state.STATE_AVAILABLE, reason="this qiskit-aer lacks AerStateWrapper")

SIMULATOR = AerSimulator(method="statevector")


def job_indices(marks: np.ndarray, iterations: int, synthesis: str, shots: int, seed: int) -> list[int]:
    """The measured indices of ``AerSimulator.run`` on the circuit, in its order."""
    circuit = aer_grover_circuit(marks, iterations, synthesis=synthesis)
    result = SIMULATOR.run(circuit, shots=shots, seed_simulator=seed, memory=True, max_parallel_threads=1).result()
    return [int(word, 2) for word in result.get_memory()]


def random_marks(num_qubits: int, seed: int, fraction: float = 0.2) -> np.ndarray:
    rng = np.random.default_rng(seed)
    marks = rng.random(1 << num_qubits) < fraction
    marks[rng.integers(1 << num_qubits)] = True
    return marks


@pytest.mark.parametrize("num_qubits", [1, 2, 3, 5, 8, 10, 11, 12, 13])
@pytest.mark.parametrize("synthesis", ["diagonal", "mcz", "auto"])
def test_the_state_measures_the_words_aersimulator_run_measures(num_qubits, synthesis):
    """Word for word, over seeds, k = 0 .. 4 and shot counts 1 (Aer's single-shot measurement)
    to 64 (its sampler); n = 10 .. 13 use Aer's optimized sampling (``statevector_sample_measure_opt``)."""
    rng = np.random.default_rng(num_qubits)
    cases = 6 if num_qubits < 10 else 2
    fraction = 0.3 if synthesis != "mcz" or num_qubits < 6 else 4 / (1 << num_qubits)  # mcz: few marked entries
    for case in range(cases):
        marks = random_marks(num_qubits, case, fraction)
        iterations, shots = case % 5, (1, 2, 64)[case % 3]
        seed = int(rng.integers(0, 2**31 - 1))
        state = aer_state.execute_grover(marks, iterations, synthesis, shots, seed)
        assert state.dtype == np.int64 and state.shape == (shots,)
        assert state.tolist() == job_indices(marks, iterations, synthesis, shots, seed)


def test_the_mcz_forms_global_phase_and_x_strings_are_applied():
    """Most entries marked: the mcz form flips the unmarked ones, with a global phase of pi per
    oracle call; a sparse oracle's X-strings and mcphase gates; both equal to the job's words."""
    many = np.ones(8, dtype=bool)
    many[[2, 5]] = False
    for marks in (many, ~many):
        for iterations in (1, 2, 3):
            circuit = aer_grover_circuit(marks, iterations, synthesis="mcz")
            assert {instruction.operation.name for instruction in circuit.data} >= {"pauli", "mcphase"}
            for seed in range(4):
                assert (aer_state.execute_grover(marks, iterations, "mcz", 32, seed).tolist()
                        == job_indices(marks, iterations, "mcz", 32, seed))
    assert aer_grover_circuit(many, 1, synthesis="mcz").global_phase != 0


def test_widths_switch_without_changing_what_is_measured():
    """The thread's state is reused for one width and reallocated for another (and reset either by
    ``apply_initialize`` or by reallocation, on both sides of ``_RESET_BY_INITIALIZE_BELOW``)."""
    widths = [3, 3, 8, 12, 12, 3, 13, 13, 11, 11, 1]
    for index, num_qubits in enumerate(widths):
        marks = random_marks(num_qubits, index)
        assert (aer_state.execute_grover(marks, 2, "diagonal", 8, index).tolist()
                == job_indices(marks, 2, "diagonal", 8, index))


def test_a_failed_call_leaves_a_usable_state(monkeypatch):
    """A call that fails half-way drops the thread's state; the next search measures what it should."""
    marks = random_marks(5, 1)
    aer_state.execute_grover(marks, 2, "diagonal", 4, 1)

    def fail(*args):
        raise RuntimeError("injected")

    monkeypatch.setattr(aer_state, "_apply_diagonal_form", fail)
    with pytest.raises(RuntimeError, match="injected"):
        aer_state.execute_grover(marks, 2, "diagonal", 4, 1)
    monkeypatch.undo()
    assert aer_state.execute_grover(marks, 2, "diagonal", 4, 9).tolist() == job_indices(marks, 2, "diagonal", 4, 9)


def test_threads_each_use_their_own_state():
    items = [(random_marks(4 + seed % 5, seed), seed) for seed in range(16)]
    alone = [aer_state.execute_grover(marks, 2, "auto", 8, seed).tolist() for marks, seed in items]
    with ThreadPoolExecutor(max_workers=4) as pool:
        together = list(pool.map(lambda item: aer_state.execute_grover(item[0], 2, "auto", 8, item[1]).tolist(),
                                 items))
    assert together == alone


@pytest.mark.parametrize("num_qubits", [0, 14])
def test_widths_outside_the_state_path_are_refused(num_qubits):
    with pytest.raises(ValueError, match="1 to 13 qubits"):
        aer_state.execute_grover(np.ones(1 << num_qubits, dtype=bool), 1, "diagonal", 1, 0)


def test_the_backend_runs_small_circuits_on_the_state_with_the_controllers_results():
    """``AerBackend.search`` on the state equals the same backend on the controller and through
    ``AerSimulator.run``, seed for seed."""
    on_state = qc.AerBackend(seed=3)
    on_controller = qc.AerBackend(seed=3)
    on_controller._use_state = False
    through_jobs = qc.AerBackend(seed=3)
    through_jobs._use_controller = False
    assert on_state._on_state(8) and not on_controller._on_state(8) and not through_jobs._on_state(8)
    for seed in range(6):
        marks = random_marks(2 + seed, seed)
        results = [backend.search(marks, 2, shots=16, seed=seed).indices
                   for backend in (on_state, on_controller, through_jobs)]
        np.testing.assert_array_equal(results[0], results[1])
        np.testing.assert_array_equal(results[0], results[2])


def test_the_backend_keeps_the_controller_where_the_simulation_would_differ(monkeypatch):
    backend = qc.AerBackend(seed=1)
    assert backend._on_state(13) and not backend._on_state(14)  # fusion and threads from 14 qubits
    assert not qc.AerBackend(method="automatic")._on_state(8)  # Aer may pick another method
    changed = qc.AerBackend(seed=1)
    changed.simulator.set_options(precision="single")  # options changed after construction
    assert not changed._on_state(8)
    calls = []
    monkeypatch.setattr(aer_direct, "execute_grover", lambda *args: calls.append(args) or ["0x0"])
    changed.search(random_marks(3, 0), 1, shots=1, seed=0)
    assert len(calls) == 1  # the single-precision search went to the controller


def test_an_option_that_cannot_be_compared_keeps_the_controller():
    backend = qc.AerBackend(seed=1)
    backend.simulator.options.__dict__["blocking_qubits"] = np.arange(3)  # == gives an array
    assert not backend._on_state(8)


def test_a_noise_model_keeps_the_gate_by_gate_path():
    """A noise model, given to the constructor or set later, never runs on the (noiseless) state."""
    from qiskit_aer.noise import NoiseModel, depolarizing_error

    noise = NoiseModel()
    noise.add_all_qubit_quantum_error(depolarizing_error(0.05, 1), ["h", "x"])
    assert not qc.AerBackend(seed=1, noise_model=noise)._on_state(5)
    later = qc.AerBackend(seed=1)
    later.simulator.set_options(noise_model=noise)
    assert not later._on_state(5)
