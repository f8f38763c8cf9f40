"""Exhaustive verification of a coherent oracle against its classical reference.

``verify_oracle`` builds the oracle, reads its gates back from the Qiskit circuit (so the circuit
itself is what is checked), simulates it on every index basis state (``simulate``) and compares:
the phase of index i must be the ``reachable_reference`` mark of entry i, the index unchanged and
every ancilla back to 0, every Toffoli an AND onto 0 or the undo of one (as tagged by the
builder), and the global phase -1 exactly when every entry is marked.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..world.environment import Environment
from .lattice import LatticeDatabase
from .motion import SampledMotion
from .oracle import build_coherent_oracle
from .plan import OracleOptions
from .reference import check_reference_fits, reachable_reference
from .simulate import CCX, circuit_gates, simulate, simulation_bytes


@dataclass(frozen=True)
class VerificationResult:
    """The outcome of ``verify_oracle``.

    Args:
        index_bits: n (2^n basis states enumerated).
        qubits: The oracle's qubits.
        gates: Its gates.
        marked: Entries the reference marks.
        mismatches: Entries whose phase differs from the reference.
        index_preserved: The index register ends as it began on every input.
        ancillas_clean: Every ancilla ends in 0 on every input.
        circuit_matches_gates: The circuit's gates are the builder's gate list.
        tag_errors: Toffolis tagged AND or undo that are not.
        other_toffolis: Toffolis that are neither an AND onto 0 nor an undo.
    """

    index_bits: int
    qubits: int
    gates: int
    marked: int
    mismatches: int
    index_preserved: bool
    ancillas_clean: bool
    circuit_matches_gates: bool
    tag_errors: int
    other_toffolis: int

    @property
    def ok(self) -> bool:
        """Every check passed."""
        return (self.mismatches == 0 and self.index_preserved and self.ancillas_clean
                and self.circuit_matches_gates and self.tag_errors == 0 and self.other_toffolis == 0)


def verify_oracle(env: Environment, database: LatticeDatabase, motion: SampledMotion,
                  options: OracleOptions | None = None) -> VerificationResult:
    """Build the oracle and check it on all 2^n index states (module text).

    Args:
        env: The ``Environment``.
        database: The ``LatticeDatabase`` (n small enough to enumerate: ``simulate``'s memory limit).
        motion: The ``SampledMotion``.
        options: ``OracleOptions`` (default: NAF digits, pruned, aligned).

    Returns:
        The ``VerificationResult``.

    Raises:
        ValueError: As ``build_coherent_oracle``, an n too large to enumerate, or an estimate of
            the reference marks and the simulation above the available memory (refused before
            either runs, naming ``database.num_index_bits``).
    """
    oracle = build_coherent_oracle(env, database, motion, options)
    qubits = oracle.layout.num_qubits
    check_reference_fits(database, motion, lambda n: simulation_bytes(n, qubits + n - database.num_index_bits),
                         "verify_oracle (the reference marks and the simulation of every index state)")
    marks = reachable_reference(env, database, motion)
    tagged = oracle.gates
    read = circuit_gates(oracle.circuit)
    untagged = tagged.copy()
    untagged[np.isin(untagged[:, 0], (2, 3)), 0] = CCX
    matches = read.shape == untagged.shape and bool(np.array_equal(read, untagged))
    n = database.num_index_bits
    result = simulate(tagged, oracle.layout.num_qubits, n)
    phases = result.phases ^ oracle.global_phase_flip
    return VerificationResult(n, oracle.layout.num_qubits, len(tagged), int(marks.sum()),
                              int(np.count_nonzero(phases != marks)), result.index_preserved, result.ancillas_clean,
                              matches, result.tag_errors, result.other_toffolis)
