"""A lookup of constants by unary iteration (Babbush et al., "Encoding electronic spectra in
quantum circuits with linear T complexity", PRX 8, 041015 (2018), Sec. III.A).

``unary_qrom`` XORs data[i] into the output qubits when the index register holds i, for
i < N = len(data) (nothing for larger indices). It walks the binary tree of the index's bits from
the most significant: a node's control c splits into c AND NOT q (one AND, a fresh qubit) for the
left subtree and, by one CX from c, c AND q for the right, then undoes the AND; the top level needs
no AND (its controls are q and NOT q). A subtree with no entry below N is skipped. The Toffoli
count (ANDs) is the number of controlled internal nodes: 2^m - 2 for a full lookup over m bits,
the ``qrom_toffolis`` of ``hardware.resources``. ``qrom_tally`` gives the gate counts of the same
walk without emitting it.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import TYPE_CHECKING

from .tally import Tally

if TYPE_CHECKING:
    from .emitter import Emitter
    from .tally import Literal


def unary_qrom(em: Emitter, index: Sequence[int], data: Sequence[int], outputs: Sequence[int]) -> None:
    """outputs ^= data[index] for index < len(data) (module text); no qubit left allocated.

    Args:
        em: The ``Emitter``.
        index: The m >= 1 index qubits, least significant first.
        data: N entries, 1 <= N <= 2^m; bit j of data[i] goes to outputs[j].
        outputs: The output qubits.

    Raises:
        ValueError: No index qubit, or N outside [1, 2^m].
    """
    m, count = len(index), len(data)
    if m < 1 or not 1 <= count <= (1 << m):
        raise ValueError(f"unary_qrom needs m >= 1 index qubits and 1 <= N <= 2^m entries, got m={m}, N={count}")

    def leaf(control: Literal, entry: int) -> None:
        value = int(data[entry])
        targets = [outputs[j] for j in range(len(outputs)) if value >> j & 1]
        if not targets:
            return
        if control[1]:
            em.x(control[0])
        for target in targets:
            em.cx(control[0], target)
        if control[1]:
            em.x(control[0])

    def node(control: Literal, height: int, base: int) -> None:
        if height == 0:
            leaf(control, base)
            return
        bit = index[height - 1]
        half = 1 << (height - 1)
        ancilla = em.and_(control, (bit, True))
        node((ancilla, False), height - 1, base)
        if base + half < count:
            em.cx_literal(control, ancilla)
            node((ancilla, False), height - 1, base + half)
            em.undo(control, (bit, False), ancilla)
        else:
            em.undo(control, (bit, True), ancilla)

    top = index[m - 1]
    node((top, True), m - 1, 0)
    if (1 << (m - 1)) < count:
        node((top, False), m - 1, 1 << (m - 1))


@functools.lru_cache(maxsize=4096)
def _node_tally(negated_control: bool, height: int, count: int) -> tuple[Tally, int]:
    """Gates of ``node`` over a subtree of ``count`` >= 1 entries, leaves' CX excluded, and the
    most qubits it holds at once."""
    tally = Tally()
    if height == 0:
        return tally, 0
    half = 1 << (height - 1)
    control_x = 2 if negated_control else 0
    tally.ands += 1
    tally.x += 2 + control_x  # the AND with NOT q
    left, left_peak = _node_tally(False, height - 1, min(count, half))
    tally.add(left)
    peak = 1 + left_peak
    if count > half:
        tally.cx += 1
        tally.x += control_x
        right, right_peak = _node_tally(False, height - 1, count - half)
        tally.add(right)
        peak = max(peak, 1 + right_peak)
        tally.x += control_x  # the undo with q
    else:
        tally.x += 2 + control_x  # the undo with NOT q
    tally.undos += 1
    return tally, peak


def qrom_tally(index_bits: int, data: Sequence[int]) -> tuple[Tally, int]:
    """The gate counts of ``unary_qrom`` and the most ancillas it holds at once, without emitting it.

    Args:
        index_bits: m >= 1.
        data: The N entries (their bits count the fan-out CX gates).

    Returns:
        (tally, peak ancillas).

    Example:
        >>> from qrrt_circuits.coherent.qrom import qrom_tally
        >>> tally, peak = qrom_tally(4, [1] * 16)  # a full lookup: 2^4 - 2 ANDs; 14 + 16 CX
        >>> tally.ands, tally.undos, tally.cx, peak
        (14, 14, 30, 3)
    """
    m, count = int(index_bits), len(data)
    if m < 1 or not 1 <= count <= (1 << m):
        raise ValueError(f"qrom_tally needs m >= 1 and 1 <= N <= 2^m, got m={m}, N={count}")
    half = 1 << (m - 1)
    tally, peak = Tally(), 0
    left, left_peak = _node_tally(True, m - 1, min(count, half))
    tally.add(left)
    peak = left_peak
    if count > half:
        right, right_peak = _node_tally(False, m - 1, count - half)
        tally.add(right)
        peak = max(peak, right_peak)
    tally.cx += sum(bin(int(value)).count("1") for value in data)
    if m == 1:  # the leaves of the top level: entry 0 is controlled by NOT q
        tally.x += 2 if int(data[0]) else 0
    return tally, peak


def qrom_ands(index_bits: int, entries: int) -> int:
    """ANDs of ``unary_qrom`` over ``entries`` of 2^m (closed form, any m): the controlled
    internal nodes with an entry below them.

    Args:
        index_bits: m >= 1.
        entries: N, 1 <= N <= 2^m.

    Returns:
        The count (2^m - 2 for N = 2^m).
    """
    m, count = int(index_bits), int(entries)

    def internal(height: int, size: int) -> int:  # controlled nodes of a subtree with `size` entries
        if height == 0:
            return 0
        half = 1 << (height - 1)
        if size >= (1 << height):
            return (1 << height) - 1
        return 1 + internal(height - 1, min(size, half)) + (internal(height - 1, size - half) if size > half else 0)

    half = 1 << (m - 1)
    return internal(m - 1, min(count, half)) + (internal(m - 1, count - half) if count > half else 0)
