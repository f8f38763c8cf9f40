"""Seeded scenarios of DESIGN §4. Each returns a ``Problem``: the world (its ``Environment``), a
start, a goal ball and the sound exact check of the paper's motion model. Same seed, same world."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from .._support.validation import check_float, check_int, check_seed
from ..world.environment import Environment
from .problem import Problem

#: the side of the paper's square cluttered workspace
CLUTTER_SIZE = 20.0
#: the paper's number of boxes in it
CLUTTER_BOXES = 525
#: the range of the boxes' side lengths
SIDE_RANGE = (0.25, 0.85)
#: the goal ball's radius in the paper's worlds
GOAL_RADIUS = 0.75
#: the most clutter boxes ``narrow_corridor`` accepts
MAX_CORRIDOR_CLUTTER = 10_000
#: the most boxes a random world (``paper_clutter``, ``annealing_field``) draws: its boxes and the
#: collision checks' structures over them stay within tens of megabytes
MAX_WORLD_BOXES = 1_000_000
#: random draws per box ``narrow_corridor`` tries before it gives up placing its clutter
PLACEMENT_TRIES = 1_000


def _random_boxes(rng: np.random.Generator, count: int, low: np.ndarray, high: np.ndarray,
                  side_range: tuple[float, float] = SIDE_RANGE) -> np.ndarray:
    """``count`` boxes with independent side lengths U(side_range), lying inside [low, high]."""
    d = low.shape[0]
    sides = rng.uniform(side_range[0], side_range[1], size=(count, d))
    lower = low + rng.random((count, d)) * (high - low - sides)
    return np.stack([lower, lower + sides], axis=1)


def _start_goal(env: Environment, rng: np.random.Generator, min_separation: float,
                radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Free start and goal at least ``min_separation`` apart, each with ``radius`` clearance from
    obstacles along the axes (so the goal ball is not hidden inside an obstacle)."""
    for _ in range(10000):
        start, goal = env.sample_free(2, rng)
        if np.linalg.norm(goal - start) >= min_separation and _clearance_ok(env, start, radius) \
                and _clearance_ok(env, goal, radius):
            return start, goal
    raise RuntimeError("could not place start and goal")


def _clearance_ok(env: Environment, point: np.ndarray, radius: float) -> bool:
    offsets = np.concatenate([np.eye(env.dim), -np.eye(env.dim)]) * radius * 0.25
    return bool(np.all(env.is_free(point + offsets)))


def _check_seed(seed: int | None) -> int | None:
    return check_seed(seed)


_STREAMS = {"paper_clutter": 1, "narrow_corridor": 2, "annealing_field": 3, "lattice": 4}


def _world_rng(name: str, seed: int | None) -> np.random.Generator:
    """The world's own stream: keyed by scenario, so ``default_rng(seed)`` in user code never
    replays the numbers that placed the obstacles."""
    if seed is None:
        return np.random.default_rng()
    return np.random.default_rng([0x51A7E, _STREAMS[name], int(seed)])


def paper_clutter(seed: int | None = 0, num_boxes: int = CLUTTER_BOXES,
                  size: float = CLUTTER_SIZE) -> Problem:
    """[0, 20]^2 with 525 boxes of sides U(0.25, 0.85): the authors' comparison world (DESIGN §4).

    Boxes lie fully inside the square and may overlap. Start and goal are uniform free points at
    least half the side apart, with 0.75 / 4 axis clearance; goal radius 0.75. The heatmap and
    wall-clock experiments use this world.

    Args:
        seed: Non-negative integer (same seed, same world) or None (fresh entropy).
        num_boxes: Boxes, >= 0.
        size: Side of the square, > 1.7 (twice the largest box side).

    Returns:
        The ``Problem``: its world (``metadata`` set), start, goal ball and exact check.

    Raises:
        ValueError: A negative ``seed``, ``num_boxes`` outside [0, ``MAX_WORLD_BOXES``], or
            ``size`` <= 1.7.
        TypeError: A non-integer ``seed``.
        RuntimeError: No start and goal could be placed (an overfull world).
    """
    _check_seed(seed)
    num_boxes = check_int(num_boxes, "num_boxes", 0, MAX_WORLD_BOXES)
    if size <= 2 * SIDE_RANGE[1]:
        raise ValueError(f"size must be > {2 * SIDE_RANGE[1]}, got {size}")
    rng = _world_rng("paper_clutter", seed)
    bounds = np.array([[0.0, size], [0.0, size]])
    boxes = _random_boxes(rng, num_boxes, bounds[:, 0], bounds[:, 1])
    env = Environment(bounds, boxes, name="paper_clutter")
    start, goal = _start_goal(env, rng, size / 2, GOAL_RADIUS)
    world = Environment(bounds, boxes, name="paper_clutter",
                        metadata={"seed": seed, "num_boxes": num_boxes, "side_range": SIDE_RANGE})
    return Problem.build(world, start, goal, GOAL_RADIUS)


def narrow_corridor(seed: int | None = 0, width: float = 0.4, length: float = 4.0,
                    clutter: int = 120, mouth_clearance: float = 1.5) -> Problem:
    """[0, 20]^2 split by two blocks leaving one horizontal channel through the middle (paper §V.C).

    The channel is ``width`` wide and ``length`` long, centred in the square: the blocks fill
    x in [10 - length/2, 10 + length/2] except y in (10 - width/2, 10 + width/2), so the channel
    covers ``width * length / 400`` of the workspace (0.4 % by default). ``clutter`` small random
    boxes (sides U(0.25, 0.85)) lie on both sides, 0.3 off the wall's columns and kept
    ``mouth_clearance`` away from the channel's mouths. Start in front of the left mouth (0.5 to
    1.5 before it, on its axis), goal on the right; goal radius 0.75. The channel's corners are in
    ``metadata["channel"]``. The defaults are the world of the ``corridor`` experiment; other
    values draw from the same stream (same seed, same draws until the geometry differs).

    Args:
        seed: Non-negative integer (same seed, same world) or None (fresh entropy).
        width: Channel width, in (0, 10).
        length: Channel length, in (0, 12) (the goal lies at least 3 beyond the right mouth).
        clutter: Small boxes beside the wall, an integer in [0, 10000].
        mouth_clearance: Box-free margin around the mouths, in [0, 5] (smaller: denser clutter
            beside the mouth).

    Returns:
        The ``Problem``: its world (``metadata`` set), start, goal ball and exact check.

    Raises:
        ValueError: A negative ``seed``, or ``width``, ``length``, ``clutter`` or
            ``mouth_clearance`` out of range.
        TypeError: A non-integer ``seed`` or ``clutter``, or a non-real ``width``, ``length`` or
            ``mouth_clearance``.
        RuntimeError: The clutter, start or goal could not be placed (a geometry leaving no room
            for them).
    """
    _check_seed(seed)
    width, length = check_float(width, "width"), check_float(length, "length")
    mouth_clearance = check_float(mouth_clearance, "mouth_clearance")
    if not (0 < width < 10):
        raise ValueError(f"width must be in (0, 10), got {width}")
    if not (0 < length < 12):
        raise ValueError(f"length must be in (0, 12), got {length}")
    clutter = check_int(clutter, "clutter", 0, MAX_CORRIDOR_CLUTTER)
    if not (0 <= mouth_clearance <= 5):
        raise ValueError(f"mouth_clearance must be in [0, 5], got {mouth_clearance}")
    rng = _world_rng("narrow_corridor", seed)
    size = CLUTTER_SIZE
    x0, x1 = (size - length) / 2, (size + length) / 2
    y0, y1 = (size - width) / 2, (size + width) / 2
    blocks = np.array([[[x0, 0.0], [x1, y0]], [[x0, y1], [x1, size]]])
    keep_out = 1.5  # free margin around the channel mouths
    small: list[np.ndarray] = []
    for _ in range(PLACEMENT_TRIES * (clutter + 1)):
        if len(small) == clutter:
            break
        box = _random_boxes(rng, 1, np.zeros(2), np.full(2, size))[0]
        if box[1, 0] > x0 - 0.3 and box[0, 0] < x1 + 0.3:
            continue  # overlaps the wall's columns: keep the wall's faces clean
        near_mouth_y = box[1, 1] > y0 - mouth_clearance and box[0, 1] < y1 + mouth_clearance
        near_mouth_x = box[1, 0] > x0 - mouth_clearance and box[0, 0] < x1 + mouth_clearance
        if near_mouth_y and near_mouth_x:
            continue
        small.append(box)
    if len(small) < clutter:
        raise RuntimeError(f"could not place {clutter} clutter boxes beside a channel {width} wide and {length} "
                           f"long with mouth_clearance {mouth_clearance} (placed {len(small)})")
    boxes = np.concatenate([blocks, np.array(small).reshape(-1, 2, 2)])
    env = Environment(np.array([[0.0, size], [0.0, size]]), boxes, name="narrow_corridor")
    for _ in range(10000):
        # start in front of the channel's left mouth, on its axis; goal anywhere on the far side
        start = np.array([rng.uniform(x0 - keep_out, x0 - 0.5), (y0 + y1) / 2 + rng.uniform(-0.1, 0.1) * width])
        goal = np.array([rng.uniform(x1 + 3.0, size - 1.0), rng.uniform(2.0, size - 2.0)])
        if env.is_free(start) and env.is_free(goal) and _clearance_ok(env, goal, GOAL_RADIUS) \
                and _clearance_ok(env, start, GOAL_RADIUS):
            break
    else:
        raise RuntimeError(f"could not place start and goal beside a channel {width} wide and {length} long")
    world = Environment(env.bounds, boxes, name="narrow_corridor",
                        metadata={"seed": seed, "channel": [[x0, y0], [x1, y1]], "width": width, "length": length,
                                  "clutter": clutter, "mouth_clearance": mouth_clearance})
    return Problem.build(world, start, goal, GOAL_RADIUS)


def annealing_field(seed: int | None = 0, num_boxes: int = 6025, side: float | None = None) -> Problem:
    """The Quantum Database Annealing world (paper §V.D, DESIGN §4).

    ``num_boxes`` boxes with ``paper_clutter``'s sides U(0.25, 0.85) on a square whose side keeps
    ``paper_clutter``'s box density (20 * sqrt(6025 / 525) ~ 67.75 by default), so the free
    fraction matches. Start and goal as in ``paper_clutter``; goal radius 0.75. The paper gives the
    box count only; ``side`` sets the square (and so the density) instead: the box density relative
    to the default is (default side / side)^2 at 6025 boxes.

    Args:
        seed: Non-negative integer (same seed, same world) or None (fresh entropy).
        num_boxes: Boxes (the paper's 6025), >= 0.
        side: Side of the square, finite and > 1.7 (twice the largest box side), or None (default:
            ``paper_clutter``'s density).

    Returns:
        The ``Problem``: its world (``metadata`` set), start, goal ball and exact check.

    Raises:
        ValueError: A negative ``seed``, ``num_boxes`` outside [0, ``MAX_WORLD_BOXES``], or
            ``side`` <= 1.7 or not finite.
        TypeError: A non-integer ``seed``, or a non-real ``side``.
        RuntimeError: No start and goal could be placed.
    """
    _check_seed(seed)
    num_boxes = check_int(num_boxes, "num_boxes", 0, MAX_WORLD_BOXES)
    if side is None:
        size = CLUTTER_SIZE * math.sqrt(num_boxes / CLUTTER_BOXES)
    else:
        size = check_float(side, "side", 2 * SIDE_RANGE[1], open_minimum=True)
    rng = _world_rng("annealing_field", seed)
    bounds = np.array([[0.0, size], [0.0, size]])
    boxes = _random_boxes(rng, num_boxes, bounds[:, 0], bounds[:, 1])
    env = Environment(bounds, boxes, name="annealing_field")
    start, goal = _start_goal(env, rng, size / 2, GOAL_RADIUS)
    metadata = {"seed": seed, "num_boxes": num_boxes} if side is None else {"seed": seed, "num_boxes": num_boxes,
                                                                           "side": size}
    return Problem.build(Environment(bounds, boxes, name="annealing_field", metadata=metadata), start, goal,
                         GOAL_RADIUS)


def lattice(seed: int | None = 0, size: int = 72, blocked_fraction: float = 0.5) -> Problem:
    """A grid of unit cells, a fraction blocked at random (the predecessor paper's world, DESIGN §4).

    round(``blocked_fraction`` * size^2) of the ``size`` x ``size`` cells are blocked (blocked
    cells along a row are merged into one box). Start and goal are centres of cells of the largest
    4-connected free component, the goal among the farthest 10 % from the start; goal radius 0.45.

    Args:
        seed: Non-negative integer (same seed, same world) or None (fresh entropy).
        size: L, cells per side, 2 .. 4096 (the authors' example: 72).
        blocked_fraction: r, in [0, 1) (default 0.5).

    Returns:
        The ``Problem`` on [0, L]^2: its world (``metadata`` with the component's cell count),
        start, goal ball and exact check.

    Raises:
        ValueError: A negative ``seed``, ``size`` out of range, ``blocked_fraction`` outside
            [0, 1), or no free cell.
        TypeError: A non-integer ``seed`` or ``size``.
    """
    _check_seed(seed)
    check_int(size, "size", 2, 4096)
    if not (0.0 <= blocked_fraction < 1.0):
        raise ValueError(f"blocked_fraction must be in [0, 1), got {blocked_fraction}")
    size = int(size)
    rng = _world_rng("lattice", seed)
    flat = np.zeros(size * size, dtype=bool)
    flat[rng.choice(size * size, int(round(blocked_fraction * size * size)), replace=False)] = True
    blocked = flat.reshape(size, size)  # blocked[ix, iy]
    boxes = []
    for iy in range(size):
        ix = 0
        while ix < size:
            if blocked[ix, iy]:
                end = ix
                while end + 1 < size and blocked[end + 1, iy]:
                    end += 1
                boxes.append([[ix, iy], [end + 1, iy + 1]])
                ix = end + 1
            else:
                ix += 1
    from scipy import ndimage  # only the lattice needs it (a slow import)

    labels, count = ndimage.label(~blocked)
    if count == 0:
        raise ValueError("the lattice has no free cell")
    sizes = ndimage.sum(np.ones_like(labels), labels, index=np.arange(1, count + 1))
    largest = int(np.argmax(sizes)) + 1
    cells = np.argwhere(labels == largest)
    first = cells[rng.integers(len(cells))]
    distances = np.linalg.norm(cells - first, axis=1)
    far = cells[distances >= np.quantile(distances, 0.9)]
    second = far[rng.integers(len(far))]
    bounds = np.array([[0.0, size], [0.0, size]])
    world = Environment(bounds, np.array(boxes, dtype=float).reshape(-1, 2, 2), name="lattice",
                        metadata={"seed": seed, "size": size, "blocked_fraction": blocked_fraction,
                                  "component_cells": int(sizes[largest - 1])})
    return Problem.build(world, first + 0.5, second + 0.5, 0.45)


#: every scenario's builder by name
SCENARIOS: dict[str, Callable[..., Problem]] = {
    "paper_clutter": paper_clutter,
    "narrow_corridor": narrow_corridor,
    "annealing_field": annealing_field,
    "lattice": lattice,
}


def by_name(name: str, seed: int | None = 0) -> Problem:
    """Build a scenario from its name (one of ``SCENARIOS``).

    Args:
        name: ``"paper_clutter"``, ``"narrow_corridor"``, ``"annealing_field"`` or ``"lattice"``.
        seed: Non-negative integer (same seed, same world; default 0) or None (fresh entropy).

    Returns:
        The ``Problem``.

    Raises:
        ValueError: An unknown ``name`` or a negative ``seed``.
        TypeError: A non-integer ``seed``.
        RuntimeError: The scenario could not place its start and goal (see each scenario).

    Example:
        >>> from qrrt_circuits.problems import scenarios
        >>> problem = scenarios.by_name("narrow_corridor")
        >>> problem.name, problem.dim, problem.goal.radius
        ('narrow_corridor', 2, 0.75)
    """
    if name not in SCENARIOS:
        raise ValueError(f"unknown scenario {name!r}; choose one of {sorted(SCENARIOS)}")
    return SCENARIOS[name](seed=seed)
