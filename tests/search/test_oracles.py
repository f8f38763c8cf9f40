"""The oracle is part of the search problem: every backend that runs circuits searches a
``LookupOracle`` or a ``CircuitOracle`` (the coherent reversible check included, on Aer's
matrix-product-state method), and the statevector backend refuses a circuit it cannot simulate in
closed form, naming what to use. Shot frequencies are held to Lemma 1's sin^2((2k+1) theta) within
an exact binomial interval (``tolerances``)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import make_backend, random_marks
from scipy import stats
from tolerances import difference_sigma, within_binomial, z_bound

import qrrt_circuits as qc
from qrrt_circuits.probability import optimal_iterations, success_probability
from qrrt_circuits.search.iterate_sequence import IterateSequence

BOXES = np.array([[[0.0, 0.0], [20.0, 7.0]], [[0.0, 13.0], [20.0, 20.0]], [[9.0, 9.0], [11.0, 11.0]]])
CORRIDOR_PROBLEM = qc.Problem.build(qc.Environment(np.array([[0.0, 20.0], [0.0, 20.0]]), BOXES), [2.0, 10.0],
                                    [18.0, 10.0], 2.5)
CORRIDOR = CORRIDOR_PROBLEM.env


def phase_flip_circuit(marks: np.ndarray, ancillas: int = 0):
    """A phase-oracle circuit of ``marks`` as a user would write one: per marked index, X on its zero
    bits and a multi-controlled Z, on n index qubits followed by idle ancillas."""
    from qiskit import QuantumCircuit

    n = int(marks.size).bit_length() - 1
    circuit = QuantumCircuit(n + ancillas)
    for index in np.flatnonzero(marks):
        zeros = [q for q in range(n) if not index >> q & 1]
        if zeros:
            circuit.x(zeros)
        if n > 1:
            circuit.mcp(math.pi, list(range(n - 1)), n - 1)
        else:
            circuit.p(math.pi, 0)
        if zeros:
            circuit.x(zeros)
    return circuit


@pytest.fixture(scope="module")
def coherent():
    """The corridor's coherent oracle (n = 7 index qubits among 37) with its marks."""
    from qrrt_circuits.coherent import (
        FixedPointFormat,
        LatticeDatabase,
        SampledMotion,
        build_coherent_oracle,
        coherent_search_oracle,
        reachable_reference,
    )

    database = LatticeDatabase(FixedPointFormat.covering(CORRIDOR, 6), 3, np.array([[3.0, 10.0], [17.0, 10.0]]))
    motion = SampledMotion.from_dynamics(qc.LinearTrackingDynamics.paper(), 4, 6)
    marks = reachable_reference(CORRIDOR, database, motion)
    built = build_coherent_oracle(CORRIDOR, database, motion)
    return coherent_search_oracle(built.circuit, 7, marks=marks), marks


def test_the_coherent_oracle_on_aer_mps_measures_lemma_1s_rate_over_its_marked_set(coherent):
    """The coherent circuit searched as a ``CircuitOracle`` by ``AerBackend(method=
    "matrix_product_state")`` (its index register in the middle of the chain): the measured marked
    share is sin^2((2k+1) theta) within the binomial interval, every measured marked index is one of
    the fixed-point reference's, marked indices come out uniformly, and the lookup of the same marks
    through the same backend measures the same rate."""
    oracle, marks = coherent
    backend = qc.AerBackend(seed=0, method="matrix_product_state")
    m, size = int(marks.sum()), marks.size
    assert oracle.num_qubits == 7 and oracle.width > 7 and oracle.marked_count() == m and 0 < m < size
    k = optimal_iterations(size, m)
    shots = 600
    result = backend.search(oracle, k, shots, seed=3)
    assert result.oracle_calls == k * shots and result.indices.shape == (shots,)
    hits = marks[result.indices]
    expected = success_probability(size, m, k)
    assert within_binomial(int(hits.sum()), shots, expected)
    assert set(result.indices[hits].tolist()) <= set(np.flatnonzero(marks).tolist())
    counts = np.bincount(result.indices[hits], minlength=size)[marks]
    assert stats.chisquare(counts).pvalue > 1e-6
    lookup = backend.search(qc.LookupOracle(marks), k, shots, seed=4)
    rate, lookup_rate = hits.mean(), marks[lookup.indices].mean()
    assert abs(rate - lookup_rate) <= z_bound() * difference_sigma(expected, shots, expected, shots)


def test_a_coherent_search_is_seeded_per_call(coherent):
    oracle, _ = coherent
    backend = qc.AerBackend(method="matrix_product_state")
    first = backend.search(oracle, 1, 64, seed=5).indices
    assert np.array_equal(first, backend.search(oracle, 1, 64, seed=5).indices)
    assert not np.array_equal(first, backend.search(oracle, 1, 64, seed=6).indices)


@pytest.mark.parametrize("backend_name", ["statevector", "aer", "aer-mps", "sampler"])
@pytest.mark.parametrize("n, m, k", [(4, 1, 3), (5, 6, 1), (6, 3, 4)])
def test_a_lookup_oracle_is_searched_at_lemma_1s_rate_by_every_backend(backend_name, n, m, k):
    marks = random_marks(np.random.default_rng(10 * n + m), n, m)
    shots = 2000
    result = make_backend(backend_name, seed=n).search(qc.LookupOracle(marks), k, shots, seed=k)
    assert within_binomial(int(marks[result.indices].sum()), shots, success_probability(2**n, m, k))


@pytest.mark.parametrize("backend_name", ["aer", "aer-mps", "sampler"])
def test_a_users_circuit_oracle_is_searched_as_its_lookup_is(backend_name):
    """A phase-flip circuit with idle ancillas and a permuted index register: the circuit
    backends measure Lemma 1's rate over its marks, as for their lookup."""
    marks = random_marks(np.random.default_rng(2), 4, 3)
    circuit = phase_flip_circuit(marks, ancillas=2)
    moved = circuit.copy_empty_like()
    order = [2, 0, 5, 3, 1, 4]  # index bit j on qubit order[j]; the ancillas elsewhere
    moved.compose(circuit, qubits=order, inplace=True)
    oracle = qc.CircuitOracle(moved, order[:4], marks=marks)
    shots = 2000
    result = make_backend(backend_name, seed=1).search(oracle, 2, shots, seed=9)
    assert within_binomial(int(marks[result.indices].sum()), shots, success_probability(16, 3, 2))


@pytest.mark.parametrize("closed_form", [True, False])
def test_the_statevector_backend_refuses_a_circuit_oracle_naming_what_runs_it(closed_form):
    marks = random_marks(np.random.default_rng(0), 3, 2)
    oracle = qc.CircuitOracle(phase_flip_circuit(marks), 3)
    backend = qc.StatevectorBackend(seed=0, closed_form=closed_form)
    message = (r"the statevector backend .*cannot simulate a circuit oracle "
               r".*AerBackend\(method='matrix_product_state'\)")
    with pytest.raises(ValueError, match=message):
        backend.search(oracle, 1, 4)
    with pytest.raises(ValueError, match=message):
        backend.search_sequence(oracle, IterateSequence.grover(1), 4)


def test_a_circuit_oracle_refuses_generalized_iterates_and_amplitude_estimation():
    marks = random_marks(np.random.default_rng(0), 3, 2)
    oracle = qc.CircuitOracle(phase_flip_circuit(marks), 3)
    with pytest.raises(ValueError, match="phase flip .* only, .*e\\^\\{i beta\\}"):
        qc.AerBackend(seed=0).search_sequence(oracle, IterateSequence.grover(1), 4)
    from qrrt_circuits._support.randomness import RandomStreams

    problem = qc.DatabaseSearch(oracle, marks, qc.AerBackend(seed=0), RandomStreams(0), 0)
    with pytest.raises(ValueError, match="EstimatedOptimal's amplitude estimation .*cannot simulate a circuit"):
        qc.EstimatedOptimal().estimate(problem)
    unknown = qc.DatabaseSearch(qc.CircuitOracle(phase_flip_circuit(marks), 3), marks, qc.AerBackend(seed=0),
                                RandomStreams(0), 0)
    assert oracle.marked_count() is None
    with pytest.raises(ValueError, match="marked count .* is unknown"):
        unknown.marked_count()


def test_bare_marks_and_bad_circuit_oracles_are_refused():
    from qiskit import QuantumCircuit

    marks = np.zeros(8, dtype=bool)
    with pytest.raises(TypeError, match=r"LookupOracle\(marks\)"):
        qc.StatevectorBackend(seed=0).search(marks, 1)
    with pytest.raises(TypeError, match="oracle must be a search oracle"):
        qc.StatevectorBackend(seed=0).search_many([qc.SearchRequest("marks", 1)])
    with pytest.raises(TypeError, match="circuit must be a QuantumCircuit"):
        qc.CircuitOracle(marks, 3)
    measured = QuantumCircuit(3, 1)
    with pytest.raises(ValueError, match="no classical bits"):
        qc.CircuitOracle(measured, 3)
    with pytest.raises(ValueError, match="distinct"):
        qc.CircuitOracle(QuantumCircuit(3), [0, 0])
    with pytest.raises(ValueError, match=r"index_qubits\[\.\.\.\] must be an integer in \[0, 2\]"):
        qc.CircuitOracle(QuantumCircuit(3), [0, 3])
    with pytest.raises(ValueError, match=r"marks must have length 2\*\*2"):
        qc.CircuitOracle(QuantumCircuit(3), 2, marks=np.zeros(8, dtype=bool))


def test_the_sampler_keeps_circuit_oracles_apart_in_its_cache():
    """Two circuit oracles are never one cache entry (their keys are their own), and one oracle
    searched twice is transpiled once."""
    backend = make_backend("sampler", seed=0)
    first, second = np.zeros(8, dtype=bool), np.zeros(8, dtype=bool)
    first[2], second[5] = True, True  # k = 1: the marked index is measured with probability 0.78
    a, b = (qc.CircuitOracle(phase_flip_circuit(marks), 3) for marks in (first, second))
    backend.search(a, 1, 200, seed=1)
    backend.search(a, 1, 200, seed=2)
    assert backend.transpile_count == 1
    measured = backend.search(b, 1, 200, seed=1).indices
    assert backend.transpile_count == 2 and second[measured].mean() > 0.5


def test_lattice_plans_search_the_coherent_oracle_on_the_planners_backend():
    """``LatticeCandidates(coherent=True)`` hands its circuit to the planner's own backend: on Aer's
    matrix-product-state method it plans, and on the statevector backend the first search is
    refused with the message that names what runs it."""
    database = qc.LatticeCandidates(3, bits=6, coherent=True)
    planner = qc.QRRT(backend=qc.AerBackend(seed=0, method="matrix_product_state"), num_qubits=7, seed=1,
                      database=database)
    result = planner.plan(CORRIDOR_PROBLEM, max_oracle_calls=60)
    assert result.metrics.quantum_oracle_calls > 0
    assert "method=matrix_product_state" in result.settings["backend"]
    refused = qc.QRRT(backend=qc.StatevectorBackend(seed=0), num_qubits=7, seed=1, database=database)
    with pytest.raises(ValueError, match="cannot simulate a circuit oracle"):
        refused.plan(CORRIDOR_PROBLEM, max_oracle_calls=60)
