"""Reachability predicates: any object with the protocol plans with every planner and backend;
the built-in ones describe themselves; bad predicates are refused with the reason."""

import numpy as np
import pytest
from conftest import BACKENDS, make_backend
from planner_checks import posed
from reference import penetration_and_clearance

import qrrt_circuits as qc
from qrrt_circuits.plotting import edge_curves, plan_dynamics
from qrrt_circuits.reachability.predicate import check_predicate
from qrrt_circuits.registry import PLANNERS


class StraightLine:
    """A user's predicate (not a ExactCheck): straight-line motion, sampled every
    ``spacing`` along the segment, in any dimension."""

    name = "straight-line"

    def __init__(self, env, spacing=0.01):
        self.env = env
        self.spacing = spacing
        self.calls = 0

    @property
    def dim(self):
        return self.env.dim

    def describe(self):
        return {"name": self.name, "spacing": self.spacing}

    def reachable(self, parents, children):
        parents, children = np.atleast_2d(parents), np.atleast_2d(children)
        self.calls += len(children)
        steps = int(np.ceil(np.max(np.linalg.norm(children - parents, axis=1)) / self.spacing)) + 1
        t = np.linspace(0.0, 1.0, max(steps, 2))
        points = parents[:, None, :] + t[None, :, None] * (children - parents)[:, None, :]
        return self.env.is_free(points.reshape(-1, self.dim)).reshape(points.shape[:2]).all(axis=1)


def segment_depth(env, parent, child, spacing=0.001):
    """How deep the straight segment enters an obstacle, from a 10x denser independent sampling."""
    steps = int(np.ceil(np.linalg.norm(child - parent) / spacing)) + 2
    t = np.linspace(0.0, 1.0, steps)[:, None]
    depth, _ = penetration_and_clearance(parent + t * (child - parent), env.bounds, env.boxes)
    return depth


@pytest.mark.parametrize("backend_name", BACKENDS)
@pytest.mark.parametrize("planner_name", list(PLANNERS))
def test_a_user_predicate_plans_with_every_planner_and_backend(planner_name, backend_name, clutter):
    predicate = StraightLine(clutter.env)
    options = {"seed": 4, "workers": 3, "num_qubits": 6, "backend": make_backend(backend_name, 4)}
    takes = PLANNERS.resolve(planner_name).options()
    planner = PLANNERS.create(planner_name, **{key: value for key, value in options.items() if key in takes})
    result = planner.plan(clutter.replace(predicate=predicate), max_nodes=15)
    assert result.metrics.nodes >= 15 and result.settings["predicate"] == predicate.describe()
    assert result.settings["dynamics"] is None and plan_dynamics(result) is None
    # classical planners evaluate the predicate once per test (plus the tests they made ahead for
    # rounds that never ran, wasted_checks); quantum ones once per database entry
    # (simulation_checks), their verifications reading those evaluations
    quantum = "quantum" in PLANNERS.resolve(planner_name).tags
    classical = result.metrics.verification_calls + result.metrics.wasted_checks
    assert predicate.calls == (result.metrics.simulation_checks if quantum else classical)
    assert quantum or result.metrics.wasted_checks > 0  # the batches did run ahead
    children = np.arange(1, len(result.nodes))
    parents = result.parents[children]
    # every edge re-checked with the plan's own predicate and with a denser independent check
    assert predicate.reachable(result.nodes[parents], result.nodes[children]).all()
    # the predicate samples every 0.01, so an edge may clip a corner by less than that, never more
    for child, parent in zip(children, parents, strict=True):
        assert segment_depth(clutter.env, result.nodes[parent], result.nodes[child]) <= predicate.spacing


def test_a_user_predicate_in_three_dimensions():
    rng = np.random.default_rng(0)
    lower = rng.uniform(0, 9, size=(40, 3))
    env = qc.Environment(np.array([[0, 10]] * 3, dtype=float), np.stack([lower, lower + 0.8], axis=1))
    start, goal = env.sample_free(2, rng)
    result = qc.QRRT(backend=qc.StatevectorBackend(0), num_qubits=6, seed=0).plan(
        posed(env, start=start, goal=goal, goal_radius=1.0, predicate=StraightLine(env)), max_nodes=25)
    assert result.nodes.shape[1] == 3 and result.metrics.nodes >= 1
    curves = edge_curves(result.nodes, result.parents, None, samples=5)
    # straight edges: the middle sample is the midpoint of parent and child
    child = 1
    middle = (result.nodes[child] + result.nodes[result.parents[child]]) / 2
    assert np.allclose(curves[0, 2], middle)


def test_builtin_predicates_describe_themselves(clutter):
    exact = qc.ExactCheck(clutter.env)
    assert check_predicate(exact, 2) is exact
    description = exact.describe()
    assert description["name"] == "exact" and description["resolution"] == 0.01 and description["sound"]
    assert qc.LinearTrackingDynamics.from_description(description["dynamics"]).describe() == \
        qc.LinearTrackingDynamics.paper().describe()
    sampled = qc.TimeSampledCheck(clutter.env, time_samples=30)
    assert sampled.describe()["sound"] is False and sampled.describe()["time_samples"] == 30
    assert isinstance(sampled, qc.ReachabilityPredicate)


def test_planner_records_the_dynamics_its_predicate_follows(clutter):
    dynamics = qc.LinearTrackingDynamics(np.diag([-1.0, -2.0]), np.eye(2), np.zeros((2, 2)))
    problem = qc.Problem.build(clutter.env, clutter.start, clutter.goal, dynamics=dynamics)
    result = qc.RRT(seed=0).plan(problem, max_nodes=3)
    assert plan_dynamics(result).describe() == dynamics.describe()


class NoName:
    dim = 2

    def reachable(self, parents, children):
        return np.ones(len(children), bool)


def test_bad_predicates_are_refused_with_the_reason(clutter):
    with pytest.raises(TypeError, match="lacks name, describe"):
        clutter.replace(predicate=NoName())
    env3 = qc.Environment(np.array([[0, 1]] * 3, dtype=float), np.zeros((0, 2, 3)))
    with pytest.raises(ValueError, match="dimension mismatch: the predicate works in d = 3"):
        clutter.replace(predicate=StraightLine(env3))
    with pytest.raises(ValueError, match="give dynamics= or predicate=, not both"):
        qc.Problem.build(clutter.env, clutter.start, clutter.goal, predicate=StraightLine(clutter.env),
                         dynamics=qc.LinearTrackingDynamics.paper())

    class WordyDescription(StraightLine):
        def describe(self):
            return "a straight line"

    with pytest.raises(TypeError, match=r"predicate.describe\(\) must return a dict"):  # before any plan
        clutter.replace(predicate=WordyDescription(clutter.env))


@pytest.mark.parametrize("time_samples", [7, 30])
def test_time_sampled_check_in_chunks_answers_as_in_one_piece(clutter, time_samples, monkeypatch):
    from qrrt_circuits.reachability import time_sampled

    rng = np.random.default_rng(3)
    parents, children = clutter.env.sample_free(301, rng), clutter.env.sample_uniform(301, rng)
    whole = qc.TimeSampledCheck(clutter.env, time_samples=time_samples).reachable(parents, children)
    monkeypatch.setattr(time_sampled, "CHUNK_COORDINATES", 2 * (3 * time_samples + 1))  # 3 pairs a chunk, a remainder
    chunked = qc.TimeSampledCheck(clutter.env, time_samples=time_samples)
    assert np.array_equal(chunked.reachable(parents, children), whole)
    assert chunked.evaluations == 301 and 0 < whole.sum() < 301


def test_time_sampled_check_memory_does_not_grow_with_pairs_times_samples(clutter):
    """128 pairs x 100 000 samples: 205 MB for the sample points in one piece; in chunks a few tens."""
    import tracemalloc

    rng = np.random.default_rng(4)
    parents, children = clutter.env.sample_free(128, rng), clutter.env.sample_uniform(128, rng)
    check = qc.TimeSampledCheck(clutter.env, time_samples=100_000)
    tracemalloc.start()
    try:
        check.reachable(parents, children)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 100 * 2**20, peak


def test_time_sampled_check_refuses_propagators_that_do_not_fit():
    d = 64
    env = qc.Environment([[0.0, 1.0]] * d, [])
    dynamics = qc.LinearTrackingDynamics(-np.eye(d), np.eye(d), np.zeros((d, d)))
    message = r"time_samples = 1000000 in d = 64 needs 31250 MiB.*at most 8192 time samples"
    with pytest.raises(ValueError, match=message):
        qc.TimeSampledCheck(env, dynamics, time_samples=1_000_000)
    assert qc.TimeSampledCheck(env, dynamics, time_samples=8192).time_samples == 8192


def test_a_user_predicates_own_validity_and_space_are_respected():
    """Optional members: ``is_valid`` refuses a start or goal, ``bounds()`` an environment that
    reaches outside the predicate's space; without them nothing changes."""
    import qrrt_circuits as qc

    class Disc:
        dim, name = 2, "disc"

        def reachable(self, parents, children):
            return np.ones(len(np.atleast_2d(children)), dtype=bool)

        def describe(self):
            return {}

        def is_valid(self, points):
            return np.linalg.norm(points - np.array([3.0, 3.0]), axis=1) > 1.0

        def bounds(self):
            return np.array([[0.0, 10.0], [0.0, 10.0]])

    env = qc.Environment(np.array([[0.0, 10.0], [0.0, 10.0]]), np.zeros((0, 2, 2)))
    with pytest.raises(ValueError, match=r"start \[3.0, 3.5\] is not a valid state: the disc check"):
        posed(env, start=[3, 3.5], goal=[9, 9], goal_radius=0.5, predicate=Disc())
    problem = posed(env, start=[6, 6], goal=[9, 9], goal_radius=0.5, predicate=Disc())
    assert qc.RRT(seed=0).plan(problem, max_nodes=2).metrics.nodes == 2
    wide = qc.Environment(np.array([[0.0, 12.0], [0.0, 10.0]]), np.zeros((0, 2, 2)))
    with pytest.raises(ValueError, match=r"reach outside the disc check's state space"):
        posed(wide, start=[6, 6], goal=[9, 9], goal_radius=0.5, predicate=Disc())

    class Miscounting(Disc):
        def is_valid(self, points):
            return np.ones(len(points) + 1, dtype=bool)

    with pytest.raises(ValueError, match="disc.is_valid must return 1 booleans for 1 points"):
        posed(env, start=[6, 6], goal=[9, 9], goal_radius=0.5, predicate=Miscounting())
