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


@pytest.mark.parametrize("num_qubits", [1, 2, 3, 5, 8, 9, 10, 11, 12, 13])
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

    monkeypatch.setattr(aer_state._StateTarget, "diagonal", fail)
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


@pytest.mark.parametrize(("marks", "iterations", "shots", "seed", "message"), [
    (np.ones(1, dtype=bool), 1, 1, 0, "length 2\\*\\*n with n >= 1"),
    (np.ones(1 << 14, dtype=bool), 1, 1, 0, "1 to 13 qubits, got 14"),
    (np.ones(6, dtype=bool), 1, 1, 0, "length 2\\*\\*n"),
    (np.array([0, 2, 0, 0]), 1, 1, 0, "marks must be a 1-D bool array"),
    (np.ones(4, dtype=bool), -1, 1, 0, "iterations must be an int >= 0"),
    (np.ones(4, dtype=bool), 1.0, 1, 0, "iterations must be an int >= 0"),
    (np.ones(4, dtype=bool), 1, 0, 0, "shots must be an int >= 1"),
    (np.ones(4, dtype=bool), 1, 2.0, 0, "shots must be an int >= 1"),
    (np.ones(4, dtype=bool), 1, 1, -1, "seed must be an int in"),
    (np.ones(4, dtype=bool), 1, 1, 1 << 64, "seed must be an int in"),
])
def test_bad_arguments_are_refused_before_any_work(marks, iterations, shots, seed, message):
    with pytest.raises(ValueError, match=message):
        aer_state.execute_grover(marks, iterations, "diagonal", shots, seed)


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
    assert backend._on_state(12) and not backend._on_state(13)  # STATE_CHOSEN_BELOW_QUBITS (measured)
    assert not backend._on_state(14)  # fusion and threads from 14 qubits
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


def test_a_process_forked_after_searches_searches_too():
    """The state's sampler runs on one thread (``parallel_state_update``): with an OpenMP team
    started by a multi-shot search, a process forked afterwards hung at its next sampling."""
    import multiprocessing

    marks = random_marks(6, 2)
    parent = aer_state.execute_grover(marks, 2, "diagonal", 8, 11).tolist()
    with multiprocessing.get_context("fork").Pool(2) as pool:
        children = pool.starmap_async(_search_words, [(marks, 11)] * 2).get(timeout=120)
    assert children == [parent, parent]


def _search_words(marks: np.ndarray, seed: int) -> list[int]:
    return aer_state.execute_grover(marks, 2, "diagonal", 8, seed).tolist()


@pytest.mark.skipif(not __import__("os").path.isdir("/proc/self/task"), reason="counts threads in /proc (Linux)")
def test_searches_start_no_threads():
    """In a fresh interpreter (OpenMP's threads, once started, stay): multi-shot searches on the
    state leave the process's thread count as it was (the sampler started min(shots, cores) - 1
    more before ``parallel_state_update``)."""
    import subprocess
    import sys

    code = ("import os, numpy as np\n"
            "from qrrt_circuits.search import aer_state\n"
            "marks = np.zeros(256, dtype=bool); marks[[3, 7]] = True\n"
            "aer_state.execute_grover(marks, 0, 'diagonal', 1, 0)\n"
            "before = len(os.listdir('/proc/self/task'))\n"
            "for seed in range(4): aer_state.execute_grover(marks, 2, 'diagonal', 64, seed)\n"
            "print(before, len(os.listdir('/proc/self/task')))\n")
    env = {**__import__("os").environ, "OMP_NUM_THREADS": "4"}
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, env=env)
    before, after = map(int, run.stdout.split())
    assert after == before


@pytest.mark.parametrize("make", [
    lambda env, backend: qc.QRRT(env, backend=backend, seed=4),
    lambda env, backend: qc.QRRT(env, backend=backend, num_qubits=11, seed=4),
    lambda env, backend: qc.PQRRT(env, workers=4, shared_database=False, backend=backend, seed=4),
])
def test_plans_on_the_state_are_the_plans_on_the_controller(make):
    """Every node, parent, counter and per-round record of a plan on Aer is the same on the state
    as on the controller (the path before ``aer_state``)."""
    env = qc.scenarios.paper_clutter(seed=4)
    on_controller = qc.AerBackend(seed=0)
    on_controller._use_state = False
    results = [make(env, backend).plan(max_nodes=40) for backend in (qc.AerBackend(seed=0), on_controller)]
    state, controller = results
    np.testing.assert_array_equal(state.nodes, controller.nodes)
    np.testing.assert_array_equal(state.parents, controller.parents)
    assert ({**state.metrics.as_dict(), "wall_time_s": 0} == {**controller.metrics.as_dict(), "wall_time_s": 0})
    assert state.history.keys() == controller.history.keys()
    for key in state.history:
        np.testing.assert_array_equal(state.history[key], controller.history[key])
    assert state.metrics.quantum_oracle_calls > 0
