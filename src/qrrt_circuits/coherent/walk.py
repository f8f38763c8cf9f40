"""The oracle's gate sequence, emitted once for the circuit and for the cost tallies alike
(``oracle`` explains the construction; ``emitter`` where the gates go)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from .emitter import Emitter
from .lattice import LatticeDatabase
from .plan import CELL, LinearForm, OraclePlan
from .tally import Literal


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
    """S of one form, as qubits (None: a constant bit, ``form.constant_ones`` saying which are 1),
    inside the caller's block."""
    terms = form.terms
    if not terms:
        return []
    lowest = form.lowest
    start = (form.initial >> lowest) << lowest  # the initial value's bits from ``lowest`` up
    if len(terms) == 1 and not terms[0].negated and not start:  # one register, shifted: used in place
        term = terms[0]
        return [None] * term.shift + _registers(database, term.register, term.axis, index, parent)
    bits: list[int | None] = [None] * lowest + [em.alloc() for _ in range(form.width - lowest)]
    for i in range(lowest, form.width):
        if start >> i & 1:
            qubit = bits[i]
            assert qubit is not None
            em.x(qubit)
    largest = start
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
            target_bits = bits[term.shift:min(form.width, grown.bit_length())]  # modulo 2^W
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
                form = point.forms[comparison.axis]
                answer = em.chain(bits[comparison.axis], comparison.threshold, form.constant_ones)
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
