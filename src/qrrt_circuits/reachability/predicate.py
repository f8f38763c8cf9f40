"""The reachability predicate: the one question every planner asks of the world (DESIGN §2, §7).

A predicate answers, for a batch of (parent, child) pairs, whether the robot can move from each
parent to its child without collision; it is what the paper's oracle evaluates. The protocol is
OMPL's motion validator (``ompl::base::MotionValidator::checkMotion``), batched:

- ``reachable(parents (M, d), children (M, d)) -> bool (M,)``;
- ``dim``: the dimension d of the states;
- ``name``: a short name recorded in every result;
- ``describe() -> dict``: the settings that fix its answers (recorded in ``PlanResult.settings``);
  a predicate that follows closed-loop dynamics puts them under the key ``"dynamics"``
  (``LinearTrackingDynamics.describe()``), so figures draw edges along the motion actually used.

A predicate may also offer, and the planners then use:

- ``can_leave(point) -> bool``: False where it is certain that it rejects every motion from
  ``point`` (the planners then refuse such a start before any work). Without it, every start is
  assumed able to leave (the stall limit ends a plan that cannot grow).
- ``is_valid(points (M, d)) -> bool (M,)``: its own state validity check (OMPL's
  ``StateValidityChecker``, batched); the planners refuse a start or goal it calls invalid, as OMPL
  refuses "no valid initial states" (``valid_states``).
- ``bounds() -> (d, 2)``: the state space it checks; the planners refuse an environment whose
  bounds reach outside it, where samples would fall outside the space (``check_within_space``).

Implementations here: ``ExactCheck`` (sound, exact up to a resolution), ``TimeSampledCheck``
(tests time samples only; unsound, for study) and, with the ``ompl`` extra,
``qrrt_circuits.adapters.ompl.OMPLMotionPredicate``. Any object with these four members works:
planners, experiments and plotting never ask which class it is.
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

import numpy as np
from numba import njit

REQUIRED_MEMBERS = ("reachable", "dim", "name", "describe")


@runtime_checkable
class ReachabilityPredicate(Protocol):
    """Batch motion validator (see the module docstring).

    The question the paper's oracle answers for every database entry (Alg. 2 / 3: the phase oracle
    marks the entries whose child is reachable from its parent; the finalizer asks it once more).
    Any object with ``dim``, ``name``, ``reachable`` and ``describe`` is one (a structural
    ``typing.Protocol``, checkable with ``isinstance``); planners pass it around without asking
    its class.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits import ReachabilityPredicate
        >>> class ShortHops:
        ...     dim = 2
        ...     name = "short-hops"
        ...     def reachable(self, parents, children):
        ...         return np.linalg.norm(children - parents, axis=1) <= 1.0
        ...     def describe(self):
        ...         return {"max_hop": 1.0}
        >>> isinstance(ShortHops(), ReachabilityPredicate)
        True
        >>> ShortHops().reachable(np.zeros((2, 2)), np.array([[0.5, 0.5], [2.0, 0.0]])).tolist()
        [True, False]
    """

    @property
    def dim(self) -> int:
        """d, the dimension of the states."""
        ...

    @property
    def name(self) -> str:
        """A short name recorded in every result."""
        ...

    def reachable(self, parents: np.ndarray, children: np.ndarray) -> np.ndarray:
        """Whether the robot can move from each parent to its child without collision.

        Args:
            parents: Float (M, d) start points.
            children: Float (M, d) targets.

        Returns:
            Bool array (M,).
        """
        ...

    def describe(self) -> dict:
        """The settings that fix the answers, JSON-able (``"dynamics"`` for closed-loop motion)."""
        ...


def check_predicate(predicate: Any, dim: int, name: str = "predicate") -> ReachabilityPredicate:
    """Return ``predicate`` if it implements the protocol in dimension ``dim``; else raise a
    ``TypeError`` naming the missing members or a ``ValueError`` naming the dimension mismatch.

    Args:
        predicate: The object to check.
        dim: The environment's dimension d.
        name: The argument's name for the error messages (default ``"predicate"``).

    Returns:
        ``predicate`` itself.

    Raises:
        TypeError: A member of ``REQUIRED_MEMBERS`` is missing.
        ValueError: ``predicate.dim != dim``.
    """
    missing = [member for member in REQUIRED_MEMBERS if not hasattr(predicate, member)]
    if missing:
        raise TypeError(
            f"{name} must implement the ReachabilityPredicate protocol (reachable(parents, children), "
            f"dim, name, describe()); {type(predicate).__name__} lacks {', '.join(missing)}")
    if predicate.dim != dim:
        raise ValueError(f"dimension mismatch: the {name} works in d = {predicate.dim}, the environment "
                         f"has d = {dim}")
    return predicate


def as_pairs(parents: np.ndarray, children: np.ndarray, dim: int) -> tuple[np.ndarray, np.ndarray]:
    """Validate and broadcast a batch of pairs to two C-contiguous float arrays of shape (M, d).

    A single parent (shape (d,) or (1, d)) is broadcast against M children. Non-finite
    coordinates are refused.

    Args:
        parents: Float (M, d), (1, d) or (d,).
        children: Float (M, d) or (d,).
        dim: d.

    Returns:
        (parents, children), both C-contiguous float (M, d).

    Raises:
        ValueError: A last axis other than d, more than 2 axes, different M (other than a single
            parent), or a non-finite coordinate.
    """
    parents = np.ascontiguousarray(parents, dtype=float)
    children = np.ascontiguousarray(children, dtype=float)
    if parents.ndim == 1:
        parents = parents.reshape(1, -1)
    if children.ndim == 1:
        children = children.reshape(1, -1)
    if parents.shape[-1] != dim or children.shape[-1] != dim or parents.ndim != 2 or children.ndim != 2:
        raise ValueError(f"parents and children must have shape (M, {dim}), got {parents.shape} and "
                         f"{children.shape}")
    if parents.shape[0] != children.shape[0] and parents.shape[0] == 1:
        parents = np.ascontiguousarray(np.broadcast_to(parents, children.shape))
    if parents.shape != children.shape:
        raise ValueError(f"parents and children must have the same shape, got {parents.shape} and "
                         f"{children.shape}")
    if not (_all_finite(parents) and _all_finite(children)):
        raise ValueError("parents and children must be finite")
    return parents, children


@njit(cache=True, nogil=True)
def _all_finite(points: np.ndarray) -> bool:
    """Whether every coordinate of the C-contiguous float (M, d) ``points`` is finite (compiled:
    one pass, no temporary array, unlike ``np.all(np.isfinite(points))``)."""
    for row in range(points.shape[0]):
        for axis in range(points.shape[1]):
            if not np.isfinite(points[row, axis]):
                return False
    return True


def check_answers(answers: Any, count: int, source: str) -> np.ndarray:
    """A predicate's (or an error model's) answers for ``count`` pairs as a bool array (M,).

    Every planner passes every batch of answers through this, so all accept and refuse the same
    answers.

    Args:
        answers: What ``reachable`` (or ``OracleErrorModel.apply``) returned: any array-like of M
            booleans or 0/1 values.
        count: M, the pairs asked.
        source: Who answered, for the error message (e.g. the predicate's name).

    Returns:
        The answers as a bool array of shape (M,) (the same array when it already is one).

    Raises:
        ValueError: Not one answer per pair (another shape), or values other than booleans or 0/1.
    """
    array = np.asarray(answers)
    if array.shape != (count,):
        raise ValueError(f"{source} answered an array of shape {array.shape} for {count} pairs: reachable must "
                         "return one bool per pair")
    if array.dtype != np.bool_:
        if not np.all(np.isin(array, (0, 1))):
            raise ValueError(f"{source} answered values other than booleans or 0/1")
        array = array.astype(bool)
    return array


def can_leave(predicate: ReachabilityPredicate, point: np.ndarray) -> bool:
    """The predicate's own ``can_leave(point)`` if it has one, else True (not decidable).

    Args:
        predicate: Any ``ReachabilityPredicate``.
        point: Float (d,), a candidate start.

    Returns:
        False only where the predicate is certain to reject every motion from ``point``.
    """
    method = getattr(predicate, "can_leave", None)
    return True if method is None else bool(method(point))


def valid_states(predicate: ReachabilityPredicate, points: np.ndarray) -> np.ndarray:
    """The predicate's own ``is_valid(points)`` if it has one, else every point valid.

    Args:
        predicate: Any ``ReachabilityPredicate``.
        points: Float (M, d).

    Returns:
        Bool (M,).

    Raises:
        ValueError: An ``is_valid`` whose answer is not M booleans.
    """
    points = np.atleast_2d(np.asarray(points, dtype=float))
    method = getattr(predicate, "is_valid", None)
    if method is None:
        return np.ones(points.shape[0], dtype=bool)
    answers = np.asarray(method(points))
    if answers.shape != (points.shape[0],):
        raise ValueError(f"{predicate.name}.is_valid must return {points.shape[0]} booleans for "
                         f"{points.shape[0]} points, got shape {answers.shape}")
    return answers.astype(bool)


def check_within_space(predicate: ReachabilityPredicate, bounds: np.ndarray) -> None:
    """Refuse (``ValueError``) environment ``bounds`` that reach outside the predicate's own state
    space (its ``bounds()``, if it has one): the planners sample inside the environment's bounds,
    so such samples would be states the predicate does not model.

    Args:
        predicate: Any ``ReachabilityPredicate``.
        bounds: Float (d, 2), the environment's [low, high] per axis.

    Raises:
        ValueError: Naming both boxes, when ``bounds`` is not inside the predicate's.
    """
    method = getattr(predicate, "bounds", None)
    if method is None:
        return
    space = np.asarray(method() if callable(method) else method, dtype=float)
    bounds = np.asarray(bounds, dtype=float)
    if space.shape != bounds.shape:
        raise ValueError(f"{predicate.name}.bounds() must be a (d, 2) array matching the environment's "
                         f"{bounds.shape}, got shape {space.shape}")
    if np.any(bounds[:, 0] < space[:, 0]) or np.any(bounds[:, 1] > space[:, 1]):
        raise ValueError(f"the environment's bounds {bounds.tolist()} reach outside the {predicate.name} "
                         f"check's state space {space.tolist()}: the planners would sample states it does "
                         "not model (build the environment with bounds inside the space)")
