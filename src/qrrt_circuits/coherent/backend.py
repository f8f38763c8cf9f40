"""A search backend bound to one coherent oracle: Grover search runs the reversible circuit of the
motion check on Aer, not a lookup of the marks.

``CoherentOracleBackend(oracle, num_index_bits)`` searches the database its oracle circuit was built
for (``LatticeCandidates(coherent=True)`` makes one per database): ``search(marks, k, shots,
seed)`` runs ``coherent_grover_circuit(oracle, n, k)`` (index register in the middle of the chain)
on ``AerSimulator(method="matrix_product_state")`` with ``seed_simulator``, transpiled to Aer's
gates once per iteration count. ``marks`` must be the circuit's own marks (``reachable_reference``,
which the circuit equals entry for entry): they size the search and keep the planner's accounting
(marked count, verification) about the same oracle; the circuit alone decides what is measured.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .._support.validation import check_int
from ..search.backends.base import QuantumSearchBackend

if TYPE_CHECKING:
    from qiskit import QuantumCircuit

__all__ = ["CoherentOracleBackend"]

#: Aer's gates for the transpile of each search
AER_BASIS = ("x", "z", "h", "cx", "ccx", "u", "p", "measure")


class CoherentOracleBackend(QuantumSearchBackend):
    """Grover search with one coherent oracle on Aer (module docstring).

    Args:
        oracle: The oracle circuit (``coherent_phase_oracle``): index qubits first.
        num_index_bits: n, its index qubits.
    """

    name = "coherent-aer"

    def __init__(self, oracle: QuantumCircuit, num_index_bits: int) -> None:
        self.oracle = oracle
        self.num_index_bits = check_int(num_index_bits, "num_index_bits", 1, oracle.num_qubits)
        self._rng = np.random.default_rng()
        self._circuits: dict[int, QuantumCircuit] = {}  # transpiled once per iteration count

    @property
    def max_qubits(self) -> int:
        return self.num_index_bits

    def describe(self) -> str:
        return (f"coherent oracle on Aer (matrix_product_state, {self.oracle.num_qubits} qubits, "
                f"{self.num_index_bits} index)")

    def _sample(self, marks: np.ndarray, num_qubits: int, iterations: int, shots: int,
                rng: np.random.Generator) -> np.ndarray:
        from qiskit import transpile
        from qiskit_aer import AerSimulator

        from .grover import coherent_grover_circuit

        if num_qubits != self.num_index_bits:
            raise ValueError(f"this backend searches its oracle's {self.num_index_bits} index qubits, "
                             f"not {num_qubits}")
        circuit = self._circuits.get(iterations)
        if circuit is None:
            circuit = transpile(coherent_grover_circuit(self.oracle, num_qubits, iterations, index_in_middle=True),
                                basis_gates=list(AER_BASIS), optimization_level=0)
            self._circuits[iterations] = circuit
        result = AerSimulator(method="matrix_product_state").run(
            circuit, shots=shots, seed_simulator=int(rng.integers(0, 2**31 - 1)), memory=True).result()
        return np.fromiter((int(word, 2) for word in result.get_memory()), dtype=np.int64, count=shots)
