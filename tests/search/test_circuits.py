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


@pytest.mark.parametrize("synthesis", ["diagonal", "mcz", "auto"])
@pytest.mark.parametrize("fraction", [0.15, 0.4, 0.85])
def test_aer_native_circuit_equals_grover_operator_circuit(synthesis, fraction):
    """Exact operators: the compact circuit (Z^n folded into the oracle, Walsh-Hadamard blocks of
    every width, the oracle's complement when most entries are marked) and the gate-by-gate one."""
    rng = np.random.default_rng(3)
    for n in (1, 2, 3, 5):
        marks = rng.random(2**n) < fraction
        for k in (0, 1, 3):
            ref = Operator(circuits.grover_circuit(marks, k, measure=False, synthesis="diagonal"))
            for block in (1, 2, 3):
                aer = circuits.aer_grover_circuit(marks, k, measure=False, synthesis=synthesis, block=block)
                assert Operator(aer).equiv(ref), (n, k, block)
            if n <= 3:
                literal = circuits.aer_literal_grover_circuit(marks, k, measure=False, synthesis=synthesis)
                assert Operator(literal).equiv(ref), (n, k)


@pytest.mark.parametrize("synthesis", ["diagonal", "mcz"])
def test_what_aer_executes_is_the_grover_state(synthesis):
    """Aer's own interpretation of the instructions (pauli labels, unitary blocks, diagonals):
    the state Aer computes equals the state of ``grover_circuit`` up to a global phase."""
    from qiskit_aer import AerSimulator

    simulator = AerSimulator(method="statevector")
    rng = np.random.default_rng(4)
    for n, fraction in ((1, 0.5), (3, 0.3), (5, 0.1), (6, 0.8), (7, 0.05)):
        marks = rng.random(2**n) < fraction
        circuit = circuits.aer_grover_circuit(marks, 3, measure=False, synthesis=synthesis)
        circuit.save_statevector()
        state = np.asarray(simulator.run(circuit).result().get_statevector())
        expected = Statevector(circuits.grover_circuit(marks, 3, measure=False)).data
        overlap = np.vdot(expected, state)
        assert abs(overlap) == pytest.approx(1.0, abs=1e-9)
        assert np.allclose(state, overlap * expected, atol=1e-9)


def test_aer_circuit_measures_indices_little_endian():
    """One iteration on N = 4 with one marked entry finds it with certainty (sin^2(3 theta) = 1)."""
    from qiskit_aer import AerSimulator

    for index in range(4):
        marks = np.zeros(4, dtype=bool)
        marks[index] = True
        for synthesis in ("diagonal", "mcz"):
            circuit = circuits.aer_grover_circuit(marks, 1, synthesis=synthesis)
            counts = AerSimulator().run(circuit, shots=50, seed_simulator=1).result().get_counts()
            assert counts == {format(index, "02b"): 50}


def test_simulation_synthesis_is_separate_from_the_cx_choice():
    sparse = np.zeros(2**16, dtype=bool)
    sparse[np.random.default_rng(0).choice(2**16, 12, replace=False)] = True
    # by CX count one MCZ per marked entry wins; for Aer too, but without X layers
    assert circuits.choose_synthesis(sparse) == "mcz"
    assert circuits.simulation_synthesis(sparse) == "mcz"
    # small or densely marked databases: one diagonal instruction (2m + 1 instructions would cost more)
    small = np.zeros(64, dtype=bool)
    small[[1, 5]] = True
    assert circuits.simulation_synthesis(small) == "diagonal"
    half = np.random.default_rng(1).random(2**12) < 0.5
    assert circuits.choose_synthesis(half) == "diagonal"
    assert circuits.simulation_synthesis(half) == "diagonal"
    # the complement counts: all but 3 marked is as cheap as 3 marked
    assert circuits.simulation_synthesis(~sparse) == "mcz"


def test_aer_circuit_instruction_count():
    """Per iteration: the oracle, two Walsh-Hadamard layers of ceil(n/3) blocks, one mcphase; the
    mcz oracle is one mcphase per flipped entry and one pauli between two of them (the first and
    the last pauli of the search cancel across the diffusers)."""
    n, k = 16, 12
    marks = np.zeros(2**n, dtype=bool)
    marks[np.random.default_rng(0).choice(2**n, 12, replace=False)] = True
    circuit = circuits.aer_grover_circuit(marks, k)
    blocks = -(-n // 3)
    per_iteration = (2 * 12 - 1) + 2 * blocks + 1
    # H^n, k iterations, the Z^n folded in (one pauli before the first oracle, one at the end), the
    # first and the last X-string of the search, n measures
    assert len(circuit.data) == blocks + k * per_iteration + 2 + 2 + n
    assert circuit.count_ops()["mcphase"] == k * (12 + 1)
    dense = np.random.default_rng(1).random(2**6) < 0.5
    compact = circuits.aer_grover_circuit(dense, k, measure=False)
    assert compact.count_ops() == {"unitary": (2 * k + 1) * 2, "diagonal": k, "mcphase": k, "pauli": 1}


def test_aer_circuit_uses_only_native_instructions():
    from qiskit_aer import AerSimulator

    native = set(AerSimulator().configuration().basis_gates) | {"measure", "barrier"}
    marks = np.zeros(64, dtype=bool)
    marks[[1, 2, 3]] = True
    for synthesis in ("diagonal", "mcz"):
        for build in (circuits.aer_grover_circuit, circuits.aer_literal_grover_circuit):
            ops = set(build(marks, 2, synthesis=synthesis).count_ops())
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
    with pytest.raises(ValueError, match="synthesis"):
        circuits.aer_grover_circuit(np.zeros(4, bool), 1, synthesis="magic")
    with pytest.raises(ValueError, match="block"):
        circuits.aer_grover_circuit(np.zeros(4, bool), 1, block=0)
