"""The oracle's arithmetic as integer constants: what the circuit adds, and what it compares with.

For a tested matrix e and axis i the point is x_i = floor(acc_i / 2^f) (``reference``) with

    acc_i = rho + sum_j (2^f [i = j] - e_ij) u_c,j + sum_j e_ij u_p,j,

a linear form in the registers: the sample's cell fields k_j (u_c,j = k_j 2^(b - a) + h, so
``k_j`` enters shifted by b - a and h only adds a constant) and the parent registers u_p,j loaded
by the lookup (constants when the tree has one node, m = 0). Each integer coefficient is written in
signed digits (``DIGITS``: the non-adjacent form, or plain binary), and each digit +-2^k becomes one
register shifted by k; a digit -2^k adds the register's complement r~ = 2^w - 1 - r instead, since
-r 2^k = r~ 2^k - (2^w - 1) 2^k. So

    acc_i = offset_i + S_i,   S_i = sum over digits of (r or r~) 2^k >= 0,

and the circuit computes the unsigned S_i only (no signed arithmetic). The comparisons of the
tested point are comparisons of S_i with constants, the rounding folded in:

    x_i >= L  <=>  S_i >= L 2^f - offset_i,
    x_i <= U  <=>  not (S_i >= (U + 1) 2^f - offset_i).

Options (``OracleOptions``):

- ``align`` (default on): S_i starts from the constant c_i = offset_i mod 2^f (X gates on the
  accumulator, or constant bits below it), so that offset_i - c_i, and with it every threshold, is a
  multiple of 2^f: a comparison's carry chain then passes the low f bits as constants and spends
  its ANDs on the top bits only (``arithmetic.chain_steps``);
- ``prune`` (default on): a comparison whose answer is the same for every valid entry (interval
  bounds of S_i over the cells and the tree's nodes) is settled here: an always-true one is
  dropped, an always-false one drops its box for that point (the box cannot be hit from there).
  Off, only comparisons settled over every register value are;
- ``digits``: the coefficients' signed digits, ``"naf"`` (default) or ``"binary"``.

The circuit then counts, per entry, the tested points out of bounds and the (point, box) hits; the
entry is reachable iff the count is zero and the parent valid.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._support.validation import check_bool, check_choice
from ..world.environment import Environment
from .lattice import LatticeDatabase
from .motion import SampledMotion
from .reference import grid_limits

#: the signed-digit forms of the constant coefficients
DIGITS = ("naf", "binary")

CELL, PARENT = "cell", "parent"

#: the most (tested point, box) pairs ``oracle_plan`` plans: points x boxes, known before planning;
#: a plan keeps about 430 bytes a pair and costs take about 50 microseconds a pair to count, so this
#: many is about 0.2 GB and half a minute. Larger sizes are refused before any work.
MAX_PLANNED_TESTS = 500_000


@dataclass(frozen=True)
class OracleOptions:
    """How the oracle is built (module text); every choice gives the same marks.

    Args:
        digits: ``"naf"`` (default) or ``"binary"`` (``signed_digits``).
        prune: Settle comparisons over the valid entries' interval bounds (default True).
        align: Start each sum from the constant that makes every threshold a multiple of 2^f
            (default True).

    Raises:
        ValueError: An unknown ``digits``.
        TypeError: A non-bool ``prune`` or ``align``.
    """

    digits: str = "naf"
    prune: bool = True
    align: bool = True

    def __post_init__(self) -> None:
        check_choice(self.digits, "digits", DIGITS)
        check_bool(self.prune, "prune")
        check_bool(self.align, "align")


def signed_digits(value: int, form: str = "naf") -> list[tuple[int, int]]:
    """``value`` as a sum of +-2^k: (k, +1 or -1) pairs, lowest k first.

    Args:
        value: Any integer.
        form: ``"naf"`` (non-adjacent form: no two adjacent non-zero digits, the fewest digits) or
            ``"binary"`` (the bits of |value|, all with value's sign).

    Returns:
        The digits; empty for 0.

    Example:
        >>> from qrrt_circuits.coherent.plan import signed_digits
        >>> signed_digits(7), signed_digits(7, "binary"), signed_digits(-6)
        ([(0, -1), (3, 1)], [(0, 1), (1, 1), (2, 1)], [(1, 1), (3, -1)])
    """
    digits = []
    if form == "binary":
        sign = 1 if value >= 0 else -1
        magnitude, k = abs(value), 0
        while magnitude:
            if magnitude & 1:
                digits.append((k, sign))
            magnitude >>= 1
            k += 1
        return digits
    k = 0
    while value:
        if value & 1:
            digit = 2 - (value & 3)  # +1 or -1, leaving a multiple of 4
            digits.append((k, digit))
            value -= digit
        value >>= 1
        k += 1
    return digits


@dataclass(frozen=True)
class Term:
    """One digit of a linear form: a register, shifted, possibly complemented.

    Args:
        register: ``"cell"`` (a cell field, a bits) or ``"parent"`` (a parent register, b bits).
        axis: The register's axis j.
        shift: k: the register enters as r 2^k.
        negated: Whether the complement r~ = 2^w - 1 - r enters instead.
        width: w, the register's width.
    """

    register: str
    axis: int
    shift: int
    negated: bool
    width: int

    @property
    def largest(self) -> int:
        """(2^w - 1) 2^k, the term's largest value."""
        return ((1 << self.width) - 1) << self.shift


@dataclass(frozen=True)
class LinearForm:
    """acc = offset + S, S = ``initial`` + the sum of the terms (sorted by shift), 0 <= S <= ``max_sum``.

    The digits of one register move together (r and its complement), so the bounds are taken per
    register: S's width W is that of its true maximum; the circuit adds modulo 2^W, where partial
    sums may wrap but the total cannot.

    Args:
        terms: The ``Term`` s, lowest shift first.
        offset: The constant.
        initial: The constant S starts from (``align``; 0 otherwise).
        max_sum: The largest S over all register values (its bit length W is the circuit's width).
        low: The smallest S over the valid entries (interval bound).
        high: The largest S over the valid entries (interval bound).
    """

    terms: tuple[Term, ...]
    offset: int
    initial: int
    max_sum: int
    low: int
    high: int

    @property
    def lowest(self) -> int:
        """The lowest bit a term touches (the accumulator's first qubit); 0 without terms."""
        return self.terms[0].shift if self.terms else 0

    @property
    def constant_ones(self) -> int:
        """The bits of S below ``lowest``: constants (those of ``initial``), as a mask."""
        return self.initial & ((1 << self.lowest) - 1)

    @property
    def width(self) -> int:
        """W = bit length of ``max_sum`` (0 when S is 0)."""
        return self.max_sum.bit_length()


@dataclass(frozen=True)
class Comparison:
    """The literal [S_axis >= threshold], negated when ``negated``.

    Args:
        axis: Which axis's sum.
        threshold: T, with 1 <= T <= the form's ``max_sum`` (settled comparisons are not kept).
        negated: Whether the test is the negation.
    """

    axis: int
    threshold: int
    negated: bool


@dataclass(frozen=True)
class PointPlan:
    """One tested point: its forms per axis and the tests left after settling.

    Args:
        matrix: The integer matrix e.
        forms: One ``LinearForm`` per axis.
        in_bounds: The comparisons whose AND is "in bounds" (empty: always in bounds).
        boxes: (box index, comparisons whose AND is "in this box") for every box not settled.
    """

    matrix: np.ndarray
    forms: tuple[LinearForm, ...]
    in_bounds: tuple[Comparison, ...]
    boxes: tuple[tuple[int, tuple[Comparison, ...]], ...]


@dataclass(frozen=True)
class OraclePlan:
    """The integer plan of the coherent oracle.

    Args:
        points: One ``PointPlan`` per tested point.
        blocked: Some test fails for every valid entry (no entry is reachable).
        box_tests: Point-box pairs before settling (points x boxes).
        box_tests_kept: Point-box pairs the circuit tests.
        comparisons_kept: Comparisons the circuit evaluates (bounds and boxes).
        options: The ``OracleOptions`` used.
    """

    points: tuple[PointPlan, ...]
    blocked: bool
    box_tests: int
    box_tests_kept: int
    comparisons_kept: int
    options: OracleOptions

    @property
    def increments(self) -> int:
        """Counter increments: a point's bounds test (when kept) and every kept box test."""
        return sum(bool(p.in_bounds) + len(p.boxes) for p in self.points)

    @property
    def counter_bits(self) -> int:
        """w: enough bits that the count of failed tests cannot wrap to 0."""
        return self.increments.bit_length()


def _settle(form: LinearForm, threshold: int, prune: bool) -> bool | None:
    """[S >= threshold] if the same for every valid entry (``prune``: over the interval bounds of
    the valid entries; else over every register value), else None."""
    low, high = (form.low, form.high) if prune else (0, form.max_sum)
    if threshold <= low:
        return True
    if threshold > high:
        return False
    return None


def _tests(forms: tuple[LinearForm, ...], low: np.ndarray, high: np.ndarray, f: int, prune: bool
           ) -> tuple[Comparison, ...] | None:
    """The comparisons of "every axis in [low, high]" left after settling; None if never true."""
    kept = []
    for i, form in enumerate(forms):
        for threshold, negated in ((int(low[i]) * (1 << f) - form.offset, False),
                                   ((int(high[i]) + 1) * (1 << f) - form.offset, True)):
            settled = _settle(form, threshold, prune)
            if settled is None:
                kept.append(Comparison(i, threshold, negated))
            elif settled == negated:  # this side fails for every valid entry
                return None
    return tuple(kept)


def _form(database: LatticeDatabase, motion: SampledMotion, matrix: np.ndarray, axis: int,
          parent_range: tuple[np.ndarray, np.ndarray], options: OracleOptions) -> LinearForm:
    f, b, a = motion.fraction_bits, database.fmt.bits, database.cell_bits
    d = database.dim
    offset = (1 << f) >> 1
    terms: list[Term] = []
    low = high = largest = 0
    single_node = database.parent_bits == 0

    def add(coefficient: int, register: str, j: int, base: int, width: int, r_low: int, r_high: int) -> None:
        """The digits of coefficient 2^base x r; S gains g(r) = coefficient 2^base r + c, c the
        complements' constant, exactly bounded per register (its digits move together)."""
        nonlocal offset, low, high, largest
        complements = 0
        for k, sign in signed_digits(coefficient, options.digits):
            term = Term(register, j, base + k, sign < 0, width)
            terms.append(term)
            if term.negated:
                complements += term.largest
        offset -= complements
        scaled = coefficient << base
        ends = sorted((scaled * r_low, scaled * r_high))
        low += complements + ends[0]
        high += complements + ends[1]
        largest += complements + max(0, scaled * ((1 << width) - 1))

    for j in range(d):
        cell_coefficient = ((1 << f) if j == axis else 0) - int(matrix[axis, j])
        offset += cell_coefficient * database.cell_offset
        add(cell_coefficient, CELL, j, database.cell_shift, a, 0, (1 << a) - 1)
    for j in range(d):
        coefficient = int(matrix[axis, j])
        if single_node:
            offset += coefficient * int(database.node_grid[0, j])
        else:
            add(coefficient, PARENT, j, 0, b, int(parent_range[0][j]), int(parent_range[1][j]))
    terms.sort(key=lambda t: (t.shift, t.register, t.axis))
    initial = offset % (1 << f) if options.align and terms else 0
    return LinearForm(tuple(terms), offset - initial, initial, initial + largest, initial + low, initial + high)


def check_planned_tests(points: int, boxes: int, time_samples: int) -> None:
    """Refuse (``ValueError``) a plan of more than ``MAX_PLANNED_TESTS`` (point, box) pairs.

    Args:
        points: The motion's tested points (at most K + 1).
        boxes: The world's boxes.
        time_samples: K, for the message.

    Raises:
        ValueError: points x boxes above the limit; the message names ``env.boxes``,
            ``motion.time_samples`` and the most boxes that fit at these points.
    """
    if points * boxes > MAX_PLANNED_TESTS:
        raise ValueError(
            f"env.boxes has {boxes} boxes and motion.time_samples = {time_samples} tests {points} points: "
            f"{points * boxes} (point, box) pairs, more than {MAX_PLANNED_TESTS} the oracle is planned for; "
            f"at most {MAX_PLANNED_TESTS // max(points, 1)} boxes fit at these points (or lower motion.time_samples)")


def oracle_plan(env: Environment, database: LatticeDatabase, motion: SampledMotion,
                options: OracleOptions | None = None) -> OraclePlan:
    """The integer plan (module text) of the oracle for a world, database and motion.

    Args:
        env: The ``Environment`` (inside the format's range).
        database: The ``LatticeDatabase``.
        motion: The ``SampledMotion`` (same d).
        options: ``OracleOptions`` (default: NAF digits, pruned, aligned).

    Returns:
        The ``OraclePlan``.

    Raises:
        ValueError: Mismatched dimensions, a world outside the format, or more than
            ``MAX_PLANNED_TESTS`` (tested point, box) pairs (refused before planning, naming
            ``env.boxes`` and ``motion.time_samples`` and the most boxes that fit).
    """
    options = OracleOptions() if options is None else options
    prune = options.prune
    if motion.dim != database.dim:
        raise ValueError(f"motion has d = {motion.dim}, the database d = {database.dim}")
    check_planned_tests(len(motion.tested), env.num_boxes, motion.time_samples)
    bounds, boxes = grid_limits(env, database)
    f = motion.fraction_bits
    parent_range = (database.node_grid.min(axis=0), database.node_grid.max(axis=0))
    points = []
    blocked = False
    kept_boxes = comparisons = 0
    for matrix in motion.tested:
        forms = tuple(_form(database, motion, matrix, i, parent_range, options) for i in range(database.dim))

        in_bounds = _tests(forms, bounds[:, 0], bounds[:, 1], f, prune)
        if in_bounds is None:
            blocked = True
            in_bounds = ()
        point_boxes = []
        for index, box in enumerate(boxes):
            kept = _tests(forms, box[0], box[1], f, prune)
            if kept is None:
                continue
            if not kept:  # inside this box for every valid entry
                blocked = True
                continue
            point_boxes.append((index, kept))
            comparisons += len(kept)
        comparisons += len(in_bounds)
        kept_boxes += len(point_boxes)
        points.append(PointPlan(matrix, forms, in_bounds, tuple(point_boxes)))
    return OraclePlan(tuple(points), blocked, len(points) * len(boxes), kept_boxes, comparisons, options)
