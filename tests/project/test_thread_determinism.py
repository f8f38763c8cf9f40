"""Same seed, same plan, whatever the executor: threads never mix the searches' seeds."""

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from conftest import ALL_BACKENDS, make_backend
from planner_checks import posed

import qrrt_circuits as qc


@pytest.mark.parametrize("backend_name", ALL_BACKENDS)
def test_unshared_pqrrt_on_threads_plans_as_in_process(backend_name):
    env = qc.paper_clutter(seed=3)
    plans = []
    for executor in (None, ThreadPoolExecutor(6), ThreadPoolExecutor(6)):
        planner = qc.PQRRT(backend=make_backend(backend_name, 11), num_qubits=4, workers=6,
                           shared_database=False, search_policy=qc.FixedIterations(1), seed=7,
                           executor=executor)
        plans.append(planner.plan(posed(env, goal_radius=1e-9), max_rounds=4))
        if executor is not None:
            executor.shutdown()
    serial = plans[0]
    assert serial.metrics.quantum_oracle_calls == 4 * 6  # every worker searched every round
    for threaded in plans[1:]:
        assert np.array_equal(threaded.nodes, serial.nodes) and np.array_equal(threaded.parents, serial.parents)
        assert threaded.metrics.rejected == serial.metrics.rejected


def test_sampler_searches_on_threads_measure_what_serial_searches_measure():
    backend = make_backend("sampler", 5)
    rng = np.random.default_rng(0)
    requests = [(rng.random(16) < 0.3, int(k), 8, seed) for seed, k in enumerate(rng.integers(0, 3, 48))]
    serial = [backend.search(qc.LookupOracle(marks), k, shots, seed=seed).indices for marks, k, shots, seed in requests]
    with ThreadPoolExecutor(8) as pool:
        threaded = list(pool.map(lambda r: backend.search(qc.LookupOracle(r[0]), r[1], r[2], seed=r[3]).indices,
                                 requests))
    assert all(np.array_equal(a, b) for a, b in zip(serial, threaded, strict=True))
