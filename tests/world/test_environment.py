import json
import math

import numpy as np
import pytest
from planner_checks import posed
from tolerances import z_bound

import qrrt_circuits as qc
from qrrt_circuits.problems import scenarios
from qrrt_circuits.problems.families import box_world, save_box_world
from qrrt_circuits.world.environment import Environment


def test_is_free_matches_brute_force(clutter_world):
    rng = np.random.default_rng(123)
    points = clutter_world.sample_uniform(3000, rng)
    lo, hi = clutter_world.boxes[:, 0], clutter_world.boxes[:, 1]
    inside = np.any(np.all((points[:, None] >= lo) & (points[:, None] <= hi), axis=2), axis=1)
    assert np.array_equal(clutter_world.is_free(points), ~inside)


def test_is_free_keeps_leading_shape_and_rejects_out_of_bounds(clutter_world):
    points = np.zeros((3, 4, 2)) - 1.0
    assert clutter_world.is_free(points).shape == (3, 4)
    assert not clutter_world.is_free(points).any()


def test_box_boundary_is_in_collision():
    env = Environment(np.array([[0, 10], [0, 10]]), np.array([[[2, 2], [4, 4]]]))
    assert not env.is_free(np.array([4.0, 3.0]))
    assert env.is_free(np.array([4.0 + 1e-9, 3.0]))


def test_sample_free_is_free_and_seeded(clutter_world):
    a = clutter_world.sample_free(500, np.random.default_rng(5))
    b = clutter_world.sample_free(500, np.random.default_rng(5))
    assert a.shape == (500, 2)
    assert clutter_world.is_free(a).all()
    assert np.array_equal(a, b)


def test_json_round_trip(tmp_path, clutter):
    path = clutter.env.save(tmp_path / "world.json")
    loaded = Environment.load(path)
    assert np.array_equal(loaded.bounds, clutter.env.bounds)
    assert np.array_equal(loaded.boxes, clutter.env.boxes)
    assert loaded.name == "paper_clutter" and loaded.metadata["num_boxes"] == clutter.env.metadata["num_boxes"]
    scenario = save_box_world(clutter, tmp_path / "scenario.json")  # the geometry with start and goal
    problem = box_world(scenario)
    assert np.array_equal(problem.start, clutter.start) and problem.goal.radius == clutter.goal.radius
    assert np.array_equal(problem.env.boxes, clutter.env.boxes)
    assert np.array_equal(Environment.load(scenario).boxes, clutter.env.boxes)


def _write(tmp_path, data):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    return path


@pytest.mark.parametrize(
    "patch, message",
    [
        ({"boxes": [[[3, 3], [1, 4]]]}, r"boxes\[0\]: lower corner must be <= upper"),
        ({"bounds": [[0, 10], [5, 1]]}, r"bounds\[1\]: low must be < high"),
        ({"bounds": [[0, float("nan")], [0, 1]]}, "finite"),
        ({"boxes": [[[0, float("nan")], [1, 1]]]}, "finite"),
        ({"format": "other"}, "'format' must be"),
        ({"boxes": [[[0, 0, 0], [1, 1, 1]]]}, r"boxes must have shape \(k, 2, 2\)"),
        ({"bounds": [["0", "10"], [0, 10]]}, "bounds must hold real numbers, got '"),
        ({"bounds": [[False, True], [0, 10]]}, "bounds must hold real numbers, got (True|False)"),
        ({"boxes": [[[1, 1], [2, "2"]]]}, "boxes must hold real numbers"),
        ({"version": True}, "'version' must be 1, got True"),
    ],
)
def test_bad_scenario_files_are_rejected(tmp_path, patch, message):
    data = Environment(np.array([[0, 10], [0, 10]]), np.zeros((0, 2, 2))).to_dict()
    data.update(patch)
    with pytest.raises(ValueError, match=message):
        Environment.load(_write(tmp_path, data))


def test_deeply_nested_json_is_rejected_without_a_recursion_error(tmp_path):
    path = tmp_path / "deep.json"
    path.write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(ValueError, match="nested too deeply"):
        Environment.load(path)


@pytest.mark.parametrize("value", [[[0, 10], [0, True]], np.array([[0, 10], [0, 1]], dtype=bool),
                                   [[0, 10], [0, "1"]], np.array([["0", "1"], ["0", "1"]]),
                                   [[0, 10], [0, np.bool_(True)]]])
def test_bounds_refuse_booleans_and_strings_that_numpy_would_read_as_numbers(value):
    with pytest.raises(ValueError, match="bounds must hold real numbers"):
        Environment(value, [])


def test_integer_and_float_arrays_of_any_width_are_accepted():
    env = Environment(np.array([[0, 10], [0, 10]], dtype=np.int32), [[[1, 1], [2.5, 2.5]]])
    problem = qc.Problem.build(env, np.array([0.5, 0.5], dtype=np.float32), (9, 9), 1)
    assert env.bounds.dtype == float and env.boxes.tolist() == [[[1.0, 1.0], [2.5, 2.5]]]
    assert problem.start.dtype == float and problem.goal.radius == 1.0


@pytest.mark.parametrize("start", [[True, True], ["1", "1.5"], np.array([1, 1], dtype=bool)])
def test_a_problem_refuses_a_start_of_booleans_or_strings(clutter, start):
    with pytest.raises(ValueError, match="start must be 2 numbers"):
        posed(clutter, start=start)


def test_not_json_is_rejected(tmp_path):
    path = tmp_path / "x.json"
    path.write_text("{not json")
    with pytest.raises(ValueError, match="not valid JSON"):
        Environment.load(path)


def test_higher_dimension_environment():
    env = Environment(np.array([[0, 1]] * 4), np.array([[[0.2] * 4, [0.4] * 4]]))
    assert env.dim == 4
    assert not env.is_free(np.full(4, 0.3))
    assert env.is_free(np.full(4, 0.5))


def test_paper_clutter_matches_design():
    problem = qc.paper_clutter(seed=3)
    env = problem.env
    sides = env.boxes[:, 1] - env.boxes[:, 0]
    assert env.num_boxes == 525
    assert np.all((sides >= 0.25) & (sides <= 0.85))
    assert np.all(env.boxes[:, 0] >= 0) and np.all(env.boxes[:, 1] <= 20)
    assert env.is_free(problem.start) and env.is_free(problem.goal.centre)
    assert problem.goal.radius == 0.75 and problem.predicate.name == "exact"
    assert 0.6 < env.free_fraction() < 0.75


def test_scenarios_are_seeded():
    for name in scenarios.SCENARIOS:
        a = scenarios.by_name(name, seed=7)
        b = scenarios.by_name(name, seed=7)
        c = scenarios.by_name(name, seed=8)
        assert np.array_equal(a.env.boxes, b.env.boxes) and np.array_equal(a.start, b.start)
        assert not np.array_equal(a.env.boxes, c.env.boxes)


def test_annealing_field_matches_clutter_density():
    field = qc.annealing_field(seed=0).env
    clutter = qc.paper_clutter(seed=0).env
    assert field.num_boxes == 6025
    assert 67 < field.bounds[0, 1] < 69
    # the two worlds draw boxes from one distribution at one expected density; their free fractions
    # differ by the box-count noise of each world (a box's area s1*s2, s ~ U(0.25, 0.85), has
    # relative sd 0.456) and the Monte Carlo noise of free_fraction (20000 samples each)
    density = 525 * 0.3025 / 400
    world_sd = [density * 0.456 / math.sqrt(count) for count in (525, 6025)]
    f1, f2 = field.free_fraction(), clutter.free_fraction()
    sampling = [f * (1 - f) / 20000 for f in (f1, f2)]
    assert abs(f1 - f2) <= z_bound() * math.sqrt(sum(sd**2 for sd in world_sd) + sum(sampling))


def test_annealing_field_side_sets_the_density():
    default = qc.annealing_field(seed=2).env
    same = qc.annealing_field(seed=2, side=float(default.bounds[0, 1])).env
    assert np.array_equal(default.boxes, same.boxes) and "side" not in default.metadata
    dense = qc.annealing_field(seed=2, side=40.0).env
    assert dense.num_boxes == 6025 and dense.bounds[0, 1] == 40.0 and dense.metadata["side"] == 40.0
    assert dense.free_fraction() < default.free_fraction()
    with pytest.raises(ValueError, match="side must be"):
        qc.annealing_field(seed=2, side=1.7)
    with pytest.raises(TypeError, match="side must be a real number"):
        qc.annealing_field(seed=2, side="40")


def test_narrow_corridor_channel():
    problem = qc.narrow_corridor(seed=1)
    env = problem.env
    (x0, y0), (x1, y1) = env.metadata["channel"]
    assert y1 - y0 == pytest.approx(0.4) and x1 - x0 == pytest.approx(4.0)
    xs = np.linspace(x0 - 0.5, x1 + 0.5, 200)
    assert env.is_free(np.stack([xs, np.full_like(xs, (y0 + y1) / 2)], axis=1)).all()
    # the channel is the only way through the wall
    ys = np.linspace(0, 20, 2001)
    wall = env.is_free(np.stack([np.full_like(ys, 10.0), ys], axis=1))
    assert np.all(wall == ((ys > y0) & (ys < y1)))
    assert problem.start[0] < x0 and problem.goal.centre[0] > x1



@pytest.mark.parametrize(("width", "length"), [(0.4, 4.0), (1.0, 2.0), (2.0, 8.0)])
def test_narrow_corridor_geometry_sets_the_channel(width, length):
    env = qc.narrow_corridor(seed=0, width=width, length=length, clutter=0).env
    (x0, y0), (x1, y1) = env.metadata["channel"]
    assert (x1 - x0, y1 - y0) == (pytest.approx(length), pytest.approx(width))
    assert (x0 + x1) / 2 == pytest.approx(10.0) and (y0 + y1) / 2 == pytest.approx(10.0)
    # without clutter the free space is the square less the two blocks: 1 - length * (20 - width) / 400
    free = 1 - length * (20 - width) / 400
    assert abs(env.free_fraction() - free) <= z_bound() * math.sqrt(free * (1 - free) / 20000)
    # the wall is closed except across the channel's width, over the channel's whole length
    ys = np.linspace(0.0, 20.0, 4001)
    for x in np.linspace(x0 + 1e-6, x1 - 1e-6, 5):
        free = env.is_free(np.stack([np.full_like(ys, x), ys], axis=1))
        assert np.all(free == ((ys > y0) & (ys < y1)))
    outside = np.stack([np.full_like(ys, x0 - 0.2), ys], axis=1)  # beside the wall: open (no clutter)
    assert env.is_free(outside[1:-1]).all()


def test_narrow_corridor_clutter_count_and_defaults():
    for clutter in (0, 60, 240):
        env = qc.narrow_corridor(seed=3, clutter=clutter).env
        assert env.num_boxes == 2 + clutter and env.metadata["clutter"] == clutter
    default = qc.narrow_corridor(seed=0)  # the corridor experiment's world
    explicit = qc.narrow_corridor(seed=0, width=0.4, length=4.0, clutter=120, mouth_clearance=1.5)
    assert np.array_equal(default.env.boxes, explicit.env.boxes) and np.array_equal(default.start, explicit.start)
    assert default.env.metadata["channel"] == [[8.0, 9.8], [12.0, 10.2]]


@pytest.mark.parametrize(("options", "error", "match"), [
    ({"width": 0.0}, ValueError, "width must be in"), ({"width": 10.0}, ValueError, "width must be in"),
    ({"width": float("nan")}, ValueError, "width"), ({"width": "wide"}, TypeError, "width"),
    ({"length": -1.0}, ValueError, "length must be in"), ({"length": 12.0}, ValueError, r"length must be in \(0, 12\)"),
    ({"length": float("inf")}, ValueError, "length"), ({"length": True}, TypeError, "length"),
    ({"clutter": -1}, ValueError, "clutter"), ({"clutter": 10_001}, ValueError, "clutter"),
    ({"clutter": 1.5}, TypeError, "clutter"), ({"mouth_clearance": 5.5}, ValueError, "mouth_clearance"),
])
def test_narrow_corridor_refuses_bad_geometry(options, error, match):
    with pytest.raises(error, match=match):
        qc.narrow_corridor(seed=0, **options)


def test_narrow_corridor_says_when_clutter_has_no_room():
    # a channel 9.9 wide with clearance 5 leaves no place for a box off the wall and the mouths
    with pytest.raises(RuntimeError, match="could not place 1 clutter boxes"):
        qc.narrow_corridor(seed=0, width=9.9, length=11.0, clutter=1, mouth_clearance=5.0)

def test_lattice_start_goal_connected():
    from scipy import ndimage

    problem = qc.lattice(seed=2, size=30)
    cells = np.stack(np.meshgrid(np.arange(30) + 0.5, np.arange(30) + 0.5, indexing="ij"), -1)
    free = problem.env.is_free(cells)
    labels, _ = ndimage.label(free)
    s = labels[int(problem.start[0]), int(problem.start[1])]
    goal = problem.goal.centre
    assert s > 0 and s == labels[int(goal[0]), int(goal[1])]
    assert abs(free.mean() - 0.5) < 0.01


def test_bad_scenario_arguments():
    with pytest.raises(ValueError, match="seed"):
        qc.paper_clutter(seed=-1)
    with pytest.raises(ValueError, match="blocked_fraction"):
        qc.lattice(blocked_fraction=1.5)
    with pytest.raises(ValueError, match="unknown scenario"):
        scenarios.by_name("nope")


def test_box_points_and_sample_uniform_are_numpys_expression():
    """low + (high - low) u, bit for bit, for a strided view and in d = 5 (the planners' samples
    depend on these exact bits: the keyed streams' contract)."""
    env = Environment(np.array([[-3.5, 2.25], [0.1, 7.0], [-1e3, 1e-3], [5.0, 5.5], [0.0, 1.0]]), np.zeros((0, 2, 5)))
    low, high = env.bounds[:, 0], env.bounds[:, 1]
    unit = np.random.default_rng(4).random((40, 6))[:, 1:]  # not contiguous
    assert np.array_equal(env.box_points(unit), low + (high - low) * unit)
    drawn = env.sample_uniform(40, np.random.default_rng(8))
    assert np.array_equal(drawn, low + (high - low) * np.random.default_rng(8).random((40, 5)))
    for bad in (np.zeros((3, 4)), np.zeros(5), np.zeros((2, 3, 5))):
        with pytest.raises(ValueError, match=r"unit must have shape \(M, 5\)"):
            env.box_points(bad)
