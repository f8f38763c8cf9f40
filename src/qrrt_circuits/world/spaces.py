"""State spaces: the distance, interpolation and nearest-neighbour structure of a planning problem
(OMPL's ``StateSpace``), chosen once per planner.

A planner samples states uniformly in its environment's bounds (paper Alg. 1, line 4), pairs each
with its nearest tree node under the space's distance (line 6), found by the nearest-neighbour
structure the space chooses once per plan (``nearest_neighbors``, ``world.nearest``), and moves a
candidate farther than ``max_extension`` toward its parent along the space's interpolation. Two
spaces are built in:

- ``RealVectorSpace(d)``: Euclidean distance, straight interpolation, and the compiled exact grid
  search (``GridNearest``); the paper's space and the default.
- ``SE2Space()``: a rigid body in the plane, states (x, y, theta) with theta in [-pi, pi);
  OMPL's ``SE2StateSpace`` metric ``||(dx, dy)|| + w * abs(dtheta)`` (dtheta wrapped to the shorter
  way round, w = 0.5 as in OMPL), interpolation along the shorter arc, and an exact scan under
  that metric (``SE2Nearest``, compiled).

Any object with ``dim``, ``distance``, ``interpolate``, ``nearest_neighbors``, ``check_bounds`` and
``describe`` is a space; its ``nearest_neighbors`` can return ``LinearNearest(self)``, exact under
any ``distance``. Goal balls (``GoalBall``) measure Euclidean distance in the coordinates whatever
the space; a goal of your own can use the space's metric.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from .._support.validation import check_float, check_int
from .nearest import GridNearest, NearestNeighbors, SE2Nearest

__all__ = ["RealVectorSpace", "SE2Space", "StateSpace", "wrap_angle"]


@runtime_checkable
class StateSpace(Protocol):
    """The space a planner's states live in (see the module docstring)."""

    @property
    def dim(self) -> int:
        """d, the number of coordinates of a state."""
        ...

    def distance(self, states: np.ndarray, others: np.ndarray) -> np.ndarray:
        """Float (M,): the distance from each row of ``states`` (M, d) to ``others`` ((M, d) or (d,))."""
        ...

    def interpolate(self, origins: np.ndarray, targets: np.ndarray, fraction: np.ndarray) -> np.ndarray:
        """Float (M, d): the states a ``fraction`` (M,) of the way from each origin to its target."""
        ...

    def nearest_neighbors(self) -> NearestNeighbors:
        """A new, empty nearest-neighbour structure exact under ``distance`` (ties: the lowest
        index; ``world.nearest``), one per plan: ``LinearNearest(self)`` suits any metric."""
        ...

    def check_bounds(self, bounds: np.ndarray) -> None:
        """Refuse (``ValueError``) environment bounds this space cannot use."""
        ...

    def describe(self) -> dict:
        """The space as JSON-able settings."""
        ...


@dataclass(frozen=True)
class RealVectorSpace:
    """R^d with the Euclidean metric: the paper's space.

    Args:
        dim: d >= 1.
    """

    dim: int

    def __post_init__(self) -> None:
        object.__setattr__(self, "dim", check_int(self.dim, "dim", 1))

    def distance(self, states: np.ndarray, others: np.ndarray) -> np.ndarray:
        return np.linalg.norm(np.atleast_2d(states) - others, axis=1)

    def interpolate(self, origins: np.ndarray, targets: np.ndarray, fraction: np.ndarray) -> np.ndarray:
        return origins + (targets - origins) * np.asarray(fraction)[:, None]

    def nearest_neighbors(self) -> GridNearest:
        """A ``GridNearest`` (the compiled exact Euclidean grid search)."""
        return GridNearest(self.dim)

    def check_bounds(self, bounds: np.ndarray) -> None:
        if bounds.shape != (self.dim, 2):
            raise ValueError(f"dimension mismatch: the space has d = {self.dim}, the environment's bounds "
                             f"{bounds.shape[0]}")

    def describe(self) -> dict:
        return {"kind": "real-vector", "dim": self.dim}


def wrap_angle(angle: np.ndarray) -> np.ndarray:
    """Angles wrapped to [-pi, pi).

    Args:
        angle: Float array of angles in radians.

    Returns:
        The same shape, each ``(angle + pi) mod 2 pi - pi``.
    """
    return np.mod(np.asarray(angle, dtype=float) + math.pi, 2 * math.pi) - math.pi


@dataclass(frozen=True)
class SE2Space:
    """A rigid body in the plane: states (x, y, theta), theta in [-pi, pi) (OMPL's
    ``SE2StateSpace``).

    The distance is ``||(x_b - x_a, y_b - y_a)|| + angle_weight * abs(wrap(theta_b - theta_a))``;
    interpolation moves (x, y) on the straight line and theta along the shorter arc.

    Args:
        angle_weight: w, the weight of the rotation (a finite number >= 0; default 0.5, OMPL's).

    Raises:
        TypeError: A non-real ``angle_weight``.
        ValueError: A negative or non-finite ``angle_weight``.
    """

    angle_weight: float = 0.5
    dim = 3

    def __post_init__(self) -> None:
        object.__setattr__(self, "angle_weight", check_float(self.angle_weight, "angle_weight", 0.0))

    def distance(self, states: np.ndarray, others: np.ndarray) -> np.ndarray:
        offset = np.atleast_2d(others) - np.atleast_2d(states)
        turn = np.abs(wrap_angle(offset[:, 2]))
        return np.hypot(offset[:, 0], offset[:, 1]) + self.angle_weight * turn

    def interpolate(self, origins: np.ndarray, targets: np.ndarray, fraction: np.ndarray) -> np.ndarray:
        fraction = np.asarray(fraction, dtype=float)[:, None]
        out = origins + (targets - origins) * fraction
        out[:, 2] = wrap_angle(origins[:, 2] + wrap_angle(targets[:, 2] - origins[:, 2]) * fraction[:, 0])
        return out

    def nearest_neighbors(self) -> SE2Nearest:
        """An ``SE2Nearest`` (the compiled exact scan under this metric; the first of equally near
        nodes)."""
        return SE2Nearest(self.angle_weight)

    def check_bounds(self, bounds: np.ndarray) -> None:
        if bounds.shape != (3, 2):
            raise ValueError(f"SE2Space needs environment bounds for (x, y, theta), shape (3, 2); got {bounds.shape}")
        if not np.allclose(bounds[2], [-math.pi, math.pi]):
            raise ValueError(f"SE2Space needs the theta bounds [-pi, pi], got {bounds[2].tolist()}")

    def describe(self) -> dict:
        return {"kind": "SE2", "angle_weight": self.angle_weight}
