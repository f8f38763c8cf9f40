"""The Grover circuit as AerSimulator runs it: few Aer-native instructions, cheap to build.

What Aer is given is the circuit of ``grover_circuit`` (paper Alg. 2, lines 4-8), rewritten with
identities that leave the unitary unchanged up to a global phase:

- The diffuser D = H^n X^n MCZ X^n H^n equals Z^n D' Z^n with D' = H^n MCZ H^n (because
  X H = H Z). Between two iterations the trailing Z^n of one diffuser, the next oracle O and the
  leading Z^n of the next diffuser are all diagonal, so Z^n O Z^n = O: the X layers disappear,
  one Z^n is folded into the first oracle and one Z^n (a single ``pauli`` instruction) is left at
  the end. Per iteration Aer runs: the oracle, W, one ``mcphase``, W.
- W = H^n is applied as Walsh-Hadamard blocks ``UnitaryGate(H^{(x)b})`` on groups of at most
  ``block`` qubits (Aer's own gate fusion builds blocks of the same kind; a ``unitary``
  instruction costs Aer's assembler about what one ``h`` costs).
- The oracle diag((-1)^marks) has two forms. ``"diagonal"``: one Aer ``diagonal`` instruction of
  2^n phases. ``"mcz"``: per marked index one ``mcphase`` on |1...1>, with ``pauli`` X-strings between them
  that bring each index to |1...1> (consecutive ones merged; successive oracle calls visit the
  indices in alternating order so the strings at their ends cancel); when more than half of the
  entries are marked, the unmarked ones are flipped instead, times the global phase -1.

Why these forms (profiled with cProfile on qiskit 2.6 / qiskit-aer 0.18; the resulting speed is
measured by ``benchmarks/bench_search.py``): for small n, Aer's Python assembler and its
per-instruction binding cost far more than the arithmetic on the state vector, so the circuit has
as few instructions as possible; a ``diagonal`` instruction is cheap to call but costs per entry
(its 2^n phases are converted into Aer's own form; through ``AerSimulator.run`` qiskit's circuit
and Aer's assembler also handle each phase as a parameter), so
``simulation_synthesis`` weighs 2^n entries against 2m + 1 instructions. That choice is separate
from ``circuits.choose_synthesis``, which counts CX gates for hardware and is what
``resource_estimate`` uses.

The parts that depend only on n (the W blocks, the ``mcphase``, the ``pauli`` Z^n,
the measurements) are built once per n and reused; per search only the oracle's instructions are
new, built from numpy arrays without per-entry Python work. ``aer_grover_program`` gives the
instructions as a ``GroverProgram`` of (operation, qubits) steps, which ``AerBackend`` hands to
Aer's controller without building a ``QuantumCircuit`` (``aer_direct``).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from qiskit import QuantumCircuit
from qiskit.circuit import CircuitInstruction, Gate, Measure, Operation, Qubit
from qiskit.circuit.library import DiagonalGate, MCPhaseGate, PauliGate, PhaseGate, UnitaryGate

from ..validation import check_int
from .backend import validate_iterations, validate_marks

AER_SYNTHESES = ("auto", "diagonal", "mcz")

#: the largest group of qubits one Walsh-Hadamard block acts on: 3 was the fastest of 1..5 for
#: n = 6..16 (wider blocks cost more arithmetic per amplitude, narrower more instructions)
WALSH_HADAMARD_BLOCK = 3

#: cost model of ``simulation_synthesis``: one phase of a ``diagonal`` instruction costs about
#: 1/ENTRIES_PER_INSTRUCTION of one extra instruction. Fitted on ``AerBackend``'s controller path
#: (``aer_direct``; qiskit 2.6 / Aer 0.18, 2-core machine, ``benchmarks/bench_search.py``'s
#: ``synthesis`` sweep: both forms for n = 8..14, m = 1..64, k = 12, 8 shots): the diagonal form
#: was faster up to 2^n / (2m + 1) = 252 at every n, the mcz form from 341 on for n = 10-12, while
#: at n = 14 the two crossed near 500 (the arithmetic of the X strings grows with 2^n); 300 lies
#: between (through ``AerSimulator.run``, whose assembler handles each phase in Python, the
#: crossover was 100-200 and this constant 128). Below 13 qubits ``AerBackend`` now runs on Aer's
#: state (``aer_state``); with it the same sweep's choice took at most 1.048 times the faster form's
#: time, 1.002 on average (``benchmarks/results/run_c22abd7.json``, ``search.synthesis``)
ENTRIES_PER_INSTRUCTION = 300

#: one instruction of a Grover program: an operation and the qubits it acts on (a
#: ``CircuitInstruction`` is made of it only when a ``QuantumCircuit`` is built: making one copies
#: a ``diagonal``'s 2^n phases into qiskit's own representation, ~1 us per phase)
Step = tuple[Operation, tuple[Qubit, ...]]


def _diagonal_gate(phases: np.ndarray) -> DiagonalGate:
    """A ``DiagonalGate`` of ``phases`` (entries +-1) without its per-entry Python validation.

    ``DiagonalGate(list)`` checks every entry in Python; the entries here are +-1 by construction,
    so the gate is made from the list directly (``Operator`` and Aer read the same list)."""
    gate = DiagonalGate.__new__(DiagonalGate)
    Gate.__init__(gate, "diagonal", int(phases.shape[0]).bit_length() - 1, [])
    gate._params = phases.astype(complex).tolist()
    return gate


def parity_signs(num_qubits: int) -> np.ndarray:
    """(-1)^popcount(i) for i = 0 .. 2^n - 1: the diagonal of Z^n.

    Args:
        num_qubits: n.

    Returns:
        Float array of 2^n entries +-1.

    Example:
        >>> from qrrt_circuits.search.aer_circuits import parity_signs
        >>> parity_signs(2).tolist()
        [1.0, -1.0, -1.0, 1.0]
    """
    index = np.arange(1 << num_qubits, dtype=np.int64)
    parity = np.zeros_like(index)
    for bit in range(num_qubits):
        parity ^= (index >> bit) & 1
    return 1.0 - 2.0 * parity


def _walsh_hadamard(size: int) -> UnitaryGate:
    hadamard = np.array([[1.0, 1.0], [1.0, -1.0]]) / math.sqrt(2.0)
    matrix: np.ndarray = np.ones((1, 1))
    for _ in range(size):
        matrix = np.kron(matrix, hadamard)
    return UnitaryGate(matrix, label=f"W{size}")


class _Parts:
    """The instructions of one register width n that no search changes (built once per n)."""

    def __init__(self, num_qubits: int, block: int) -> None:
        self.num_qubits = n = num_qubits
        template = QuantumCircuit(n, n, name="grover_aer")
        self.qubits = qubits = tuple(template.qubits)
        self.clbits = template.clbits
        self.qregs, self.cregs = template.qregs, template.cregs
        walsh = []
        for start in range(0, n, block):
            group = qubits[start:start + block]
            walsh.append((_walsh_hadamard(len(group)), group))
        self.walsh = tuple(walsh)
        reflection = PhaseGate(math.pi) if n == 1 else MCPhaseGate(math.pi, n - 1)
        self.reflection: Step = (reflection, qubits)
        self.parity: Step = (PauliGate("Z" * n), qubits)
        self.measures = tuple(CircuitInstruction(Measure(), (qubit,), (clbit,))
                              for qubit, clbit in zip(qubits, self.clbits, strict=True))
        self.signs = parity_signs(n)
        #: qubit tuple -> its indices, filled as instructions are assembled for Aer (aer_direct)
        self.qubit_indices: dict[tuple, list[int]] = {}

    def indices_of(self, qubits: tuple) -> list[int]:
        """The indices of ``qubits`` in this register (cached per tuple)."""
        indices = self.qubit_indices.get(qubits)
        if indices is None:
            position = {qubit: index for index, qubit in enumerate(self.qubits)}
            indices = self.qubit_indices[qubits] = [position[qubit] for qubit in qubits]
        return indices


@functools.lru_cache(maxsize=32)
def _parts(num_qubits: int, block: int) -> _Parts:
    return _Parts(num_qubits, block)


def simulation_synthesis(marks: np.ndarray) -> str:
    """The oracle form Aer runs fastest (``"diagonal"`` or ``"mcz"``): a ``diagonal`` costs its
    2^n entries, the ``mcz`` form two instructions per flipped entry (min(m, N - m) of them).

    Args:
        marks: Boolean (or 0/1) array of length 2^n.

    Returns:
        ``"diagonal"`` if N <= ``ENTRIES_PER_INSTRUCTION`` (2 min(m, N - m) + 1), else ``"mcz"``.

    Raises:
        ValueError: ``marks`` not of length 2^n or not boolean.
    """
    return choose_simulation_synthesis(validate_marks(marks)[0])


def choose_simulation_synthesis(marks: np.ndarray) -> str:
    """``simulation_synthesis`` of marks already validated (a bool array of length 2^n)."""
    return simulation_synthesis_for(marks.shape[0].bit_length() - 1, int(np.count_nonzero(marks)))


def simulation_synthesis_for(num_qubits: int, marked: int) -> str:
    """``simulation_synthesis`` of any marks with m = ``marked`` entries among 2^n: ``"diagonal"``
    if 2^n <= ``ENTRIES_PER_INSTRUCTION`` (2 min(m, 2^n - m) + 1), else ``"mcz"``."""
    entries = 1 << num_qubits
    flipped = min(marked, entries - marked)
    return "diagonal" if entries <= ENTRIES_PER_INSTRUCTION * (2 * flipped + 1) else "mcz"


def _sparse_oracles(parts: _Parts, marks: np.ndarray, iterations: int) -> tuple[list[list[Step]], float]:
    """The ``mcz`` form of the k oracles: per oracle call one ``mcphase`` per flipped index i,
    conjugated by X on the zero bits of i (which maps |i> to |1...1>); returns the instructions
    to put before each iteration's diffuser, and the global phase of one oracle call.

    Consecutive X-strings are merged (X^a X^b = X^(a xor b)). An X-string commutes with the
    diffuser W MCZ W (W X^a W = Z^a, diagonal like MCZ), so an oracle's last X-string cancels the
    next oracle's first one when the next oracle visits the indices in reverse order: the oracles
    alternate forward and backward, and only the first and the last X-string of the whole search
    remain (m - 1 X-strings per call instead of m + 1)."""
    n = parts.num_qubits
    flip_marked = 2 * int(np.count_nonzero(marks)) <= marks.shape[0]
    indices = np.flatnonzero(marks if flip_marked else ~marks).tolist()
    phase = 0.0 if flip_marked else math.pi
    if not indices:
        return [[] for _ in range(iterations)], phase
    full = (1 << n) - 1
    wanted = [~index & full for index in indices]  # X on the zero bits maps |index> to |1...1>
    forward = [parts.reflection]
    for previous, current in zip(wanted, wanted[1:], strict=False):
        forward += [*_x_string(parts, previous ^ current), parts.reflection]
    backward = forward[::-1]
    calls = [list(forward if call % 2 == 0 else backward) for call in range(iterations)]
    calls[0][:0] = _x_string(parts, wanted[0])
    calls[-1] += _x_string(parts, wanted[-1] if (iterations - 1) % 2 == 0 else wanted[0])
    return calls, phase


def _x_string(parts: _Parts, mask: int) -> list[Step]:
    """X on the qubits whose bit is set in ``mask`` (one ``PauliGate``, whose label is big-endian;
    none for mask 0)."""
    if not mask:
        return []
    label = "".join("X" if mask >> qubit & 1 else "I" for qubit in reversed(range(parts.num_qubits)))
    return [(PauliGate(label), parts.qubits)]


def aer_grover_circuit(
    marks: np.ndarray, iterations: int, measure: bool = True, synthesis: str = "auto",
    block: int = WALSH_HADAMARD_BLOCK,
) -> QuantumCircuit:
    """W|0>, ``iterations`` Grover iterations and (if ``measure``) measurement into the classical
    register ``c`` (n bits, little-endian as ``grover_circuit``'s ``meas``), from Aer-native
    instructions only; the same unitary as ``grover_circuit`` up to a global phase.

    ``synthesis``: the oracle's form, ``"diagonal"``, ``"mcz"`` or ``"auto"``
    (``simulation_synthesis``); ``block``: the widest Walsh-Hadamard block (1 gives single-qubit
    ones).

    Args:
        marks: Boolean (or 0/1) array of length 2^n, n >= 1.
        iterations: k, 0 .. ``MAX_ITERATIONS`` (paper Alg. 2, lines 7-8).
        measure: Measure into the register ``c`` (default True).
        synthesis: ``"auto"`` (default), ``"diagonal"`` or ``"mcz"``.
        block: The widest Walsh-Hadamard block, 1 .. 10 qubits.

    Returns:
        An n-qubit ``QuantumCircuit`` named ``grover_aer``.

    Raises:
        ValueError: ``marks`` not of length 2^n or not boolean, k out of range, an unknown
            ``synthesis`` or ``block`` out of range.
        TypeError: A non-integer k or ``block``.

    Example:
        >>> import numpy as np
        >>> from qiskit.quantum_info import Operator
        >>> from qrrt_circuits.search.aer_circuits import aer_grover_circuit
        >>> from qrrt_circuits.search.circuits import grover_circuit
        >>> marks = np.array([0, 0, 0, 0, 0, 1, 0, 0], dtype=bool)
        >>> fast = aer_grover_circuit(marks, 2, measure=False)
        >>> Operator(fast).equiv(Operator(grover_circuit(marks, 2, measure=False)))
        True
    """
    return aer_grover_program(marks, iterations, synthesis, block).circuit(measure)


@dataclass(frozen=True, eq=False)
class GroverProgram:
    """The instruction sequence of ``aer_grover_circuit`` before it becomes a ``QuantumCircuit``:
    the Walsh-Hadamard blocks, then per Grover iteration the oracle's instructions, W, one
    ``mcphase`` and W, and the final Z^n, with the circuit's global phase.

    ``circuit()`` makes the ``QuantumCircuit``; ``aer_direct.assemble_program`` hands the same
    instructions, in the same order, to Aer's controller without building one (``AerBackend``'s
    path; the measured words are the same, tested).

    Attributes:
        num_qubits: n.
        steps: The (operation, qubits) pairs, in order (without measurements).
        global_phase: The circuit's global phase.
    """

    parts: _Parts
    steps: tuple[Step, ...]
    global_phase: float

    @property
    def num_qubits(self) -> int:
        return self.parts.num_qubits

    def circuit(self, measure: bool = True) -> QuantumCircuit:
        """The n-qubit ``QuantumCircuit`` named ``grover_aer`` (with ``measure``, measured into
        the classical register ``c``, qubit i into bit i)."""
        parts = self.parts
        circuit = QuantumCircuit(*parts.qregs, *(parts.cregs if measure else ()), name="grover_aer")
        append = circuit._append
        made: dict[int, CircuitInstruction] = {}  # one instruction per operation object (the k - 1
        for operation, qubits in self.steps:      # later oracle calls share one diagonal)
            instruction = made.get(id(operation))
            if instruction is None or instruction.qubits != qubits:
                instruction = made[id(operation)] = CircuitInstruction(operation, qubits)
            append(instruction)
        circuit.global_phase = self.global_phase
        if measure:
            for instruction in parts.measures:
                append(instruction)
        return circuit


def aer_grover_program(marks: np.ndarray, iterations: int, synthesis: str = "auto",
                       block: int = WALSH_HADAMARD_BLOCK) -> GroverProgram:
    """The instructions of ``aer_grover_circuit(marks, iterations, synthesis=synthesis,
    block=block)`` as a ``GroverProgram`` (same arguments, same checks).

    Args:
        marks: Boolean (or 0/1) array of length 2^n, n >= 1.
        iterations: k, 0 .. ``MAX_ITERATIONS``.
        synthesis: ``"auto"`` (default), ``"diagonal"`` or ``"mcz"``.
        block: The widest Walsh-Hadamard block, 1 .. 10 qubits.

    Returns:
        The ``GroverProgram``.

    Raises:
        ValueError: ``marks`` not of length 2^n or not boolean, k out of range, an unknown
            ``synthesis`` or ``block`` out of range.
        TypeError: A non-integer k or ``block``.
    """
    marks, n = validate_marks(marks)
    iterations = validate_iterations(iterations)
    if synthesis not in AER_SYNTHESES:
        raise ValueError(f"synthesis must be one of {AER_SYNTHESES}, got {synthesis!r}")
    block = check_int(block, "block", 1, 10)
    if synthesis == "auto":
        synthesis = choose_simulation_synthesis(marks)
    parts = _parts(n, block)
    steps: list[Step] = list(parts.walsh)
    phase = 0.0
    if iterations:
        if synthesis == "diagonal":
            signs = np.where(marks, -1.0, 1.0)
            first: Step = (_diagonal_gate(signs * parts.signs), parts.qubits)
            rest: Step = (_diagonal_gate(signs), parts.qubits) if iterations > 1 else first
            calls: list[list[Step]] = [[first]] + [[rest]] * (iterations - 1)
        else:
            calls, phase = _sparse_oracles(parts, marks, iterations)
            calls[0].insert(0, parts.parity)
        for oracle in calls:
            steps += oracle
            steps += parts.walsh
            steps.append(parts.reflection)
            steps += parts.walsh
        steps.append(parts.parity)
    return GroverProgram(parts, tuple(steps), phase * iterations)


def check_grover_arguments(marks: np.ndarray, iterations: int) -> None:
    """The cheap checks the direct paths (``aer_direct.execute_grover``, ``aer_state.execute_grover``)
    make themselves, behind ``AerBackend``'s full ones: a 1-D bool array of length 2^n >= 2 and an
    int k >= 0 (no coercion).

    Raises:
        ValueError: Either argument is not of that form, naming it.
    """
    if not (isinstance(marks, np.ndarray) and marks.dtype == np.bool_ and marks.ndim == 1):
        raise ValueError(f"marks must be a 1-D bool array (validate_marks), got {marks!r}")
    size = marks.shape[0]
    if size < 2 or size & (size - 1):
        raise ValueError(f"marks must have length 2**n with n >= 1, got length {size}")
    if type(iterations) is not int or iterations < 0:
        raise ValueError(f"iterations must be an int >= 0 (validate_iterations), got {iterations!r}")


class DiagonalFormTarget(Protocol):
    """Where ``DiagonalForm.emit`` puts the instructions: Aer's circuit object (``aer_direct``) or
    Aer's statevector state (``aer_state``); qubits as register indices."""

    def unitary(self, qubits: list[int], matrix: np.ndarray, label: str) -> None:
        """A ``unitary`` instruction (a Walsh-Hadamard block)."""

    def diagonal(self, qubits: list[int], phases: list[complex]) -> None:
        """A ``diagonal`` instruction of 2^n phases (the oracle)."""

    def gate(self, name: str, qubits: list[int], params: list[float], label: str) -> None:
        """The reflection: ``mcphase`` (``p`` for n = 1) with its angle."""

    def pauli(self, qubits: list[int], label: str) -> None:
        """A ``pauli`` instruction (the final Z^n; big-endian label)."""


@dataclass(frozen=True, eq=False)
class DiagonalForm:
    """The instructions of ``aer_grover_program(marks, k, "diagonal", block)`` that no search
    changes, as the arguments of Aer's calls (register indices, matrices, labels), made once per n
    and block width (``diagonal_form``): the Walsh-Hadamard blocks, the reflection, the final Z^n
    and the signs (-1)^popcount(i) folded into the first oracle call.

    ``emit`` gives a target the program's instructions in order, with only the oracle's two phase
    lists made per search, without building the program's operations."""

    qubits: list[int]
    walsh: tuple[tuple[list[int], np.ndarray, str], ...]
    reflection: tuple[str, list[float], str]
    parity: str
    signs: np.ndarray

    def emit(self, target: DiagonalFormTarget, marks: np.ndarray, iterations: int) -> None:
        """W, then per iteration the oracle's ``diagonal`` (the first with Z^n folded in), W, the
        reflection and W, then Z^n (none of these for k = 0 but W): the program's steps, in order.

        Args:
            target: Where the instructions go.
            marks: Bool array of length 2^n (validated by the caller).
            iterations: k >= 0 (validated by the caller).
        """
        qubits = self.qubits
        walsh = self.walsh
        for group, matrix, label in walsh:
            target.unitary(group, matrix, label)
        if not iterations:
            return
        signs = np.where(marks, -1.0, 1.0)
        first = (signs * self.signs).astype(complex).tolist()
        rest = signs.astype(complex).tolist() if iterations > 1 else first
        name, params, reflection_label = self.reflection
        for call in range(iterations):
            target.diagonal(qubits, rest if call else first)
            for group, matrix, label in walsh:
                target.unitary(group, matrix, label)
            target.gate(name, qubits, params, reflection_label)
            for group, matrix, label in walsh:
                target.unitary(group, matrix, label)
        target.pauli(qubits, self.parity)


@functools.lru_cache(maxsize=32)
def diagonal_form(num_qubits: int, block: int) -> DiagonalForm:
    """The ``DiagonalForm`` of n qubits and Walsh-Hadamard blocks of at most ``block`` qubits,
    from the cached parts ``aer_grover_program`` uses (``_parts``)."""
    parts = _parts(num_qubits, block)
    reflection, _ = parts.reflection
    parity, _ = parts.parity
    return DiagonalForm(
        list(range(num_qubits)),
        tuple((parts.indices_of(group), gate.params[0], gate.label or "unitary") for gate, group in parts.walsh),
        (reflection.name, [float(p) for p in reflection.params], reflection.label or reflection.name),
        str(parity.params[0]), parts.signs)
