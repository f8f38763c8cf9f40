"""The coherent oracle as a reversible circuit: its components exhaustively, the whole oracle
against the diagonal of its marks (operators for tiny n, the bit-level simulation on every index
state beyond), ancillas returned to 0 and every Toffoli an AND or the undo of one."""

import numpy as np
import pytest
from coherent_instances import random_instance, wall_instance
from qiskit.circuit.library import IntegerComparatorGate
from qiskit.quantum_info import Operator

from qrrt_circuits import Environment, LinearTrackingDynamics
from qrrt_circuits.coherent import (
    FixedPointFormat,
    LatticeDatabase,
    OracleOptions,
    SampledMotion,
    build_coherent_oracle,
    coherent_phase_oracle,
    reachable_reference,
    simulate,
    verify_oracle,
)
from qrrt_circuits.coherent.arithmetic import add_into, and_ladder, compare_chain, controlled_increment
from qrrt_circuits.coherent.emitter import GateEmitter
from qrrt_circuits.coherent.qrom import qrom_ands, unary_qrom
from qrrt_circuits.search.circuits import phase_oracle


def _run(em: GateEmitter, inputs: int):
    return simulate(np.array(em.gates, dtype=np.int64).reshape(-1, 4), em.num_qubits, inputs)


def _value(result, qubits) -> np.ndarray:
    return sum(result.qubit_values(q).astype(np.int64) << i for i, q in enumerate(qubits))


@pytest.mark.parametrize("source_bits, target_bits", [(1, 1), (1, 3), (2, 2), (3, 3), (2, 5), (4, 4), (3, 6)])
def test_the_adder_adds_on_every_input_and_cleans_its_carries(source_bits, target_bits):
    em = GateEmitter()
    source = [em.alloc() for _ in range(source_bits)]
    target = [em.alloc() for _ in range(target_bits)]
    add_into(em, source, target)
    result = _run(em, source_bits + target_bits)
    inputs = np.arange(1 << (source_bits + target_bits))
    a, b = inputs & ((1 << source_bits) - 1), inputs >> source_bits
    assert np.array_equal(_value(result, target), (a + b) % (1 << target_bits))
    assert np.array_equal(_value(result, source), a)
    assert result.ancillas_clean and result.tag_errors == 0 and result.other_toffolis == 0
    assert em.tally.ands == em.tally.undos == target_bits - 1


@pytest.mark.parametrize("pattern", ["1111", "0111", "0011", "1101", "0101", "01", "1"])
def test_the_comparison_chain_is_the_comparison_for_every_threshold(pattern):
    """``pattern``: which bits of S are qubits (least significant first), the others constant 0."""
    present = [c == "1" for c in pattern]
    width = len(present)
    for threshold in range(1, 1 << width):
        em = GateEmitter()
        bits = [em.alloc() if p else None for p in present]
        answer = compare_chain(em, bits, threshold)
        qubits = [b for b in bits if b is not None]
        result = _run(em, len(qubits))
        values = np.zeros(1 << len(qubits), dtype=np.int64)
        for k, i in enumerate(i for i, p in enumerate(present) if p):
            values += result.qubit_values(qubits[k]).astype(np.int64) << i
        expected = values >= threshold
        if isinstance(answer, bool):
            got = np.full(expected.shape, answer)
        else:
            got = result.qubit_values(answer[0]) ^ answer[1]
        assert np.array_equal(got, expected), threshold
        assert result.tag_errors == 0 and em.tally.ands <= width - 1


@pytest.mark.parametrize("threshold", range(1, 8))
def test_the_chain_agrees_with_qiskits_integer_comparator(threshold):
    operator = Operator(IntegerComparatorGate(3, threshold, geq=True)).data  # qubits: 3 state, then result
    qiskit_answers = [bool(np.argmax(np.abs(operator[:, s])) >> 3 & 1) for s in range(8)]
    em = GateEmitter()
    bits = [em.alloc() for _ in range(3)]
    answer = compare_chain(em, bits, threshold)
    ours = _run(em, 3).qubit_values(answer[0]) ^ answer[1]
    assert ours.tolist() == qiskit_answers


@pytest.mark.parametrize("width, negated", [(1, False), (2, True), (3, False), (4, True)])
def test_the_controlled_increment_counts(width, negated):
    em = GateEmitter()
    control = em.alloc()
    counter = [em.alloc() for _ in range(width)]
    controlled_increment(em, (control, negated), counter)
    result = _run(em, width + 1)
    inputs = np.arange(1 << (width + 1))
    fire = (inputs & 1).astype(bool) ^ negated
    assert np.array_equal(_value(result, counter), ((inputs >> 1) + fire) % (1 << width))
    assert result.ancillas_clean and result.tag_errors == 0


def test_the_and_ladder_dedupes_and_sees_contradictions():
    em = GateEmitter()
    a, b, c = em.alloc(), em.alloc(), em.alloc()
    assert and_ladder(em, []) is True
    assert and_ladder(em, [(a, False), (a, True)]) is False
    assert and_ladder(em, [(a, True), (a, True)]) == (a, True)
    out = and_ladder(em, [(a, False), (b, True), (c, False), (b, True)])
    result = _run(em, 3)
    inputs = np.arange(8)
    assert np.array_equal(result.qubit_values(out[0]), (inputs & 1).astype(bool) & ~(inputs >> 1 & 1).astype(bool)
                          & (inputs >> 2 & 1).astype(bool))
    assert em.tally.ands == 2


@pytest.mark.parametrize("index_bits, entries", [(1, 1), (1, 2), (2, 3), (3, 5), (3, 8), (4, 11)])
def test_the_lookup_loads_every_entry_and_nothing_beyond(index_bits, entries):
    data = np.random.default_rng([index_bits, entries]).integers(0, 8, entries).tolist()
    em = GateEmitter()
    index = [em.alloc() for _ in range(index_bits)]
    outputs = [em.alloc() for _ in range(3)]
    unary_qrom(em, index, data, outputs)
    result = _run(em, index_bits)
    expected = np.array(data + [0] * ((1 << index_bits) - entries))
    assert np.array_equal(_value(result, outputs), expected)
    assert not any(result.qubit_values(q).any() for q in range(index_bits + 3, em.num_qubits))
    assert result.tag_errors == 0 and em.tally.ands == qrom_ands(index_bits, entries)


def _block(circuit, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The operator's block on index states with the ancillas in |0> (rows and columns 0 .. 2^n - 1)."""
    data = Operator(circuit).data
    return data[: 1 << n, : 1 << n], data


def test_the_tiny_oracle_is_the_diagonal_of_its_marks_as_an_operator():
    env, database, motion = wall_instance()
    circuit = coherent_phase_oracle(env, database, motion)
    marks = reachable_reference(env, database, motion)
    assert circuit.num_qubits == 10 and 0 < marks.sum() < 16
    block, _ = _block(circuit, 4)
    lookup = Operator(phase_oracle(marks, "diagonal")).data  # the library's lookup oracle
    assert np.allclose(block, np.diag(np.where(marks, -1.0, 1.0))) and np.allclose(block, lookup)
    # (the operator is unitary, so a block that is unitary leaves nothing outside it: ancillas clean)


def test_a_world_where_every_entry_or_none_is_reachable_gives_minus_identity_or_identity():
    fmt = FixedPointFormat(3, 0.0, 8.0)
    database = LatticeDatabase(fmt, 1, np.array([[2.0, 2.0]]))
    motion = SampledMotion.straight_line(2, 2, 0)
    free = Environment([[0, 7.9], [0, 7.9]], [])
    blocked = Environment([[0, 7.9], [0, 7.9]], [[[0, 0], [7.9, 7.9]]])
    for env, sign in ((free, -1.0), (blocked, 1.0)):
        oracle = build_coherent_oracle(env, database, motion)
        assert np.allclose(Operator(oracle.circuit).data, sign * np.eye(1 << oracle.circuit.num_qubits))
        assert reachable_reference(env, database, motion).all() == (sign < 0)
        assert verify_oracle(env, database, motion).ok


OPTIONS = [OracleOptions(), OracleOptions("binary"), OracleOptions(prune=False), OracleOptions(align=False)]


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("options", OPTIONS, ids=["naf", "binary", "unpruned", "unaligned"])
def test_every_index_state_gets_its_mark_and_clean_ancillas(dim, options):
    """Seeded random worlds, databases and motions (straight lines, the paper's dynamics, random
    closed loops with cross terms), each simulated on all of its 2^n index states."""
    marked = 0
    for seed in range(12):
        env, database, motion = random_instance(seed, dim=dim, max_cell_bits=3 if dim == 2 else 2)
        result = verify_oracle(env, database, motion, options)
        assert result.ok, (seed, result)
        marked += 0 < result.marked < 1 << result.index_bits
    assert marked >= 4  # most instances mark some entries and not others


def test_a_larger_instance_verifies():
    """n = 10 (2 x 4 cell bits, a 4-node tree), 7-bit coordinates, the paper's dynamics at 6
    samples, 6 boxes: 1024 index states."""
    rng = np.random.default_rng(5)
    low = rng.uniform(0, 8, (6, 2))
    boxes = np.stack([low, np.minimum(low + rng.uniform(0.5, 2, (6, 2)), 9.9)], axis=1)
    env = Environment([[0.5, 9.5], [0.5, 9.5]], boxes)
    database = LatticeDatabase(FixedPointFormat(7, 0.0, 10.0), 4, env.sample_free(4, rng))
    motion = SampledMotion.from_dynamics(LinearTrackingDynamics.paper(horizon=1.0), 6, 7)
    result = verify_oracle(env, database, motion)
    assert result.index_bits == 10 and result.ok and 0 < result.marked < 1024


def test_naf_digits_use_fewer_ands_than_binary_and_mark_the_same():
    env, database, _ = wall_instance()
    motion = SampledMotion.straight_line(2, 9, 3)  # coefficients 7/8, 6/8, ...: 7 = 8 - 1
    naf = build_coherent_oracle(env, database, motion, OracleOptions("naf"))
    binary = build_coherent_oracle(env, database, motion, OracleOptions("binary"))
    assert naf.tally.ands < binary.tally.ands
    assert verify_oracle(env, database, motion, OracleOptions("naf")).ok
    assert verify_oracle(env, database, motion, OracleOptions("binary")).ok
