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
from .emitter import AND, CX, UNDO, Emitter, GateEmitter, Literal, Tally
from .lattice import LatticeDatabase
from .motion import SampledMotion
from .plan import CELL, LinearForm, OraclePlan, oracle_plan

if TYPE_CHECKING:
    from qiskit import QuantumCircuit

#: the most gates ``coherent_phase_oracle`` builds (the gate list and the Qiskit circuit of this
#: many gates take about 0.7 GB together); larger sizes are refused before building
MAX_BUILD_GATES = 2_000_000


@dataclass(frozen=True)
class Layout:
    """Where the oracle's registers lie.

    Args:
        index: The n index qubits (0 .. n - 1).
        parent: Per axis the b qubits of u_p (empty for m = 0).
        valid: The valid bit's qubit, or -1 where every parent index is a node.
        counter: The counter's qubits.
        num_qubits: All qubits.
    """

    index: tuple[int, ...]
    parent: tuple[tuple[int, ...], ...]
    valid: int
    counter: tuple[int, ...]
    num_qubits: int


def _registers(database: LatticeDatabase, term_register: str, axis: int, index: Sequence[int],
               parent: Sequence[Sequence[int]]) -> list[int]:
    if term_register == CELL:
        a = database.cell_bits
        return list(index[axis * a:(axis + 1) * a])
    return list(parent[axis])


def _accumulate(em: Emitter, database: LatticeDatabase, form: LinearForm, index: Sequence[int],
                parent: Sequence[Sequence[int]]) -> list[int | None]:
    """S of one form, as qubits (None: a constant 0 bit), inside the caller's block."""
    terms = form.terms
    if not terms:
        return []
    if len(terms) == 1 and not terms[0].negated:  # one register, shifted: used in place
        term = terms[0]
        return [None] * term.shift + _registers(database, term.register, term.axis, index, parent)
    lowest = terms[0].shift
    bits: list[int | None] = [None] * lowest + [em.alloc() for _ in range(form.width - lowest)]
    largest = 0
    for term in terms:
        register = _registers(database, term.register, term.axis, index, parent)
        if term.negated:
            for qubit in register:
                em.x(qubit)
        grown = largest + term.largest
        if largest.bit_length() <= term.shift:  # nothing below: copy
            for i, qubit in enumerate(register):
                target = bits[term.shift + i]
                assert target is not None
                em.cx(qubit, target)
        else:
            target_bits = bits[term.shift:grown.bit_length()]
            em.adder(register, [q for q in target_bits if q is not None])
        if term.negated:
            for qubit in register:
                em.x(qubit)
        largest = grown
    return bits


def lookup_data(database: LatticeDatabase, with_valid: bool) -> list[int]:
    """The lookup's entries: node i's grid coordinates, b bits per axis from axis 0 up, and a 1
    above them (the ``valid`` bit) when ``with_valid``."""
    b, d = database.fmt.bits, database.dim
    flag = (1 << (d * b)) if with_valid else 0
    return [sum(int(v) << (j * b) for j, v in enumerate(row)) | flag for row in database.node_grid]


def emit_oracle(em: Emitter, database: LatticeDatabase, plan: OraclePlan) -> Layout:
    """Emit the whole oracle (module text) on ``em``.

    Args:
        em: An empty ``Emitter`` (``GateEmitter`` for a circuit, a counting one for costs).
        database: The ``LatticeDatabase``.
        plan: Its ``OraclePlan``.

    Returns:
        The ``Layout``.
    """
    n, d, b = database.num_index_bits, database.dim, database.fmt.bits
    index = [em.alloc() for _ in range(n)]
    if plan.blocked:  # no entry reachable: the identity
        return Layout(tuple(index), (), -1, (), em.num_qubits)
    forward = em.begin()
    m = int(database.parent_bits or 0)
    parent: list[list[int]] = []
    valid = -1
    if m:
        parent = [[em.alloc() for _ in range(b)] for _ in range(d)]
        outputs = [q for register in parent for q in register]
        if database.num_nodes < (1 << m):
            valid = em.alloc()
            outputs.append(valid)
        em.qrom(index[d * database.cell_bits:], lookup_data(database, valid >= 0), outputs)
    counter = [em.alloc() for _ in range(plan.counter_bits)]
    for point in plan.points:
        sums = em.begin()
        bits = [_accumulate(em, database, form, index, parent) for form in point.forms]
        em.end(sums)
        groups = ([(point.in_bounds, True)] if point.in_bounds else []) + [(tests, False) for _, tests in point.boxes]
        for comparisons, out_of_bounds in groups:
            test = em.begin()
            literals: list[Literal] = []
            never = False
            for comparison in comparisons:
                answer = em.chain(bits[comparison.axis], comparison.threshold)
                if isinstance(answer, bool):
                    if answer == comparison.negated:
                        never = True
                        break
                    continue
                literals.append((answer[0], answer[1] != comparison.negated))
            hit = False if never else em.ladder(literals)
            em.end(test)
            if isinstance(hit, bool):
                # a chain is constant only where the plan settled it, so only a contradiction
                # (x AND NOT x: never true) is left here
                assert hit is False and not out_of_bounds, "a test the plan keeps is constant"
            else:
                em.increment((hit[0], hit[1] != out_of_bounds), counter)
            em.mirror(test)
        em.mirror(sums)
    em.end(forward)
    final = em.begin()
    literals = [(q, True) for q in counter] + ([(valid, False)] if valid >= 0 else [])
    reachable = em.ladder(literals)
    em.end(final)
    if not isinstance(reachable, bool):
        em.z_literal(reachable)
    em.mirror(final)
    em.mirror(forward)
    return Layout(tuple(index), tuple(tuple(r) for r in parent), valid, tuple(counter), em.num_qubits)


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
                          digits: str = "naf", max_gates: int = MAX_BUILD_GATES) -> CoherentOracle:
    """Build the coherent oracle (module text) with its layout, plan and gate counts.

    Args:
        env: The ``Environment``: its bounds, boxes and start inside the format's range.
        database: The ``LatticeDatabase`` (its format, cells and tree nodes).
        motion: The ``SampledMotion`` of the same d.
        digits: ``"naf"`` (default) or ``"binary"``: the coefficients' digits (``plan``).
        max_gates: Refuse (before building) an oracle of more gates (default ``MAX_BUILD_GATES``).

    Returns:
        The ``CoherentOracle``.

    Raises:
        ValueError: Mismatched dimensions, a world outside the format, an unknown ``digits``, or
            an oracle of more than ``max_gates`` gates (the message names the argument to lower and
            the largest value that fits).
    """
    from .costs import check_buildable

    plan = oracle_plan(env, database, motion, digits)
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
                          digits: str = "naf") -> QuantumCircuit:
    """The coherent phase oracle: on |i>|0...0> it gives (-1)^r(i) |i>|0...0>, r(i) the
    ``reachable_reference`` mark of entry i, computing r(i) from i by reversible arithmetic.

    The index register is the circuit's first n = ``database.num_index_bits`` qubits (qubit 0 the
    least significant), the others ancillas in |0>; swap it in for ``phase_oracle(marks)`` by
    reflecting about the uniform state on the index qubits only (``grover.coherent_grover_circuit``).

    Args:
        env: The ``Environment`` (inside ``database.fmt``'s range).
        database: The ``LatticeDatabase``.
        motion: The ``SampledMotion``.
        digits: ``"naf"`` (default) or ``"binary"``.

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
    return build_coherent_oracle(env, database, motion, digits).circuit


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
