"""Qubits and Toffolis of the coherent oracle, from the constructors' closed-form tallies, beside
the lookup oracle's.

``oracle_costs`` walks the same ``walk.emit_oracle`` as the circuit builder on a
``FastCountEmitter``: no gate is stored, and every component is counted in closed form (an adder
or an increment once per width, memoised; a comparison from its steps, ``arithmetic.chain_steps``;
the lookup from its tree, ``qrom.qrom_tally``), so sizes far beyond what can be built (n up to 64,
thousands of boxes) are counted in seconds. For buildable sizes the counts equal the built
circuit's (``tests/coherent/test_coherent_costs.py``).

Counts (``OracleCost``): ``ands`` is the Toffoli count with measurement-based uncomputation (an
AND costs one Toffoli, 4 T, its undo none; Gidney 2018); ``toffolis`` counts every CCX, undos
included (what the circuit holds). ``lookup_costs`` gives the lookup oracle's Toffolis for the same
n (``hardware.resources``: unary-iteration QROM over the 2^n marks, load and unload, and
select-swap where Qualtran is installed), counted the same way (ANDs only).

``check_buildable`` refuses before building an oracle of more than ``oracle.MAX_BUILD_GATES``
gates, naming the argument to lower and the largest value that fits. It counts with a
``BoundedCountEmitter``, which stops as soon as the gates counted so far pass the limit (the count
only grows as the walk goes on), so a refusal costs at most the walk of a limit's worth of gates for
each box count it tries, whatever the oracle's full size.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..world.environment import Environment
from .arithmetic import QUBIT, add_into, bit_kinds, chain_steps, controlled_increment
from .emitter import Block, CountEmitter
from .lattice import LatticeDatabase
from .motion import SampledMotion
from .plan import OracleOptions, OraclePlan, oracle_plan
from .qrom import qrom_tally
from .tally import Literal, Tally
from .walk import emit_oracle


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

    def chain(self, bits: Sequence[int | None], threshold: int, ones: int = 0) -> Literal | bool:
        """Count ``compare_chain``'s steps (one AND each, 5 X for an OR) and allocate its carries."""
        steps, result = chain_steps(bit_kinds(bits, ones), threshold)
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


class _PastLimit(Exception):
    """The gates counted so far passed a ``BoundedCountEmitter``'s limit."""


class BoundedCountEmitter(FastCountEmitter):
    """A ``FastCountEmitter`` that raises ``_PastLimit`` once its gate count passes ``limit``,
    checked after each block and each lookup (module text)."""

    def __init__(self, limit: int) -> None:
        super().__init__()
        self.limit = limit

    def _check(self) -> None:
        if self.tally.gates > self.limit:
            raise _PastLimit

    def end(self, block: Block) -> None:
        """Close the block, then stop past the limit."""
        super().end(block)
        self._check()

    def mirror(self, block: Block) -> None:
        """Mirror the block, then stop past the limit."""
        super().mirror(block)
        self._check()

    def qrom(self, index: Sequence[int], data: Sequence[int], outputs: Sequence[int]) -> None:
        """Count the lookup, then stop past the limit."""
        super().qrom(index, data, outputs)
        self._check()


def gates_up_to(database: LatticeDatabase, plan: OraclePlan, limit: int) -> int:
    """The oracle's gate count where it is at most ``limit``, else ``limit + 1`` (counting stops
    there: module text).

    Args:
        database: The ``LatticeDatabase``.
        plan: Its ``OraclePlan``.
        limit: The largest count wanted exactly.

    Returns:
        min(gates, limit + 1).
    """
    em = BoundedCountEmitter(limit)
    try:
        emit_oracle(em, database, plan)
    except _PastLimit:
        return limit + 1
    return min(em.tally.gates, limit + 1)


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
    em = FastCountEmitter()
    layout = emit_oracle(em, database, plan)
    tally = em.tally
    return OracleCost(len(layout.index), em.peak, tally.ands, tally.toffolis, tally.gates, tally,
                      len(plan.points), plan.box_tests, plan.box_tests_kept, plan.comparisons_kept)


def oracle_costs(env: Environment, database: LatticeDatabase, motion: SampledMotion,
                 options: OracleOptions | None = None) -> OracleCost:
    """Qubits and Toffolis of ``coherent_phase_oracle(env, database, motion, options)`` without
    building it (module text).

    Args:
        env: The ``Environment``.
        database: The ``LatticeDatabase``.
        motion: The ``SampledMotion``.
        options: ``OracleOptions`` (default: NAF digits, pruned, aligned).

    Returns:
        The ``OracleCost``.

    Raises:
        ValueError: As ``oracle.build_coherent_oracle`` (except the size limit).
    """
    return plan_costs(database, oracle_plan(env, database, motion, options))


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
    if gates_up_to(database, plan, max_gates) <= max_gates:
        return
    boxes = env.num_boxes

    def gates_with(count: int) -> int:
        subset = Environment(env.bounds, env.boxes[:count])
        return gates_up_to(database, oracle_plan(subset, database, motion, plan.options), max_gates)

    low, high = 0, boxes
    if gates_with(0) > max_gates:
        raise ValueError(
            f"the oracle would have more than {max_gates} gates even without boxes: lower database.parent_bits "
            f"(m = {database.parent_bits}: a lookup over 2^m nodes), motion.time_samples "
            f"(K = {motion.time_samples}) or the fixed-point bits (b = {database.fmt.bits})")
    step = 1
    while low + step < high:  # gallop up from 0 (small counts are cheap), then bisect
        if gates_with(low + step) > max_gates:
            high = low + step - 1
            break
        low, step = low + step, 2 * step
    while low < high:  # the most boxes (a prefix of env.boxes) that fit
        middle = (low + high + 1) // 2
        if gates_with(middle) <= max_gates:
            low = middle
        else:
            high = middle - 1
    raise ValueError(f"the oracle would have more than {max_gates} gates: env.boxes has {boxes} boxes, "
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


@dataclass(frozen=True)
class ComparisonCost:
    """Toffolis spent on the comparisons of one oracle call (each comparison is evaluated and
    uncomputed once in the compute half and once in the uncompute half).

    Args:
        comparisons: Comparisons per half (``OraclePlan.comparisons_kept``).
        ands: Ours, with measurement-based uncomputation: the chains' ANDs (``compare_chain``).
        toffolis: Ours, every CCX: twice ``ands``.
        full_width_ands: Ours without following constants: W - 1 ANDs per chain.
        qiskit_toffolis: With Qiskit's ``synth_integer_comparator_2s`` instead (every CCX): its
            2 W - 3 Toffolis per call, two calls per comparison (compute, uncompute) per half.
    """

    comparisons: int
    ands: int
    toffolis: int
    full_width_ands: int
    qiskit_toffolis: int


@functools.lru_cache(maxsize=256)
def qiskit_comparator_toffolis(width: int) -> int:
    """CCX gates of Qiskit's carry-chain comparator ``synth_integer_comparator_2s`` on ``width``
    bits (its ``OrGate`` s written as X and CCX), counted on one built circuit.

    Args:
        width: W >= 2.

    Returns:
        The count (2 W - 3).
    """
    from qiskit import transpile
    from qiskit.synthesis.arithmetic import synth_integer_comparator_2s

    circuit = synth_integer_comparator_2s(width, (1 << (width - 1)) + 1, geq=True)
    compiled = transpile(circuit, basis_gates=["x", "cx", "ccx"], optimization_level=0)
    return int(compiled.count_ops().get("ccx", 0))


def comparison_costs(plan: OraclePlan) -> ComparisonCost:
    """The comparisons' Toffolis, ours against Qiskit's comparator and against full-width chains.

    Args:
        plan: An ``OraclePlan``.

    Returns:
        The ``ComparisonCost``.
    """
    ands = full = qiskit = count = 0
    for point in plan.points:
        groups = [point.in_bounds] + [tests for _, tests in point.boxes]
        for comparisons in groups:
            for comparison in comparisons:
                form = point.forms[comparison.axis]
                width = form.width
                kinds = bit_kinds([None] * form.lowest, form.constant_ones) + [QUBIT] * (width - form.lowest)
                steps, _ = chain_steps(kinds, comparison.threshold)
                ands += 2 * len(steps)
                full += 2 * max(width - 1, 0)
                qiskit += 4 * qiskit_comparator_toffolis(max(width, 2))
                count += 1
    return ComparisonCost(count, ands, 2 * ands, full, qiskit)


def scaling_instance(index_bits: int, boxes: int, parent_bits: int = 6, bits: int = 16, time_samples: int = 16,
                     seed: int = 0) -> tuple[Environment, LatticeDatabase, SampledMotion]:
    """A world, database and motion of given sizes, for costs as functions of the sizes: the
    paper's clutter world (``scenarios.paper_clutter(seed, num_boxes=boxes)``, [0, 20]^2, d = 2),
    ``b``-bit coordinates covering it, 2^m tree nodes uniform over its free space, (n - m) / 2 cell
    bits per axis, and the paper's dynamics at K samples with f = b fraction bits.

    Args:
        index_bits: n, with n - m even and 2 <= n - m <= 2 b.
        boxes: B, 0 .. 100 000.
        parent_bits: m, 0 .. 20 (default 6: 64 nodes).
        bits: b, 1 .. 24 (default 16).
        time_samples: K, 2 .. 4096 (default 16).
        seed: The world's and the nodes' seed (default 0).

    Returns:
        (env, database, motion).

    Raises:
        TypeError: A non-integer argument.
        ValueError: An argument out of range, or n - m odd or outside [2, 2 b].
    """
    from .._support.validation import check_int
    from ..problems.scenarios import paper_clutter
    from ..reachability.dynamics import LinearTrackingDynamics
    from .number_format import FixedPointFormat

    boxes = check_int(boxes, "boxes", 0, 100_000)
    parent_bits = check_int(parent_bits, "parent_bits", 0, 20)
    bits = check_int(bits, "bits", 1, 24)
    index_bits = check_int(index_bits, "index_bits", parent_bits + 2, parent_bits + 2 * bits)
    if (index_bits - parent_bits) % 2:
        raise ValueError(f"index_bits - parent_bits must be even (two cell fields), got n = {index_bits}, "
                         f"m = {parent_bits}")
    env = paper_clutter(seed, num_boxes=boxes).env
    fmt = FixedPointFormat.covering(env, bits)
    nodes = env.sample_free(1 << parent_bits, np.random.default_rng([0xC0E, seed]))
    database = LatticeDatabase(fmt, (index_bits - parent_bits) // 2, nodes, parent_bits=parent_bits)
    motion = SampledMotion.from_dynamics(LinearTrackingDynamics.paper(), time_samples, bits)
    return env, database, motion


__all__ = ["BoundedCountEmitter", "ComparisonCost", "FastCountEmitter", "LookupCost", "OracleCost",
           "check_buildable", "comparison_costs", "gates_up_to", "lookup_costs", "mirror_tally", "oracle_costs",
           "plan_costs", "qiskit_comparator_toffolis", "scaling_instance", "toffoli_depth"]
