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

Why these forms: for small n, the per-instruction work around the simulation (building the
circuit, Aer's conversion of each instruction) costs far more than the arithmetic on the state
vector, so the circuit has as few instructions as possible; a ``diagonal`` instruction costs per
entry (its 2^n phases are copied into qiskit's circuit and converted by Aer for every instance),
so ``simulation_synthesis`` weighs 2^n entries against 2m + 1 instructions. That choice is
separate from ``circuits.choose_synthesis``, which counts CX gates for hardware and is what
``resource_estimate`` uses.

The parts that depend only on n (the W blocks, the ``mcphase``, the ``pauli`` Z^n, the
measurements) are built once per n and reused; per search only the oracle's instructions are new,
built from numpy arrays without per-entry Python work. ``aer_grover_program`` gives the
instructions as a ``GroverProgram`` of (operation, qubits) steps; its ``circuit()`` is the
``QuantumCircuit`` of ``aer_grover_circuit``.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from qiskit import QuantumCircuit
from qiskit.circuit import CircuitInstruction, Measure, Operation, Qubit
from qiskit.circuit.library import DiagonalGate, MCPhaseGate, PauliGate, PhaseGate, UnitaryGate

from .._support.validation import check_int
from .requests import validate_iterations, validate_marks
from .synthesis import OracleSynthesis

#: the largest group of qubits one Walsh-Hadamard block acts on (wider blocks cost more arithmetic
#: per amplitude, narrower ones more instructions)
WALSH_HADAMARD_BLOCK = 3

#: cost model of ``simulation_synthesis``: one phase of a ``diagonal`` instruction costs about
#: 1/ENTRIES_PER_INSTRUCTION of one extra instruction
ENTRIES_PER_INSTRUCTION = 300

#: one instruction of a Grover program: an operation and the qubits it acts on (a
#: ``CircuitInstruction`` is made of it only when a ``QuantumCircuit`` is built: making one copies
#: a ``diagonal``'s 2^n phases into qiskit's own representation)
Step = tuple[Operation, tuple[Qubit, ...]]


def _diagonal_gate(phases: np.ndarray) -> DiagonalGate:
    """A ``DiagonalGate`` of ``phases`` (entries +-1.0), through its documented constructor.

    The gate checks and converts every entry in Python; given a list of Python ``complex`` (the
    type it stores) it does so about twice as fast as from floats or from an array, which makes
    this the cheapest documented way to build it."""
    return DiagonalGate(phases.astype(complex).tolist())


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


@functools.lru_cache(maxsize=32)
def _parts(num_qubits: int, block: int) -> _Parts:
    return _Parts(num_qubits, block)


def simulation_synthesis(marks: np.ndarray) -> OracleSynthesis:
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


def choose_simulation_synthesis(marks: np.ndarray) -> OracleSynthesis:
    """``simulation_synthesis`` of marks already validated (a bool array of length 2^n)."""
    return simulation_synthesis_for(marks.shape[0].bit_length() - 1, int(np.count_nonzero(marks)))


def simulation_synthesis_for(num_qubits: int, marked: int) -> OracleSynthesis:
    """``simulation_synthesis`` of any marks with m = ``marked`` entries among 2^n: ``"diagonal"``
    if 2^n <= ``ENTRIES_PER_INSTRUCTION`` (2 min(m, 2^n - m) + 1), else ``"mcz"``."""
    entries = 1 << num_qubits
    flipped = min(marked, entries - marked)
    if entries <= ENTRIES_PER_INSTRUCTION * (2 * flipped + 1):
        return OracleSynthesis.DIAGONAL
    return OracleSynthesis.MCZ


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
    marks: np.ndarray, iterations: int, measure: bool = True, synthesis: str | OracleSynthesis = "auto",
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

    ``circuit()`` makes the ``QuantumCircuit``.

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


def aer_grover_program(marks: np.ndarray, iterations: int, synthesis: str | OracleSynthesis = "auto",
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
    synthesis = OracleSynthesis.parse(synthesis)
    block = check_int(block, "block", 1, 10)
    if synthesis is OracleSynthesis.AUTO:
        synthesis = choose_simulation_synthesis(marks)
    parts = _parts(n, block)
    steps: list[Step] = list(parts.walsh)
    phase = 0.0
    if iterations:
        if synthesis is OracleSynthesis.DIAGONAL:
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
