"""Qubits and Toffolis of the coherent oracle, from the constructors' closed-form tallies, beside
the lookup oracle's.

``oracle_costs`` walks the same ``oracle.emit_oracle`` as the circuit builder on a
``FastCountEmitter``: no gate is stored, and every component is counted in closed form (an adder
or an increment once per width, memoised; a comparison from its steps, ``arithmetic.chain_steps``;
the lookup from its tree, ``qrom.qrom_tally``), so sizes far beyond what can be built (n up to 64,
thousands of boxes) are counted in seconds. For buildable sizes the counts equal the built
circuit's (``tests/test_coherent_costs.py``).

Counts (``OracleCost``): ``ands`` is the Toffoli count with measurement-based uncomputation (an
AND costs one Toffoli, 4 T, its undo none; Gidney 2018); ``toffolis`` counts every CCX, undos
included (what the circuit holds). ``lookup_costs`` gives the lookup oracle's Toffolis for the same
n (``hardware.resources``: unary-iteration QROM over the 2^n marks, load and unload, and
select-swap where Qualtran is installed), counted the same way (ANDs only).

``check_buildable`` refuses before building an oracle of more than ``oracle.MAX_BUILD_GATES``
gates, naming the argument to lower and the largest value that fits.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..world.environment import Environment
from .arithmetic import add_into, chain_steps, controlled_increment
from .emitter import CountEmitter, Literal, Tally
from .lattice import LatticeDatabase
from .motion import SampledMotion
from .plan import OraclePlan, oracle_plan
from .qrom import qrom_tally


@functools.lru_cache(maxsize=1024)
def _component(kind: str, first: int, second: int) -> tuple[Tally, int]:
    """Tally and transient ancillas of one adder (source, target widths) or one increment (width,
    negated control), counted once by running it on a ``CountEmitter``."""
    em = CountEmitter()
    if kind == "adder":
        source = [em.alloc() for _ in range(first)]
        target = [em.alloc() for _ in range(second)]
        base = em.live
        add_into(em, source, target)
    else:
        control = em.alloc()
        counter = [em.alloc() for _ in range(first)]
        base = em.live
        controlled_increment(em, (control, bool(second)), counter)
    return em.tally, em.peak - base


class FastCountEmitter(CountEmitter):
    """A ``CountEmitter`` whose components are counted in closed form (module text)."""

    def adder(self, source: Sequence[int], target: Sequence[int]) -> None:
        """Add the memoised tally of one adder of these widths."""
        tally, extra = _component("adder", len(source), len(target))
        self.bump(extra)
        self.tally.add(tally)

    def increment(self, control: Literal, counter: Sequence[int]) -> None:
        """Add the memoised tally of one increment of this width."""
        tally, extra = _component("increment", len(counter), int(control[1]))
        self.bump(extra)
        self.tally.add(tally)

    def chain(self, bits: Sequence[int | None], threshold: int) -> Literal | bool:
        """Count ``compare_chain``'s steps (one AND each, 5 X for an OR) and allocate its carries."""
        steps, result = chain_steps([b is not None for b in bits], threshold)
        ors = sum(kind == "or" for kind, _, _ in steps)
        self.tally.ands += len(steps)
        self.tally.x += 5 * ors
        made = [self.alloc() for _ in steps]
        if result[0] == "const":
            return bool(result[1])
        if result[0] == "bit":
            bit = bits[result[1]]
            assert bit is not None
            return (bit, False)
        return (made[result[1]], False)

    def qrom(self, index: Sequence[int], data: Sequence[int], outputs: Sequence[int]) -> None:
        """Add the lookup's tally from its tree (``qrom.qrom_tally``)."""
        tally, extra = qrom_tally(len(index), data)
        self.bump(extra)
        self.tally.add(tally)


@dataclass(frozen=True)
class OracleCost:
    """The coherent oracle's size (one call: compute, phase, uncompute).

    Args:
        index_bits: n.
        qubits: All qubits (index and ancillas).
        ands: Toffolis with measurement-based uncomputation (module text).
        toffolis: CCX gates (ANDs and undos).
        gates: All gates.
        tally: The ``Tally``.
        points: Tested points per entry.
        box_tests: Point-box pairs before settling.
        box_tests_kept: Point-box pairs the circuit tests.
        comparisons: Comparisons the circuit evaluates (per compute half).
    """

    index_bits: int
    qubits: int
    ands: int
    toffolis: int
    gates: int
    tally: Tally
    points: int
    box_tests: int
    box_tests_kept: int
    comparisons: int


def plan_costs(database: LatticeDatabase, plan: OraclePlan) -> OracleCost:
    """``OracleCost`` of an oracle plan, counted in closed form (module text).

    Args:
        database: The ``LatticeDatabase``.
        plan: Its ``OraclePlan``.

    Returns:
        The ``OracleCost``.
    """
    from .oracle import emit_oracle

    em = FastCountEmitter()
    layout = emit_oracle(em, database, plan)
    tally = em.tally
    return OracleCost(len(layout.index), em.peak, tally.ands, tally.toffolis, tally.gates, tally,
                      len(plan.points), plan.box_tests, plan.box_tests_kept, plan.comparisons_kept)


def oracle_costs(env: Environment, database: LatticeDatabase, motion: SampledMotion, digits: str = "naf"
                 ) -> OracleCost:
    """Qubits and Toffolis of ``coherent_phase_oracle(env, database, motion, digits)`` without
    building it (module text).

    Args:
        env: The ``Environment``.
        database: The ``LatticeDatabase``.
        motion: The ``SampledMotion``.
        digits: ``"naf"`` (default) or ``"binary"``.

    Returns:
        The ``OracleCost``.

    Raises:
        ValueError: As ``oracle.build_coherent_oracle`` (except the size limit).
    """
    return plan_costs(database, oracle_plan(env, database, motion, digits))


def check_buildable(env: Environment, database: LatticeDatabase, motion: SampledMotion, plan: OraclePlan,
                    max_gates: int) -> None:
    """Refuse an oracle of more than ``max_gates`` gates before it is built.

    Args:
        env: The ``Environment``.
        database: The ``LatticeDatabase``.
        motion: The ``SampledMotion``.
        plan: Their ``OraclePlan``.
        max_gates: The limit.

    Raises:
        ValueError: Too many gates; the message gives the count, and the largest number of the
            world's boxes (``env.boxes``) that fits, or, where none fits, the lookup's and points' share.
    """
    cost = plan_costs(database, plan)
    if cost.gates <= max_gates:
        return
    boxes = env.num_boxes

    def gates_with(count: int) -> int:
        subset = Environment(env.bounds, env.boxes[:count], start=env.start)
        return plan_costs(database, oracle_plan(subset, database, motion, plan.digits)).gates

    low, high = 0, boxes
    if gates_with(0) > max_gates:
        raise ValueError(
            f"the oracle would have {cost.gates} gates, more than {max_gates}, and {gates_with(0)} even without "
            f"boxes: lower database.parent_bits (m = {database.parent_bits}: a lookup over 2^m nodes), "
            f"motion.time_samples (K = {motion.time_samples}) or the fixed-point bits (b = {database.fmt.bits})")
    while low < high:  # the most boxes (a prefix of env.boxes) that fit
        middle = (low + high + 1) // 2
        if gates_with(middle) <= max_gates:
            low = middle
        else:
            high = middle - 1
    raise ValueError(f"the oracle would have {cost.gates} gates, more than {max_gates}: env.boxes has {boxes} boxes, "
                     f"at most {low} fit with these sizes (or lower motion.time_samples, K = {motion.time_samples})")


@dataclass(frozen=True)
class LookupCost:
    """The lookup oracle's Toffolis (ANDs) over 2^n marks.

    Args:
        index_bits: n.
        qrom_ands: Unary-iteration QROM, load and unload: 2 (2^n - 2) (``qrom_toffolis``).
        select_swap_ands: Select-swap QROM (Qualtran's ``SelectSwapQROM``), load and unload, or
            None without Qualtran or beyond n = 30.
    """

    index_bits: int
    qrom_ands: int
    select_swap_ands: float | None


def lookup_costs(index_bits: int, select_swap: bool = True) -> LookupCost:
    """The lookup oracle's Toffolis for the same n (``hardware.resources``).

    Args:
        index_bits: n, 1 .. 60.
        select_swap: Also count select-swap (Qualtran, n <= 30; default True).

    Returns:
        The ``LookupCost``.

    Raises:
        ValueError: n out of range.
    """
    from ..hardware.resources import fault_tolerant_counts, has_qualtran, qrom_toffolis

    swap: float | None = None
    if select_swap and 2 <= index_bits <= 30 and has_qualtran():
        count = fault_tolerant_counts(index_bits, "select-swap", use_qualtran=True)
        swap = count.oracle_ands + count.oracle_t / 4
    return LookupCost(index_bits, 2 * qrom_toffolis(index_bits), swap)


def mirror_tally(tally: Tally) -> Tally:
    """A tally with ANDs and undos swapped (the cost of the reversed circuit)."""
    out = Tally()
    out.add(tally, mirrored=True)
    return out


def toffoli_depth(gates: np.ndarray, num_qubits: int) -> int:
    """The Toffoli depth of a gate list: the most CCX gates on any path, every gate ordering the
    qubits it touches (as soon as possible, Clifford gates taking no time).

    Args:
        gates: (code, q0, q1, q2) rows (``emitter`` or ``simulate.CCX`` codes).
        num_qubits: All qubits.

    Returns:
        The depth.
    """
    level = [0] * num_qubits
    for code, a, b, c in gates.tolist():
        if code in (0, 4):
            continue
        if code == 1:
            level[a] = level[b] = max(level[a], level[b])
            continue
        top = max(level[a], level[b], level[c]) + 1
        level[a] = level[b] = level[c] = top
    return max(level, default=0)


__all__ = ["FastCountEmitter", "LookupCost", "OracleCost", "check_buildable", "lookup_costs", "mirror_tally",
           "oracle_costs", "plan_costs", "toffoli_depth"]
