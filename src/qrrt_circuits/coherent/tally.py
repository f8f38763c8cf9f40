"""Gate counts of the coherent oracle's circuits, and the gate codes of its gate lists."""

from __future__ import annotations

from dataclasses import dataclass

#: gate codes of ``GateEmitter.gates``
X, CX, AND, UNDO, Z = 0, 1, 2, 3, 4

Literal = tuple[int, bool]


@dataclass
class Tally:
    """Gate counts. ``ands`` + ``undos`` are the CCX gates; with measurement-based uncomputation
    only the ``ands`` cost a Toffoli.

    Args:
        x: X gates.
        cx: CX gates.
        ands: Toffolis computing an AND into a fresh |0> qubit.
        undos: Toffolis uncomputing one (the qubit returns to |0>).
        z: Z gates.
    """

    x: int = 0
    cx: int = 0
    ands: int = 0
    undos: int = 0
    z: int = 0

    def add(self, other: Tally, mirrored: bool = False, times: int = 1) -> None:
        """Add ``times`` copies of ``other`` (its ANDs and undos swapped when ``mirrored``)."""
        self.x += times * other.x
        self.cx += times * other.cx
        self.z += times * other.z
        ands, undos = (other.undos, other.ands) if mirrored else (other.ands, other.undos)
        self.ands += times * ands
        self.undos += times * undos

    def minus(self, other: Tally) -> Tally:
        """The counts of ``self`` less ``other``."""
        return Tally(self.x - other.x, self.cx - other.cx, self.ands - other.ands, self.undos - other.undos,
                     self.z - other.z)

    @property
    def toffolis(self) -> int:
        """CCX gates: ``ands`` + ``undos``."""
        return self.ands + self.undos

    @property
    def gates(self) -> int:
        """All gates."""
        return self.x + self.cx + self.ands + self.undos + self.z
