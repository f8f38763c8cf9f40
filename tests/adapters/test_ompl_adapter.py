"""The OMPL adapter (``qrrt_circuits.adapters.ompl``): protocol, planning on OMPL's motion checks,
every edge re-checked, bad constructions refused, and the install hint when OMPL is missing."""

import importlib
import json
import math
import sys

import numpy as np
import pytest

ob = pytest.importorskip("ompl.base")

from planner_checks import posed  # noqa: E402

import qrrt_circuits as qc  # noqa: E402
from qrrt_circuits.adapters.ompl import OMPLMotionPredicate, from_environment  # noqa: E402
from qrrt_circuits.reachability.predicate import check_predicate  # noqa: E402


def wall_world() -> qc.Environment:
    """[0, 10]^2 with a wall x in [4, 6] over the lower 8 units (free above y = 8)."""
    return qc.Environment(np.array([[0.0, 10.0], [0.0, 10.0]]), np.array([[[4.0, 0.0], [6.0, 8.0]]]),
                          name="wall")


def real_vector_si(dim: int, low: float = 0.0, high: float = 1.0) -> "ob.SpaceInformation":
    space = ob.RealVectorStateSpace(dim)
    bounds = ob.RealVectorBounds(dim)
    bounds.setLow(low)
    bounds.setHigh(high)
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(lambda state: True)
    return si


# ------------------------------------------------------------------------------------ (a) protocol
def test_satisfies_the_predicate_protocol(clutter):
    clutter = clutter.env
    predicate = from_environment(clutter)
    assert check_predicate(predicate, clutter.dim) is predicate
    assert isinstance(predicate, qc.ReachabilityPredicate)
    assert predicate.dim == 2 and predicate.name == "ompl"
    description = predicate.describe()
    json.dumps(description)
    assert "dynamics" not in description  # straight segments: plots draw edges straight
    assert description["sound"] is None
    assert description["bounds"] == clutter.bounds.tolist()
    assert description["motion_validator"] == "DiscreteMotionValidator"
    assert description["longest_valid_segment_fraction"] == pytest.approx(0.01)
    diagonal = float(np.linalg.norm(clutter.bounds[:, 1] - clutter.bounds[:, 0]))
    assert description["longest_valid_segment_length"] == pytest.approx(0.01 * diagonal)

    wrapped = OMPLMotionPredicate(real_vector_si(3), name="mine")  # set up here, not by the caller
    assert wrapped.si.isSetup() and check_predicate(wrapped, 3) is wrapped
    assert wrapped.describe()["name"] == "mine" and wrapped.describe()["bounds"] == [[0.0, 1.0]] * 3


def test_answers_are_ompl_check_motion_per_pair():
    env = wall_world()
    predicate = from_environment(env, resolution=0.005)
    parents = np.array([[1.0, 5.0], [1.0, 9.0], [1.0, 1.0], [1.0, 9.5]])
    children = np.array([[9.0, 5.0], [9.0, 9.0], [3.0, 7.0], [5.0, 5.0]])
    expected = [False, True, True, False]  # through the wall, above it, beside it, child inside it
    assert predicate.reachable(parents, children).tolist() == expected
    s1, s2 = predicate.si.allocState(), predicate.si.allocState()
    for (p, c), want in zip(zip(parents, children, strict=True), expected, strict=True):
        s1[0], s1[1], s2[0], s2[1] = (float(v) for v in (*p, *c))
        assert predicate.si.checkMotion(s1, s2) is want
    # one parent broadcast against several children; the counter counts pairs
    answers = predicate.reachable(np.array([1.0, 9.0]), children)  # (9, 5) is behind the wall
    assert answers.dtype == np.bool_ and answers.tolist() == [False, True, True, False]
    assert predicate.evaluations == 8
    with pytest.raises(ValueError, match="shape"):
        predicate.reachable(np.zeros((2, 3)), np.zeros((2, 3)))


# ------------------------------------------------------------------------------------ (b) planning
def assert_edges_free_up_to_ompl_resolution(env: qc.Environment, result, segment_length: float) -> int:
    """Re-check every tree edge as a straight segment sampled densely, and return how many samples
    were in collision.

    The tolerance, from OMPL's ``DiscreteMotionValidator::checkMotion(s1, s2)``: it tests the child
    s2 and the states s1 + (j / n)(s2 - s1), j = 1 .. n - 1, with n = ceil(|s2 - s1| / L) (L the
    longest valid segment length), and assumes the parent s1 valid (it is a tree node, so it was
    tested as a child, or it is the start). Consecutive tested states are at most L apart, so an
    accepted segment can cross an obstacle only between two tested free states: every point of it
    is within L / 2 of a tested free state. With samples h apart, a sample in collision therefore
    lies within L / 2 + h of a free sample (a tested state's free neighbourhood is open; we assume it
    holds a sample, i.e. that the free gap there is not thinner than h)."""
    nodes, parents = result.nodes, result.parents
    children = np.flatnonzero(parents >= 0)
    assert children.size == result.metrics.nodes
    collisions = 0
    for child in children:
        start, end = nodes[parents[child]], nodes[child]
        length = float(np.linalg.norm(end - start))
        count = max(400, math.ceil(20 * length / segment_length) + 1)
        along = np.linspace(0.0, 1.0, count)
        free = env.is_free(start + along[:, None] * (end - start))
        assert free[0] and free[-1], f"edge {parents[child]} -> {child}: an endpoint is in collision"
        blocked = np.flatnonzero(~free)
        if blocked.size:
            collisions += blocked.size
            step = length / (count - 1)
            distance = np.abs(along[blocked][:, None] - along[free][None, :]).min(axis=1) * length
            assert distance.max() <= segment_length / 2 + step + 1e-12, (
                f"edge {parents[child]} -> {child} is in collision {distance.max():.4f} from free space "
                f"along the segment, beyond OMPL's resolution L / 2 = {segment_length / 2:.4f}")
    return collisions


PLANNERS = {
    "rrt": lambda: qc.RRT(seed=0),
    "qrrt": lambda: qc.QRRT(backend=qc.StatevectorBackend(seed=0), num_qubits=6, seed=0),
    "pqrrt-shared-aer": lambda: qc.PQRRT(backend=qc.AerBackend(seed=0), workers=4, num_qubits=5,
                                         shared_database=True, seed=0),
}


@pytest.mark.parametrize("name", list(PLANNERS))
def test_planners_plan_on_ompl_checks_and_every_edge_rechecks(name, clutter):
    predicate = from_environment(clutter.env)
    result = PLANNERS[name]().plan(clutter.replace(predicate=predicate), max_nodes=15)
    assert str(result.status) in ("reached", "max_nodes")
    assert result.metrics.nodes >= 1
    assert result.settings["predicate"] == predicate.describe()
    assert result.settings["dynamics"] is None
    assert predicate.evaluations > 0
    segment_length = predicate.space.getLongestValidSegmentLength()
    assert segment_length == pytest.approx(predicate.describe()["longest_valid_segment_length"])
    assert_edges_free_up_to_ompl_resolution(clutter.env, result, segment_length)


# ------------------------------------------------------------------------------------ (c) refusals
def test_bad_constructions_are_refused_with_clear_messages():
    with pytest.raises(ValueError, match="RealVectorStateSpace.*SO2StateSpace"):
        OMPLMotionPredicate(ob.SpaceInformation(ob.SO2StateSpace()))
    with pytest.raises(TypeError, match="must be an ompl.base.SpaceInformation"):
        OMPLMotionPredicate(ob.RealVectorStateSpace(2))
    with pytest.raises(TypeError, match="must be an ompl.base.SpaceInformation"):
        OMPLMotionPredicate(wall_world())
    unbounded = ob.SpaceInformation(ob.RealVectorStateSpace(2))
    unbounded.setStateValidityChecker(lambda state: True)
    with pytest.raises(ValueError, match="bounds"):
        OMPLMotionPredicate(unbounded)
    with pytest.raises(TypeError, match="name"):
        OMPLMotionPredicate(real_vector_si(2), name="")
    with pytest.raises(ValueError, match="resolution"):
        from_environment(wall_world(), resolution=0.0)
    with pytest.raises(TypeError, match="Environment"):
        from_environment(np.zeros((2, 2)))
    with pytest.raises(ValueError, match="dimension mismatch"):
        qc.Problem.build(qc.Environment(np.array([[0.0, 1.0]] * 3), np.zeros((0, 2, 3))), [0.5] * 3, [0.6] * 3,
                         0.05, predicate=from_environment(wall_world()))


def test_import_without_ompl_names_the_extra(monkeypatch):
    for module in [m for m in sys.modules if m == "ompl" or m.startswith("ompl.")]:
        monkeypatch.setitem(sys.modules, module, None)  # None in sys.modules: import fails
    monkeypatch.setitem(sys.modules, "ompl", None)
    monkeypatch.delitem(sys.modules, "qrrt_circuits.adapters.ompl")
    with pytest.raises(ImportError, match=r'pip install "qrrt-circuits\[ompl\]"'):
        importlib.import_module("qrrt_circuits.adapters.ompl")


# ------------------------------------------------------------------- start, goal and bounds checks
def test_an_invalid_start_or_goal_under_ompls_validity_check_is_refused():
    """OMPL's own validity checker decides (here: a disc at (2, 2) invalid that the box world does
    not know), as OMPL refuses "no valid initial states"."""
    env = qc.Environment(np.array([[0.0, 10.0], [0.0, 10.0]]), np.zeros((0, 2, 2)))
    si = real_vector_si(2, 0.0, 10.0)
    si.setStateValidityChecker(lambda state: (state[0] - 2) ** 2 + (state[1] - 2) ** 2 > 0.25)
    predicate = OMPLMotionPredicate(si)
    assert predicate.is_valid(np.array([[2.0, 2.0], [5.0, 5.0], [11.0, 5.0]])).tolist() == [False, True, False]
    with pytest.raises(ValueError, match=r"start \[2.0, 2.0\] is not a valid state: the ompl check's own validity"):
        posed(env, start=[2, 2], goal=[9, 9], goal_radius=0.5, predicate=predicate)
    with pytest.raises(ValueError, match=r"goal \[2.0, 2.0\] is not a valid state"):
        posed(env, start=[8, 8], goal=[2, 2], goal_radius=0.5, predicate=predicate)
    result = qc.RRT(seed=0).plan(posed(env, start=[5, 5], goal=[9, 9], goal_radius=0.5, predicate=predicate),
                                 max_nodes=3)
    assert result.metrics.nodes >= 3


def test_an_environment_wider_than_ompls_space_is_refused():
    env = qc.Environment(np.array([[0.0, 20.0], [0.0, 20.0]]), np.zeros((0, 2, 2)))
    predicate = OMPLMotionPredicate(real_vector_si(2, 0.0, 10.0))
    with pytest.raises(ValueError, match=r"outside the ompl check's state space \[\[0.0, 10.0\], \[0.0, 10.0\]\]"):
        posed(env, start=[1, 1], goal=[9, 9], goal_radius=0.5, predicate=predicate)
