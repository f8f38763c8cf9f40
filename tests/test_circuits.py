import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from qiskit.quantum_info import Operator, Statevector

from qrrt_circuits.search import circuits


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 6).flatmap(lambda n: st.lists(st.booleans(), min_size=2**n, max_size=2**n)),
       st.sampled_from(["diagonal", "mcz", "auto"]))
def test_phase_oracle_is_the_sign_diagonal(marks, synthesis):
    marks = np.array(marks)
    expected = Operator(np.diag(np.where(marks, -1.0, 1.0)))
    assert Operator(circuits.phase_oracle(marks, synthesis)).equiv(expected)


@pytest.mark.parametrize("n, marked, k", [(2, [1], 1), (3, [0, 5], 1), (4, [2, 3, 9], 2),
                                          (5, [7], 4), (5, list(range(32)), 3), (3, [], 2)])
def test_grover_probabilities_are_exact(n, marked, k):
    marks = np.zeros(2**n, dtype=bool)
    marks[marked] = True
    probs = Statevector(circuits.grover_circuit(marks, k, measure=False)).probabilities()
    m = len(marked)
    p_good = math.sin((2 * k + 1) * math.asin(math.sqrt(m / 2**n))) ** 2
    assert probs[marks].sum() == pytest.approx(p_good, abs=1e-10)
    if 0 < m:
        assert np.allclose(probs[marks], p_good / m, atol=1e-10)
    if m < 2**n:
        assert np.allclose(probs[~marks], (1 - p_good) / (2**n - m), atol=1e-10)


@pytest.mark.parametrize("synthesis", ["diagonal", "mcz"])
def test_aer_native_circuit_equals_grover_operator_circuit(synthesis):
    rng = np.random.default_rng(3)
    for n in (1, 2, 3, 4):
        marks = rng.random(2**n) < 0.4
        for k in (0, 1, 3):
            ref = Operator(circuits.grover_circuit(marks, k, measure=False, synthesis=synthesis))
            aer = Operator(circuits.aer_grover_circuit(marks, k, measure=False, synthesis=synthesis))
            assert aer.equiv(ref)


def test_aer_circuit_uses_only_native_instructions():
    from qiskit_aer import AerSimulator

    native = set(AerSimulator().configuration().basis_gates) | {"measure", "barrier"}
    marks = np.zeros(64, dtype=bool)
    marks[[1, 2, 3]] = True
    for synthesis in ("diagonal", "mcz"):
        ops = set(circuits.aer_grover_circuit(marks, 2, synthesis=synthesis).count_ops())
        assert ops <= native, ops - native


def test_auto_synthesis_picks_the_cheaper():
    one = np.zeros(256, dtype=bool)
    one[17] = True
    many = np.ones(256, dtype=bool)
    assert circuits.choose_synthesis(one) == "mcz"
    assert circuits.choose_synthesis(many) == "diagonal"
    estimate = circuits.oracle_cx_estimate(8, 1)
    assert estimate["diagonal"] == 254


def test_resource_estimate_counts_transpiled_gates():
    marks = np.zeros(16, dtype=bool)
    marks[[3, 12]] = True
    est = circuits.resource_estimate(marks, 2)
    assert est.no_ancilla.qubits == 4 and est.one_ancilla.qubits == 5
    assert est.no_ancilla.cx > 0 and est.no_ancilla.depth > 0
    zero = circuits.resource_estimate(marks, 0)
    assert zero.no_ancilla.cx == 0
    # iterations are identical and the transpiler does not merge across them: CX is exactly linear
    one = circuits.resource_estimate(marks, 1)
    assert est.no_ancilla.cx == 2 * one.no_ancilla.cx and est.one_ancilla.cx == 2 * one.one_ancilla.cx
    assert circuits.resource_estimate(marks, 4).no_ancilla.cx == 4 * one.no_ancilla.cx


@pytest.mark.parametrize("bad, message", [(np.zeros(6, bool), "power of two"),
                                          (np.zeros((2, 2), bool), "1-D"),
                                          (np.array([0, 2, 1, 0]), "booleans")])
def test_bad_marks(bad, message):
    with pytest.raises(ValueError, match=message):
        circuits.grover_circuit(bad, 1)


def test_bad_iterations_and_synthesis():
    with pytest.raises(ValueError, match="iterations"):
        circuits.grover_circuit(np.zeros(4, bool), -1)
    with pytest.raises(ValueError, match="synthesis"):
        circuits.phase_oracle(np.zeros(4, bool), "magic")
