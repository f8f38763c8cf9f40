"""Problem families and problem files: each builds, plans, and refuses bad input by field."""

from __future__ import annotations

import json

import numpy as np
import pytest

import qrrt_circuits as qc
from qrrt_circuits.problems.families import (
    load_problem,
    narrow_passage,
    open_space,
    se2_gap,
    straight_line_dynamics,
    winding_band,
)


def test_straight_line_motions_follow_the_segment():
    dynamics = straight_line_dynamics(3)
    parent, child = np.zeros(3), np.array([1.0, 2.0, 3.0])
    points = dynamics.positions(parent, child, np.linspace(0, dynamics.horizon, 50))
    offsets = points - parent
    assert np.allclose(np.cross(offsets, child), 0.0, atol=1e-12)  # on the line
    assert np.linalg.norm(points[-1] - child) < 1e-8


@pytest.mark.parametrize("dim", [2, 3, 4, 6])
def test_the_narrow_passage_is_open_only_through_its_hole(dim):
    problem = narrow_passage(dim, width=0.5)
    env, check = problem.env, problem.predicate
    through = np.full(dim, 5.0)
    beside = through.copy()
    beside[1] = 5.3  # just outside the hole on axis 1
    assert env.is_free(through) and not env.is_free(beside)
    left, right = np.full(dim, 5.0), np.full(dim, 5.0)
    left[0], right[0] = 3.0, 7.0
    assert check.reachable(left[None], right[None])[0]
    left[1] = right[1] = 5.3
    assert not check.reachable(left[None], right[None])[0]


@pytest.mark.parametrize("make", [open_space, lambda: narrow_passage(2, 1.0), lambda: narrow_passage(3, 1.5)])
def test_families_are_solved_by_rrt_and_q_rrt(make):
    problem = make()
    for planner in (qc.RRT(seed=0, goal_bias=0.05, max_extension=2.0),
                    qc.QRRT(backend=qc.StatevectorBackend(seed=0), num_qubits=6, seed=0, goal_bias=0.05,
                            max_extension=2.0, search_policy=qc.Adaptive())):
        result = planner.plan(problem, max_oracle_calls=30000)
        assert result.reached, (problem.name, planner.name)
        assert problem.predicate.reachable(result.nodes[result.parents[1:]], result.nodes[1:]).all()


def test_the_se2_gap_problem_plans_in_se2():
    problem = se2_gap()
    assert problem.space.describe()["kind"] == "SE2" and problem.env.dim == 3
    result = qc.RRT(seed=1, max_extension=1.0).plan(problem, max_oracle_calls=20000)
    assert result.reached and problem.predicate.reachable(result.nodes[result.parents[1:]], result.nodes[1:]).all()


def _write(tmp_path, **fields):
    path = tmp_path / "problem.json"
    path.write_text(json.dumps({"format": "qrrt-problem", "version": 1} | fields))
    return path


def test_problem_files_build_their_family(tmp_path):
    problem = load_problem(_write(tmp_path, family="narrow-passage", dim=3, width=1.0))
    assert problem.name == "narrow-passage-3d" and problem.env.dim == 3
    scenario = tmp_path / "world.json"
    scenario.write_text(json.dumps({"format": "qrrt-environment", "version": 1, "bounds": [[0, 20], [0, 20]],
                                    "boxes": [], "start": [1, 1], "goal": [19, 19], "goal_radius": 0.75}))
    boxes = load_problem(_write(tmp_path, family="boxes", scenario="world.json"))
    assert boxes.env.bounds.tolist() == [[0.0, 20.0], [0.0, 20.0]]


@pytest.mark.parametrize(("fields", "message"), [
    ({"family": "labyrinth"},
     r"\"family\" must be one of \['boxes', 'image', 'maze', 'narrow-passage', 'open-space', 'se2-gap', "
     r"'winding-band'\]"),
    ({"family": "winding-band", "width": 2.0}, "width"),
    ({"family": "narrow-passage", "dim": 9}, "dim must be an integer in"),
    ({"family": "narrow-passage", "width": 0}, "width must be a finite number"),
    ({"family": "narrow-passage", "depth": 1}, r"takes \['dim', 'width'\], not \['depth'\]"),
    ({"family": "se2-gap", "width": "wide"}, "width"),
    ({"family": "boxes"}, 'family "boxes" takes one field, "scenario"'),
    ({"family": "open-space", "version": 2}, '"version" must be 1'),
])
def test_bad_problem_files_name_the_field(tmp_path, fields, message):
    with pytest.raises(ValueError, match=message):
        load_problem(_write(tmp_path, **fields))


def test_unreadable_problem_files_are_refused(tmp_path):
    with pytest.raises(ValueError, match="no such file"):
        load_problem(tmp_path / "missing.json")
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(ValueError, match="is not valid JSON"):
        load_problem(bad)
    other = tmp_path / "other.json"
    other.write_text(json.dumps({"format": "qrrt-environment"}))
    with pytest.raises(ValueError, match='"format" must be "qrrt-problem"'):
        load_problem(other)


def test_qrrt_plan_takes_a_problem_file(tmp_path, capsys):
    from qrrt_circuits.cli import main

    path = _write(tmp_path, family="narrow-passage", dim=2, width=1.0)
    assert main(["plan", "--problem", str(path), "--planner", "qrrt", "--backend", "statevector", "--qubits", "5",
                 "--policy", "adaptive", "--goal-bias", "0.05", "--max-extension", "2", "--max-oracle-calls",
                 "20000"]) == 0
    out = capsys.readouterr().out
    assert "QRRT on narrow-passage-2d" in out and "reached: reached the goal" in out and "beside RRT" in out


@pytest.mark.parametrize(("extra", "message"), [
    (["--scenario-file", "world.json"], "--problem fixes the world and the motion check: leave out --scenario-file"),
    (["--predicate", "authors"], "leave out --predicate"),
    (["--scenario", "narrow_corridor"], "leave out --scenario"),
])
def test_qrrt_plan_refuses_a_problem_beside_what_it_fixes(tmp_path, capsys, extra, message):
    from qrrt_circuits.cli import main

    path = _write(tmp_path, family="open-space")
    with pytest.raises(SystemExit) as exit_info:
        main(["plan", "--problem", str(path), *extra])
    assert exit_info.value.code == 2 and message in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["plan", "--problem", str(tmp_path)])
    assert "is a folder, not a problem file" in capsys.readouterr().err


def test_an_image_problem_file_plans_on_its_grid(tmp_path):
    import matplotlib.pyplot as plt

    pixels = np.ones((20, 20))
    pixels[:, 9:11] = 0.0  # a black wall ...
    pixels[8:12, 9:11] = 1.0  # ... with a door in the middle
    plt.imsave(tmp_path / "door.png", pixels, cmap="gray", vmin=0, vmax=1)
    path = _write(tmp_path, family="image", image="door.png", pixel_size=0.5, start=[1, 5], goal=[9, 5],
                  goal_radius=0.5)
    problem = load_problem(path)
    assert problem.env.bounds.tolist() == [[0.0, 10.0], [0.0, 10.0]]
    result = qc.RRT(seed=0, goal_bias=0.05).plan(problem, max_oracle_calls=20000)
    assert result.reached and problem.predicate.reachable(result.nodes[result.parents[1:]], result.nodes[1:]).all()
    with pytest.raises(ValueError, match='family "image" needs'):
        load_problem(_write(tmp_path, family="image", image="door.png"))
    walled = _write(tmp_path, family="image", image="door.png", pixel_size=0.5, start=[5, 1], goal=[9, 5],
                    goal_radius=0.5)
    with pytest.raises(ValueError, match=r"start \[5.0, 1.0\] is not a free point of the map: it lies in or on "
                                         r"the boundary of the occupied image pixel \(row 18, col 9\)"):
        load_problem(walled)  # refused as it is read, before any planner is built


@pytest.mark.parametrize("cells,seed", [(2, 0), (4, 3), (7, 11)])
def test_mazes_are_perfect_and_seeded(cells, seed):
    from qrrt_circuits.world.maze import maze_grid

    grid = maze_grid(cells, seed)
    free = grid.free
    assert free.shape == (2 * cells + 1, 2 * cells + 1)
    assert not free[0].any() and not free[-1].any() and not free[:, 0].any() and not free[:, -1].any()
    # a perfect maze is a spanning tree of the rooms: rooms + openings = 2 rooms - 1 free pixels,
    # and every free pixel is connected to room (0, 0)
    assert int(free.sum()) == 2 * cells * cells - 1
    seen, stack = {(2 * cells - 1, 1)}, [(2 * cells - 1, 1)]
    while stack:
        r, c = stack.pop()
        for nr, nc in ((r + 1, c), (r - 1, c), (r, c + 1), (r, c - 1)):
            if free[nr, nc] and (nr, nc) not in seen:
                seen.add((nr, nc))
                stack.append((nr, nc))
    assert len(seen) == int(free.sum())
    assert np.array_equal(maze_grid(cells, seed).free, free)
    assert any(not np.array_equal(maze_grid(cells, other).free, free) for other in range(seed + 1, seed + 6))


@pytest.mark.parametrize("arguments,message", [({"cells": 1}, "cells"), ({"cells": 40000}, "MAX_SIDE|at most"),
                                               ({"seed": -1}, "seed"), ({"pixel_size": 0.0}, "pixel_size"),
                                               ({"corridor": 0}, "corridor")])
def test_bad_maze_arguments_are_refused_by_name(arguments, message):
    from qrrt_circuits.world.maze import maze_grid

    with pytest.raises(ValueError, match=message):
        maze_grid(**({"cells": 3, "seed": 0} | arguments))


def test_the_maze_problem_is_solved_through_its_corridors():
    from qrrt_circuits.problems.families import maze

    problem = maze(4, seed=2)
    assert problem.env.bounds.tolist() == [[0.0, 10.0], [0.0, 10.0]]
    for planner in (qc.RRT(seed=0, goal_bias=0.05),
                    qc.QRRT(backend=qc.StatevectorBackend(seed=0), seed=0, goal_bias=0.05,
                            search_policy=qc.Adaptive())):
        result = planner.plan(problem, max_oracle_calls=20000)
        assert result.reached
        assert problem.predicate.reachable(result.nodes[result.parents[1:]], result.nodes[1:]).all()
    assert load_problem(_write_maze(problem)).env.metadata == problem.env.metadata


def _write_maze(problem):
    import tempfile
    from pathlib import Path

    path = Path(tempfile.mkdtemp()) / "maze.json"
    path.write_text(json.dumps({"format": "qrrt-problem", "version": 1, "family": "maze", "cells": 4, "seed": 2}))
    return path


def test_the_shortcut_keeps_checked_motions_and_never_lengthens():
    from qrrt_circuits.planners.paths import path_length, shortcut

    problem = narrow_passage(2, 0.5)
    result = qc.RRT(seed=3, goal_bias=0.05, max_extension=1.0).plan(problem, max_oracle_calls=20000)
    assert result.reached
    short = shortcut(result.path, problem.predicate)
    assert np.array_equal(short[0], result.path[0]) and np.array_equal(short[-1], result.path[-1])
    assert problem.predicate.reachable(short[:-1], short[1:]).all()
    assert path_length(short) <= path_length(result.path) + 1e-12
    assert len(short) < len(result.path)  # 1-unit steps across 8 units of free space shorten
    straight = np.array([[1.0, 1.0], [2.0, 1.0], [3.0, 1.0]])  # collinear in free space: one motion
    assert shortcut(straight, open_space().predicate).tolist() == [[1.0, 1.0], [3.0, 1.0]]
    assert path_length(straight) == pytest.approx(2.0)


def test_rigid_body_checks_are_counted():
    problem = se2_gap()
    problem.predicate.reachable(np.array([[2.0, 2.0, 0.0]] * 3), np.array([[2.5, 2.0, 0.0]] * 3))
    assert problem.predicate.evaluations == 3




@pytest.mark.parametrize("dim", [2, 4, 6])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_winding_band_is_open_only_along_its_legs(dim, seed):
    problem = winding_band(dim, 0.1, seed)
    env, check = problem.env, problem.predicate
    start, goal = problem.start.copy(), problem.goal.centre
    assert env.is_free(start) and env.is_free(goal)
    assert not check.reachable(start[None], goal[None])[0]  # the straight motion meets the wall
    off = start.copy()
    off[1] += 0.1  # beside the first leg
    assert not env.is_free(off)
    along = start.copy()
    along[0] += 1.0  # along the first leg
    assert check.reachable(start[None], along[None])[0]
    if dim > 2:  # every other axis is free
        lifted = start.copy()
        lifted[2:] = 9.5
        assert env.is_free(lifted) and check.reachable(start[None], lifted[None])[0]


def test_winding_bands_differ_by_seed_and_repeat_by_seed():
    first, again, other = (winding_band(2, 0.2, s) for s in (3, 3, 4))
    assert np.array_equal(first.env.boxes, again.env.boxes)
    assert not (np.array_equal(first.env.boxes, other.env.boxes)
                and np.array_equal(first.goal.centre, other.goal.centre))


def test_the_winding_band_is_solved_by_q_rrt_within_a_budget():
    """5 bands of width 0.2 (2-D): q-RRT under Adaptive solves at least 4 within 20 000 oracle calls,
    and every tree edge passes the check again."""
    solved = 0
    for seed in range(5):
        problem = winding_band(2, 0.2, seed)
        planner = qc.QRRT(backend=qc.StatevectorBackend(seed=seed), num_qubits=8, seed=seed,
                          goal_bias=0.05, search_policy=qc.Adaptive())
        result = planner.plan(problem, max_oracle_calls=20000)
        solved += int(result.reached)
        assert problem.predicate.reachable(result.nodes[result.parents[1:]], result.nodes[1:]).all()
    assert solved >= 4


@pytest.mark.parametrize(("arguments", "message"), [({"dim": 7}, "dim"), ({"width": 0.0}, "width"),
                                                    ({"width": 1.5}, "width"), ({"seed": -1}, "seed"),
                                                    ({"dim": 2.5}, "dim")])
def test_bad_winding_band_arguments_are_refused_by_name(arguments, message):
    with pytest.raises((TypeError, ValueError), match=message):
        winding_band(**arguments)


def _problem_folder(tmp_path, name, **fields):
    folder = tmp_path / name
    folder.mkdir()
    return folder, _write(folder, **fields)


def _scenario(start=(1, 1)):
    return json.dumps({"format": "qrrt-environment", "version": 1, "bounds": [[0, 20], [0, 20]],
                       "boxes": [[[0, 0], [5, 5]]], "start": list(start), "goal": [19, 19], "goal_radius": 0.75})


def _bad_problem_files(tmp_path):
    """(case, problem file, extra flags, what the one line must say) for files an adversarial user
    would write."""
    import os

    cases = []
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100_000 + "]" * 100_000)
    cases.append(("nested", deep, [], "nested too deeply"))
    folder, path = _problem_folder(tmp_path, "bigint", family="image", image="map.pgm", pixel_size=1.0,
                                   start=[1, 1], goal=[3, 3], goal_radius=0.5)
    (folder / "map.pgm").write_bytes(b"P5 4 4 255\n" + bytes([255]) * 16)
    path.write_text(path.read_text().replace("[1, 1]", "[" + "9" * 401 + ", 1]"))
    cases.append(("401 digits", path, [], "start must be numeric"))
    cases.append(("family list", _problem_folder(tmp_path, "list", family=["maze"])[1], [], '"family" must be one of'))
    cases.append(("version true", _problem_folder(tmp_path, "true", family="open-space", version=True)[1], [],
                  '"version" must be 1, got True'))
    cases.append(("missing scenario", _problem_folder(tmp_path, "missing", family="boxes", scenario="no.json")[1], [],
                  '"scenario": scenario file: no such file'))
    folder, path = _problem_folder(tmp_path, "collide", family="boxes", scenario="world.json")
    (folder / "world.json").write_text(_scenario())
    cases.append(("start in collision", path, [], "world.json: start [1.0, 1.0] is in collision"))
    cases.append(("absolute", _problem_folder(tmp_path, "zero", family="boxes", scenario="/dev/zero")[1], [],
                  '"scenario" must name a file inside the problem file\'s folder'))
    cases.append(("device allowed", tmp_path / "zero" / "problem.json", ["--allow-outside-files"],
                  "'/dev/zero' is not a regular file"))
    folder, path = _problem_folder(tmp_path, "fifo", family="boxes", scenario="pipe.json")
    os.mkfifo(folder / "pipe.json")
    cases.append(("FIFO", path, [], "pipe.json' is not a regular file"))
    cases.append(("dot dot", _problem_folder(tmp_path, "up", family="boxes", scenario="../collide/world.json")[1], [],
                  '"scenario" leads outside the problem file\'s folder'))
    folder, path = _problem_folder(tmp_path, "link", family="boxes", scenario="world.json")
    (folder / "world.json").symlink_to(tmp_path / "collide" / "world.json")
    cases.append(("symbolic link out", path, [], '"scenario" leads outside'))
    secret = tmp_path / "secret.txt"
    secret.write_text("root:*:0:0:secret")
    folder, path = _problem_folder(tmp_path, "secret", family="image", image=str(secret), pixel_size=1.0,
                                   start=[1, 1], goal=[3, 3], goal_radius=0.5)
    cases.append(("content never echoed", path, ["--allow-outside-files"], "unknown format"))
    return cases


def test_bad_problem_files_exit_2_with_one_line_naming_the_file_and_the_field(tmp_path, capsys):
    """Every bad problem file: exit 2 and one line that names the problem file and the field, never
    a traceback, never the content of a file it reads."""
    from qrrt_circuits.cli import main

    for case, path, flags, message in _bad_problem_files(tmp_path):
        with pytest.raises(SystemExit) as exit_info:
            main(["plan", "--problem", str(path), "--planner", "rrt", "--max-nodes", "5", *flags])
        err = capsys.readouterr().err.strip().splitlines()
        assert exit_info.value.code == 2, case
        assert len(err) == 1 and str(path) in err[0] and message in err[0], (case, err)
        assert "root:*" not in err[0] and "Traceback" not in err[0], case


def test_files_a_problem_names_inside_its_folder_are_read():
    """A scenario in a subfolder of the problem file's folder is inside it."""
    import tempfile

    with tempfile.TemporaryDirectory() as name:
        from pathlib import Path

        root = Path(name)
        (root / "worlds").mkdir()
        (root / "worlds" / "world.json").write_text(_scenario(start=(10, 10)))
        problem = load_problem(_write(root, family="boxes", scenario="worlds/world.json"))
        assert problem.start.tolist() == [10.0, 10.0]


def _broken(member, value):
    """The paper's problem with one protocol member replaced by one that returns ``value``."""
    problem = qc.paper_clutter(seed=0)
    owner = {"predicate": problem.predicate, "space": problem.space, "goal": problem.goal}[member.split(".")[0]]
    name = member.split(".")[1]

    class Broken:
        def __getattr__(self, attribute):
            return getattr(owner, attribute)

    broken = Broken()
    if name == "dim":
        broken.dim = value
    else:
        setattr(broken, name, lambda *args, **kwargs: value)
    return problem, member.split(".")[0], broken


@pytest.mark.parametrize(("member", "value", "message"), [
    ("predicate.describe", "a string", r"predicate.describe\(\) must return a dict"),
    ("predicate.describe", {"k": object()}, r"predicate.describe\(\) must return JSON-able values"),
    ("predicate.dim", 2.0, "predicate.dim must be an int"),
    ("space.describe", {"k": {1, 2}}, r"space.describe\(\) must return JSON-able values"),
    ("space.distance", [[0.0]], r"space.distance\(states, others\) must return one finite distance"),
    ("space.distance", np.array([-1.0]), r"space.distance\(states, others\) must return one finite distance"),
    ("space.interpolate", np.array([np.nan, 0.0]), r"space.interpolate\(origins, targets, fraction\) must return"),
    ("space.nearest_neighbors", [], r"space.nearest_neighbors\(\) must return a NearestNeighbors structure"),
    ("space.dim", True, "space.dim must be an int"),
    ("goal.describe", None, r"goal.describe\(\) must return a dict"),
    ("goal.is_satisfied", np.array([0.5]), "the goal's is_satisfied must return booleans"),
])
def test_every_protocol_member_is_probed_with_its_return_type_before_planning(member, value, message):
    """A predicate, space or goal whose member returns the wrong kind of value is refused when the
    problem is built, naming the member, not after a plan (where a result could not be built)."""
    problem, part, broken = _broken(member, value)
    with pytest.raises((TypeError, ValueError), match=message):
        problem.replace(**{part: broken})


def test_a_predicate_that_describes_itself_in_words_fails_before_any_round():
    """The issue's case: describe() returning a string used to plan to the end and then fail."""
    problem, part, broken = _broken("predicate.describe", "straight lines")
    calls = []
    broken.reachable = lambda parents, children: calls.append(len(children)) or np.ones(len(children), bool)
    with pytest.raises(TypeError, match="predicate.describe"):
        qc.RRT(seed=0).plan(problem.replace(**{part: broken}), max_nodes=50)
    assert calls == []
