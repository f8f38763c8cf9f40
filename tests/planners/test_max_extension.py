"""``max_extension`` (OMPL's RRT ``range``): candidates farther than r from their nearest node are
moved toward it; every planner, the classical tests and the quantum databases alike."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from conftest import make_backend
from planner_checks import assert_tree_edges_valid

import qrrt_circuits as qc
from qrrt_circuits.planners.database import steer


def test_steer_caps_the_step_and_keeps_the_direction():
    origins = np.zeros((3, 2))
    samples = np.array([[3.0, 4.0], [0.3, 0.4], [0.0, 0.0]])
    space = qc.RealVectorSpace(2)
    steered = steer(space, origins, samples, 1.0)
    assert np.allclose(steered, [[0.6, 0.8], [0.3, 0.4], [0.0, 0.0]])
    assert steer(space, origins, samples, None) is samples


def _make(name, env, backend, **kwargs):
    return {"RRT": lambda: qc.RRT(seed=3, **kwargs),
            "ParallelRRT": lambda: qc.ParallelRRT(workers=4, seed=3, **kwargs),
            "QRRT": lambda: qc.QRRT(backend=make_backend(backend, 3), num_qubits=6, seed=3, **kwargs),
            "PQRRT": lambda: qc.PQRRT(backend=make_backend(backend, 3), num_qubits=6, workers=4, seed=3,
                                      **kwargs)}[name]()


@pytest.mark.parametrize(("name", "backend"), [("RRT", None), ("ParallelRRT", None), ("QRRT", "statevector"),
                                             ("QRRT", "aer"), ("PQRRT", "statevector"), ("PQRRT", "aer")])
def test_every_edge_is_at_most_the_range_and_valid(clutter, name, backend):
    result = _make(name, clutter, backend, max_extension=1.5).plan(clutter, max_nodes=25)
    steps = np.linalg.norm(result.nodes[1:] - result.nodes[result.parents[1:]], axis=1)
    assert result.metrics.nodes >= 25 and steps.max() <= 1.5 + 1e-9
    assert result.settings["max_extension"] == 1.5
    assert_tree_edges_valid(clutter.env, qc.LinearTrackingDynamics.paper(), result)
    raw = _make(name, clutter, backend).plan(clutter, max_nodes=25)  # without a range some step is longer
    assert np.linalg.norm(raw.nodes[1:] - raw.nodes[raw.parents[1:]], axis=1).max() > 1.5


def test_a_range_gives_the_same_plan_on_an_executor(clutter):
    alone = qc.ParallelRRT(workers=4, seed=5, max_extension=1.0).plan(clutter, max_nodes=15)
    with ThreadPoolExecutor(2) as pool:
        pooled = qc.ParallelRRT(workers=4, seed=5, max_extension=1.0, executor=pool).plan(clutter, max_nodes=15)
    assert np.array_equal(alone.nodes, pooled.nodes) and np.array_equal(alone.parents, pooled.parents)
    assert alone.metrics.oracle_calls == pooled.metrics.oracle_calls


@pytest.mark.parametrize(("value", "error", "message"), [
    (0, ValueError, "max_extension must be a finite number > 0.0"),
    (-1.0, ValueError, "max_extension must be a finite number > 0.0"),
    (float("nan"), ValueError, "max_extension must be a finite number"),
    (float("inf"), ValueError, "max_extension must be a finite number"),
    ("2", TypeError, "max_extension"),
    (True, TypeError, "max_extension"),
])
def test_a_bad_range_is_refused_before_planning(clutter, value, error, message):
    for make in (lambda: qc.RRT(max_extension=value),
                 lambda: qc.QRRT(backend=qc.StatevectorBackend(seed=0), num_qubits=3, max_extension=value)):
        with pytest.raises(error, match=message):
            make()
