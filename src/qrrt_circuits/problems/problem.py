"""A planning problem as one value (OMPL's ``ProblemDefinition`` with its ``SpaceInformation``):
the world, the state space, the motion check, the start and the goal, checked once when built.

Every planner plans a ``Problem`` (``planner.plan(problem, termination, *, budgets)``); the
scenarios (``problems.scenarios``), the problem families and files (``problems.families``), the
image worlds and OMPL setups (``adapters.ompl_planning.problem_from_setup``) build one.

- ``env``: the workspace bounds and, for box worlds, the boxes (the geometry the paper's exact
  check, the plots and the coherent oracle read); a world whose check lives elsewhere (an image,
  an OMPL setup) has no boxes.
- ``space``: the ``StateSpace`` whose metric picks nearest nodes and steers candidates.
- ``predicate``: the ``ReachabilityPredicate`` that decides whether a motion is free (paper §III:
  the reachability check every oracle call evaluates).
- ``start``: the root of the tree, a valid state inside the workspace that some motion can leave.
- ``goal``: a ``Goal`` (``GoalBall``: the paper's goal ball).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._support.json_files import dumps
from .._support.validation import check_float, check_instance, check_real_array
from ..reachability.dynamics import LinearTrackingDynamics
from ..reachability.exact import ExactCheck
from ..reachability.predicate import (
    ReachabilityPredicate,
    can_leave,
    check_predicate,
    check_within_space,
    valid_states,
)
from ..world.environment import Environment
from ..world.spaces import RealVectorSpace, StateSpace
from .goals import Goal, GoalBall, ball_of, check_goal, first_satisfying

__all__ = ["SPACE_MEMBERS", "Problem", "check_space"]

#: the members a state space must have (``world.spaces.StateSpace``)
SPACE_MEMBERS = ("dim", "distance", "interpolate", "nearest_neighbors", "check_bounds", "describe")


def check_space(space: Any, env: Environment) -> StateSpace:
    """``space`` if it implements ``StateSpace`` in ``env``'s dimension and accepts its bounds.

    Raises:
        TypeError: A member of ``SPACE_MEMBERS`` missing.
        ValueError: A dimension mismatch, or bounds the space refuses (``check_bounds``).
    """
    missing = [member for member in SPACE_MEMBERS if not hasattr(space, member)]
    if missing:
        raise TypeError(f"space must be a StateSpace (RealVectorSpace, SE2Space, ...); {type(space).__name__} lacks "
                        f"{', '.join(missing)}")
    if space.dim != env.dim:
        raise ValueError(f"dimension mismatch: the space has d = {space.dim}, the environment has d = {env.dim}")
    space.check_bounds(env.bounds)
    return space


def _check_description(owner: str, description: Any) -> dict:
    """``description`` if it is a dict with string keys that JSON can write (what ``describe()``
    must return: results record it as JSON)."""
    if not isinstance(description, dict) or not all(isinstance(key, str) for key in description):
        raise TypeError(f"{owner}.describe() must return a dict with string keys (it is recorded in every "
                        f"result), got {type(description).__name__}: {description!r:.80}")
    try:
        dumps(description)
    except (TypeError, ValueError, RecursionError) as exc:
        raise TypeError(f"{owner}.describe() must return JSON-able values (it is recorded in every result): "
                        f"{exc}") from None
    return description


def _check_dim(owner: str, dim: Any) -> None:
    """``dim`` must be an int (not a bool)."""
    if isinstance(dim, bool) or not isinstance(dim, int | np.integer):
        raise TypeError(f"{owner}.dim must be an int, got {type(dim).__name__}: {dim!r:.40}")


def _probe_space(space: StateSpace, start: np.ndarray) -> None:
    """Call every member of the space on the start (a zero-length motion) and check what each
    returns, so that a space that returns the wrong kind of value fails here and not after rounds
    of planning: ``distance`` one finite distance >= 0 per pair, ``interpolate`` one finite state
    per pair, ``nearest_neighbors()`` a structure with ``size``, ``add`` and ``nearest`` that
    finds the one point it holds."""
    pair = start[None]
    distance = np.asarray(space.distance(pair, pair))
    numeric = distance.dtype.kind in "iuf"
    if distance.shape != (1,) or not numeric or not (np.isfinite(distance) & (distance >= 0)).all():
        raise TypeError(f"space.distance(states, others) must return one finite distance >= 0 per pair (float (M,)), "
                        f"got {distance!r:.80} for one pair")
    middle = np.asarray(space.interpolate(pair, pair, np.array([0.5])))
    if middle.shape != pair.shape or middle.dtype.kind not in "iuf" or not np.isfinite(middle).all():
        raise TypeError(f"space.interpolate(origins, targets, fraction) must return one finite state per pair "
                        f"(float (M, {start.shape[0]})), got {middle!r:.80} for one pair")
    structure = space.nearest_neighbors()
    missing = [member for member in ("size", "add", "nearest") if not hasattr(structure, member)]
    if missing:
        raise TypeError(f"space.nearest_neighbors() must return a NearestNeighbors structure (size, add(points), "
                        f"nearest(queries)); {type(structure).__name__} lacks {', '.join(missing)}")
    structure.add(pair)
    found = np.asarray(structure.nearest(pair))
    if found.shape != (1,) or found.dtype.kind not in "iu" or int(found[0]) != 0 or structure.size != 1:
        raise TypeError(f"space.nearest_neighbors(): after add(one point), nearest(that point) must return the "
                        f"int array [0] and size 1, got {found!r:.60} and size {structure.size!r:.20}")


def _checked_point(name: str, point: Any, env: Environment, predicate: ReachabilityPredicate) -> np.ndarray:
    """``point`` as d finite coordinates inside the bounds, free of the environment's boxes and
    valid under the predicate's own validity check (``is_valid``)."""
    if point is None or isinstance(point, str | bytes):
        raise ValueError(f"{name} must be {env.dim} numbers, got {point!r}")
    try:
        point = check_real_array(point, name).reshape(-1)  # booleans and strings refused
    except ValueError as exc:
        raise ValueError(f"{name} must be {env.dim} numbers, got {point!r}") from exc
    if point.shape != (env.dim,):
        raise ValueError(f"dimension mismatch: {name} has {point.shape[0]} coordinates, the environment "
                         f"has d = {env.dim}")
    if not np.all(np.isfinite(point)):
        raise ValueError(f"{name} must be finite, got {point.tolist()}")
    if not env.in_bounds(point):
        raise ValueError(f"{name} {point.tolist()} is out of bounds {env.bounds.tolist()}")
    if not env.is_free(point):
        raise ValueError(f"{name} {point.tolist()} is in collision with an obstacle")
    if not valid_states(predicate, point[None])[0]:
        raise ValueError(f"{name} {point.tolist()} is not a valid state: the {predicate.name} "
                         f"check's own validity check (is_valid) rejects it")
    return np.array(point, dtype=float)


@dataclass(frozen=True, eq=False)
class Problem:
    """A planning problem: world, state space, motion check, start and goal, checked when built.

    Build one with ``Problem.build`` (a goal point and radius, the default exact check) or
    directly from its parts; ``dataclasses.replace(problem, predicate=...)`` gives a checked copy
    with one part changed.

    Args:
        env: The ``Environment`` (bounds and boxes).
        start: The root of the tree, d numbers.
        goal: A ``Goal`` in dimension d (``GoalBall``, ``GoalState`` or a region of your own with
            ``dim``, ``is_satisfied(points)`` and ``describe()``).
        predicate: The ``ReachabilityPredicate`` of motions (its ``dim`` is d; ``describe()``
            returns a dict).
        space: The ``StateSpace`` (its ``dim`` is d and it accepts the bounds).
        name: The problem's name (default: the environment's).

    Every member of the space, goal and predicate protocols is checked here with the type of what
    it returns, on a probe at the start (``dim`` an int; ``describe()`` a JSON-able dict; the
    space's ``distance``, ``interpolate`` and ``nearest_neighbors`` on a zero-length motion; the
    goal's ``is_satisfied`` and the predicate's ``is_valid`` and ``can_leave`` at the start), so a
    wrong one fails before any planning. The predicate's ``reachable`` is not called here (every
    call is an oracle call, DESIGN §2): its answers are checked on every batch from the first
    round's (``predicate.check_answers``).

    Raises:
        TypeError: ``env`` not an ``Environment``, a predicate, space or goal that lacks a member
            of its protocol, whose ``dim`` is not an int, whose ``describe()`` returns no
            JSON-able dict, or a space member that returns the wrong kind of value on the probe.
        ValueError: A dimension mismatch; a start or a ball goal's centre that is not d finite
            numbers, out of bounds, inside a box or rejected by the predicate's validity check;
            a start on the workspace boundary that the predicate can never leave (unless it already
            satisfies the goal).
    """

    env: Environment
    start: np.ndarray
    goal: Goal
    predicate: ReachabilityPredicate
    space: StateSpace
    name: str = ""

    def __post_init__(self) -> None:
        env = check_instance(self.env, "env", Environment, "an Environment")
        for owner, member in (("predicate", self.predicate), ("space", self.space), ("goal", self.goal)):
            if hasattr(member, "dim"):
                _check_dim(owner, member.dim)
        predicate = check_predicate(self.predicate, env.dim)
        check_within_space(predicate, env.bounds)
        if not isinstance(predicate.name, str):
            raise TypeError(f"predicate.name must be a string, got {predicate.name!r}")
        _check_description("predicate", predicate.describe())
        space = check_space(self.space, env)
        _check_description("space", space.describe())
        start = _checked_point("start", self.start, env, predicate)
        _probe_space(space, start)
        goal = check_goal(self.goal, env.dim)  # the protocol; whether a planner can end in it is its own check
        _check_description("goal", goal.describe())
        ball = ball_of(goal)
        if ball is not None:  # a ball's centre (a goal state) must be a valid point
            _checked_point("goal", ball[0], env, predicate)
        reached = first_satisfying(goal, start[None]) == 0  # a start in the goal ends at once
        if not reached and not can_leave(predicate, start):
            raise ValueError(
                f"start {start.tolist()} lies on the workspace boundary {env.bounds.tolist()}: the "
                f"{predicate.name} check rejects every motion from it, so no node could ever be "
                "added (move the start inside the workspace)")
        start.flags.writeable = False
        object.__setattr__(self, "start", start)
        if not isinstance(self.name, str):
            raise TypeError(f"name must be a string, got {self.name!r}")
        object.__setattr__(self, "name", self.name or env.name)

    @classmethod
    def build(cls, env: Environment, start: Any, goal: Goal | Any, goal_radius: float | None = None, *,
              predicate: ReachabilityPredicate | None = None, dynamics: LinearTrackingDynamics | None = None,
              resolution: float = 0.01, space: StateSpace | None = None, name: str = "") -> Problem:
        """The problem of ``env`` from ``start`` to a goal point (a ball of ``goal_radius``) or a
        ``Goal``, with the sound exact check by default.

        Args:
            env: The world.
            start: d numbers.
            goal: d numbers (the centre of a ball of ``goal_radius``) or a ``Goal``.
            goal_radius: The goal ball's radius (> 0, finite) with a goal point; not given with a
                ``Goal`` (it carries its own extent).
            predicate: The motion check, or None (default) for ``ExactCheck(env, dynamics,
                resolution=resolution)``: sound up to the clearance ``resolution``.
            dynamics: A ``LinearTrackingDynamics`` for the default check (default
                ``LinearTrackingDynamics.paper()``); not given with ``predicate`` (a predicate
                carries its own motion model).
            resolution: The default check's clearance in length units (> 0, finite; default 0.01);
                unused with ``predicate``.
            space: The state space, or None (default) for ``RealVectorSpace(env.dim)`` (the
                paper's Euclidean metric).
            name: The problem's name (default the environment's).

        Returns:
            The checked problem.

        Raises:
            TypeError: An argument of the wrong type.
            ValueError: ``goal_radius`` missing with a goal point or given with a ``Goal``, both
                ``predicate`` and ``dynamics``, a dimension mismatch, or what ``Problem`` refuses.
        """
        check_instance(env, "env", Environment, "an Environment")
        if predicate is None:
            if dynamics is not None:
                check_instance(dynamics, "dynamics", LinearTrackingDynamics, "a LinearTrackingDynamics")
                if dynamics.dim != env.dim:
                    raise ValueError(f"dimension mismatch: the dynamics act in d = {dynamics.dim}, the "
                                     f"environment has d = {env.dim}")
            predicate = ExactCheck(env, dynamics, resolution=resolution)
        elif dynamics is not None:
            raise ValueError("give dynamics= or predicate=, not both (a predicate carries its own motion model)")
        check_predicate(predicate, env.dim)  # (before the goal point is checked with it)
        if isinstance(goal, Goal):
            if goal_radius is not None:
                raise ValueError("goal_radius is given with a goal point, not with a Goal object "
                                 f"({type(goal).__name__} carries its own extent)")
            region = goal
        else:
            if goal_radius is None:
                raise ValueError("goal_radius is required with a goal point (a ball's radius, > 0)")
            region = GoalBall(_checked_point("goal", goal, env, predicate),
                              check_float(goal_radius, "goal_radius", 0.0, open_minimum=True))
        return cls(env, start, region, predicate, RealVectorSpace(env.dim) if space is None else space, name)

    @property
    def dim(self) -> int:
        """d, the dimension of the states."""
        return self.env.dim

    def replace(self, **changes: Any) -> Problem:
        """A checked copy with the given fields changed (``dataclasses.replace``).

        Args:
            **changes: New values of fields (``start``, ``goal``, ``predicate``, ``space``, ...).

        Returns:
            The new problem, checked as when built.
        """
        return dataclasses.replace(self, **changes)

    def with_goal_radius(self, radius: float) -> Problem:
        """The same problem with a goal ball of ``radius`` about the goal's centre (a radius of
        1e-9 grows a tree that in effect never reaches the goal: tree-size experiments).

        Args:
            radius: The new radius (> 0, finite).

        Returns:
            The checked problem.

        Raises:
            ValueError: A goal that is not a ball (no centre), or a radius that is not > 0.
        """
        ball = ball_of(self.goal)
        if ball is None:
            raise ValueError(f"with_goal_radius needs a ball goal (a centre and a radius), got {self.goal!r}")
        return self.replace(goal=GoalBall(ball[0], check_float(radius, "radius", 0.0, open_minimum=True)))

    def describe(self) -> dict:
        """What results record of the problem: its name, start, goal and environment.

        Returns:
            A JSON-able dict.
        """
        ball = ball_of(self.goal)
        return {"problem": self.name, "environment": self.env.name, "start": self.start.tolist(),
                "goal": None if ball is None else ball[0].tolist(), "goal_radius": None if ball is None else ball[1],
                "goal_region": self.goal.describe()}

    def __repr__(self) -> str:
        return (f"Problem({self.name!r}, d={self.dim}, start={self.start.tolist()}, goal={self.goal!r}, "
                f"predicate={self.predicate.name!r}, space={type(self.space).__name__})")
