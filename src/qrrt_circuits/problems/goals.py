"""Goals: where a plan ends (OMPL's ``ompl::base::Goal``), as a protocol and two built-in goals.

A goal answers, for a batch of states, whether each satisfies it; the first node of a plan that
does is the goal node (paper Algorithms 1-4 end when a node lands in the goal ball). A goal may
also draw states in itself (``sample(count, rng)``, OMPL's ``GoalSampleableRegion``): the planners'
``goal_bias`` draws candidates there. A goal with no volume (``has_volume`` False, such as one
exact state) can only be reached through such draws, so a plan refuses it without ``goal_bias``.

- ``GoalBall(centre, radius)``: the closed ball, the paper's goal (the default built from an
  environment's goal and goal radius).
- ``GoalState(state, threshold)``: one state, satisfied within ``threshold`` (OMPL's
  ``GoalState``); its samples are the state itself.
- Any object with ``dim``, ``is_satisfied(points) -> bool (M,)`` and ``describe()`` (a region
  test of your own), with ``sample`` if it is to be drawn from.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np
from numba import njit

from .._support.validation import check_float, check_real_array

__all__ = ["Goal", "GoalBall", "GoalState", "check_goal", "first_satisfying", "in_ball", "sample_ball", "sample_goal",
           "ball_of"]

REQUIRED_MEMBERS = ("dim", "is_satisfied", "describe")


@runtime_checkable
class Goal(Protocol):
    """Where a plan ends (see the module docstring).

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits import Goal
        >>> class RightEdge:  # every state with x >= 9
        ...     dim = 2
        ...     def is_satisfied(self, points):
        ...         return points[:, 0] >= 9.0
        ...     def describe(self):
        ...         return {"kind": "x >= 9"}
        >>> isinstance(RightEdge(), Goal)
        True
    """

    @property
    def dim(self) -> int:
        """d, the dimension of the states."""
        ...

    def is_satisfied(self, points: np.ndarray) -> np.ndarray:
        """Whether each state satisfies the goal.

        Args:
            points: Float (M, d).

        Returns:
            Bool (M,).
        """
        ...

    def describe(self) -> dict:
        """The goal as JSON-able settings (recorded in ``PlanResult.settings["goal_region"]``)."""
        ...


@njit(cache=True, nogil=True)
def in_ball(points: np.ndarray, centre: np.ndarray, radius: float) -> np.ndarray:
    """Bool (M,): whether each row of ``points`` lies in the closed ball of ``radius`` around
    ``centre``: the goal test of the paper's Algorithms 1-4.

    The distance is sqrt(sum over the axes, in order, of (x_i - c_i)^2), each operation rounded
    once, so the answer is the same on every machine. ``np.linalg.norm(x - c)`` would take its dot
    product from the BLAS, whose kernels may fuse a multiply and an add depending on the machine,
    so a node within a rounding error of the goal radius could count as in on one machine and out
    on another."""
    out = np.empty(points.shape[0], dtype=np.bool_)
    for row in range(points.shape[0]):
        squared = 0.0
        for axis in range(points.shape[1]):
            offset = points[row, axis] - centre[axis]
            squared += offset * offset
        out[row] = np.sqrt(squared) <= radius
    return out


def sample_ball(centre: np.ndarray, radius: float, count: int, rng: np.random.Generator) -> np.ndarray:
    """``count`` points uniform in the d-ball of ``radius`` around ``centre``.

    A Gaussian direction, normalised, scaled by ``radius * u^(1/d)`` with u uniform in [0, 1).

    Args:
        centre: Float (d,), the ball's centre.
        radius: The ball's radius.
        count: Number of points.
        rng: The generator of the draws.

    Returns:
        Float array (count, d).
    """
    d = centre.shape[0]
    direction = rng.normal(size=(count, d))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    return centre + direction * radius * rng.random(count)[:, None] ** (1.0 / d)


def _point(value: Any, name: str) -> np.ndarray:
    point = check_real_array(value, name).reshape(-1)
    if point.size == 0 or not np.all(np.isfinite(point)):
        raise ValueError(f"{name} must be d >= 1 finite numbers, got {point.tolist()}")
    point.setflags(write=False)
    return point


@dataclass(frozen=True, eq=False)
class GoalBall:
    """The closed ball of ``radius`` around ``centre``: the paper's goal.

    Args:
        centre: Float (d,), finite.
        radius: A finite number > 0.

    Raises:
        TypeError: A non-real ``centre`` or ``radius``.
        ValueError: A non-finite ``centre``, or a ``radius`` that is not finite and > 0.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits import GoalBall
        >>> GoalBall([9, 9], 1.0).is_satisfied(np.array([[9.5, 9.0], [7.0, 9.0]])).tolist()
        [True, False]
    """

    centre: np.ndarray
    radius: float
    has_volume = True

    def __post_init__(self) -> None:
        object.__setattr__(self, "centre", _point(self.centre, "goal"))
        object.__setattr__(self, "radius", check_float(self.radius, "goal_radius", 0.0, open_minimum=True))

    @property
    def dim(self) -> int:
        """d."""
        return int(self.centre.shape[0])

    def is_satisfied(self, points: np.ndarray) -> np.ndarray:
        """Bool (M,): within ``radius`` of ``centre`` (``in_ball``: the same bits on every machine)."""
        return in_ball(np.ascontiguousarray(np.atleast_2d(points), dtype=float), self.centre, self.radius)

    def sample(self, count: int, rng: np.random.Generator) -> np.ndarray:
        """``count`` states uniform in the ball (``sample_ball``)."""
        return sample_ball(self.centre, self.radius, count, rng)

    def describe(self) -> dict:
        return {"kind": "ball", "centre": self.centre.tolist(), "radius": self.radius}

    def __repr__(self) -> str:
        return f"GoalBall(centre={self.centre.tolist()}, radius={self.radius})"


@dataclass(frozen=True, eq=False)
class GoalState:
    """One state, satisfied within ``threshold`` (OMPL's ``GoalState``); it has no volume, so a
    plan reaches it only through goal-biased draws (``goal_bias > 0``), which are the state itself.

    Args:
        state: Float (d,), finite.
        threshold: The distance within which a state satisfies the goal, a finite number >= 0
            (default 1e-9).

    Raises:
        TypeError: A non-real ``state`` or ``threshold``.
        ValueError: A non-finite ``state``, or a negative or non-finite ``threshold``.
    """

    state: np.ndarray
    threshold: float = 1e-9
    has_volume = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "state", _point(self.state, "goal"))
        object.__setattr__(self, "threshold", check_float(self.threshold, "threshold", 0.0))

    @property
    def dim(self) -> int:
        """d."""
        return int(self.state.shape[0])

    def is_satisfied(self, points: np.ndarray) -> np.ndarray:
        """Bool (M,): within ``threshold`` of ``state``."""
        return in_ball(np.ascontiguousarray(np.atleast_2d(points), dtype=float), self.state, self.threshold)

    @property
    def centre(self) -> np.ndarray:
        """``state`` (the goal as a ball of radius ``threshold``)."""
        return self.state

    @property
    def radius(self) -> float:
        """``threshold``."""
        return self.threshold

    def sample(self, count: int, rng: np.random.Generator) -> np.ndarray:
        """The state, ``count`` times (``rng`` unused)."""
        return np.repeat(self.state[None], count, axis=0)

    def describe(self) -> dict:
        return {"kind": "state", "state": self.state.tolist(), "threshold": self.threshold}

    def __repr__(self) -> str:
        return f"GoalState(state={self.state.tolist()}, threshold={self.threshold})"


def sample_goal(goal: Goal, count: int, rng: np.random.Generator) -> np.ndarray:
    """``count`` states drawn in ``goal`` by its ``sample`` (the goal-biased candidates).

    Args:
        goal: A ``Goal`` with ``sample(count, rng)`` (``check_goal`` ensures it where
            ``goal_bias > 0``).
        count: How many states.
        rng: The generator of the draws.

    Returns:
        Float (count, d).

    Raises:
        TypeError: A goal without ``sample``.
        ValueError: A ``sample`` whose answer is not (count, d).
    """
    method = getattr(goal, "sample", None)
    if method is None:
        raise TypeError(f"{type(goal).__name__} has no sample(count, rng): it cannot be drawn from")
    states = np.asarray(method(count, rng), dtype=float)
    if states.shape != (count, goal.dim):
        raise ValueError(f"the goal's sample must return shape ({count}, {goal.dim}), got {states.shape}")
    return states


def ball_of(goal: Goal) -> tuple[np.ndarray, float] | None:
    """(centre, radius) of a goal that is a ball (it has ``centre`` and ``radius``: ``GoalBall``,
    ``GoalState``), else None: what results record as ``goal`` and ``goal_radius`` and plots draw.

    Args:
        goal: Any ``Goal``.

    Returns:
        The centre as a float (d,) array and the radius, or None.
    """
    centre, radius = getattr(goal, "centre", None), getattr(goal, "radius", None)
    if centre is None or radius is None:
        return None
    return np.asarray(centre, dtype=float).reshape(-1), float(radius)


def satisfying(goal: Goal, points: np.ndarray) -> np.ndarray:
    """Bool (M,): which rows of ``points`` satisfy ``goal`` (its ``is_satisfied``, checked).

    Args:
        goal: Any ``Goal``.
        points: Float (M, d) or (d,).

    Returns:
        Bool (M,).

    Raises:
        ValueError: An ``is_satisfied`` whose answer is not M booleans.
    """
    points = np.atleast_2d(points)
    answers = np.asarray(goal.is_satisfied(points))
    if answers.shape != (points.shape[0],):
        raise ValueError(f"the goal's is_satisfied must return {points.shape[0]} booleans for {points.shape[0]} "
                         f"points, got shape {answers.shape}")
    if answers.dtype != np.bool_ and (answers.dtype.kind not in "iuf" or not np.isin(answers, (0, 1)).all()):
        raise ValueError(f"the goal's is_satisfied must return booleans (or 0 / 1), got {answers!r:.60}")
    return answers.astype(bool)


def first_satisfying(goal: Goal, points: np.ndarray) -> int:
    """The first row of ``points`` that satisfies ``goal`` (``satisfying``), or -1.

    Args:
        goal: Any ``Goal``.
        points: Float (M, d).

    Returns:
        The row, or -1.

    Raises:
        ValueError: An ``is_satisfied`` whose answer is not M booleans.
    """
    hits = np.flatnonzero(satisfying(goal, points))
    return int(hits[0]) if hits.size else -1


def check_goal(goal: Any, dim: int) -> Goal:
    """Return ``goal`` if it implements the ``Goal`` protocol in dimension ``dim``.

    Args:
        goal: The object to check.
        dim: The environment's d.

    Returns:
        ``goal`` itself.

    Raises:
        TypeError: A member of the protocol missing.
        ValueError: A dimension mismatch.
    """
    missing = [member for member in REQUIRED_MEMBERS if not hasattr(goal, member)]
    if missing:
        raise TypeError(f"goal must be d numbers or a Goal (dim, is_satisfied(points), describe()); "
                        f"{type(goal).__name__} lacks {', '.join(missing)}")
    if goal.dim != dim:
        raise ValueError(f"dimension mismatch: the goal has d = {goal.dim}, the environment has d = {dim}")
    return goal


def check_reachable_by(goal: Goal, goal_bias: float) -> Goal:
    """Return ``goal`` if a planner with ``goal_bias`` can end in it: with ``sample`` where
    ``goal_bias > 0``, and drawable where it has no volume.

    Args:
        goal: A checked ``Goal``.
        goal_bias: The planner's goal bias.

    Returns:
        ``goal`` itself.

    Raises:
        TypeError: ``sample`` missing with ``goal_bias > 0``.
        ValueError: A goal without volume and ``goal_bias == 0``.
    """
    if goal_bias > 0 and not hasattr(goal, "sample"):
        raise TypeError(f"goal_bias = {goal_bias} draws candidates in the goal, but {type(goal).__name__} has no "
                        "sample(count, rng): give it one, or goal_bias = 0")
    if goal_bias == 0 and not getattr(goal, "has_volume", True):
        raise ValueError(f"goal_bias = 0, but the goal {goal!r} has no volume: a uniform sample lands in it with "
                         "probability 0, so the plan could never end there; give goal_bias > 0 (OMPL's RRT "
                         "uses 0.05) or a goal with volume (GoalBall)")
    return goal
