"""Where the oracle's gates go: a gate list, or only their tally.

The oracle is written once against ``Emitter``: qubit allocation (a freed qubit is reused before a
new one is taken, so the qubits used equal the most alive at once), five primitives and blocks.

- ``x``, ``cx``, ``z``;
- ``and_(a, b)``: a Toffoli onto a fresh |0> qubit (a logical AND, Gidney, "Halving the cost of
  quantum addition", Quantum 2, 74 (2018)); ``undo(a, b, t)``: the same Toffoli when t is known to
  hold a AND b, returning t to |0>. Inputs are literals (qubit, negated), a negated one conjugated
  by X. On hardware an AND costs 4 T and its undo none (an X-basis measurement and a classically
  controlled CZ); here both are CCX gates, counted apart (``Tally.ands``, ``Tally.undos``);
- ``begin`` / ``end`` / ``mirror``: ``mirror(block)`` appends the block's gates reversed (each is its
  own inverse), which swaps ANDs and undos, and frees the qubits the block left allocated.

``GateEmitter`` records the gates (``gates``: (code, q0, q1, q2) tuples) for a circuit;
``CountEmitter`` only tallies them (the same code, no memory per gate). The components
(``arithmetic``, ``qrom``) are methods so that ``costs.FastCountEmitter`` can replace them by
their closed-form tallies.
"""

from __future__ import annotations

import heapq
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

from .arithmetic import add_into, and_ladder, compare_chain, controlled_increment
from .qrom import unary_qrom
from .tally import AND, CX, UNDO, Literal, Tally, X, Z


@dataclass
class Block:
    """An open or closed block: where it started, what it allocated, its tally once closed."""

    start_gate: int
    start_tally: Tally
    allocated: list[int] = field(default_factory=list)
    end_gate: int = -1
    tally: Tally | None = None


class Emitter:
    """Allocation, blocks and the components; subclasses implement the primitives' recording."""

    def __init__(self) -> None:
        self.tally = Tally()
        self.num_qubits = 0
        self.live = 0
        self.peak = 0
        self._pool: list[int] = []
        self._alive: set[int] = set()
        self._open: list[Block] = []

    # ------------------------------------------------------------------ qubits
    def alloc(self) -> int:
        """A qubit in |0> (a freed one first)."""
        if self._pool:
            qubit = heapq.heappop(self._pool)
        else:
            qubit = self.num_qubits
            self.num_qubits += 1
        self._alive.add(qubit)
        self.live += 1
        self.peak = max(self.peak, self.live)
        if self._open:
            self._open[-1].allocated.append(qubit)
        return qubit

    def free(self, qubit: int) -> None:
        """Return a qubit known to be |0>."""
        self._alive.discard(qubit)
        heapq.heappush(self._pool, qubit)
        self.live -= 1

    def bump(self, extra: int) -> None:
        """Record a transient ``extra`` qubits above those alive (closed-form components)."""
        self.peak = max(self.peak, self.live + extra)

    # ------------------------------------------------------------------ primitives
    def _record(self, code: int, a: int, b: int = -1, c: int = -1) -> None:
        raise NotImplementedError

    def x(self, qubit: int) -> None:
        """X."""
        self.tally.x += 1
        self._record(X, qubit)

    def cx(self, control: int, target: int) -> None:
        """CX."""
        self.tally.cx += 1
        self._record(CX, control, target)

    def z(self, qubit: int) -> None:
        """Z."""
        self.tally.z += 1
        self._record(Z, qubit)

    def _conjugate(self, *literals: Literal) -> None:
        for qubit, negated in literals:
            if negated:
                self.x(qubit)

    def and_(self, a: Literal, b: Literal) -> int:
        """A fresh qubit holding a AND b (literals)."""
        target = self.alloc()
        self._conjugate(a, b)
        self.tally.ands += 1
        self._record(AND, a[0], b[0], target)
        self._conjugate(a, b)
        return target

    def undo(self, a: Literal, b: Literal, target: int) -> None:
        """Uncompute ``target`` = a AND b back to |0> and free it."""
        self._conjugate(a, b)
        self.tally.undos += 1
        self._record(UNDO, a[0], b[0], target)
        self._conjugate(a, b)
        self.free(target)

    def cx_literal(self, control: Literal, target: int) -> None:
        """CX from a literal."""
        self._conjugate(control)
        self.cx(control[0], target)
        self._conjugate(control)

    def z_literal(self, literal: Literal) -> None:
        """Phase -1 where the literal is true."""
        self._conjugate(literal)
        self.z(literal[0])
        self._conjugate(literal)

    # ------------------------------------------------------------------ blocks
    def _gate_count(self) -> int:
        return 0

    def begin(self) -> Block:
        """Open a block."""
        block = Block(self._gate_count(), replace(self.tally))
        self._open.append(block)
        return block

    def end(self, block: Block) -> None:
        """Close the innermost block (``block``)."""
        if not self._open or self._open[-1] is not block:
            raise RuntimeError("blocks must be closed innermost first")
        self._open.pop()
        block.end_gate = self._gate_count()
        block.tally = self.tally.minus(block.start_tally)
        if self._open:
            self._open[-1].allocated.extend(block.allocated)

    def mirror(self, block: Block) -> None:
        """Append a closed block's gates reversed and free what it left allocated."""
        if block.tally is None:
            raise RuntimeError("mirror a block after closing it")
        self._replay_reversed(block)
        self.tally.add(block.tally, mirrored=True)
        for qubit in dict.fromkeys(block.allocated):
            if qubit in self._alive:
                self.free(qubit)

    def _replay_reversed(self, block: Block) -> None:
        """Record the block's gates reversed (``GateEmitter``); counting emitters record none."""

    # ------------------------------------------------------------------ components
    def adder(self, source: Sequence[int], target: Sequence[int]) -> None:
        """target += source (mod 2^len(target)), ``arithmetic.add_into``."""
        add_into(self, source, target)

    def chain(self, bits: Sequence[int | None], threshold: int, ones: int = 0) -> Literal | bool:
        """[S >= threshold] of the bits (None: a constant, 1 where ``ones`` says),
        ``arithmetic.compare_chain``."""
        return compare_chain(self, bits, threshold, ones)

    def ladder(self, literals: Sequence[Literal]) -> Literal | bool:
        """The AND of literals, ``arithmetic.and_ladder``."""
        return and_ladder(self, literals)

    def increment(self, control: Literal, counter: Sequence[int]) -> None:
        """counter += 1 where ``control`` holds, ``arithmetic.controlled_increment``."""
        controlled_increment(self, control, counter)

    def qrom(self, index: Sequence[int], data: Sequence[int], outputs: Sequence[int]) -> None:
        """outputs ^= data[index] (``qrom.unary_qrom``)."""
        unary_qrom(self, index, data, outputs)


class GateEmitter(Emitter):
    """Records every gate in ``gates``."""

    def __init__(self) -> None:
        super().__init__()
        self.gates: list[tuple[int, int, int, int]] = []

    def _record(self, code: int, a: int, b: int = -1, c: int = -1) -> None:
        self.gates.append((code, a, b, c))

    def _gate_count(self) -> int:
        return len(self.gates)

    def _replay_reversed(self, block: Block) -> None:
        swap = {AND: UNDO, UNDO: AND}
        for code, a, b, c in reversed(self.gates[block.start_gate:block.end_gate]):
            self.gates.append((swap.get(code, code), a, b, c))


class CountEmitter(Emitter):
    """Tallies the gates, records none."""

    def _record(self, code: int, a: int, b: int = -1, c: int = -1) -> None:
        return None
