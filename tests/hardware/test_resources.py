"""Gate counts per oracle call against hand-derived ones, the fault-tolerant formulas against
Qualtran's bloqs (when the ``ft`` extra is installed), and the plan-time arithmetic."""

import math

import numpy as np
import pytest

from qrrt_circuits.hardware import resources as res
from qrrt_circuits.search.circuits import phase_oracle


def _one_mark(n, index=None):
    marks = np.zeros(1 << n, dtype=bool)
    marks[(1 << n) - 1 if index is None else index] = True
    return marks


@pytest.mark.parametrize("n", [2, 3, 4, 5, 6])
def test_diagonal_oracle_costs_two_to_the_n_minus_two_cx(n):
    # a uniformly controlled Rz network: 2^n - 2 CX (Shende, Bullock, Markov 2006, Thm. 7)
    marks = np.random.default_rng(n).integers(0, 2, 1 << n).astype(bool)
    compiled = res.transpile_to(phase_oracle(marks, "diagonal"))
    assert compiled.count_ops().get("cx", 0) == (1 << n) - 2


def test_multi_controlled_z_on_two_and_three_qubits():
    # MCZ on 2 qubits is CPhase(pi): 2 CX (Nielsen & Chuang Fig. 4.6); on 3 qubits CCZ: 6 CX
    assert res.transpile_to(phase_oracle(_one_mark(2), "mcz")).count_ops()["cx"] == 2
    assert res.transpile_to(phase_oracle(_one_mark(3), "mcz")).count_ops()["cx"] == 6
    # one iteration with one mark on 3 qubits: the oracle's CCZ and the diffuser's CCZ
    count = res.near_term_counts(_one_mark(3, 5), "mcz", "all-to-all")
    assert count.two_qubit_gates == 12 and count.two_qubit_depth == 12


def test_routing_only_adds_two_qubit_gates():
    marks = np.random.default_rng(0).integers(0, 2, 32).astype(bool)
    full = res.near_term_counts(marks, "diagonal", "all-to-all")
    for connectivity in ("line", "heavy-hex"):
        routed = res.near_term_counts(marks, "diagonal", connectivity)
        assert routed.two_qubit_gates >= full.two_qubit_gates
        assert routed.connectivity == connectivity and routed.num_qubits == 5
    assert res.near_term_counts(marks, "diagonal", "line").physical_qubits == 5


def test_qrom_and_diffuser_formulas():
    # unary iteration over L = 2^n entries: L - 1 Toffolis controlled, L - 2 without (Babbush et al. 2018)
    assert [res.qrom_toffolis(n) for n in (1, 2, 3, 4)] == [0, 2, 6, 14]
    assert [res.qrom_toffolis(n, controlled=True) for n in (1, 2, 3)] == [1, 3, 7]
    assert [res.multi_controlled_z_toffolis(n) for n in (1, 2, 3, 4, 8)] == [0, 0, 1, 2, 6]
    count = res.fault_tolerant_counts(4, "qrom", use_qualtran=False)
    assert (count.oracle_ands, count.diffuser_ands, count.oracle_t) == (28, 2, 0)
    assert count.t_count == 4 * 30 and count.toffoli_equivalents == 30 and count.source == "formula"


@pytest.mark.parametrize("n", [2, 3, 4, 6])
def test_qualtran_counts_equal_the_formulas(n):
    pytest.importorskip("qualtran")
    formula = res.fault_tolerant_counts(n, "qrom", use_qualtran=False)
    counted = res.fault_tolerant_counts(n, "qrom", use_qualtran=True)
    assert (counted.oracle_ands, counted.diffuser_ands, counted.oracle_t) == (
        formula.oracle_ands, formula.diffuser_ands, formula.oracle_t)
    assert counted.source.startswith("qualtran")


def test_select_swap_is_cheaper_than_qrom_for_large_tables():
    pytest.importorskip("qualtran")
    qrom = res.fault_tolerant_counts(10, "qrom")
    swap = res.fault_tolerant_counts(10, "select-swap")
    assert swap.toffoli_equivalents < qrom.toffoli_equivalents
    assert qrom.ands > 2 * (2**10 - 2) - 1  # the O(2^n) of a lookup


def test_plan_time_and_break_even_arithmetic():
    # RRT: 100 tests of 1 ms = 0.1 s; q-RRT: 20 quantum calls and 10 verifications
    assert res.plan_time_s(20, 10, 2e-3, 1e-3) == pytest.approx(0.05)
    limit = res.break_even_call_s(100, 20, 10, 1e-3)
    assert limit == pytest.approx(90 * 1e-3 / 20)
    assert res.plan_time_s(20, 10, limit, 1e-3) == pytest.approx(100 * 1e-3)  # equal at the break-even
    assert res.break_even_call_s(5, 20, 10, 1e-3) < 0  # fewer RRT tests than verifications: never
    assert math.isinf(res.break_even_call_s(5, 0, 10, 1e-3))
    assumptions = res.ProjectionAssumptions()
    count = res.fault_tolerant_counts(4, use_qualtran=False)
    assert assumptions.fault_tolerant_call_s(count) == pytest.approx(30 * 10e-6)


def test_bad_input_is_refused():
    with pytest.raises(ValueError, match="toffoli_s"):
        res.ProjectionAssumptions(toffoli_s=0)
    with pytest.raises(ValueError, match="connectivity"):
        res.near_term_counts(_one_mark(3), "diagonal", "torus")
    with pytest.raises(ValueError, match="synthesis"):
        res.near_term_counts(_one_mark(3), "auto-ish")
    with pytest.raises(ValueError, match="lookup"):
        res.fault_tolerant_counts(4, "ram")
    with pytest.raises(ValueError, match="qualtran"):
        res.fault_tolerant_counts(4, "select-swap", use_qualtran=False)
    with pytest.raises(ValueError, match="num_qubits"):
        res.fault_tolerant_counts(1)
