import numpy as np
import pytest
from reference import dense_trajectory, penetration_and_clearance

import qrrt_circuits as qc
from qrrt_circuits.world.environment import Environment


def _check_against_reference(env, dyn, parents, children, resolution):
    oracle = qc.ExactCheck(env, dyn, resolution=resolution)
    verdict = oracle.reachable(parents, children)
    assert oracle.evaluations == len(parents)
    for p, c, ok in zip(parents, children, verdict, strict=True):
        points = dense_trajectory(dyn.A, dyn.B, dyn.K, p, c, dyn.horizon, spacing=resolution / 5)
        depth, clearance = penetration_and_clearance(points, env.bounds, env.boxes)
        if ok:
            # never called reachable if the trajectory penetrates deeper than the resolution
            assert depth <= resolution / 5, (p, c, depth)
        else:
            # only rejected if it collides or passes within the resolution of an obstacle
            assert clearance <= resolution * 1.01, (p, c, clearance)
    return verdict


def test_oracle_agrees_with_dense_reference_on_clutter(clutter_world):
    rng = np.random.default_rng(11)
    parents = clutter_world.sample_free(300, rng)
    children = np.clip(parents + rng.normal(scale=2.0, size=parents.shape), 0.01, 19.99)
    verdict = _check_against_reference(clutter_world, qc.LinearTrackingDynamics.paper(), parents,
                                       children, 0.01)
    assert 0.15 < verdict.mean() < 0.85  # the sample exercises both outcomes


def test_oracle_in_three_dimensions_with_non_normal_closed_loop():
    rng = np.random.default_rng(4)
    bounds = np.array([[0.0, 6.0]] * 3)
    lower = rng.uniform(0, 5.4, size=(40, 3))
    env = Environment(bounds, np.stack([lower, lower + rng.uniform(0.2, 0.6, (40, 3))], axis=1))
    A = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [-1.0, -2.0, -1.0]])
    B = np.eye(3)
    K = A + np.array([[1.5, -2.0, 0.0], [0.5, 1.0, 0.3], [0.0, 0.0, 2.0]])
    dyn = qc.LinearTrackingDynamics(A, B, K)
    parents = env.sample_free(120, rng)
    children = np.clip(parents + rng.normal(scale=1.5, size=parents.shape), 0.05, 5.95)
    verdict = _check_against_reference(env, dyn, parents, children, 0.02)
    assert 0.1 < verdict.mean() < 0.9


def test_wall_crossing_is_rejected_and_free_motion_accepted():
    env = Environment(np.array([[0, 10], [0, 10]]), np.array([[[4.9, 0.0], [5.1, 10.0]]]))
    oracle = qc.ExactCheck(env)
    verdict = oracle.reachable(np.array([[2.0, 5.0], [2.0, 5.0]]), np.array([[8.0, 5.0], [3.0, 3.0]]))
    assert verdict.tolist() == [False, True]


def test_thin_obstacle_between_samples_is_caught():
    # an obstacle thinner than any fixed time step: evenly spaced samples would jump over it
    env = Environment(np.array([[0, 100], [0, 100]]), np.array([[[50.0, 0.0], [50.02, 100.0]]]))
    oracle = qc.ExactCheck(env)
    assert not oracle.reachable(np.array([[1.0, 50.0]]), np.array([[99.0, 50.0]]))[0]


def test_endpoint_in_collision_is_rejected(clutter_world):
    box = clutter_world.boxes[0]
    centre = box.mean(axis=0)
    start = clutter_world.sample_free(1, np.random.default_rng(0))[0]
    oracle = qc.ExactCheck(clutter_world)
    assert not oracle.reachable(start[None], centre[None])[0]


def test_oracle_rejects_bad_shapes(clutter_world):
    oracle = qc.ExactCheck(clutter_world)
    with pytest.raises(ValueError, match=r"shape \(M, 2\)"):
        oracle.reachable(np.zeros((3, 3)), np.zeros((3, 3)))
    with pytest.raises(ValueError, match="same shape"):
        oracle.reachable(np.zeros((3, 2)), np.zeros((4, 2)))
    with pytest.raises(ValueError, match="resolution"):
        qc.ExactCheck(clutter_world, resolution=0)
    with pytest.raises(ValueError, match="dimension"):
        qc.ExactCheck(clutter_world, qc.LinearTrackingDynamics(-np.eye(3), np.eye(3), np.zeros((3, 3))))


def test_error_model_rates():
    truth = np.zeros(20000, dtype=bool)
    truth[:10000] = True
    model = qc.OracleErrorModel(false_positive=0.1, false_negative=0.2, seed=0)
    marks = model.apply(truth)
    n = 10000
    for rate, observed in ((0.2, 1 - marks[:10000].mean()), (0.1, marks[10000:].mean())):
        assert abs(observed - rate) < 5 * np.sqrt(rate * (1 - rate) / n)
    assert np.array_equal(qc.OracleErrorModel(0.1, 0.2, seed=0).apply(truth), marks)
    with pytest.raises(ValueError, match="false_positive"):
        qc.OracleErrorModel(false_positive=1.5)


def test_oracle_agrees_with_exact_diagonal_check(clutter_world):
    """For the paper's diagonal closed loop the exact interval check is the truth: the oracle
    never accepts a touching trajectory, and rejects a free one only within the resolution."""
    from reference import diagonal_edge_hits

    dyn = qc.LinearTrackingDynamics.paper()
    oracle = qc.ExactCheck(clutter_world, dyn)
    rng = np.random.default_rng(21)
    parents = clutter_world.sample_free(3000, rng)
    children = np.clip(parents + rng.normal(scale=2.5, size=parents.shape), 0.0, 20.0)
    verdict = oracle.reachable(parents, children)
    rates = np.diag(dyn.closed_loop)
    for p, c, ok in zip(parents, children, verdict, strict=True):
        touches = diagonal_edge_hits(p, c, rates, dyn.horizon, clutter_world.bounds, clutter_world.boxes)
        if ok:
            assert not touches
        elif not touches:
            # a false rejection must come within the resolution of an obstacle: shrinking every
            # obstacle by that margin... is tested the other way: grow them by the resolution
            grown = clutter_world.boxes + np.array([-0.0101, 0.0101])[None, :, None]
            inner = clutter_world.bounds + np.array([0.0101, -0.0101])
            assert diagonal_edge_hits(p, c, rates, dyn.horizon, inner, grown, shrink=0.0)
    assert 0.1 < verdict.mean() < 0.9


def test_chord_grid_is_computed_once_per_dynamics_and_equals_the_direct_computation(clutter_world):
    from qrrt_circuits.reachability import exact as oracle_module

    oracle_module._CHORD_GRIDS.clear()
    dyn = qc.LinearTrackingDynamics.paper()
    max_error = float(np.linalg.norm(clutter_world.bounds[:, 1] - clutter_world.bounds[:, 0])) * 1.0001
    times, bounds = dyn.curvature_bound_times(max_error, 0.01)
    phis = dyn.propagators(times)
    first = qc.ExactCheck(clutter_world, dyn, resolution=0.01)
    assert len(oracle_module._CHORD_GRIDS) == 1
    first._times[0] = 99.0  # each predicate owns its copy: corrupting it reaches no other
    # another dynamics object with the same closed loop and horizon reuses the grid...
    second = qc.ExactCheck(clutter_world, qc.LinearTrackingDynamics.paper(), resolution=0.01)
    assert len(oracle_module._CHORD_GRIDS) == 1
    for got, want in ((second._times, times), (second._curvature, bounds), (second._phis, phis)):
        np.testing.assert_array_equal(got, want)
        assert got.flags["C_CONTIGUOUS"] and got.flags["WRITEABLE"]
    # ...and a different resolution, horizon, workspace size (the largest tracking error the grid
    # must cover) or closed loop gets its own, equal to the direct computation
    qc.ExactCheck(clutter_world, dyn, resolution=0.02)
    qc.ExactCheck(clutter_world, qc.LinearTrackingDynamics.paper(horizon=4.0), resolution=0.01)
    wide = Environment(clutter_world.bounds * 3.0, clutter_world.boxes)
    faster = qc.LinearTrackingDynamics(dyn.A, dyn.B, dyn.K * 2.0)
    for env, dynamics in ((wide, dyn), (clutter_world, faster)):
        predicate = qc.ExactCheck(env, dynamics, resolution=0.01)
        extent = float(np.linalg.norm(env.bounds[:, 1] - env.bounds[:, 0])) * 1.0001
        direct_times, direct_bounds = dynamics.curvature_bound_times(extent, 0.01)
        np.testing.assert_array_equal(predicate._times, direct_times)
        np.testing.assert_array_equal(predicate._curvature, direct_bounds)
        np.testing.assert_array_equal(predicate._phis, dynamics.propagators(direct_times))
    assert len(oracle_module._CHORD_GRIDS) == 5


NON_NORMAL = qc.LinearTrackingDynamics(np.array([[0.0, 30.0], [0.0, 0.0]]), np.eye(2), np.eye(2))


@pytest.mark.parametrize("dynamics", [qc.LinearTrackingDynamics.paper(), NON_NORMAL], ids=["paper", "non-normal"])
@pytest.mark.parametrize("max_error, resolution", [(28.3, 0.01), (28.3, 1e-4), (2.83e4, 0.01)])
def test_chord_count_estimate_is_close_below_the_grid(dynamics, max_error, resolution):
    """The estimate the oracle refuses by: the grid has 1-1.43x as many chords (its steps are
    max_step x 0.7^j), so estimate / 0.7 bounds it."""
    estimate = dynamics.chord_count_estimate(max_error, resolution)
    chords = len(dynamics.curvature_bound_times(max_error, resolution)[0]) - 1
    assert estimate <= chords <= estimate / 0.7, (estimate, chords)


def test_a_resolution_too_fine_for_the_workspace_is_refused_before_the_grid_is_built(clutter_world, monkeypatch):
    from qrrt_circuits.reachability import exact as oracle

    monkeypatch.setattr(oracle, "MAX_CHORDS", 500)
    monkeypatch.setattr(oracle, "_CHORD_GRIDS", {})
    with pytest.raises(ValueError, match=r"resolution = 0\.0001 on a workspace 28\.2843 across needs up to about "
                                         r".* chords per trajectory .*more than the 500 allowed.*at least ([0-9.e-]+)"):
        qc.ExactCheck(clutter_world, resolution=1e-4)
    assert oracle._CHORD_GRIDS == {}  # refused before any grid was built
    try:
        qc.ExactCheck(clutter_world, resolution=1e-4)
    except ValueError as error:
        finest = float(str(error).rsplit("at least ", 1)[1].split(",")[0])
    fitting = qc.ExactCheck(clutter_world, resolution=finest)  # the suggestion (as printed) is accepted
    assert len(fitting._times) - 1 <= 500
    assert oracle.max_chords(512) == 127 < oracle.max_chords(2) == 500  # d x d propagators limit large d


def test_a_workspace_too_large_for_the_default_resolution_is_refused():
    huge = qc.Environment([[-1e12, 1e12], [-1e12, 1e12]], [])
    with pytest.raises(ValueError, match="resolution = 0.01 on a workspace 2.82843e\\+12 across needs up to about"):
        qc.ExactCheck(huge)
    with pytest.raises(ValueError, match="resolution = 0.01"):
        qc.Problem.build(huge, [0.0, 0.0], [1.0, 1.0], 0.5)  # (its default check)


def test_the_chord_grid_refuses_more_intervals_than_asked():
    with pytest.raises(ValueError, match="more than 10 intervals for resolution = 0.0001"):
        qc.LinearTrackingDynamics.paper().curvature_bound_times(28.3, 1e-4, max_intervals=10)


def test_a_dimension_too_large_for_any_grid_says_so(monkeypatch):
    """Below 16 / 0.7 chords no resolution fits (the grid's longest step is T / 16): the error names
    d instead of suggesting a resolution that would fail again."""
    from qrrt_circuits.reachability import exact as oracle

    d = 1200
    with pytest.raises(ValueError, match=r"an exact check in d = 1200 needs at least 17 propagators"):
        oracle.chord_grid(qc.LinearTrackingDynamics(-np.eye(d), np.eye(d), np.zeros((d, d))), 2.0, 0.01,
                          oracle.max_chords(d))
