"""Grover search with the coherent oracle on Aer: the measured share of marked indices against
sin^2((2k+1) theta), sin^2 theta = m / 2^n (Lemma 1), within a binomial interval (tail 1e-6).

Instances (``coherent_instances``): the wall world with one tree node (n = 4, 10 qubits: Aer's
statevector), with two nodes (n = 5, 33 qubits) and with four (n = 6, 38 qubits), both on Aer's
matrix-product-state method. Each circuit is transpiled once, to Aer-native gates."""

import math

import numpy as np
import pytest
from coherent_instances import grover_instance, wall_instance
from qiskit import transpile
from qiskit_aer import AerSimulator
from tolerances import within_binomial

from qrrt_circuits.coherent import build_coherent_oracle, coherent_grover_circuit, reachable_reference

BASIS = ["x", "z", "h", "cx", "ccx", "u", "p", "measure"]
SHOTS = 400
INSTANCES = {
    "wall-1-node": (wall_instance, "statevector", 4, 10),
    "wall-2-nodes": (lambda: grover_instance(2), "matrix_product_state", 5, 33),
    "wall-4-nodes": (lambda: grover_instance(4), "matrix_product_state", 6, 38),
}


@pytest.fixture(scope="module", params=sorted(INSTANCES))
def built(request):
    make, method, n, qubits = INSTANCES[request.param]
    env, database, motion = make()
    oracle = build_coherent_oracle(env, database, motion)
    marks = reachable_reference(env, database, motion)
    assert database.num_index_bits == n and oracle.circuit.num_qubits == qubits
    return oracle, marks, method, request.param


@pytest.mark.parametrize("iterations", [0, 1, 2, 3])
def test_grover_with_the_coherent_oracle_finds_marked_entries_at_lemma_1s_rate(built, iterations):
    oracle, marks, method, name = built
    n = int(math.log2(marks.size))
    circuit = transpile(coherent_grover_circuit(oracle.circuit, n, iterations), basis_gates=BASIS,
                        optimization_level=0)
    seed = 1000 * iterations + sorted(INSTANCES).index(name)
    counts = AerSimulator(method=method).run(circuit, shots=SHOTS, seed_simulator=seed).result().get_counts()
    hits = sum(count for bits, count in counts.items() if marks[int(bits, 2)])
    theta = math.asin(math.sqrt(marks.sum() / marks.size))
    expected = math.sin((2 * iterations + 1) * theta) ** 2
    assert 0 < marks.sum() < marks.size
    assert within_binomial(hits, SHOTS, expected), (name, iterations, hits / SHOTS, expected)


def test_the_grover_circuit_acts_on_the_index_only():
    env, database, motion = wall_instance()
    oracle = build_coherent_oracle(env, database, motion)
    circuit = coherent_grover_circuit(oracle.circuit, 4, 2)
    assert circuit.num_qubits == 10 and circuit.num_clbits == 4
    measured = {circuit.find_bit(inst.qubits[0]).index for inst in circuit.data if inst.operation.name == "measure"}
    assert measured == {0, 1, 2, 3}
    middle = coherent_grover_circuit(oracle.circuit, 4, 2, index_in_middle=True)
    assert [middle.find_bit(inst.qubits[0]).index for inst in middle.data if inst.operation.name == "measure"] == [
        3, 4, 5, 6]
    with pytest.raises(ValueError, match=r"num_index_bits must be an integer in \[1, 10\]"):
        coherent_grover_circuit(oracle.circuit, 11, 1)
    assert np.isclose(0.375, reachable_reference(env, database, motion).mean())
