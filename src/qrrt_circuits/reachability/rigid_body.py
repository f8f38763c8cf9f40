"""A rectangular rigid body moving in the plane among boxes: the SE(2) reachability check.

States are (x, y, theta) (``world.spaces.SE2Space``). The robot is the rectangle of half-lengths
(a, b) centred at (x, y) and turned by theta; the obstacles are axis-aligned boxes, and the robot
must stay inside the workspace rectangle. A motion follows the SE(2) interpolation (straight in
(x, y), the shorter arc in theta). It is tested at K + 1 states, K = ceil((|dxy| + R |dtheta|) /
``resolution``) with R = sqrt(a^2 + b^2), so that no point of the robot moves more than
``resolution`` between two tested states; each tested state uses the rectangle grown by
``resolution`` / 2 on every side, which contains every position a point takes between its two
tested neighbours (a path of length <= resolution stays within resolution / 2 of one of its ends).
The check is therefore sound: it accepts no motion whose swept robot touches an obstacle or leaves
the workspace; it may reject a motion that passes within ``resolution`` of one. Overlap of the
grown rectangle and a box is decided exactly by the separating-axis test on the four axes (the
box's two, the robot's two). Compiled with numba, batched over the pairs.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._support.validation import check_float
from ..world.environment import Environment
from .predicate import as_pairs

__all__ = ["RigidBodyCheck", "se2_world"]


@njit(cache=True, nogil=True)
def _state_free(x: float, y: float, theta: float, a: float, b: float, boxes: np.ndarray, bounds: np.ndarray) -> bool:
    """Whether the rectangle of half-lengths (a, b) at (x, y, theta) lies inside ``bounds`` (2, 2) and
    overlaps no box of ``boxes`` (B, 2, 2) (separating axes; touching counts as overlap)."""
    c, s = math.cos(theta), math.sin(theta)
    ex = abs(c) * a + abs(s) * b  # half-extent of the rectangle along the world axes
    ey = abs(s) * a + abs(c) * b
    if x - ex < bounds[0, 0] or x + ex > bounds[0, 1] or y - ey < bounds[1, 0] or y + ey > bounds[1, 1]:
        return False
    for k in range(boxes.shape[0]):
        lx, ly, hx, hy = boxes[k, 0, 0], boxes[k, 0, 1], boxes[k, 1, 0], boxes[k, 1, 1]
        cx, cy = 0.5 * (lx + hx), 0.5 * (ly + hy)
        wx, wy = 0.5 * (hx - lx), 0.5 * (hy - ly)
        dx, dy = cx - x, cy - y
        if abs(dx) > ex + wx or abs(dy) > ey + wy:  # the world axes separate them
            continue
        # the robot's axes u = (c, s), v = (-s, c): the box's half-extent along each
        if abs(dx * c + dy * s) > a + abs(c) * wx + abs(s) * wy:
            continue
        if abs(-dx * s + dy * c) > b + abs(s) * wx + abs(c) * wy:
            continue
        return False
    return True


@njit(cache=True, nogil=True)
def _motions_free(parents: np.ndarray, children: np.ndarray, a: float, b: float, resolution: float,
                  boxes: np.ndarray, bounds: np.ndarray, out: np.ndarray) -> None:
    radius = math.sqrt(a * a + b * b)
    grown_a, grown_b = a + 0.5 * resolution, b + 0.5 * resolution
    for m in range(parents.shape[0]):
        x0, y0, t0 = parents[m, 0], parents[m, 1], parents[m, 2]
        dx, dy = children[m, 0] - x0, children[m, 1] - y0
        turn = (children[m, 2] - t0 + math.pi) % (2.0 * math.pi) - math.pi
        steps = max(1, int(math.ceil((math.hypot(dx, dy) + radius * abs(turn)) / resolution)))
        free = True
        for i in range(steps + 1):
            f = i / steps
            if not _state_free(x0 + f * dx, y0 + f * dy, t0 + f * turn, grown_a, grown_b, boxes, bounds):
                free = False
                break
        out[m] = free


@njit(cache=True, nogil=True)
def _states_free(points: np.ndarray, a: float, b: float, boxes: np.ndarray, bounds: np.ndarray,
                 out: np.ndarray) -> None:
    for m in range(points.shape[0]):
        out[m] = _state_free(points[m, 0], points[m, 1], points[m, 2], a, b, boxes, bounds)


class RigidBodyCheck:
    """Reachability of SE(2) motions of a rectangle among boxes (see the module docstring).

    Args:
        workspace: Float (2, 2), the plane's [low, high] for x and y.
        boxes: Float (B, 2, 2) axis-aligned obstacles, each [[x_low, y_low], [x_high, y_high]].
        half_lengths: (a, b), the rectangle's half-length along its own x and y axes (> 0).
        resolution: The largest motion of any robot point between two tested states (> 0,
            default 0.02).
        name: The check's name in results (default ``"rigid-body"``).

    Attributes:
        evaluations: Pairs evaluated so far through ``reachable``.

    Raises:
        ValueError: Malformed ``workspace`` or ``boxes``, or non-positive lengths or resolution.
    """

    dim = 3

    def __init__(self, workspace: np.ndarray, boxes: np.ndarray, half_lengths: tuple[float, float],
                 resolution: float = 0.02, name: str = "rigid-body") -> None:
        workspace = np.asarray(workspace, dtype=float)
        boxes = np.asarray(boxes, dtype=float).reshape(-1, 2, 2) if np.size(boxes) else np.zeros((0, 2, 2))
        malformed = workspace.shape != (2, 2) or not np.all(np.isfinite(workspace))
        if malformed or np.any(workspace[:, 0] >= workspace[:, 1]):
            raise ValueError(f"workspace must be [[x_low, x_high], [y_low, y_high]] with low < high, got "
                             f"{workspace.tolist()}")
        if not np.all(np.isfinite(boxes)) or np.any(boxes[:, 0] > boxes[:, 1]):
            raise ValueError("boxes must be finite [[x_low, y_low], [x_high, y_high]] with low <= high")
        if not isinstance(half_lengths, tuple | list) or len(half_lengths) != 2:
            raise ValueError(f"half_lengths must be (a, b), got {half_lengths!r}")
        self.half_lengths = (check_float(half_lengths[0], "half_lengths[0]", 0.0, open_minimum=True),
                             check_float(half_lengths[1], "half_lengths[1]", 0.0, open_minimum=True))
        self.resolution = check_float(resolution, "resolution", 0.0, open_minimum=True)
        self.workspace, self.boxes, self.name = workspace, np.ascontiguousarray(boxes), name
        self.evaluations = 0

    def reachable(self, parents: np.ndarray, children: np.ndarray) -> np.ndarray:
        parents, children = as_pairs(parents, children, 3)
        out = np.empty(parents.shape[0], dtype=np.bool_)
        _motions_free(parents, children, *self.half_lengths, self.resolution, self.boxes, self.workspace, out)
        self.evaluations += int(parents.shape[0])
        return out

    def is_valid(self, points: np.ndarray) -> np.ndarray:
        """Bool (M,): the robot at each state lies in the workspace and touches no box."""
        points = np.ascontiguousarray(np.atleast_2d(points), dtype=float)
        out = np.empty(points.shape[0], dtype=np.bool_)
        _states_free(points, *self.half_lengths, self.boxes, self.workspace, out)
        return out

    def bounds(self) -> np.ndarray:
        """(3, 2): the workspace, and theta in [-pi, pi]."""
        return np.vstack([self.workspace, [-math.pi, math.pi]])

    def describe(self) -> dict:
        """Straight (x, y) and shorter-arc theta motions: no ``dynamics`` key."""
        return {"name": self.name, "robot": "rectangle", "half_lengths": list(self.half_lengths),
                "resolution": self.resolution, "boxes": len(self.boxes), "sound": True}


def se2_world(workspace: np.ndarray, boxes: np.ndarray, half_lengths: tuple[float, float], resolution: float = 0.02,
              name: str = "se2") -> tuple[Environment, RigidBodyCheck]:
    """The environment (x, y, theta bounds, no boxes of its own) and the check of a rectangle among
    ``boxes``: a problem with ``space=SE2Space(), predicate=check``.

    Args:
        workspace: (2, 2) plane bounds.
        boxes: (B, 2, 2) obstacles.
        half_lengths: The rectangle's (a, b).
        resolution: The check's resolution.
        name: The world's name.

    Returns:
        (environment, check).
    """
    check = RigidBodyCheck(workspace, boxes, half_lengths, resolution, name=f"{name}-rigid-body")
    return Environment(check.bounds(), np.zeros((0, 2, 3)), name=name), check
