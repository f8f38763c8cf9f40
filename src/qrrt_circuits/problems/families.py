"""Planning problems beyond the paper's box worlds, in OMPL's terms: an environment (bounds and
start), a motion check, a state space and a goal; built by family or read from a JSON file.

Families (each a function returning a ``Problem``):

- ``open_space()``: [0, 10]^2 with one box in the middle; straight-line motions.
- ``narrow_passage(dim, width)``: [0, 10]^d cut by a wall 1 thick at x_0 = 5 with one square hole
  of side ``width`` at its centre; straight-line motions; d = 2 .. 6.
- ``winding_band(dim, width, seed)``: a staircase band of width ``width`` in the (x_0, x_1) plane
  of [0, 10]^d, from left to right with two turns drawn from ``seed``, every other axis free: a long
  narrow passage the tree must travel along, where most samples see no part of it; d = 2 .. 6.
- ``se2_gap(width)``: a 1.2 x 0.4 rectangle in SE(2) through a gap of ``width`` in a wall
  (``reachability.rigid_body``).
- ``maze(cells, seed)``: a perfect maze of ``cells`` x ``cells`` rooms drawn by the library
  (``world.maze``) in [0, 10]^2, from the bottom-left room to the top-right one, with the exact
  grid check of straight segments (``reachability.grid_check``).
- ``box_world(path)``: a ``qrrt-environment`` scenario file (the paper's motion model).
- ``image_problem(path, pixel_size, start, goal, goal_radius)``: an occupancy image (PNG, PGM,
  PPM) with the exact grid check of straight segments (``reachability.grid_check``).

Straight-line motions are the exact check (``ExactCheck``) under the closed loop -4 I over 5 s,
x(t) = c + exp(-4 t) (p - c): the segment from p toward c, stopping exp(-20) (about 2e-9) of the
way short of c.

``load_problem(path)`` reads ``{"format": "qrrt-problem", "version": 1, "family": NAME, ...}`` with
the family's arguments, refusing a bad field by name before anything is built.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from .._support.validation import check_float, check_int
from ..reachability.dynamics import LinearTrackingDynamics
from ..reachability.exact import ExactCheck
from ..reachability.grid_check import check_map_point, grid_world, image_world
from ..reachability.rigid_body import se2_world
from ..world.environment import Environment
from ..world.image import OccupancyGrid
from ..world.spaces import SE2Space
from .problem import Problem

__all__ = ["FAMILIES", "box_world", "grid_problem", "image_problem", "load_problem", "maze", "narrow_passage",
           "open_space", "save_box_world", "se2_gap", "straight_line_dynamics", "winding_band"]

PROBLEM_FORMAT, PROBLEM_VERSION = "qrrt-problem", 1


def straight_line_dynamics(dim: int) -> LinearTrackingDynamics:
    """Closed loop -4 I in d dimensions over 5 s: straight segments (see the module docstring).

    Args:
        dim: d >= 1.

    Returns:
        ``LinearTrackingDynamics(0, I, 4 I)``.
    """
    dim = check_int(dim, "dim", 1)
    return LinearTrackingDynamics(np.zeros((dim, dim)), np.eye(dim), 4.0 * np.eye(dim))


def _box_problem(name: str, bounds: np.ndarray, boxes: np.ndarray, start: np.ndarray, goal: np.ndarray,
                 goal_radius: float) -> Problem:
    env = Environment(bounds, boxes, name=name)
    return Problem.build(env, start, goal, goal_radius, predicate=ExactCheck(env, straight_line_dynamics(env.dim)))


def open_space() -> Problem:
    """[0, 10]^2, one box [4, 6]^2, start (1, 1), goal ball (9, 9) of radius 0.5."""
    return _box_problem("open-space", np.array([[0.0, 10.0], [0.0, 10.0]]), np.array([[[4.0, 4.0], [6.0, 6.0]]]),
                        np.array([1.0, 1.0]), np.array([9.0, 9.0]), 0.5)


def narrow_passage(dim: int = 2, width: float = 0.5) -> Problem:
    """[0, 10]^d cut by the wall 4.5 <= x_0 <= 5.5 with a hole |x_i - 5| < width / 2 (i >= 1);
    start (1, 2, ..., 2), goal ball (9, 2, ..., 2) of radius 0.5: the straight line between them
    meets the wall, so every path turns through the hole.

    Args:
        dim: d in [2, 6].
        width: The hole's side, in (0, 8].

    Returns:
        The problem.

    Raises:
        TypeError: A non-integer ``dim`` or non-real ``width``.
        ValueError: ``dim`` outside [2, 6] or ``width`` outside (0, 8].
    """
    dim = check_int(dim, "dim", 2, 6)
    width = check_float(width, "width", 0.0, 8.0, open_minimum=True)
    boxes = []
    for axis in range(1, dim):  # the wall minus the hole: below and above the hole on each other axis
        for low, high in ((0.0, 5.0 - width / 2), (5.0 + width / 2, 10.0)):
            lower, upper = np.zeros(dim), np.full(dim, 10.0)
            lower[0], upper[0] = 4.5, 5.5
            lower[axis], upper[axis] = low, high
            boxes.append([lower, upper])
    start, goal = np.full(dim, 2.0), np.full(dim, 2.0)  # level with each other, away from the hole
    start[0], goal[0] = 1.0, 9.0
    return _box_problem(f"narrow-passage-{dim}d", np.tile([0.0, 10.0], (dim, 1)), np.array(boxes), start, goal, 0.5)


def winding_band(dim: int = 2, width: float = 0.2, seed: int = 0) -> Problem:
    """[0, 10]^d whose free space is a staircase band in the (x_0, x_1) plane (every other axis
    free): three horizontal legs joined by two vertical ones, each leg a rectangle of side
    ``width`` across its axis (the legs' ends overlap by ``width / 2``, so the turns are square).

    The band runs from x_0 = 0.5 to x_0 = 9.5; ``seed`` draws the two turns' abscissae a_1 in
    [2.5, 4] and a_2 in [6, 7.5] and the legs' heights y_0, y_1, y_2 in [1.5, 8.5] with
    |y_1 - y_0| >= 3 and |y_2 - y_1| >= 3 (rejection sampling), so the band is between about 15
    and 23 long and a straight motion from one leg to the next meets the wall. Start (1, y_0, 5,
    ..., 5), goal ball (9, y_2, 5, ..., 5) of radius 0.5. The obstacles are the complement of the
    band in the plane (a grid of the legs' edges, merged along x_0), extended over the other axes.

    Args:
        dim: d in [2, 6].
        width: The band's width, in (0, 1].
        seed: The world's seed (>= 0): the turns and heights.

    Returns:
        The problem, named ``winding-band-{d}d-seed{seed}``.

    Raises:
        TypeError: A non-integer ``dim`` or ``seed``, or a non-real ``width``.
        ValueError: ``dim`` outside [2, 6], ``width`` outside (0, 1] or a negative ``seed``.
    """
    dim = check_int(dim, "dim", 2, 6)
    width = check_float(width, "width", 0.0, 1.0, open_minimum=True)
    seed = check_int(seed, "seed", 0)
    rng = np.random.default_rng([seed, 0xBA2D])
    a1, a2 = rng.uniform(2.5, 4.0), rng.uniform(6.0, 7.5)
    heights = [rng.uniform(1.5, 8.5)]
    while len(heights) < 3:
        height = rng.uniform(1.5, 8.5)
        if abs(height - heights[-1]) >= 3.0:
            heights.append(height)
    y0, y1, y2 = heights
    half = width / 2
    legs = [(0.5, a1, y0, y0), (a1, a1, y0, y1), (a1, a2, y1, y1), (a2, a2, y1, y2), (a2, 9.5, y2, y2)]
    free = [(min(x0, x1) - half, max(x0, x1) + half, min(ya, yb) - half, max(ya, yb) + half)
            for x0, x1, ya, yb in legs]
    xs = sorted({0.0, 10.0, *(v for r in free for v in r[:2])})
    ys = sorted({0.0, 10.0, *(v for r in free for v in r[2:])})
    boxes = []
    for y_low, y_high in zip(ys[:-1], ys[1:], strict=True):
        run_start = None
        for x_low, x_high in zip(xs[:-1], xs[1:], strict=True):
            cx, cy = (x_low + x_high) / 2, (y_low + y_high) / 2
            blocked = not any(r[0] <= cx <= r[1] and r[2] <= cy <= r[3] for r in free)
            if blocked and run_start is None:
                run_start = x_low
            if not blocked and run_start is not None:
                boxes.append((run_start, x_low, y_low, y_high))
                run_start = None
        if run_start is not None:
            boxes.append((run_start, 10.0, y_low, y_high))
    lower, upper = np.zeros((len(boxes), dim)), np.full((len(boxes), dim), 10.0)
    lower[:, :2] = [(box[0], box[2]) for box in boxes]
    upper[:, :2] = [(box[1], box[3]) for box in boxes]
    start, goal = np.full(dim, 5.0), np.full(dim, 5.0)
    start[:2], goal[:2] = (1.0, y0), (9.0, y2)
    return _box_problem(f"winding-band-{dim}d-seed{seed}", np.tile([0.0, 10.0], (dim, 1)),
                        np.stack([lower, upper], axis=1), start, goal, 0.5)


def se2_gap(width: float = 1.2) -> Problem:
    """A 1.2 x 0.4 rectangle (half-lengths 0.6, 0.2) in SE(2) through a gap of ``width`` (centred
    at y = 5) in the wall 4.8 <= x <= 5.2 of [0, 10]^2; start (2, 8, pi / 2), goal ball (8, 8, 0)
    of radius 1 (Euclidean in (x, y, theta)): the straight motion between them meets the wall, so
    every path goes down to the gap and through it.

    Args:
        width: The gap, in (0, 8].

    Returns:
        The problem (``space`` is ``SE2Space()``).

    Raises:
        TypeError: A non-real ``width``.
        ValueError: ``width`` outside (0, 8].
    """
    width = check_float(width, "width", 0.0, 8.0, open_minimum=True)
    wall = np.array([[[4.8, 0.0], [5.2, 5.0 - width / 2]], [[4.8, 5.0 + width / 2], [5.2, 10.0]]])
    goal = np.array([8.0, 8.0, 0.0])
    env, check = se2_world(np.array([[0.0, 10.0], [0.0, 10.0]]), wall, (0.6, 0.2), resolution=0.05, name="se2-gap")
    return Problem.build(env, np.array([2.0, 8.0, math.pi / 2]), goal, 1.0, predicate=check, space=SE2Space())


def maze(cells: int = 4, seed: int = 0) -> Problem:
    """A perfect maze of ``cells`` x ``cells`` rooms (``world.maze.maze_grid``) scaled to
    [0, 10]^2 (pixel side 10 / (2 cells + 1)); start at the centre of the bottom-left room, goal
    ball at the centre of the top-right room with radius 0.4 pixel sides.

    Args:
        cells: Rooms along a side, in [2, 32].
        seed: The maze's seed (>= 0).

    Returns:
        The problem (``GridCheck`` over the maze).

    Raises:
        TypeError: A non-integer ``cells`` or ``seed``.
        ValueError: ``cells`` outside [2, 32] or a negative ``seed``.
    """
    from ..world.maze import maze_grid, room_center

    cells = check_int(cells, "cells", 2, 32)
    grid = maze_grid(cells, seed, 10.0 / (2 * cells + 1))
    start, goal = room_center(grid, cells - 1, 0), room_center(grid, 0, cells - 1)  # bottom-left, top-right
    radius = 0.4 * grid.pixel_size
    name = f"maze-{cells}x{cells}-seed{seed}"
    return grid_problem(grid, start, goal, radius, name=name)


def grid_problem(grid: OccupancyGrid, start: Any, goal: Any, goal_radius: float, name: str = "grid") -> Problem:
    """An ``OccupancyGrid`` as a problem: the grid's bounds, the ``GridCheck`` of straight segments,
    R^2 and the goal ball.

    Args:
        grid: The grid.
        start: (x, y), a free point of the map.
        goal: (x, y), the goal ball's centre, a free point of the map.
        goal_radius: Its radius (> 0).
        name: The problem's name.

    Returns:
        The problem.

    Raises:
        ValueError: A start or goal that is not a free point of the map (naming the pixel), or
            what ``Problem`` refuses.
    """
    env, check = grid_world(grid, name=name)
    for key, point in (("start", start), ("goal", goal)):
        check_map_point(check, key, point)
    return Problem.build(env, start, goal, goal_radius, predicate=check)


def box_world(path: str | Path) -> Problem:
    """A ``qrrt-environment`` scenario file (its geometry with ``start``, ``goal`` and
    ``goal_radius``) with the library's default motion model (the paper's dynamics, ``ExactCheck``).

    Args:
        path: The scenario file.

    Returns:
        The problem.

    Raises:
        ValueError: What ``Environment.load`` refuses, or a file without ``start``, ``goal`` and
            ``goal_radius`` or with values ``Problem.build`` refuses; the message starts with the
            path.
    """
    env = Environment.load(path)
    data = json.loads(Path(path).read_text(encoding="utf-8"))
    missing = [key for key in ("start", "goal", "goal_radius") if data.get(key) is None]
    if missing:
        raise ValueError(f"{path}: a problem's scenario needs start, goal and goal_radius "
                         f"(missing {', '.join(missing)})")
    try:
        return Problem.build(env, data["start"], data["goal"], data["goal_radius"])
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{path}: {exc}") from exc


def save_box_world(problem: Problem, path: str | Path) -> Path:
    """Write ``problem`` as a ``qrrt-environment`` scenario file (``box_world`` reads it back with
    the default exact check).

    Args:
        problem: A problem whose goal is a ball (``GoalBall``).
        path: The file (overwritten).

    Returns:
        The path written.

    Raises:
        ValueError: A goal that is not a ball.
    """
    centre, radius = getattr(problem.goal, "centre", None), getattr(problem.goal, "radius", None)
    if centre is None or radius is None:
        raise ValueError(f"a scenario file holds a goal ball; the problem's goal is {problem.goal!r}")
    data = problem.env.to_dict() | {"start": problem.start.tolist(), "goal": np.asarray(centre).tolist(),
                                    "goal_radius": float(radius)}
    path = Path(path)
    path.write_text(json.dumps(data, indent=1))
    return path


def image_problem(path: str | Path, pixel_size: float, start: Any, goal: Any, goal_radius: float,
                  free_threshold: float = 0.5, negate: bool = False) -> Problem:
    """An occupancy image as a problem (``grid_problem`` of the image's grid).

    Args:
        path: A PNG, PGM or PPM file.
        pixel_size: A pixel's side in world units (> 0).
        start: (x, y).
        goal: (x, y), the goal ball's centre.
        goal_radius: Its radius (> 0).
        free_threshold: A pixel is free where its grey value is >= this (in [0, 1]).
        negate: Read 1 - grey instead (black free).

    Returns:
        The problem, named ``image:STEM``.

    Raises:
        ValueError: What ``OccupancyGrid.from_image`` or ``grid_problem`` refuses.
    """
    env, check = image_world(path, pixel_size, free_threshold=free_threshold, negate=negate)
    return grid_problem(check.grid, start, goal, goal_radius, name=env.name)


#: family name -> (builder, its JSON arguments and their defaults)
FAMILIES: dict[str, tuple[Any, dict[str, Any]]] = {
    "open-space": (open_space, {}),
    "narrow-passage": (narrow_passage, {"dim": 2, "width": 0.5}),
    "winding-band": (winding_band, {"dim": 2, "width": 0.2, "seed": 0}),
    "se2-gap": (se2_gap, {"width": 1.2}),
    "maze": (maze, {"cells": 4, "seed": 0}),
    "image": (image_problem, {"path": None, "pixel_size": None, "start": None, "goal": None, "goal_radius": None,
                              "free_threshold": 0.5, "negate": False}),
}


def _check_named_file(path: Path, key: str, named: Path) -> None:
    """Refuse a file named by the problem file's ``key`` that is not a file, naming the key."""
    if not named.is_file():
        raise ValueError(f'{path}: "{key}" names {str(named)!r}, which is not a file (the name is read relative '
                         "to the problem file's folder)")


def load_problem(path: str | Path) -> Problem:
    """Read a problem file: ``{"format": "qrrt-problem", "version": 1, "family": NAME, ARGS...}``
    for a family of ``FAMILIES``, or ``{"format": "qrrt-problem", "version": 1, "family": "boxes",
    "scenario": FILE}`` for a scenario file (relative to the problem file).

    Args:
        path: The file.

    Returns:
        The problem.

    Raises:
        ValueError: A missing, unreadable or malformed file, naming the field and what is accepted.
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"--problem: no such file {str(path)!r}")
    try:
        data = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise ValueError(f"{path}: not a JSON problem file ({exc})") from exc
    if not isinstance(data, dict) or data.get("format") != PROBLEM_FORMAT:
        raise ValueError(f'{path}: "format" must be "{PROBLEM_FORMAT}"')
    if data.get("version") != PROBLEM_VERSION:
        raise ValueError(f'{path}: "version" must be {PROBLEM_VERSION}, got {data.get("version")!r}')
    family = data.get("family")
    arguments = {key: value for key, value in data.items() if key not in ("format", "version", "family")}
    if family == "boxes":
        if set(arguments) != {"scenario"} or not isinstance(arguments["scenario"], str):
            raise ValueError(f'{path}: family "boxes" takes one field, "scenario" (a scenario file name)')
        _check_named_file(path, "scenario", path.parent / arguments["scenario"])
        return box_world(path.parent / arguments["scenario"])
    if family == "image":  # the file's "image", relative to the problem file, is the builder's path
        if not isinstance(arguments.get("image"), str) or "path" in arguments:
            raise ValueError(f'{path}: family "image" needs "image", the file name of a PNG, PGM or PPM image')
        missing = sorted({"pixel_size", "start", "goal", "goal_radius"} - set(arguments))
        if missing:
            raise ValueError(f'{path}: family "image" needs {missing}')
        _check_named_file(path, "image", path.parent / arguments["image"])
        arguments["path"] = str(path.parent / arguments.pop("image"))
    if family not in FAMILIES:
        raise ValueError(f'{path}: "family" must be one of {sorted([*FAMILIES, "boxes"])}, got {family!r}')
    builder, accepted = FAMILIES[family]
    unknown = sorted(set(arguments) - set(accepted))
    if unknown:
        raise ValueError(f'{path}: family "{family}" takes {sorted(accepted) or "no fields"}, not {unknown}')
    try:
        problem: Problem = builder(**arguments)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{path}: {exc}") from exc
    return problem
