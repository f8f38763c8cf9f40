"""OMPL's motion validation as a reachability predicate (needs the ``ompl`` extra, OMPL >= 2.0).

``OMPLMotionPredicate`` wraps an OMPL ``SpaceInformation`` on a ``RealVectorStateSpace``, an
``SE2StateSpace`` or a compound of real-vector spaces (``ompl_states``: states as coordinates):
``reachable(parents, children)`` answers, for each pair, ``si.checkMotion(parent, child)``, that
is whatever motion validator the ``SpaceInformation`` holds (OMPL's default, the
``DiscreteMotionValidator``, tests the child state and then the straight segment at interpolated
states no further apart than the space's longest valid segment length). Any planner of this library
then plans with OMPL's notion of a valid motion::

    import qrrt_circuits as qc
    from qrrt_circuits.adapters.ompl import OMPLMotionPredicate, from_environment

    predicate = OMPLMotionPredicate(si)          # an ob.SpaceInformation you built and set up
    predicate = from_environment(problem.env)    # or: OMPL checks for a qc.Environment
    result = qc.RRT(seed=0).plan(problem.replace(predicate=predicate), max_nodes=100)

Notes:

* ``reachable`` is a Python loop calling ``si.checkMotion`` once per pair, and the validity checker
  built by ``from_environment`` is a Python callback called once per interpolated state, so this
  predicate is much slower than the library's vectorized, compiled checks (``ExactCheck``,
  ``TimeSampledCheck``). It is for interoperability, not speed.
* Soundness is OMPL's: the ``DiscreteMotionValidator`` tests states at most one longest valid
  segment length L apart, so an obstacle thinner than L can be stepped over (and the parent state
  itself is assumed valid, not tested). ``describe()`` records L and reports ``"sound": None``.
* A predicate holds OMPL objects, which do not pickle: use planners in-process or with a thread
  executor, not a process pool.
* OMPL 2.0's Python states are owned by Python: never pass them to ``si.freeState`` (double free).
"""

from __future__ import annotations

import numpy as np

from .._support.validation import check_float, check_instance
from ..reachability.predicate import as_pairs
from ..world.environment import Environment

INSTALL_HINT = 'pip install "qrrt-circuits[ompl]"'

try:
    from ompl import base as ob
except ImportError as exc:  # pragma: no cover - exercised by a test that hides ompl
    raise ImportError(
        "qrrt_circuits.adapters.ompl needs the OMPL Python bindings (OMPL >= 2.0); install them with "
        f"{INSTALL_HINT}") from exc

from .ompl_states import coordinates_for  # noqa: E402  (after the hint for a missing OMPL)

__all__ = ["INSTALL_HINT", "OMPLMotionPredicate", "from_environment"]

#: OMPL's default motion validator for a real-vector space, a C++ class OMPL 2.0 does not bind:
#: Python sees it as a plain ``ob.MotionValidator``
DEFAULT_VALIDATOR = "DiscreteMotionValidator"


class OMPLMotionPredicate:
    """Reachability predicate answering ``si.checkMotion(parent, child)`` for each pair.

    ``space_information`` must be an ``ompl.base.SpaceInformation`` whose state space
    ``ompl_states.coordinates_for`` maps (a ``RealVectorStateSpace``, an ``SE2StateSpace`` or a
    compound of real-vector spaces; ``dim`` coordinates per state, ``coordinates`` reads them).
    It is set up here if it is not
    yet (``si.setup()``, as OMPL's planners do); its validity checker and motion validator are used
    as they are. ``evaluations`` counts the pairs checked through this object.

    Args:
        space_information: An ``ompl.base.SpaceInformation`` on a space ``coordinates_for`` maps.
        name: A non-empty short name recorded in every result (default ``"ompl"``).

    Raises:
        TypeError: ``space_information`` not a ``SpaceInformation``, or an empty or non-string
            ``name``.
        ValueError: A state space ``coordinates_for`` does not map, or one OMPL cannot set up
            (its bounds unset).
    """

    def __init__(self, space_information: ob.SpaceInformation, name: str = "ompl") -> None:
        if not isinstance(space_information, ob.SpaceInformation):
            raise TypeError("space_information must be an ompl.base.SpaceInformation, got "
                            f"{type(space_information).__name__}")
        if not isinstance(name, str) or not name:
            raise TypeError(f"name must be a non-empty string, got {name!r}")
        space = space_information.getStateSpace()
        self.coordinates = coordinates_for(space)
        if not space_information.isSetup():
            try:
                space_information.setup()
            except RuntimeError as exc:
                raise ValueError(f"OMPL could not set up the SpaceInformation (are the space's bounds set?): "
                                 f"{exc}") from exc
        self.si = space_information
        self.space = space
        self.name = name
        self.environment: Environment | None = None  # set by from_environment, for describe()
        self.evaluations = 0
        self._dim = self.coordinates.dim

    @property
    def dim(self) -> int:
        """d, the state space's dimension."""
        return self._dim

    def bounds(self) -> np.ndarray:
        """(d, 2) array of the state space's [low, high] per coordinate."""
        return self.coordinates.bounds()

    def is_valid(self, points: np.ndarray) -> np.ndarray:
        """Bool (M,): ``si.isValid(state)`` for each point (the space's bounds and the state
        validity checker, as OMPL tests a start or goal state).

        Args:
            points: Float (M, d) or (d,).

        Returns:
            Bool array (M,).
        """
        points = np.atleast_2d(np.asarray(points, dtype=float))
        if points.ndim != 2 or points.shape[1] != self._dim:
            raise ValueError(f"points must have shape (M, {self._dim}), got {points.shape}")
        state = self.si.allocState()
        out = np.empty(points.shape[0], dtype=np.bool_)
        for m, point in enumerate(points.tolist()):
            self.coordinates.write(state, point)
            out[m] = self.si.isValid(state) and self.si.satisfiesBounds(state)
        return out

    def motion_validator(self) -> str:
        """The class of the ``SpaceInformation``'s motion validator (a Python subclass by its name;
        OMPL's unbound C++ default by ``DEFAULT_VALIDATOR``)."""
        validator = self.si.getMotionValidator()
        if type(validator) is ob.MotionValidator:
            return DEFAULT_VALIDATOR
        return f"{type(validator).__module__}.{type(validator).__qualname__}"

    def describe(self) -> dict:
        """Name, space bounds and OMPL's motion-checking resolution; soundness unknown (None)."""
        space = self.space
        description = {
            "name": self.name,
            "library": "ompl",
            "state_space": type(space).__name__,  # not getName(): OMPL numbers unnamed spaces per process
            "dim": self._dim,
            "bounds": self.bounds().tolist(),
            "motion_validator": self.motion_validator(),
            "longest_valid_segment_fraction": float(space.getLongestValidSegmentFraction()),
            "longest_valid_segment_length": float(space.getLongestValidSegmentLength()),
            "valid_segment_count_factor": int(space.getValidSegmentCountFactor()),
            "sound": None,
        }
        if self.environment is not None:
            description["environment"] = self.environment.name
            description["validity_checker"] = "Environment.is_free"
        return description

    def reachable(self, parents: np.ndarray, children: np.ndarray) -> np.ndarray:
        """Bool (M,): ``si.checkMotion(parent, child)`` for each pair (a Python loop; see the
        module docstring). A single parent is broadcast against M children.

        Args:
            parents: Float (M, d), (1, d) or (d,).
            children: Float (M, d) or (d,).

        Returns:
            Bool array (M,); adds M to ``evaluations``.

        Raises:
            ValueError: Shapes other than (M, d), different M, or non-finite coordinates.
        """
        parents, children = as_pairs(parents, children, self._dim)
        si, write = self.si, self.coordinates.write
        parent_state, child_state = si.allocState(), si.allocState()  # owned by Python: no freeState
        out = np.empty(parents.shape[0], dtype=np.bool_)
        for m, (parent, child) in enumerate(zip(parents.tolist(), children.tolist(), strict=True)):
            write(parent_state, parent)
            write(child_state, child)
            out[m] = si.checkMotion(parent_state, child_state)
        self.evaluations += int(parents.shape[0])
        return out

    def __repr__(self) -> str:
        return (f"OMPLMotionPredicate(name={self.name!r}, d={self._dim}, "
                f"longest_valid_segment_length={self.space.getLongestValidSegmentLength():.4g})")


def real_vector_space(bounds: np.ndarray) -> ob.RealVectorStateSpace:
    """OMPL's ``RealVectorStateSpace`` with these bounds.

    Args:
        bounds: Float (d, 2), [low, high] per axis.

    Returns:
        The state space, its bounds set.
    """
    d = bounds.shape[0]
    space = ob.RealVectorStateSpace(d)
    limits = ob.RealVectorBounds(d)
    for axis in range(d):
        limits.setLow(axis, float(bounds[axis, 0]))
        limits.setHigh(axis, float(bounds[axis, 1]))
    space.setBounds(limits)
    return space


def environment_space_information(env: Environment) -> ob.SpaceInformation:
    """An OMPL ``SpaceInformation`` for ``env``: a ``RealVectorStateSpace`` with its bounds and a
    state validity checker that is ``env.is_free`` on one state (motion validation left to OMPL's
    default, or to whatever the caller installs).

    Args:
        env: The ``Environment``.

    Returns:
        The ``SpaceInformation`` (not yet set up).
    """
    d = env.dim
    si = ob.SpaceInformation(real_vector_space(env.bounds))

    def is_valid(state: ob.State) -> bool:
        return bool(env.is_free(np.array(state[0:d])))

    si.setStateValidityChecker(is_valid)
    return si


def from_environment(env: Environment, resolution: float = 0.01, name: str = "ompl") -> OMPLMotionPredicate:
    """An ``OMPLMotionPredicate`` checking straight-line motions in ``env`` with OMPL.

    Builds a ``RealVectorStateSpace`` with the environment's bounds, a ``SpaceInformation`` whose
    state validity checker is ``env.is_free`` on one state, and OMPL's default motion validator for
    such a space, the ``DiscreteMotionValidator`` (installed by ``SpaceInformation``'s constructor;
    OMPL 2.0 does not bind the class itself), with ``resolution`` as the longest valid segment
    fraction (``si.setStateValidityCheckingResolution``): states along a segment are tested at most
    ``resolution * space.getMaximumExtent()`` apart (the workspace diagonal times ``resolution``).

    Args:
        env: The ``Environment``.
        resolution: The longest valid segment fraction, in (0, 1] (default 0.01).
        name: The predicate's name (default ``"ompl"``).

    Returns:
        The ``OMPLMotionPredicate``, its ``environment`` set to ``env``.

    Raises:
        TypeError: ``env`` not an ``Environment``, or a non-real ``resolution``.
        ValueError: ``resolution`` outside (0, 1].
    """
    check_instance(env, "env", Environment, "an Environment")
    resolution = check_float(resolution, "resolution", 0.0, 1.0, open_minimum=True)
    si = environment_space_information(env)
    si.setStateValidityCheckingResolution(resolution)
    si.setup()
    predicate = OMPLMotionPredicate(si, name=name)
    predicate.environment = env
    return predicate
