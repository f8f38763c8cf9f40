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

from .._support.validation import check_bool, check_int
from ..search.oracles import CircuitForm, CircuitOracle

if TYPE_CHECKING:
    import numpy as np
    from qiskit import QuantumCircuit


def coherent_search_oracle(oracle: QuantumCircuit, num_index_bits: int, marks: np.ndarray | None = None,
                           index_in_middle: bool = True) -> CircuitOracle:
    """The coherent oracle as the ``CircuitOracle`` a backend searches (``backend.search(oracle, k,
    shots, seed)``), its index register in the middle of the qubits by default (module text: the
    layout a matrix-product-state simulation runs fastest).

    Args:
        oracle: A coherent oracle (``coherent_phase_oracle``): index qubits first, ancillas in |0>.
        num_index_bits: n, 1 .. the oracle's qubits.
        marks: The 2^n marks it computes (``reachable_reference``), where known; None (default).
        index_in_middle: Move the index register to the middle of the qubits (default True); False:
            the oracle's order, index first.

    Returns:
        The ``CircuitOracle``.

    Raises:
        TypeError: A non-integer n.
        ValueError: n out of range, or ``marks`` not of length 2^n.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits import AerBackend, Environment
        >>> from qrrt_circuits.coherent import (FixedPointFormat, LatticeDatabase, SampledMotion,
        ...                                     coherent_phase_oracle, coherent_search_oracle, reachable_reference)
        >>> env = Environment([[0, 15], [0, 15]], [[[6, 0], [9, 9]]])
        >>> db = LatticeDatabase(FixedPointFormat(4, 0.0, 16.0), 2, np.array([[2.0, 2.0]]))
        >>> motion = SampledMotion.straight_line(2, 3, 1)
        >>> marks = reachable_reference(env, db, motion)
        >>> oracle = coherent_search_oracle(coherent_phase_oracle(env, db, motion), 4, marks=marks)
        >>> result = AerBackend(method="matrix_product_state").search(oracle, 1, shots=200, seed=1)
        >>> bool(marks[result.indices].mean() > marks.mean())  # amplified above the marked share
        True
    """
    n = check_int(num_index_bits, "num_index_bits", 1, oracle.num_qubits)
    if not check_bool(index_in_middle, "index_in_middle"):
        return CircuitOracle(oracle, n, marks)
    from qiskit import QuantumCircuit

    ancillas = list(range(n, oracle.num_qubits))
    half = len(ancillas) // 2
    order = ancillas[:half] + list(range(n)) + ancillas[half:]  # order[position] = oracle qubit
    position = {qubit: place for place, qubit in enumerate(order)}
    moved = QuantumCircuit(oracle.num_qubits, name=oracle.name)
    moved.compose(oracle, qubits=[position[q] for q in range(oracle.num_qubits)], inplace=True)
    return CircuitOracle(moved, [position[q] for q in range(n)], marks)


def coherent_grover_circuit(oracle: QuantumCircuit, num_index_bits: int, iterations: int,
                            measure: bool = True, index_in_middle: bool = False) -> QuantumCircuit:
    """H^n on the index, ``iterations`` Grover iterations with ``oracle``, then (optionally) the
    index measured into a register ``meas``: ``CircuitOracle.grover_circuit`` of
    ``coherent_search_oracle``.

    Args:
        oracle: A coherent oracle (``coherent_phase_oracle``): index qubits first, ancillas in |0>.
        num_index_bits: n, 1 .. the oracle's qubits.
        iterations: k, 0 .. 10 000, and k x (the oracle's gates + 4 n + 1) at most
            ``search.oracles.MAX_GROVER_GATES``.
        measure: Measure the index qubits (default True); bit j of the result is index bit j.
        index_in_middle: Put the index register in the middle of the qubits, half of the ancillas
            before it (module text); default False: the oracle's order, index first.

    Returns:
        The ``QuantumCircuit`` on the oracle's qubits.

    Raises:
        TypeError: A non-integer n or k.
        ValueError: n or k out of range, or a circuit of more than ``MAX_GROVER_GATES`` gates
            (refused before it is built, naming ``iterations``, the oracle's size and the most
            iterations that fit).
    """
    iterations = check_int(iterations, "iterations", 0, 10_000)
    searched = coherent_search_oracle(oracle, num_index_bits, index_in_middle=index_in_middle)
    circuit = searched.grover_circuit(iterations, CircuitForm.LOGICAL)
    if not measure:
        circuit = circuit.copy()
        circuit.remove_final_measurements()
    return circuit
