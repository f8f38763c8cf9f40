"""State spaces: R^d (the paper's) and SE(2); the planners' nearest nodes and steps follow the
space's metric (its nearest-neighbour structure: ``tests/world/test_nearest.py``)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import qrrt_circuits as qc
from qrrt_circuits.planners.database import steer
from qrrt_circuits.world.spaces import wrap_angle

PI = math.pi


def test_se2_distance_wraps_the_angle_the_shorter_way():
    space = qc.SE2Space()
    a = np.array([[0.0, 0.0, PI - 0.1]])
    b = np.array([[3.0, 4.0, -PI + 0.1]])
    assert space.distance(a, b)[0] == pytest.approx(5.0 + 0.5 * 0.2)
    assert qc.SE2Space(angle_weight=0.0).distance(a, b)[0] == pytest.approx(5.0)
    assert np.all(wrap_angle(np.array([PI, -PI, 3 * PI, 0.5])) < PI)


def test_se2_interpolation_turns_along_the_shorter_arc():
    space = qc.SE2Space()
    a, b = np.array([[0.0, 0.0, PI - 0.1]]), np.array([[2.0, 0.0, -PI + 0.1]])
    middle = space.interpolate(a, b, np.array([0.5]))[0]
    assert middle[:2].tolist() == [1.0, 0.0] and abs(abs(middle[2]) - PI) < 1e-12
    assert np.allclose(space.interpolate(a, b, np.array([1.0])), [[2.0, 0.0, -PI + 0.1]])


def test_steering_in_se2_caps_the_metric_step():
    space = qc.SE2Space()
    origins = np.zeros((2, 3))
    samples = np.array([[3.0, 4.0, 2.0], [0.1, 0.0, 0.1]])
    steered = steer(space, origins, samples, 1.0)
    assert space.distance(origins, steered) == pytest.approx([1.0, 0.15])


class ShortMoves:
    """An SE(2) predicate of one's own: moves of metric length at most 2 in a disc-free plane."""

    dim, name = 3, "short-se2"

    def reachable(self, parents, children):
        return qc.SE2Space().distance(parents, children) <= 2.0

    def describe(self):
        return {"max_move": 2.0}


@pytest.mark.parametrize("make", [
    lambda: qc.RRT(seed=0, max_extension=1.5),
    lambda: qc.QRRT(backend=qc.StatevectorBackend(seed=0), num_qubits=4, seed=0, max_extension=1.5),
])
def test_planners_plan_in_se2(make):
    bounds = np.array([[0.0, 10.0], [0.0, 10.0], [-PI, PI]])
    problem = qc.Problem.build(qc.Environment(bounds, np.zeros((0, 2, 3))), [1, 1, 0], [9, 9, 3.0], 1.0,
                               predicate=ShortMoves(), space=qc.SE2Space())
    result = make().plan(problem, max_oracle_calls=5000)
    assert result.reached and result.settings["space"] == {"kind": "SE2", "angle_weight": 0.5}
    steps = qc.SE2Space().distance(result.nodes[result.parents[1:]], result.nodes[1:])
    assert steps.max() <= 1.5 + 1e-9 and np.all(np.abs(result.nodes[:, 2]) <= PI)


def test_bad_spaces_are_refused(clutter):
    with pytest.raises(ValueError, match="dimension mismatch: the space has d = 3, the environment has d = 2"):
        clutter.replace(space=qc.SE2Space())
    with pytest.raises(ValueError, match=r"SE2Space needs environment bounds for \(x, y, theta\)"):
        qc.SE2Space().check_bounds(np.zeros((2, 2)))
    wide = qc.Environment(np.array([[0.0, 1.0], [0.0, 1.0], [0.0, 7.0]]), np.zeros((0, 2, 3)))
    with pytest.raises(ValueError, match=r"theta bounds \[-pi, pi\]"):
        qc.Problem.build(wide, [0.5, 0.5, 1.0], [0.7, 0.7, 1.0], 0.1, predicate=ShortMoves(), space=qc.SE2Space())
    with pytest.raises(ValueError, match="dimension mismatch: the space has d = 3"):
        clutter.replace(space=qc.RealVectorSpace(3))
    with pytest.raises(TypeError, match="space must be a StateSpace"):
        clutter.replace(space="se2")
    with pytest.raises(TypeError, match="RRT does not take space"):
        qc.RRT(space=qc.SE2Space())
    with pytest.raises(ValueError, match="angle_weight must be a finite number >= 0.0"):
        qc.SE2Space(angle_weight=-1.0)
