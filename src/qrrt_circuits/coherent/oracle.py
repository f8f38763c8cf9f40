"""The motion check as a reversible circuit: the coherent phase oracle (paper Alg. 2, line 7).

The lookup oracle (``search.circuits.phase_oracle``) is diag((-1)^marks) with the 2^n marks
computed classically. ``coherent_phase_oracle`` computes the mark of index i from i itself:

1. the lookup ``qrom.unary_qrom`` loads the parent's grid coordinates u_p (b bits per axis) and a
   ``valid`` bit from the parent field (``lattice``); the sample's coordinates are the cell fields;
2. for every tested point (``motion``) and axis, the unsigned sum S of shifted registers of the
   integer plan (``plan``: signed-digit coefficients, complements for negative digits) is built in
   an accumulator by ripple-carry additions (``arithmetic.add_into``; a single unshifted term is
   used in place, a term whose bits do not overlap the sum so far is copied);
3. each kept test compares S with constants (``arithmetic.compare_chain``), ANDs the comparisons of
   a box (or of the bounds) and adds 1 to a counter when the point is in the box (or out of
   bounds); the comparisons are then uncomputed (the block mirrored), and so is the accumulator
   after the point's last test;
4. the entry is reachable iff ``valid`` and the counter is 0: that AND gets a Z, then everything
   above is mirrored, so every ancilla returns to |0>.

The circuit holds X, CX and CCX gates and one Z (or none where no entry, or every entry, is
reachable: then it is the identity, or -I as a global phase). Its first n qubits are the index
register (qubit 0 the least significant), the rest ancillas starting and ending in |0>.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..world.environment import Environment
from .costs import check_buildable
from .emitter import GateEmitter
from .lattice import LatticeDatabase
from .motion import SampledMotion
from .plan import OracleOptions, OraclePlan, oracle_plan
from .tally import AND, CX, UNDO, Tally
from .walk import Layout, emit_oracle

if TYPE_CHECKING:
    from qiskit import QuantumCircuit

#: the most gates ``coherent_phase_oracle`` builds (the gate list and the Qiskit circuit of this
#: many gates take about 0.7 GB together); larger sizes are refused before building
MAX_BUILD_GATES = 2_000_000


@dataclass(frozen=True, eq=False)
class CoherentOracle:
    """A built coherent oracle.

    Args:
        circuit: The ``QuantumCircuit`` (registers ``index`` and ``work``).
        layout: The ``Layout``.
        plan: The ``OraclePlan``.
        tally: Its gate counts (ANDs and undos apart).
        global_phase_flip: Whether every entry is marked (the circuit is -I, a global phase).
        gates: The circuit's gates as int64 (G, 4) rows (code, q0, q1, q2) of ``emitter`` codes, the
            Toffolis tagged AND or UNDO (``simulate`` checks the tags).
    """

    circuit: QuantumCircuit
    layout: Layout
    plan: OraclePlan
    tally: Tally
    global_phase_flip: bool
    gates: np.ndarray


def _every_entry_marked(database: LatticeDatabase, plan: OraclePlan) -> bool:
    return not plan.blocked and plan.counter_bits == 0 and database.num_nodes == (1 << int(database.parent_bits or 0))


def build_coherent_oracle(env: Environment, database: LatticeDatabase, motion: SampledMotion,
                          options: OracleOptions | None = None, max_gates: int = MAX_BUILD_GATES
                          ) -> CoherentOracle:
    """Build the coherent oracle (module text) with its layout, plan and gate counts.

    Args:
        env: The ``Environment``: its bounds, boxes and start inside the format's range.
        database: The ``LatticeDatabase`` (its format, cells and tree nodes).
        motion: The ``SampledMotion`` of the same d.
        options: ``OracleOptions`` (default: NAF digits, pruned, aligned; ``plan``).
        max_gates: Refuse (before building) an oracle of more gates (default ``MAX_BUILD_GATES``).

    Returns:
        The ``CoherentOracle``.

    Raises:
        ValueError: Mismatched dimensions, a world outside the format, or an oracle of more than
            ``max_gates`` gates (the message names the argument to lower and the largest value
            that fits).
    """
    plan = oracle_plan(env, database, motion, options)
    check_buildable(env, database, motion, plan, max_gates)
    em = GateEmitter()
    layout = emit_oracle(em, database, plan)
    circuit = to_circuit(em.gates, layout.num_qubits, len(layout.index))
    flip = _every_entry_marked(database, plan)
    if flip:
        circuit.global_phase = np.pi
    gates = np.array(em.gates, dtype=np.int64).reshape(-1, 4)
    return CoherentOracle(circuit, layout, plan, em.tally, flip, gates)


def coherent_phase_oracle(env: Environment, database: LatticeDatabase, motion: SampledMotion,
                          options: OracleOptions | None = None) -> QuantumCircuit:
    """The coherent phase oracle: on |i>|0...0> it gives (-1)^r(i) |i>|0...0>, r(i) the
    ``reachable_reference`` mark of entry i, computing r(i) from i by reversible arithmetic.

    The index register is the circuit's first n = ``database.num_index_bits`` qubits (qubit 0 the
    least significant), the others ancillas in |0>; swap it in for ``phase_oracle(marks)`` by
    reflecting about the uniform state on the index qubits only (``grover.coherent_grover_circuit``).

    Args:
        env: The ``Environment`` (inside ``database.fmt``'s range).
        database: The ``LatticeDatabase``.
        motion: The ``SampledMotion``.
        options: ``OracleOptions`` (default: NAF digits, pruned, aligned).

    Returns:
        A ``QuantumCircuit`` of X, CX, CCX and at most one Z.

    Raises:
        ValueError: As ``build_coherent_oracle``.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits import Environment
        >>> from qrrt_circuits.coherent import (FixedPointFormat, LatticeDatabase, SampledMotion,
        ...                                     coherent_phase_oracle)
        >>> env = Environment([[0, 15], [0, 15]], [[[6, 0], [9, 9]]])
        >>> db = LatticeDatabase(FixedPointFormat(4, 0.0, 16.0), 2, np.array([[2.0, 2.0]]))
        >>> circuit = coherent_phase_oracle(env, db, SampledMotion.straight_line(2, 3, 1))
        >>> circuit.qregs[0].size, sorted(circuit.count_ops())
        (4, ['ccx', 'cx', 'x', 'z'])
    """
    return build_coherent_oracle(env, database, motion, options).circuit


def to_circuit(gates: Sequence[tuple[int, int, int, int]], num_qubits: int, num_index: int) -> QuantumCircuit:
    """The gate list as a ``QuantumCircuit`` (registers ``index`` of ``num_index`` qubits, ``work``).

    Args:
        gates: (code, q0, q1, q2) tuples of ``emitter.GateEmitter``.
        num_qubits: All qubits.
        num_index: The index register's qubits (the first ones).

    Returns:
        The circuit, named ``coherent_oracle``.
    """
    from qiskit import AncillaRegister, QuantumCircuit, QuantumRegister

    registers = [QuantumRegister(num_index, "index")]
    if num_qubits > num_index:
        registers.append(AncillaRegister(num_qubits - num_index, "work"))
    circuit = QuantumCircuit(*registers, name="coherent_oracle")
    for code, a, b, c in gates:
        if code in (AND, UNDO):
            circuit.ccx(a, b, c)
        elif code == CX:
            circuit.cx(a, b)
        elif code == 0:
            circuit.x(a)
        else:
            circuit.z(a)
    return circuit
