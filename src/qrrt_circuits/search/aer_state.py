"""Running the package's Grover circuits on qiskit-aer's own statevector state (``AerState``).

qiskit-aer offers two ways to simulate a circuit: its controller, which takes a whole circuit and
a run configuration (``AerSimulator.run``, or ``aer_direct``, which calls it directly), and
``AerState``, the native state behind ``qiskit_aer.quantum_info.AerStatevector``, to which a caller
applies the instructions one by one (``apply_unitary``, ``apply_diagonal``, ``apply_mcphase``, ...)
and then samples (``sample_memory``). Both apply the same C++ kernels of Aer's ``QubitVector`` to
the same ``complex128`` amplitudes and sample them with the same sampler.

A small Grover circuit costs the controller a fixed time per run beyond its arithmetic:
each run constructs three ``std::random_device`` (about 11 us each on this project's machine,
``benchmarks/bench_aer_overhead.py``) and converts its configuration and result through JSON.
``AerState`` pays one ``std::random_device`` per flush, and ``execute_grover`` flushes once per
search (when it samples), on a state that is kept per thread and reset to |0> between searches
(at n = 13 the reset reallocates the state: three per search there, as on the controller, counted
by the same benchmark, but still no assembly).

What runs is the circuit of ``aer_circuits.aer_grover_program``, instruction for instruction:
the Walsh-Hadamard blocks as ``apply_unitary`` of their matrices, the oracle's ``diagonal`` as
``apply_diagonal`` (or, in the ``mcz`` form, its X-strings as ``apply_x`` on their qubits and its
``mcphase`` gates as ``apply_mcphase``), the reflection as ``apply_mcphase``, the final Z^n as
``apply_z`` on every qubit, the circuit's global phase first (where the controller applies it).
The seed is set with ``set_seed(seed_simulator)``, as the controller seeds a run of one circuit.
The controller returns a run's samples last to first, ``sample_memory`` first to last, so
the words are reversed here. The measured words are those of ``AerSimulator.run`` on
``aer_grover_circuit`` with ``seed_simulator``, word for word, for every n, k, shot count, oracle
form and seed tested (``tests/test_aer_state.py``).

Only where the two are the same simulation: ``statevector`` method on the CPU, no noise model,
the simulator's options as ``AerBackend`` made them, and fewer than ``STATE_BELOW_QUBITS`` (14)
qubits. From 14 qubits on the controller fuses gates (Aer's ``fusion_threshold``) and runs on
several threads, which the state does not. ``AerBackend`` takes the state below 13 qubits only
(``aer.STATE_CHOSEN_BELOW_QUBITS``: at 13 the state's mcz form is slower than the controller) and
the controller path elsewhere.

These are qiskit-aer internals (``controller_wrappers.AerStateWrapper``, checked with qiskit-aer
0.18.2); if the installed qiskit-aer lacks them, ``STATE_AVAILABLE`` is False and ``AerBackend``
uses the controller.
"""

from __future__ import annotations

import threading
from typing import Any

import numpy as np

from .aer_circuits import (
    WALSH_HADAMARD_BLOCK,
    GroverProgram,
    aer_grover_program,
    check_grover_arguments,
    choose_simulation_synthesis,
    diagonal_form,
)

try:  # qiskit-aer internals (checked with 0.18.2); without them AerBackend uses the controller
    from qiskit_aer.backends.controller_wrappers import AerStateWrapper
    _NEEDED = ("configure", "allocate_qubits", "initialize", "clear", "apply_initialize", "apply_unitary",
               "apply_diagonal", "apply_mcphase", "apply_x", "apply_z", "apply_global_phase", "set_seed",
               "sample_memory")
    STATE_AVAILABLE = all(hasattr(AerStateWrapper, name) for name in _NEEDED)
except ImportError:  # pragma: no cover - depends on the installed qiskit-aer
    STATE_AVAILABLE = False

#: circuits on fewer qubits may run on the state (Aer's fusion_threshold and
#: statevector_parallel_threshold are both 14: below them the controller runs the instructions one
#: by one on one thread, as the state does)
STATE_BELOW_QUBITS = 14
#: below this width the state is reset to |0> with ``apply_initialize`` of a cached list, from it on
#: by clearing and reallocating it (``python benchmarks/bench_aer_overhead.py``, ``state_reset``, in
#: ``benchmarks/results/run_c22abd7.json``: the list's conversion grows with 2^n, 25.6 us at n = 12
#: and 66.4 at 13, while the reallocation costs 33-37 us whatever n)
_RESET_BY_INITIALIZE_BELOW = 13


class _ThreadState:
    """One thread's ``AerStateWrapper``, allocated for ``num_qubits`` qubits (0: none yet)."""

    def __init__(self) -> None:
        self.wrapper: Any = None
        self.num_qubits = 0
        self.zero: list[complex] = []

    def reset(self, num_qubits: int) -> Any:
        """The thread's state on ``num_qubits`` qubits, in |0> (a new one for a new width)."""
        wrapper = self.wrapper
        if wrapper is not None and num_qubits == self.num_qubits and num_qubits < _RESET_BY_INITIALIZE_BELOW:
            wrapper.apply_initialize(list(range(num_qubits)), self.zero)
            return wrapper
        self.num_qubits = 0  # until the state below is allocated
        if wrapper is None:
            wrapper = self.wrapper = AerStateWrapper()
        else:
            wrapper.clear()
        allocate(wrapper, num_qubits)
        if num_qubits < _RESET_BY_INITIALIZE_BELOW:
            self.zero = [1.0 + 0.0j] + [0.0j] * ((1 << num_qubits) - 1)
        self.num_qubits = num_qubits
        return wrapper

    def release(self) -> None:
        """Drop the state (after a failed call, whose state may be half-applied)."""
        wrapper, self.wrapper, self.num_qubits, self.zero = self.wrapper, None, 0, []
        if wrapper is not None:
            try:
                wrapper.clear()
            except RuntimeError:  # pragma: no cover - depends on the failure
                pass


def allocate(wrapper: Any, num_qubits: int) -> None:
    """Configure a new (or cleared) ``AerStateWrapper`` as ``execute_grover`` runs it (statevector,
    CPU, double precision, one thread) and allocate and initialize it on ``num_qubits`` qubits,
    in |0>."""
    wrapper.configure("method", "statevector")
    wrapper.configure("device", "CPU")
    wrapper.configure("precision", "double")
    wrapper.configure("max_parallel_threads", "1")
    # one thread for the sampler too: without this, sample_memory starts an OpenMP team of up to
    # min(shots, OMP_NUM_THREADS) threads (max_parallel_threads does not reach it), whose threads a
    # process forked after it lacks, so a forked child's next sampling hung
    wrapper.configure("parallel_state_update", "1")
    wrapper.allocate_qubits(num_qubits)
    wrapper.initialize()


_THREAD = threading.local()


def _thread_state() -> _ThreadState:
    state = getattr(_THREAD, "state", None)
    if state is None:
        state = _THREAD.state = _ThreadState()
    return state


def execute_grover(marks: np.ndarray, iterations: int, synthesis: str, shots: int, seed: int) -> np.ndarray:
    """The measured indices of ``aer_grover_circuit(marks, iterations, synthesis=synthesis)``
    with ``shots`` shots and ``seed_simulator = seed``, run on this thread's ``AerState``: the
    indices of the words ``AerSimulator(method="statevector").run`` measures, in its order.

    ``AerBackend``'s path for n < ``aer.STATE_CHOSEN_BELOW_QUBITS`` (13), after its own checks; the
    cheap ones are made again here (``check_grover_arguments``, the shots and the seed; no
    coercion), the rest (the synthesis name) is the backend's.

    Args:
        marks: The oracle's marks: a 1-D bool array of length 2^n, 1 <= n < ``STATE_BELOW_QUBITS``.
        iterations: k, an int >= 0.
        synthesis: ``"auto"``, ``"diagonal"`` or ``"mcz"``.
        shots: Shots, an int >= 1.
        seed: The simulator seed, an int in [0, 2^64).

    Returns:
        Int array (shots,) of measured indices.

    Raises:
        ValueError: An argument outside those ranges, naming it.
    """
    check_grover_arguments(marks, iterations)
    num_qubits = marks.shape[0].bit_length() - 1
    if num_qubits >= STATE_BELOW_QUBITS:
        raise ValueError(f"aer_state runs circuits of 1 to {STATE_BELOW_QUBITS - 1} qubits, got {num_qubits}")
    if type(shots) is not int or shots < 1:
        raise ValueError(f"shots must be an int >= 1, got {shots!r}")
    if type(seed) is not int or not 0 <= seed < 1 << 64:
        raise ValueError(f"seed must be an int in [0, 2**64), got {seed!r}")
    if synthesis == "auto":
        synthesis = choose_simulation_synthesis(marks)
    thread = _thread_state()
    try:
        state = thread.reset(num_qubits)
        state.set_seed(seed)
        if synthesis == "diagonal":
            diagonal_form(num_qubits, WALSH_HADAMARD_BLOCK).emit(_StateTarget(state), marks, iterations)
        else:
            _apply_program(state, aer_grover_program(marks, iterations, synthesis))
        words = state.sample_memory(list(range(num_qubits)), shots)
    except BaseException:
        thread.release()
        raise
    return np.fromiter((int(word, 2) for word in reversed(words)), dtype=np.int64, count=shots)


class _StateTarget:
    """``DiagonalFormTarget`` on Aer's state: each instruction applied as its ``AerState`` call."""

    __slots__ = ("state",)

    def __init__(self, state: Any) -> None:
        self.state = state

    def unitary(self, qubits: list[int], matrix: np.ndarray, label: str) -> None:
        self.state.apply_unitary(qubits, matrix)

    def diagonal(self, qubits: list[int], phases: list[complex]) -> None:
        self.state.apply_diagonal(qubits, phases)

    def gate(self, name: str, qubits: list[int], params: list[float], label: str) -> None:
        self.state.apply_mcphase(qubits, params[0])  # mcphase, or p on one qubit: the same phase

    def pauli(self, qubits: list[int], label: str) -> None:
        _apply_pauli(self.state, qubits, label)


def _apply_program(state: Any, program: GroverProgram) -> None:
    """Every instruction of an ``mcz``-form ``program`` (Walsh-Hadamard ``unitary`` blocks, ``pauli``
    strings, ``mcphase``; the diagonal form goes through ``DiagonalForm.emit``) in order, after its
    global phase."""
    if program.global_phase:
        state.apply_global_phase(float(program.global_phase))
    indices_of = program.parts.indices_of
    for operation, qubit_tuple in program.steps:
        qubits = indices_of(qubit_tuple)
        name = operation.name
        if name == "unitary":
            state.apply_unitary(qubits, operation.params[0])
        elif name in ("mcphase", "p"):
            state.apply_mcphase(qubits, float(operation.params[0]))
        elif name == "pauli":
            _apply_pauli(state, qubits, operation.params[0])
        else:  # pragma: no cover - the mcz form has no other instruction
            raise ValueError(f"aer_state cannot apply the instruction {name!r}")


def _apply_pauli(state: Any, qubits: list[int], label: str) -> None:
    """A Pauli string of X, Z and I (big-endian label, qubit 0 last), one qubit at a time."""
    for qubit, letter in zip(qubits, reversed(label), strict=True):
        if letter == "X":
            state.apply_x(qubit)
        elif letter == "Z":
            state.apply_z(qubit)
        elif letter != "I":  # pragma: no cover - the package's circuits use X and Z strings only
            raise ValueError(f"aer_state applies X, Z and I Pauli strings, got {label!r}")
