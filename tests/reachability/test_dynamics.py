import numpy as np
import pytest
from scipy.integrate import solve_ivp

import qrrt_circuits as qc


def test_paper_closed_loop_is_diagonal():
    dyn = qc.LinearTrackingDynamics.paper()
    assert np.allclose(dyn.closed_loop, np.diag([-2.7, -4.0]))


def test_positions_match_ode_integration_of_the_tracking_law():
    dyn = qc.LinearTrackingDynamics.paper()
    parent, child = np.array([1.0, 2.0]), np.array([4.0, -1.0])
    u_ff = np.linalg.solve(dyn.B, -dyn.A @ child)  # makes the target an equilibrium

    def rhs(_t, x):
        return dyn.A @ x + dyn.B @ (-dyn.K @ (x - child) + u_ff)

    times = np.linspace(0, 5, 51)
    ode = solve_ivp(rhs, (0, 5), parent, t_eval=times, rtol=1e-10, atol=1e-12)
    assert np.allclose(dyn.positions(parent, child, times), ode.y.T, atol=1e-7)


def test_trajectory_is_arc_length_uniform():
    dyn = qc.LinearTrackingDynamics.paper()
    points = dyn.trajectory([0.0, 0.0], [3.0, 2.0], num=50)
    steps = np.linalg.norm(np.diff(points, axis=0), axis=1)
    assert np.allclose(points[0], [0, 0])
    assert np.allclose(points[-1], [3, 2], atol=1e-4)
    assert steps.max() / steps.min() < 1.05


def test_non_hurwitz_gain_is_rejected():
    with pytest.raises(ValueError, match="Hurwitz"):
        qc.LinearTrackingDynamics(np.eye(2), np.eye(2), np.zeros((2, 2)))


def test_shape_mismatch_is_rejected():
    with pytest.raises(ValueError, match="K must have shape"):
        qc.LinearTrackingDynamics(-np.eye(2), np.eye(2), np.zeros((3, 2)))
    with pytest.raises(ValueError, match="horizon"):
        qc.LinearTrackingDynamics(-np.eye(2), np.eye(2), np.zeros((2, 2)), horizon=0)


def test_curvature_bound_dominates_sampled_curvature():
    rng = np.random.default_rng(0)
    A = rng.normal(size=(3, 3))
    B = np.eye(3)
    K = A + np.array([[2.0, 1.0, 0.0], [-1.0, 2.0, 0.5], [0.0, 0.0, 1.0]])  # closed loop non-normal
    dyn = qc.LinearTrackingDynamics(A, B, K)
    times, bounds = dyn.curvature_bound_times(max_error=10.0, resolution=0.01)
    m2 = dyn.closed_loop @ dyn.closed_loop
    for i in range(len(bounds)):
        fine = np.linspace(times[i], times[i + 1], 20)
        actual = max(np.linalg.norm(m2 @ dyn.propagators([t])[0], 2) for t in fine)
        assert actual <= bounds[i] * (1 + 1e-9)


@pytest.mark.parametrize("horizon", [1e300, 1.000001e6, float("inf"), 0.0, -1.0])
def test_horizon_outside_its_range_is_refused(horizon):
    """A huge horizon overflowed deep in the chord grid (step ** 2); it is refused up front."""
    with pytest.raises(ValueError, match=r"horizon must be a finite number in \(0.0, 1000000.0\]"):
        qc.LinearTrackingDynamics.paper(horizon=horizon)


def test_the_longest_horizon_builds_an_exact_check(clutter):
    dynamics = qc.LinearTrackingDynamics.paper(horizon=1e6)
    oracle = qc.ExactCheck(clutter.env, dynamics)
    assert oracle.reachable(np.array([[1.0, 1.0]]), np.array([[1.5, 1.2]])).shape == (1,)
