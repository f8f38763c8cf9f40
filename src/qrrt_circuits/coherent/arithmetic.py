"""Reversible arithmetic from X, CX and AND (Toffolis onto fresh qubits), on an ``Emitter``.

- ``add_into``: target += source (a narrower source is zero-extended), Gidney's ripple-carry
  adder ("Halving the cost of quantum addition", Quantum 2, 74 (2018), Fig. 3): the carry
  c_{i+1} = c_i XOR ((a_i XOR c_i) AND (b_i XOR c_i)) is one AND per bit, uncomputed in reverse
  after the sum bits: W - 1 ANDs and W - 1 undos for a W-bit target. (Qiskit's
  ``CDKMRippleCarryAdder`` needs no ancillas but about 2 W Toffolis whose targets are not fresh,
  so none of them can be uncomputed by measurement.)
- ``compare_chain``: [S >= T] for a constant T as the carry out of S + (2^W - T): bit by bit the
  carry is MAJ(s_i, k_i, c) = s_i AND c where k_i = 0 and s_i OR c (an AND of negations) where
  k_i = 1, one AND each; constant bits of S and a constant carry are followed classically
  (``chain_steps``), so no gate is spent below the constant's lowest set bit or on S's constant
  low bits. The carries stay
  allocated until the caller mirrors the block (no copy of the result, no second chain to
  uncompute it). Qiskit's ``IntegerComparatorGate`` synthesises by default as one
  multi-controlled X per value below T (exponential in W), and its carry-chain synthesis
  (``synth_integer_comparator_2s``) computes, copies and uncomputes the chain on every call.
- ``and_ladder``: the AND of literals, one AND per literal after the first.
- ``controlled_increment``: counter += 1 under a control: carries g_{i+1} = g_i AND t_i, then the
  bits flipped from the top while the carries are undone (w - 1 ANDs and undos).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .emitter import Emitter
    from .tally import Literal


def add_into(em: Emitter, source: Sequence[int], target: Sequence[int]) -> None:
    """target += source mod 2^W (W = len(target) >= len(source) >= 1; source restored).

    Args:
        em: The ``Emitter``.
        source: The addend's qubits, least significant first.
        target: The accumulator's qubits, least significant first.

    Raises:
        ValueError: An empty source or a source wider than the target.
    """
    width, wide = len(source), len(target)
    if not 1 <= width <= wide:
        raise ValueError(f"add_into needs 1 <= len(source) <= len(target), got {width} and {wide}")
    if wide == 1:
        em.cx(source[0], target[0])
        return
    carry: list[int] = [-1] * wide  # carry[i] = c_i, i >= 1
    for i in range(wide - 1):
        if i < width:
            if i:
                em.cx(carry[i], source[i])
                em.cx(carry[i], target[i])
            carry[i + 1] = em.and_((source[i], False), (target[i], False))
            if i:
                em.cx(carry[i], carry[i + 1])
        else:  # the source is 0 here: c_{i+1} = b_i AND c_i
            carry[i + 1] = em.and_((target[i], False), (carry[i], False))
    top = wide - 1
    em.cx(carry[top], target[top])
    if top < width:
        em.cx(source[top], target[top])
    for i in range(wide - 2, -1, -1):
        if i < width:
            if i:
                em.cx(carry[i], carry[i + 1])
            em.undo((source[i], False), (target[i], False), carry[i + 1])
            if i:
                em.cx(carry[i], source[i])
            em.cx(source[i], target[i])
        else:
            em.undo((target[i], False), (carry[i], False), carry[i + 1])
            em.cx(carry[i], target[i])


#: the kinds of the bits of S in ``chain_steps``
ZERO, ONE, QUBIT = 0, 1, 2


def bit_kinds(bits: Sequence[int | None], ones: int = 0) -> list[int]:
    """Each bit's kind: ``QUBIT`` where ``bits`` has a qubit, else ``ONE`` where ``ones`` has the
    bit set, else ``ZERO``."""
    return [QUBIT if b is not None else ONE if ones >> i & 1 else ZERO for i, b in enumerate(bits)]


def chain_steps(kinds: Sequence[int], threshold: int
                ) -> tuple[list[tuple[str, int, tuple[str, int]]], tuple[str, int]]:
    """The gates of ``compare_chain`` as steps, constants followed classically.

    Args:
        kinds: Per bit of S (least significant first), ``QUBIT``, or the constant ``ZERO`` / ``ONE``.
        threshold: T, 1 <= T <= 2^W - 1.

    Returns:
        (steps, result): steps ``(kind, i, carry)``: ``kind`` ``"and"`` or ``"or"`` of bit i with
        the carry (one AND each), the carry being ``("bit", j)`` (bit j of S itself) or
        ``("step", s)`` (step s's qubit); ``result`` ``("const", 0 or 1)``, ``("bit", j)`` or
        ``("step", s)``. Only the steps the result depends on are kept.

    Raises:
        ValueError: T outside [1, 2^W - 1].

    Example:
        >>> from qrrt_circuits.coherent.arithmetic import QUBIT, ZERO, chain_steps
        >>> chain_steps([QUBIT] * 4, 6)  # S >= 6: k = 10 = 0b1010
        ([('and', 2, ('bit', 1)), ('or', 3, ('step', 0))], ('step', 1))
        >>> chain_steps([ZERO, ZERO, QUBIT, QUBIT], 8)  # bits 0, 1 constant 0: S >= 8 is bit 3
        ([], ('bit', 3))
    """
    width = len(kinds)
    if not 1 <= threshold <= (1 << width) - 1:
        raise ValueError(f"threshold must lie in [1, 2^{width} - 1], got {threshold}")
    k = (1 << width) - threshold
    steps: list[tuple[str, int, tuple[str, int]]] = []
    carry: tuple[str, int] = ("const", 0)
    for i in range(width):
        ki = (k >> i) & 1
        if kinds[i] == ZERO:  # MAJ(0, k_i, c) = k_i AND c
            if carry[0] == "const":
                carry = ("const", carry[1] & ki)
            elif not ki:
                carry = ("const", 0)
        elif kinds[i] == ONE:  # MAJ(1, k_i, c) = k_i OR c
            if carry[0] == "const":
                carry = ("const", carry[1] | ki)
            elif ki:
                carry = ("const", 1)
        elif carry == ("const", 0):
            carry = ("bit", i) if ki else ("const", 0)
        elif carry == ("const", 1):
            carry = ("const", 1) if ki else ("bit", i)
        else:
            steps.append(("or" if ki else "and", i, carry))
            carry = ("step", len(steps) - 1)
    # keep only the steps the result depends on (a constant bit can reset the carry)
    needed: list[int] = []
    ref = carry
    while ref[0] == "step":
        needed.append(ref[1])
        ref = steps[ref[1]][2]
    renumber = {old: new for new, old in enumerate(reversed(needed))}

    def moved(ref: tuple[str, int]) -> tuple[str, int]:
        return ("step", renumber[ref[1]]) if ref[0] == "step" else ref

    kept = [(kind, i, moved(ref)) for kind, i, ref in (steps[j] for j in reversed(needed))]
    return kept, moved(carry)


def compare_chain(em: Emitter, bits: Sequence[int | None], threshold: int, ones: int = 0) -> Literal | bool:
    """[S >= threshold] as the carry out of S + (2^W - threshold) (module text).

    The carries it allocates stay allocated: mirror the enclosing block to uncompute them.

    Args:
        em: The ``Emitter``.
        bits: S's qubits, least significant first; None for a constant bit (0, or 1 in ``ones``).
        threshold: T, 1 <= T <= 2^W - 1.
        ones: The constant bits of S that are 1 (a mask; only where ``bits`` is None).

    Returns:
        A literal holding the answer, or a bool where it is a constant.

    Raises:
        ValueError: T out of range.
    """
    steps, result = chain_steps(bit_kinds(bits, ones), threshold)

    def qubit(ref: tuple[str, int]) -> int:
        found = bits[ref[1]] if ref[0] == "bit" else made[ref[1]]
        assert found is not None
        return found

    made: list[int] = []
    for kind, i, carry in steps:
        bit = bits[i]
        assert bit is not None
        if kind == "and":
            made.append(em.and_((bit, False), (qubit(carry), False)))
        else:
            made.append(em.and_((bit, True), (qubit(carry), True)))
            em.x(made[-1])
    if result[0] == "const":
        return bool(result[1])
    return (qubit(result), False)


def and_ladder(em: Emitter, literals: Sequence[Literal]) -> Literal | bool:
    """The AND of literals: one AND per literal after the first, allocated until mirrored.

    Repeated literals count once; a literal and its negation make the constant False.

    Args:
        em: The ``Emitter``.
        literals: (qubit, negated) pairs.

    Returns:
        A literal, True for no literals, or False for a contradiction.
    """
    unique: dict[int, bool] = {}
    for qubit, negated in literals:
        if unique.setdefault(qubit, negated) != negated:
            return False
    if not unique:
        return True
    items = list(unique.items())
    if len(items) == 1:
        return items[0]
    current = em.and_(items[0], items[1])
    for literal in items[2:]:
        current = em.and_((current, False), literal)
    return (current, False)


def controlled_increment(em: Emitter, control: Literal, counter: Sequence[int]) -> None:
    """counter += 1 (mod 2^w) where ``control`` holds (module text); no qubit left allocated.

    Args:
        em: The ``Emitter``.
        control: A literal.
        counter: The counter's w >= 1 qubits, least significant first.
    """
    qubit, negated = control
    if negated:
        em.x(qubit)
    width = len(counter)
    carry = [qubit] + [-1] * (width - 1)
    for i in range(width - 1):
        carry[i + 1] = em.and_((carry[i], False), (counter[i], False))
    for i in range(width - 1, -1, -1):
        if i < width - 1:
            em.undo((carry[i], False), (counter[i], False), carry[i + 1])
        em.cx(carry[i], counter[i])
    if negated:
        em.x(qubit)
