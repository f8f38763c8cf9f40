"""Grover search with the coherent oracle (paper Alg. 2, lines 4-8), the ancillas left alone.

The oracle's ancillas start and end in |0> (``oracle``), so Grover's iteration acts on the index
register only: W = H^n on the n index qubits, Q = (reflection about W|0> on the index qubits) x
oracle, as Qiskit's ``grover_operator`` with ``reflection_qubits`` the index. After k iterations a
marked index is measured with probability sin^2((2k+1) theta), sin^2 theta = m / 2^n (Lemma 1),
as with the lookup oracle.

The qubits' order does not change the circuit, but it changes the cost of a matrix-product-state
simulation, where a gate between distant qubits costs swaps along the chain: every part of the
oracle talks to the index register, and placing it in the middle of the chain
(``index_in_middle``) halves the longest distance to it (``benchmarks/bench_coherent_oracle.py``
uses it; the commit that added it gives the measured effect).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._support.validation import check_int

if TYPE_CHECKING:
    from qiskit import QuantumCircuit


def coherent_grover_circuit(oracle: QuantumCircuit, num_index_bits: int, iterations: int,
                            measure: bool = True, index_in_middle: bool = False) -> QuantumCircuit:
    """H^n on the index, ``iterations`` Grover iterations with ``oracle``, then (optionally) the
    index measured into a register ``meas``.

    Args:
        oracle: A coherent oracle (``coherent_phase_oracle``): index qubits first, ancillas in |0>.
        num_index_bits: n, 1 .. the oracle's qubits.
        iterations: k, 0 .. 10 000.
        measure: Measure the index qubits (default True); bit j of the result is index bit j.
        index_in_middle: Put the index register in the middle of the qubits, half of the ancillas
            before it (module text); default False: the oracle's order, index first.

    Returns:
        The ``QuantumCircuit`` (named ``coherent_grover``) on the oracle's qubits.

    Raises:
        TypeError: A non-integer n or k.
        ValueError: n or k out of range.
    """
    from qiskit import ClassicalRegister, QuantumCircuit
    from qiskit.circuit.library import grover_operator

    from .._support.validation import check_bool

    n = check_int(num_index_bits, "num_index_bits", 1, oracle.num_qubits)
    iterations = check_int(iterations, "iterations", 0, 10_000)
    index = list(range(n))
    preparation = QuantumCircuit(oracle.num_qubits, name="W")
    preparation.h(index)
    circuit = QuantumCircuit(*oracle.qregs, name="coherent_grover")
    circuit.compose(preparation, inplace=True)
    if iterations:
        step = grover_operator(oracle, state_preparation=preparation, reflection_qubits=index)
        for _ in range(iterations):
            circuit.compose(step, inplace=True)
    if check_bool(index_in_middle, "index_in_middle"):
        ancillas = list(range(n, oracle.num_qubits))
        half = len(ancillas) // 2
        order = ancillas[:half] + index + ancillas[half:]  # order[position] = oracle qubit
        position = {qubit: place for place, qubit in enumerate(order)}
        moved = QuantumCircuit(oracle.num_qubits, name="coherent_grover")
        moved.compose(circuit, qubits=[position[q] for q in range(oracle.num_qubits)], inplace=True)
        circuit, index = moved, [position[q] for q in index]
    if measure:
        bits = ClassicalRegister(n, "meas")
        circuit.add_register(bits)
        circuit.measure(index, bits)
    return circuit
