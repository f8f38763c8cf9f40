"""Running a circuit on ``AerSimulator``'s C++ controller directly: the simulation that
``AerSimulator.run`` performs, without its job machinery and its generic assembler.

``AerSimulator.run(circuit).result()`` does three things around the simulation itself (profiled
with cProfile, qiskit-aer 0.18.2, an 8-qubit Grover circuit of 36 instructions): it starts an
``AerJob`` on a thread pool and waits on it, it converts the circuit with
``aer_compiler.assemble_circuits`` (a generic converter that inspects every parameter of every
instruction: the 256 phases of each ``diagonal`` one by one, ~0.6 ms of ~1.8 ms), and it turns the
controller's output into a ``qiskit.result.Result``. The controller call itself is the same
whoever makes it.

``assemble`` converts the few instruction kinds the Grover circuits of this package use
(``unitary``, ``diagonal``, ``mcphase``, ``p``, ``h``, ``x``, ``z``, ``pauli``, ``measure``, and
``barrier``, which becomes nothing) with the same controller-wrapper calls and arguments as Aer's
assembler (one call per instruction, the phases of a ``diagonal`` handed over as the list they
already are), and falls back to Aer's own
assembler for anything else (parameters, control flow, other instructions). ``assemble_grover`` makes the
diagonal-form Grover circuit ``AerBackend`` runs for small n with the same calls as
``assemble_program`` of its program, from arguments cached per n (the Walsh-Hadamard matrices,
qubit lists, labels, header), so that per search only the oracle's two phase lists are new
(``benchmarks/bench_search.py`` times ``assemble_grover`` beside ``build`` + ``assemble``, the
program's path); ``execute_grover`` makes those calls into one ``AerCircuit`` per thread, emptied
and refilled for every search, instead of a new one; what is left is mostly the controller
wrappers' own cost per call, a few microseconds per ``unitary``, ``mcphase`` or ``AerCircuit()``. ``execute`` builds
the run configuration with Aer's ``generate_aer_config`` from the simulator's options and the
run options (once per thread, circuit width, shots and thread count, and again whenever the
simulator's options change; only the seed changes between searches), calls the simulator's
controller and returns the per-shot memory. The measured
words are identical to ``AerSimulator.run``'s for every seed (``tests/test_aer_direct.py``),
so the planners' results do not change.

These are qiskit-aer internals (``AerCircuit``, ``CircuitHeader``, ``generate_aer_config``,
``AerSimulator._execute_circuits``; checked with qiskit-aer 0.18.2, and ``tests/test_aer_direct.py``
compares every circuit form against ``AerSimulator.run``, so a change in them fails the suite); if
an installed qiskit-aer lacks them, ``DIRECT_AVAILABLE`` is False and ``AerBackend`` runs its
circuits through ``AerSimulator.run``.
"""

from __future__ import annotations

import functools
import threading
import weakref
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from qiskit import QuantumCircuit

from .aer_circuits import (
    WALSH_HADAMARD_BLOCK,
    GroverProgram,
    _parts,
    aer_grover_program,
    check_grover_arguments,
    choose_simulation_synthesis,
    diagonal_form,
)

try:  # qiskit-aer internals (checked with 0.18.2); without them AerBackend uses AerSimulator.run
    from qiskit_aer import AerSimulator
    from qiskit_aer.backends.aer_compiler import assemble_circuits, generate_aer_config
    from qiskit_aer.backends.backend_utils import CircuitHeader
    from qiskit_aer.backends.controller_wrappers import AerCircuit
    DIRECT_AVAILABLE = hasattr(AerSimulator, "_execute_circuits")
except ImportError:  # pragma: no cover - depends on the installed qiskit-aer
    DIRECT_AVAILABLE = False


def _can_recycle() -> bool:
    """Whether an ``AerCircuit``'s operations can be emptied (``ops = []``, qiskit-aer 0.18.2)."""
    if not DIRECT_AVAILABLE:
        return False
    try:
        AerCircuit().ops = []
    except (AttributeError, TypeError):  # pragma: no cover - depends on the installed qiskit-aer
        return False
    return True


#: ``execute_grover`` refills one ``AerCircuit`` per thread (``_recycled``) when this is True
RECYCLABLE = _can_recycle()

#: the register of no condition, as Aer's assembler passes it
_UNCONDITIONAL = -1


def _unitary(aer: Any, qubits: list[int], operation: Any) -> None:
    aer.unitary(qubits, operation.params[0], _UNCONDITIONAL, None, operation.label or "unitary")


def _diagonal(aer: Any, qubits: list[int], operation: Any) -> None:
    aer.diagonal(qubits, operation.params, _UNCONDITIONAL, operation.label or "diagonal")


def _pauli(aer: Any, qubits: list[int], operation: Any) -> None:
    aer.gate("pauli", qubits, [], operation.params, _UNCONDITIONAL, None, operation.label or "pauli")


def _gate(aer: Any, qubits: list[int], operation: Any) -> None:
    name = operation.name
    aer.gate(name, qubits, [float(p) for p in operation.params], [], _UNCONDITIONAL, None,
             operation.label or name)


def _barrier(aer: Any, qubits: list[int], operation: Any) -> None:
    """Aer's assembler makes no operation of a barrier."""


#: instruction name -> the controller-wrapper call Aer's assembler makes for it (measure apart)
_CONVERTERS: dict[str, Callable[[Any, list[int], Any], None]] = {
    "unitary": _unitary, "diagonal": _diagonal, "pauli": _pauli,
    "mcphase": _gate, "p": _gate, "h": _gate, "x": _gate, "z": _gate, "barrier": _barrier,
}


class _Unconvertible(Exception):
    """An instruction this module does not convert (the circuit goes to Aer's assembler)."""


def _circuit_header(circuit_name: str, num_qubits: int, num_memory: int, qregs: Any, cregs: Any,
                    global_phase: float) -> Any:
    """The ``CircuitHeader`` Aer's assembler makes for a circuit of these registers."""
    return CircuitHeader(
        n_qubits=num_qubits,
        qreg_sizes=[[register.name, register.size] for register in qregs],
        memory_slots=num_memory,
        creg_sizes=[[register.name, register.size] for register in cregs],
        name=circuit_name,
        global_phase=global_phase,
    )


def _header(aer: Any, circuit_name: str, num_qubits: int, num_memory: int, qregs: Any, cregs: Any,
            global_phase: float) -> None:
    aer.set_header(_circuit_header(circuit_name, num_qubits, num_memory, qregs, cregs, global_phase))
    aer.num_qubits = num_qubits
    aer.num_memory = num_memory
    aer.global_phase_angle = global_phase


def _convert(aer: Any, operation: Any, qubits: list[int], clbits: list[int]) -> None:
    if operation.name == "measure":
        aer.measure(qubits, clbits, [])
        return
    converter = _CONVERTERS.get(operation.name)
    if converter is None:
        raise _Unconvertible(operation.name)
    converter(aer, qubits, operation)


def assemble(circuit: QuantumCircuit) -> Any:
    """The ``AerCircuit`` Aer's ``assemble_circuits`` makes of ``circuit`` (experiment id 0).

    The instructions of this package's Grover circuits are converted here, one controller-wrapper
    call each with Aer's own arguments; any other circuit (parameters, other instructions) goes
    through Aer's assembler.

    Args:
        circuit: A ``QuantumCircuit`` without classical conditions.

    Returns:
        A ``qiskit_aer.backends.controller_wrappers.AerCircuit``.
    """
    if not circuit.num_parameters:
        aer = AerCircuit()
        _header(aer, circuit.name, circuit.num_qubits, circuit.num_clbits, circuit.qregs, circuit.cregs,
                float(circuit.global_phase))
        qubit_index = {qubit: index for index, qubit in enumerate(circuit.qubits)}
        clbit_index = {clbit: index for index, clbit in enumerate(circuit.clbits)}
        try:
            for instruction in circuit.data:
                _convert(aer, instruction.operation, [qubit_index[qubit] for qubit in instruction.qubits],
                         [clbit_index[clbit] for clbit in instruction.clbits])
        except _Unconvertible:
            pass
        else:
            aer.circ_id = 0
            return aer
    aer_circuits, _ = assemble_circuits([circuit])
    aer = aer_circuits[0]
    aer.circ_id = 0
    return aer


def assemble_program(program: GroverProgram) -> Any:
    """The ``AerCircuit`` of ``program.circuit(measure=True)``, made from the program's
    instructions without building the ``QuantumCircuit``: the same calls, in the same order, as
    ``assemble(program.circuit())``, except that the n one-qubit measurements are one n-qubit
    measurement (qubit i into bit i; the same measured words, tested).

    Args:
        program: An ``aer_circuits.GroverProgram``.

    Returns:
        A ``qiskit_aer.backends.controller_wrappers.AerCircuit`` with experiment id 0.
    """
    parts = program.parts
    n = parts.num_qubits
    aer = AerCircuit()
    _header(aer, "grover_aer", n, n, parts.qregs, parts.cregs, float(program.global_phase))
    indices_of = parts.indices_of
    try:
        for operation, qubits in program.steps:
            _convert(aer, operation, indices_of(qubits), [])
    except _Unconvertible:  # a step of a kind not converted here: the whole circuit through Aer's assembler
        return assemble(program.circuit())
    aer.measure(list(range(n)), list(range(n)), [])  # qubit i into bit i, as n one-qubit measurements
    aer.circ_id = 0
    return aer


@functools.lru_cache(maxsize=32)
def _grover_header(num_qubits: int) -> Any:
    """The header ``_header`` gives a diagonal-form Grover circuit on n qubits (``set_header``
    copies it into each circuit)."""
    parts = _parts(num_qubits, WALSH_HADAMARD_BLOCK)  # (the registers do not depend on the block)
    return _circuit_header("grover_aer", num_qubits, num_qubits, parts.qregs, parts.cregs, 0.0)


class _CircuitTarget:
    """``DiagonalFormTarget`` on an ``AerCircuit``: the controller-wrapper calls Aer's assembler
    makes for each instruction (``_convert``), with the same arguments."""

    __slots__ = ("aer",)

    def __init__(self, aer: Any) -> None:
        self.aer = aer

    def unitary(self, qubits: list[int], matrix: np.ndarray, label: str) -> None:
        self.aer.unitary(qubits, matrix, _UNCONDITIONAL, None, label)

    def diagonal(self, qubits: list[int], phases: list[complex]) -> None:
        self.aer.diagonal(qubits, phases, _UNCONDITIONAL, "diagonal")

    def gate(self, name: str, qubits: list[int], params: list[float], label: str) -> None:
        self.aer.gate(name, qubits, params, [], _UNCONDITIONAL, None, label)

    def pauli(self, qubits: list[int], label: str) -> None:
        self.aer.gate("pauli", qubits, [], [label], _UNCONDITIONAL, None, "pauli")


def assemble_grover(marks: np.ndarray, iterations: int, synthesis: str = "auto",
                    block: int = WALSH_HADAMARD_BLOCK) -> Any:
    """The ``AerCircuit`` of ``aer_grover_program(marks, iterations, synthesis, block)`` with its
    measurements: ``assemble_program`` of that program, the same calls with the same arguments in
    the same order (tested instruction by instruction through the measured words).

    For the diagonal form (the one ``AerBackend`` takes for small n) the calls are made here from
    cached arguments, without building the program's operations: per search only the two phase
    lists of the oracle (the first call carries the folded Z^n, ``aer_circuits``) are new. The
    ``mcz`` form goes through ``assemble_program``. The arguments are not validated here: this is
    ``AerBackend``'s path, behind its own checks.

    Args:
        marks: Bool array of length 2^n (n >= 1), already validated.
        iterations: k >= 0, already validated.
        synthesis: ``"auto"``, ``"diagonal"`` or ``"mcz"`` (``aer_circuits.AER_SYNTHESES``).
        block: The widest Walsh-Hadamard block (1 .. 10).

    Returns:
        A ``qiskit_aer.backends.controller_wrappers.AerCircuit`` with experiment id 0.
    """
    if synthesis == "auto":
        synthesis = choose_simulation_synthesis(marks)
    if synthesis != "diagonal":
        return assemble_program(aer_grover_program(marks, iterations, synthesis, block))
    return _fill_grover(AerCircuit(), marks, iterations, block, fresh=True)


def _fill_grover(aer: Any, marks: np.ndarray, iterations: int, block: int, fresh: bool) -> Any:
    """Make the diagonal-form Grover circuit's calls on ``aer``, an empty ``AerCircuit``: a new one
    (``fresh``) or a recycled one whose header is already that of n qubits (``_recycled``)."""
    n = marks.shape[0].bit_length() - 1
    if fresh:
        aer.set_header(_grover_header(n))
    aer.num_qubits = n
    aer.num_memory = n
    aer.global_phase_angle = 0.0
    form = diagonal_form(n, block)
    form.emit(_CircuitTarget(aer), marks, iterations)
    aer.measure(form.qubits, form.qubits, [])
    aer.circ_id = 0
    return aer


#: per thread: one ``AerCircuit`` that ``execute_grover`` empties and refills for every search, and
#: the (n, block) whose header it carries. A new ``AerCircuit`` draws its seed from
#: ``std::random_device`` (qiskit-aer's ``Circuit()`` constructor), about 14 us per ``AerCircuit()``
#: on this project's virtual machine (``benchmarks/bench_search.py``, ``round_search``), for a seed
#: that ``seed_simulator`` overwrites anyway. The controller recomputes everything it derives from the operations
#: (``Circuit::set_params``, ``set_metadata``) on every run, so an emptied circuit refilled with
#: the same calls runs exactly like a new one (tested word for word, ``tests/test_aer_direct.py``).
#: ``execute_grover`` empties it again right after the run, so no search's operations outlive it.
_RECYCLED = threading.local()


def _recycled(marks: np.ndarray, iterations: int, block: int) -> Any:
    """The diagonal-form Grover circuit of ``marks`` in this thread's recycled ``AerCircuit``
    (valid until this thread's next ``execute_grover``); only where ``RECYCLABLE``."""
    shape = (marks.shape[0], block)
    aer = getattr(_RECYCLED, "circuit", None)
    if aer is None:
        aer = _RECYCLED.circuit = AerCircuit()
        _RECYCLED.shape = None
    else:
        aer.ops = []
    fresh = _RECYCLED.shape != shape
    _RECYCLED.shape = None  # until the calls below complete
    _fill_grover(aer, marks, iterations, block, fresh)
    _RECYCLED.shape = shape
    return aer


@dataclass(frozen=True)
class _Width:
    """What ``generate_aer_config`` reads of its circuits: their qubits and classical bits."""

    num_qubits: int
    num_clbits: int


#: per thread: (simulator, width, shots, threads) -> (the simulator's options when the configuration
#: was made, the configuration); the controller reads a configuration, it does not keep it
_CONFIGURATIONS = threading.local()


def _configuration(simulator: Any, width: _Width, shots: int, seed: int, threads: int) -> Any:
    """``generate_aer_config([width], simulator.options, shots=..., seed_simulator=seed,
    memory=True, max_parallel_threads=threads)``, made once per thread and reused (with the new
    seed) while the simulator's options stay the same."""
    cache = getattr(_CONFIGURATIONS, "cache", None)
    if cache is None:
        cache = _CONFIGURATIONS.cache = {}
    key = (id(simulator), width, shots, threads)
    options = dict(simulator.options.__dict__)
    cached = cache.get(key)
    if cached is None or cached[0] != options or cached[2]() is not simulator:
        if len(cache) >= _CONFIGURATIONS_KEPT:
            cache.clear()
        config = generate_aer_config([width], simulator.options, shots=shots, seed_simulator=seed, memory=True,
                                     max_parallel_threads=threads)
        cache[key] = (options, config, weakref.ref(simulator))  # the cache keeps no simulator alive
        return config
    config = cached[1]
    config.seed_simulator = seed
    return config


_CONFIGURATIONS_KEPT = 64


def execute(simulator: Any, circuit: QuantumCircuit | GroverProgram, shots: int, seed: int,
            threads: int) -> list[str]:
    """Simulate ``circuit`` on ``simulator``'s controller with ``shots`` shots and
    ``seed_simulator = seed``; the per-shot measured words (hexadecimal strings, as
    ``Result.get_memory`` gives them before formatting).

    The configuration is Aer's ``generate_aer_config`` of the simulator's options and the run
    options ``shots``, ``seed_simulator``, ``memory=True`` and ``max_parallel_threads = threads``,
    exactly what ``simulator.run(circuit, shots=..., seed_simulator=..., memory=True,
    max_parallel_threads=...)`` passes to the controller. Only for a simulator without a noise
    model (``AerSimulator.run``'s own compile step prepares a noise model).

    Args:
        simulator: A ``qiskit_aer.AerSimulator`` without a noise model.
        circuit: The circuit, with measurements into its classical register, or a
            ``GroverProgram`` (run as ``program.circuit(measure=True)``, without building it).
        shots: Shots (>= 1).
        seed: The simulator seed.
        threads: Aer's ``max_parallel_threads`` for this run (0 = all cores).

    Returns:
        One hexadecimal word per shot.

    Raises:
        ValueError: The simulator has a noise model.
        RuntimeError: The controller reports a failure.
    """
    _refuse_noise(simulator)
    if isinstance(circuit, GroverProgram):
        aer = assemble_program(circuit)
        width = _Width(circuit.num_qubits, circuit.num_qubits)
    else:
        aer = assemble(circuit)
        width = _Width(circuit.num_qubits, circuit.num_clbits)
    return _run(simulator, aer, width, shots, seed, threads)


def execute_grover(simulator: Any, marks: np.ndarray, iterations: int, synthesis: str, shots: int, seed: int,
                   threads: int) -> list[str]:
    """``execute(simulator, aer_grover_program(marks, iterations, synthesis), shots, seed,
    threads)``: the same words, the circuit assembled as ``assemble_grover`` assembles it (the same
    calls, made from cached arguments), for the diagonal form into this thread's recycled
    ``AerCircuit`` (``_recycled``: no new circuit, hence no ``std::random_device`` seed, per
    search); ``AerBackend``'s path, after the backend's own checks. ``marks`` must
    be a bool array of length 2^n and ``iterations`` an int >= 0 (``ValueError`` otherwise; no
    coercion); raises what ``execute`` raises."""
    _refuse_noise(simulator)
    check_grover_arguments(marks, iterations)
    n = marks.shape[0].bit_length() - 1
    if synthesis == "auto":
        synthesis = choose_simulation_synthesis(marks)
    if synthesis != "diagonal" or not RECYCLABLE:  # a new circuit, as assemble_grover makes it
        return _run(simulator, assemble_grover(marks, iterations, synthesis), _Width(n, n), shots, seed, threads)
    aer = _recycled(marks, iterations, WALSH_HADAMARD_BLOCK)
    try:
        return _run(simulator, aer, _Width(n, n), shots, seed, threads)
    finally:
        # emptied at once, so the thread's circuit holds no phases between searches (Aer copies
        # the oracle's 2^n phases once per iteration: k x 16 x 2^n bytes, as a new circuit would
        # hold only until it is dropped here)
        aer.ops = []


def _refuse_noise(simulator: Any) -> None:
    if getattr(simulator.options, "noise_model", None) is not None:
        raise ValueError("aer_direct.execute runs noiseless simulators only; a simulator with a noise_model "
                         "goes through AerSimulator.run, whose compile step prepares the model")


def _run(simulator: Any, aer: Any, width: _Width, shots: int, seed: int, threads: int) -> list[str]:
    """The controller's run of the assembled circuit ``aer``; its per-shot memory."""
    output = simulator._execute_circuits([aer], None, _configuration(simulator, width, shots, seed, threads))
    if not isinstance(output, dict) or not output.get("success", False):
        status = output.get("status") if isinstance(output, dict) else output
        raise RuntimeError(f"AerSimulator failed: {status}")
    result = output["results"][0]
    if not result.get("success", False):
        raise RuntimeError(f"AerSimulator failed: {result.get('status')}")
    return list(result["data"]["memory"])
