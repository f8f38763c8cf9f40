"""Independent searches handed to a backend together (``search_many``, ``PolicyState.run_many``):
bit for bit what searching them one by one gives."""

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from conftest import ALL_BACKENDS, make_backend, random_marks

import qrrt_circuits as qc


def requests_for(rng: np.random.Generator, seeded: bool) -> list[qc.SearchRequest]:
    shapes = [(3, 1, 0, 1), (5, 3, 2, 4), (4, 16, 3, 2), (6, 5, 1, 8), (5, 0, 4, 1), (2, 1, 1, 3)]
    return [qc.SearchRequest(qc.LookupOracle(random_marks(rng, n, m)), k, shots,
                             int(rng.integers(2**31)) if seeded else None)
            for n, m, k, shots in shapes]


@pytest.mark.parametrize("backend_name", ALL_BACKENDS)
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_search_many_equals_one_by_one(backend_name, seed):
    requests = requests_for(np.random.default_rng(seed), seeded=True)
    together = make_backend(backend_name, seed).search_many(requests)
    alone = make_backend(backend_name, seed)
    assert len(together) == len(requests)
    for request, result in zip(requests, together, strict=True):
        expected = alone.search(request.oracle, request.iterations, request.shots, seed=request.seed)
        assert np.array_equal(result.indices, expected.indices)
        assert (result.iterations, result.shots, result.oracle_calls) == (
            expected.iterations, expected.shots, expected.oracle_calls)


@pytest.mark.parametrize("backend_name", ["aer", "statevector"])
def test_search_many_without_seeds_draws_the_backends_stream_in_order(backend_name):
    requests = requests_for(np.random.default_rng(5), seeded=False)
    together = make_backend(backend_name, 11).search_many(requests)
    alone = make_backend(backend_name, 11)
    for request, result in zip(requests, together, strict=True):
        assert np.array_equal(result.indices, alone.search(request.oracle, request.iterations, request.shots).indices)


def test_search_many_checks_every_request_before_searching():
    backend = qc.StatevectorBackend(seed=0)
    good = qc.SearchRequest(qc.LookupOracle(np.array([True, False, False, False])), 1, 2, 3)
    with pytest.raises(TypeError, match="SearchRequest"):
        backend.search_many([good, (good.oracle, 1)])
    with pytest.raises(ValueError, match="shots"):
        backend.search_many([good, qc.SearchRequest(good.oracle, 1, 0)])
    with pytest.raises(ValueError, match="iterations"):
        backend.search_many([qc.SearchRequest(good.oracle, -1)])
    assert backend.search_many([]) == ()


def test_one_aer_job_cannot_carry_independent_seeds():
    """Why ``AerBackend.search_many`` runs one simulation per request: in a multi-circuit run Aer
    seeds circuit i with seed_simulator + 2113 i, so one run cannot give each circuit its own seed."""
    from qiskit import QuantumCircuit
    from qiskit_aer import AerSimulator

    circuit = QuantumCircuit(3, 3)
    circuit.h(range(3))
    circuit.measure(range(3), range(3))
    result = AerSimulator().run([circuit] * 3, shots=4, seed_simulator=7).result()
    assert [experiment.seed_simulator for experiment in result.results] == [7, 7 + 2113, 7 + 2 * 2113]


@pytest.mark.parametrize("policy", [qc.PaperIterations(), qc.KnownOptimal(), qc.Adaptive(), qc.BBHT()],
                         ids=lambda policy: policy.name)
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_unshared_pqrrt_round_searched_together_equals_one_by_one(policy, seed, clutter):
    """Without an executor, unshared Pq-RRT hands a round's searches to the backend together; on
    an executor each database is searched by its own task. Same trees and counts, bit for bit."""
    def plan(executor):
        planner = qc.PQRRT(backend=qc.AerBackend(), num_qubits=5, workers=4, shared_database=False,
                           search_policy=policy, seed=seed, executor=executor)
        return planner.plan(clutter, max_rounds=6)

    together = plan(None)
    with ThreadPoolExecutor(max_workers=1) as pool:
        one_by_one = plan(pool)
    assert np.array_equal(together.nodes, one_by_one.nodes)
    assert np.array_equal(together.parents, one_by_one.parents)
    assert together.metrics.as_dict() | {"wall_time_s": 0} == one_by_one.metrics.as_dict() | {"wall_time_s": 0}
    assert together.metrics.quantum_oracle_calls > 0


def test_a_state_overriding_run_keeps_its_run_in_run_many(clutter):
    """A user's policy state that overrides ``run`` (not ``run_many``) is not bypassed."""
    from qrrt_circuits.search.policies import PolicyState

    class OneIterationState(PolicyState):
        calls = 0

        def run(self, problem, workers, tree_nodes):
            OneIterationState.calls += 1
            return super().run(problem, workers, tree_nodes)

    class OneIteration(qc.FixedIterations):
        def start(self, num_items):
            return OneIterationState(self, num_items)

    planner = qc.PQRRT(backend=qc.StatevectorBackend(), num_qubits=4, workers=3, shared_database=False,
                       search_policy=OneIteration(1), seed=0)
    result = planner.plan(clutter, max_rounds=2)
    assert OneIterationState.calls == 3 * result.metrics.rounds
