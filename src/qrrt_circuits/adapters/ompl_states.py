"""OMPL states as the library's coordinates (needs the ``ompl`` extra, OMPL >= 2.0).

``coordinates_for(space)`` maps an OMPL state space onto one of the library's state spaces and
reads and writes its states as rows of floats:

- ``RealVectorStateSpace(d)``: R^d (``qc.RealVectorSpace(d)``), the coordinates as they are;
- ``SE2StateSpace``: (x, y, yaw) (``qc.SE2Space``, its angle weight the SO(2) part's weight in
  OMPL's compound metric, so nearest nodes are OMPL's); the yaw bounds [-pi, pi];
- a ``CompoundStateSpace`` of real-vector spaces: their coordinates one after another
  (``qc.RealVectorSpace`` of the total dimension). OMPL measures such a space by the weighted
  sum of its parts' distances; the library's nearest nodes use the Euclidean distance of the
  whole vector instead (motions and the goal are still OMPL's to check).

Any other space is refused, naming the ones accepted. OMPL 2.0's ``copyToReals`` and
``copyFromReals`` are not used: the wheel of OMPL 2.0.1 crashes in them on an SE(2) state.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..world.spaces import RealVectorSpace, SE2Space

try:
    from ompl import base as ob
except ImportError as exc:  # pragma: no cover - the hint of adapters.ompl
    raise ImportError('qrrt_circuits.adapters.ompl_states needs the OMPL Python bindings; install them with '
                      'pip install "qrrt-circuits[ompl]"') from exc

__all__ = ["CompoundCoordinates", "OMPLCoordinates", "RealVectorCoordinates", "SE2Coordinates", "coordinates_for"]

#: OMPL's ``StateSpaceType`` numbers of the spaces mapped here (``space.getType()``)
REAL_VECTOR, SE2 = 1, 4
#: the spaces ``coordinates_for`` accepts, in words
ACCEPTED = "a RealVectorStateSpace, an SE2StateSpace, or a CompoundStateSpace of RealVectorStateSpaces"


class OMPLCoordinates:
    """How the states of one OMPL state space read as the library's coordinates.

    Attributes:
        space: The OMPL state space.
        dim: d, the coordinates per state.
    """

    space: Any
    dim: int

    def bounds(self) -> np.ndarray:
        """(d, 2) array of [low, high] per coordinate."""
        raise NotImplementedError

    def library_space(self) -> Any:
        """The library's state space of these coordinates."""
        raise NotImplementedError

    def read(self, state: Any) -> list[float]:
        """The d coordinates of an OMPL state."""
        raise NotImplementedError

    def write(self, state: Any, values: Sequence[float]) -> None:
        """Set an OMPL state (allocated by ``space``) to d coordinates."""
        raise NotImplementedError

    def state(self, values: Sequence[float]) -> Any:
        """A new OMPL state (owned by Python: never ``freeState`` it) at these coordinates."""
        made = self.space.allocState()
        self.write(made, values)
        return made


class RealVectorCoordinates(OMPLCoordinates):
    """``RealVectorStateSpace(d)``: ``state[i]`` is coordinate i."""

    def __init__(self, space: Any) -> None:
        self.space, self.dim = space, int(space.getDimension())

    def bounds(self) -> np.ndarray:
        limits = self.space.getBounds()
        return np.column_stack([np.asarray(limits.low, dtype=float), np.asarray(limits.high, dtype=float)])

    def library_space(self) -> RealVectorSpace:
        return RealVectorSpace(self.dim)

    def read(self, state: Any) -> list[float]:
        return [state[axis] for axis in range(self.dim)]

    def write(self, state: Any, values: Sequence[float]) -> None:
        for axis in range(self.dim):
            state[axis] = float(values[axis])


class SE2Coordinates(OMPLCoordinates):
    """``SE2StateSpace``: (x, y, yaw) through ``getX``/``getY``/``getYaw``."""

    dim = 3

    def __init__(self, space: Any) -> None:
        self.space = space

    def bounds(self) -> np.ndarray:
        limits = self.space.getBounds()
        low, high = np.asarray(limits.low, dtype=float), np.asarray(limits.high, dtype=float)
        return np.array([[low[0], high[0]], [low[1], high[1]], [-math.pi, math.pi]])

    def library_space(self) -> SE2Space:
        return SE2Space(angle_weight=float(self.space.getSubspaceWeight(1)))

    def read(self, state: Any) -> list[float]:
        return [state.getX(), state.getY(), state.getYaw()]

    def write(self, state: Any, values: Sequence[float]) -> None:
        state.setX(float(values[0]))
        state.setY(float(values[1]))
        state.setYaw(float(values[2]))


class CompoundCoordinates(OMPLCoordinates):
    """A ``CompoundStateSpace`` of real-vector spaces: the parts' coordinates one after another."""

    def __init__(self, space: Any, parts: Sequence[RealVectorCoordinates]) -> None:
        self.space, self.parts = space, tuple(parts)
        self.dim = sum(part.dim for part in self.parts)

    def bounds(self) -> np.ndarray:
        return np.vstack([part.bounds() for part in self.parts])

    def library_space(self) -> RealVectorSpace:
        return RealVectorSpace(self.dim)

    def read(self, state: Any) -> list[float]:
        return [value for index, part in enumerate(self.parts) for value in part.read(state[index])]

    def write(self, state: Any, values: Sequence[float]) -> None:
        first = 0
        for index, part in enumerate(self.parts):
            part.write(state[index], values[first:first + part.dim])
            first += part.dim


def coordinates_for(space: Any) -> OMPLCoordinates:
    """The coordinates of an OMPL state space (by OMPL's own type number, ``getType()``).

    Args:
        space: An ``ompl.base.StateSpace``.

    Returns:
        Its ``OMPLCoordinates``.

    Raises:
        ValueError: A space other than those of ``ACCEPTED``, naming it.
    """
    kind = int(space.getType())
    if kind == REAL_VECTOR:
        return RealVectorCoordinates(space)
    if kind == SE2:
        return SE2Coordinates(space)
    compound = isinstance(space, ob.CompoundStateSpace)  # (OMPL numbers a compound space UNKNOWN, 0)
    parts = [space.getSubspace(index) for index in range(int(space.getSubspaceCount()))] if compound else []
    if parts and all(int(part.getType()) == REAL_VECTOR for part in parts):
        return CompoundCoordinates(space, [RealVectorCoordinates(part) for part in parts])
    raise ValueError(f"the library plans on {ACCEPTED} (states as rows of coordinates); got a "
                     f"{type(space).__name__} ({space.getName()!r})")

