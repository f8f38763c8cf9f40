"""The coherent oracle's costs: the closed-form tallies equal the built circuits' counts, the
lookup's closed form equals its built count and the library's ``qrom_toffolis``, large sizes are
counted without building, and sizes too large to build are refused before building."""

import time

import numpy as np
import pytest
from coherent_instances import random_instance, wall_instance

from qrrt_circuits import Environment
from qrrt_circuits.coherent import (
    LatticeDatabase,
    OracleOptions,
    SampledMotion,
    build_coherent_oracle,
    lookup_costs,
    oracle_costs,
    oracle_plan,
)
from qrrt_circuits.coherent.costs import (
    comparison_costs,
    qiskit_comparator_toffolis,
    scaling_instance,
    toffoli_depth,
)
from qrrt_circuits.coherent.emitter import GateEmitter
from qrrt_circuits.coherent.qrom import qrom_ands, qrom_tally, unary_qrom
from qrrt_circuits.hardware.resources import qrom_toffolis

OPTIONS = [OracleOptions(), OracleOptions("binary"), OracleOptions(prune=False), OracleOptions(align=False)]


@pytest.mark.parametrize("options", OPTIONS, ids=["naf", "binary", "unpruned", "unaligned"])
def test_closed_form_counts_equal_the_built_circuits(options):
    for seed in range(15):
        env, database, motion = random_instance(seed, dim=2 + seed % 2, max_boxes=4)
        oracle = build_coherent_oracle(env, database, motion, options)
        cost = oracle_costs(env, database, motion, options)
        assert cost.tally == oracle.tally and cost.qubits == oracle.circuit.num_qubits, seed
        counted = oracle.circuit.count_ops()
        assert cost.toffolis == counted.get("ccx", 0) and cost.gates == oracle.circuit.size(), seed
        assert cost.ands == cost.tally.undos  # every AND is undone once: the uncompute half is free


@pytest.mark.parametrize("index_bits, entries", [(1, 1), (2, 4), (3, 5), (4, 16), (5, 19), (6, 64)])
def test_the_lookup_closed_form_equals_the_built_lookup(index_bits, entries):
    data = np.random.default_rng(entries).integers(0, 64, entries).tolist()
    em = GateEmitter()
    index = [em.alloc() for _ in range(index_bits)]
    outputs = [em.alloc() for _ in range(6)]
    unary_qrom(em, index, data, outputs)
    tally, peak = qrom_tally(index_bits, data)
    assert tally == em.tally and peak == em.peak - index_bits - 6
    assert qrom_ands(index_bits, entries) == em.tally.ands
    if entries == 1 << index_bits and index_bits >= 2:
        assert qrom_ands(index_bits, entries) == qrom_toffolis(index_bits)


def test_the_lookup_closed_form_reaches_any_width():
    assert qrom_ands(30, 1 << 30) == qrom_toffolis(30)
    assert qrom_ands(40, 3) == 40  # 38 single-child levels, then a node of two leaves under one of one


def test_our_adder_costs_what_qualtrans_adder_does():
    pytest.importorskip("qualtran")
    from qualtran import QUInt
    from qualtran.bloqs.arithmetic import Add
    from qualtran.resource_counting import QECGatesCost, get_cost_value

    from qrrt_circuits.coherent.costs import _component

    for width in (2, 5, 9):
        tally, _ = _component("adder", width, width)
        assert tally.ands == get_cost_value(Add(QUInt(width)), QECGatesCost()).and_bloq == width - 1


def test_qiskits_comparator_costs_two_w_minus_three_toffolis_per_call():
    assert [qiskit_comparator_toffolis(w) for w in (4, 8, 12)] == [5, 13, 21]


def test_large_sizes_are_counted_without_building():
    """n = 30 (2 x 12 cell bits, 64 nodes), 16-bit coordinates, K = 16, 300 boxes: seconds, and
    far fewer Toffolis than the lookup over 2^30 marks."""
    env, database, motion = scaling_instance(30, 300)
    start = time.perf_counter()
    cost = oracle_costs(env, database, motion)
    assert time.perf_counter() - start < 20
    assert cost.index_bits == 30 and cost.points <= 17 and cost.qubits < 300  # K points and the sample, deduplicated
    assert 0 < cost.ands < lookup_costs(30, select_swap=False).qrom_ands / 100


def test_the_optimizations_pay():
    env, database, motion = scaling_instance(14, 50)
    plain = oracle_costs(env, database, motion, OracleOptions(align=False))
    aligned = oracle_costs(env, database, motion)
    assert aligned.ands < 0.8 * plain.ands and aligned.qubits < plain.qubits
    assert aligned.toffolis == 2 * aligned.ands  # measurement-based uncomputation halves them
    comparisons = comparison_costs(oracle_plan(env, database, motion))
    assert comparisons.ands < comparisons.full_width_ands and comparisons.toffolis < comparisons.qiskit_toffolis / 2


def test_the_toffoli_depth_is_at_most_the_count():
    env, database, motion = random_instance(4)
    oracle = build_coherent_oracle(env, database, motion)
    assert 0 < toffoli_depth(oracle.gates, oracle.circuit.num_qubits) <= oracle.tally.toffolis


def test_an_oracle_too_large_to_build_is_refused_before_building_naming_the_largest_that_fits():
    env, database, motion = wall_instance()
    boxes = [[[1.0 + i, 10.0], [1.5 + i, 11.0]] for i in range(8)]
    env = Environment(env.bounds, boxes)
    full = oracle_costs(env, database, motion).gates
    limit = full - 1
    with pytest.raises(ValueError, match=r"more than \d+ gates: env.boxes has 8 boxes, at most (\d) fit") as error:
        build_coherent_oracle(env, database, motion, max_gates=limit)
    fits = int(error.value.args[0].split("at most ")[1].split()[0])
    smaller = Environment(env.bounds, env.boxes[:fits])
    assert build_coherent_oracle(smaller, database, motion, max_gates=limit).tally.gates <= limit
    walled = Environment([[0, 12], [0, 12]], boxes)  # cells beyond 12: a bounds test at every point
    with pytest.raises(ValueError, match="even without boxes: lower database.parent_bits"):
        build_coherent_oracle(walled, database, motion, max_gates=5)
    big = LatticeDatabase(database.fmt, 4, np.array([[2.0, 2.0]]))
    with pytest.raises(ValueError, match="env.boxes has 8 boxes"):
        build_coherent_oracle(env, big, SampledMotion.straight_line(2, 9, 3), max_gates=5000)


@pytest.mark.parametrize("boxes_fitting", range(8))
def test_the_largest_box_count_named_is_the_largest_that_fits(boxes_fitting):
    """The gallop-and-bisect over box counts names exactly the largest prefix whose gates fit."""
    env, database, motion = wall_instance()
    boxes = [[[1.0 + i, 10.0], [1.5 + i, 11.0]] for i in range(8)]
    gates = [oracle_costs(Environment(env.bounds, boxes[:count]), database, motion).gates for count in range(9)]
    limit = gates[boxes_fitting]
    expected = max(count for count in range(9) if gates[count] <= limit)
    if expected == 8:
        return
    with pytest.raises(ValueError, match=rf"at most {expected} fit"):
        build_coherent_oracle(Environment(env.bounds, boxes), database, motion, max_gates=limit)


def test_a_plan_too_large_is_refused_from_its_size_before_planning():
    """points x boxes above MAX_PLANNED_TESTS: refused at once, naming env.boxes and K."""
    from qrrt_circuits.coherent.plan import MAX_PLANNED_TESTS

    env, database, motion = scaling_instance(10, 2000, time_samples=1024)
    start = time.perf_counter()
    refusal = r"env.boxes has 2000 boxes and motion.time_samples = 1024 .* at most \d+ boxes fit"
    with pytest.raises(ValueError, match=refusal):
        oracle_costs(env, database, motion)
    assert time.perf_counter() - start < 1
    assert len(motion.tested) * 2000 > MAX_PLANNED_TESTS


def test_an_oracle_far_too_large_is_refused_in_seconds():
    """525 boxes at K = 256 (51.8 M gates): the count stops at the limit."""
    env, database, motion = scaling_instance(10, 525, time_samples=256)
    start = time.perf_counter()
    with pytest.raises(ValueError, match="env.boxes has 525 boxes, at most 11 fit"):
        build_coherent_oracle(env, database, motion)
    assert time.perf_counter() - start < 30
