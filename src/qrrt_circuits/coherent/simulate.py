"""Exhaustive classical simulation of a reversible oracle: every index basis state at once.

A circuit of X, CX and CCX gates maps basis states to basis states, and a Z only multiplies one by
-1; so the oracle on |i>|0> is (-1)^phase(i) |pi(i)>, and all 2^n inputs can be followed at
once, bit by bit: each qubit is a vector of 2^n bits (packed in 64-bit words), X complements
it, CX XORs the control's vector into the target's, CCX the AND of the two controls', and a Z
XORs its qubit's vector into the phase. ``simulate`` returns the phases, whether the index and
every ancilla end as they began, and checks every Toffoli against its tag: an AND's target must be
0 before it for every input, an undo's target must equal the AND of its controls (so it returns to
0, and measurement-based uncomputation is valid there). Memory: (qubits + 3) x 2^n / 8 bytes.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from .tally import AND, CX, UNDO, X, Z

if TYPE_CHECKING:
    from qiskit import QuantumCircuit

#: an untagged CCX (read from a circuit)
CCX = 5
#: the most bytes of qubit vectors ``simulate`` allocates
MAX_SIMULATION_BYTES = 2 << 30


def simulation_bytes(num_index: int, num_qubits: int) -> int:
    """Peak bytes ``simulate`` adds: the qubit vectors, the index's initial bits and the phase
    ((qubits + n + 3) 2^n / 8) and the index bits' construction and the phases unpacked (26 bytes
    an index state).

    Args:
        num_index: n.
        num_qubits: All qubits.

    Returns:
        The bytes.
    """
    states = 1 << num_index
    words = max(1, (states + 63) // 64)
    return (num_qubits + num_index + 3) * words * 8 + 26 * words * 64


@dataclass(frozen=True)
class PermutationResult:
    """The oracle on every |i>|0> (module text).

    Args:
        phases: Bool (2^n,): the phase bit of each index (True: -1).
        index_preserved: Every index qubit ends as it began.
        ancillas_clean: Every other qubit ends in 0.
        ands: Toffolis whose target is 0 before them for every input.
        undos: The other Toffolis whose target equals the AND of the controls for every input.
        other_toffolis: Toffolis that are neither (0 for a circuit of ANDs and undos).
        tag_errors: Tagged Toffolis whose tag the simulation contradicts.
        final: Uint64 (qubits, words): each qubit's final bits over the inputs, packed
            (``qubit_values`` unpacks one).
    """

    phases: np.ndarray
    index_preserved: bool
    ancillas_clean: bool
    ands: int
    undos: int
    other_toffolis: int
    tag_errors: int
    final: np.ndarray

    def qubit_values(self, qubit: int) -> np.ndarray:
        """Bool (2^n,): the qubit's final value for each index."""
        states = self.phases.shape[0]
        return np.unpackbits(self.final[qubit].view(np.uint8), bitorder="little")[:states].astype(bool)


def circuit_gates(circuit: QuantumCircuit) -> np.ndarray:
    """A circuit of x, cx, ccx and z gates as (code, q0, q1, q2) rows (CCX untagged).

    Args:
        circuit: The ``QuantumCircuit``.

    Returns:
        Int64 (G, 4).

    Raises:
        ValueError: A gate other than x, cx, ccx and z.
    """
    codes = {"x": X, "cx": CX, "ccx": CCX, "z": Z}
    position = {qubit: i for i, qubit in enumerate(circuit.qubits)}
    rows = np.full((len(circuit.data), 4), -1, dtype=np.int64)
    for row, instruction in enumerate(circuit.data):
        name = instruction.operation.name
        if name not in codes:
            raise ValueError(f"simulate handles x, cx, ccx and z gates, got {name!r}")
        rows[row, 0] = codes[name]
        for k, qubit in enumerate(instruction.qubits):
            rows[row, 1 + k] = position[qubit]
    return rows


def simulate(gates: np.ndarray, num_qubits: int, num_index: int) -> PermutationResult:
    """Run the gates on every index basis state with all other qubits 0 (module text).

    Args:
        gates: (code, q0, q1, q2) rows: ``emitter`` codes (AND and UNDO tagged) or ``CCX``.
        num_qubits: All qubits.
        num_index: n, the index qubits 0 .. n - 1.

    Returns:
        The ``PermutationResult``.

    Raises:
        ValueError: The qubit vectors would exceed ``MAX_SIMULATION_BYTES``.
    """
    states = 1 << num_index
    words = max(1, (states + 63) // 64)
    needed = (num_qubits + 3) * words * 8
    if needed > MAX_SIMULATION_BYTES:
        raise ValueError(f"simulating n = {num_index} index bits on {num_qubits} qubits needs "
                         f"{needed / 2**30:.1f} GiB, more than {MAX_SIMULATION_BYTES / 2**30:.0f} GiB: "
                         "use fewer index bits")
    mask = np.full(words, np.uint64(0xFFFFFFFFFFFFFFFF), dtype=np.uint64)
    if states < 64:
        mask[0] = np.uint64((1 << states) - 1)
    values = np.zeros((num_qubits, words), dtype=np.uint64)
    counting = np.arange(words * 64, dtype=np.int64)
    initial = np.empty((num_index, words), dtype=np.uint64)
    for q in range(num_index):
        bits = ((counting >> q) & 1).astype(np.uint8)
        initial[q] = np.packbits(bits, bitorder="little").view(np.uint64)
    values[:num_index] = initial & mask
    phase = np.zeros(words, dtype=np.uint64)
    ones = np.uint64(0xFFFFFFFFFFFFFFFF)
    ands = undos = other = tag_errors = 0
    scratch = np.empty(words, dtype=np.uint64)
    for code, a, b, c in gates.tolist():
        if code == X:
            np.bitwise_xor(values[a], ones, out=values[a])
        elif code == CX:
            np.bitwise_xor(values[b], values[a], out=values[b])
        elif code == Z:
            np.bitwise_xor(phase, values[a], out=phase)
        else:
            np.bitwise_and(values[a], values[b], out=scratch)
            target = values[c]
            zero = not np.any(target & mask)
            equal = zero and not np.any(scratch & mask) or np.array_equal(target & mask, scratch & mask)
            if code == AND:
                tag_errors += not zero
            elif code == UNDO:
                tag_errors += not equal
            if zero:
                ands += 1
            elif equal:
                undos += 1
            else:
                other += 1
            np.bitwise_xor(target, scratch, out=target)
    values &= mask
    phase &= mask
    index_preserved = bool(np.array_equal(values[:num_index], initial & mask))
    ancillas_clean = not bool(np.any(values[num_index:]))
    unpacked = np.unpackbits(phase.view(np.uint8), bitorder="little")[:states].astype(bool)
    return PermutationResult(unpacked, index_preserved, ancillas_clean, ands, undos, other, tag_errors, values)
