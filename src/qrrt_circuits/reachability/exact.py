"""The sound reachability predicate (the oracle's truth, DESIGN §2).

Candidate (c, p) is reachable iff the closed-loop trajectory x(t) = c + expm(M t)(p - c),
t in [0, T], stays in the workspace and outside every obstacle. The check is conservative at a
documented ``resolution`` (default 0.01 length units): any trajectory that touches an obstacle is
rejected, and a collision-free one is only rejected if it passes within
(1 + sqrt(d)) * ``resolution`` of an obstacle or 2 * ``resolution`` of the workspace boundary
(``ExactCheck.false_rejection_bound``; the derivation is in ``qrrt_circuits.reachability.collision``).

``ExactCheck`` implements the ``ReachabilityPredicate`` protocol
(``qrrt_circuits.reachability.predicate``).
"""

from __future__ import annotations

import math

import numpy as np

from .._support.validation import check_positive_float
from ..world.environment import Environment
from .collision import trajectories_free
from .dynamics import MAX_PROPAGATOR_BYTES, LinearTrackingDynamics
from .predicate import as_pairs

__all__ = ["ExactCheck"]


def chord_grid(
    dynamics: LinearTrackingDynamics, max_error: float, resolution: float, limit: int | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The check's time grid, per-chord curvature bounds and propagators expm(M t_i).

    ``dynamics.curvature_bound_times(max_error, resolution)`` and ``dynamics.propagators`` of its
    times, a pure function of M = A - B K, T, ``max_error`` and ``resolution``: computed once per
    process for each distinct set and shared by every predicate built on it (an experiment builds
    one predicate per trial). Fresh copies are returned, so the caller owns them. With a
    ``limit``, a grid not yet computed is first estimated (``chord_count_estimate``) and refused if
    it would have more than ``limit`` chords (and ``curvature_bound_times`` stops at twice that).

    Args:
        dynamics: The ``LinearTrackingDynamics`` (its closed loop M and horizon T).
        max_error: The largest tracking error ``|e|`` the grid covers.
        resolution: The chord error the grid keeps below.
        limit: The most chords accepted, or None for no limit.

    Returns:
        (times, bounds, propagators): shapes (K + 1,), (K,) and (K + 1, d, d), C-contiguous.

    Raises:
        ValueError: More than ``limit`` chords (the message gives the finest resolution that fits).
    """
    closed = np.ascontiguousarray(dynamics.closed_loop, dtype=float)
    key = (closed.tobytes(), closed.shape, dynamics.horizon, float(max_error), float(resolution))
    grid = _CHORD_GRIDS.get(key)
    if grid is None:
        if limit is not None:
            if limit < _FEWEST_CHORDS_BOUND:  # even the coarsest grid's d x d propagators do not fit
                dim = closed.shape[0]
                raise ValueError(f"an exact check in d = {dim} needs at least 17 propagators of d x d doubles "
                                 f"({17 * 8 * dim * dim / 2**20:.0f} MiB), more than MAX_PROPAGATOR_BYTES "
                                 f"({MAX_PROPAGATOR_BYTES >> 20} MiB) allows")
            estimate = _chords_bound(dynamics, max_error, resolution)
            if estimate > limit:
                raise ValueError(
                    f"resolution = {resolution:g} on a workspace {max_error / 1.0001:.6g} across needs up to about "
                    f"{estimate:.3g} chords per trajectory (bounded by the estimate / 0.7), more than the {limit} "
                    "allowed (MAX_CHORDS, and MAX_PROPAGATOR_BYTES of d x d propagators): use a resolution of at "
                    f"least {_finest_fitting(dynamics, max_error, resolution, limit):.3g}, or a smaller workspace")
        times, bounds = dynamics.curvature_bound_times(max_error, resolution,
                                                       max_intervals=None if limit is None else 2 * limit)
        grid = (times, bounds, np.ascontiguousarray(dynamics.propagators(times)))
        if len(_CHORD_GRIDS) >= _CHORD_GRIDS_KEPT:
            _CHORD_GRIDS.clear()
        _CHORD_GRIDS[key] = grid
    return grid[0].copy(), grid[1].copy(), grid[2].copy()


#: the most chords (time-grid intervals) one exact check's trajectories are cut into; building the
#: grid computes one ``expm`` per chord, so this bounds its build time
MAX_CHORDS = 100_000


def max_chords(dim: int) -> int:
    """The chord limit in d = ``dim`` dimensions: ``MAX_CHORDS``, or fewer where their propagators
    would exceed ``MAX_PROPAGATOR_BYTES``."""
    return max(1, min(MAX_CHORDS, MAX_PROPAGATOR_BYTES // (8 * dim * dim) - 1))


#: the bound ``_chords_bound`` never goes below: the grid's longest step is T / 16, so 16 chords / 0.7
_FEWEST_CHORDS_BOUND = 16 / 0.7


def _chords_bound(dynamics: LinearTrackingDynamics, max_error: float, resolution: float) -> float:
    """``chord_count_estimate`` / 0.7: the grid's steps are ``max_step`` x 0.7^j, so it has at most
    1 / 0.7 times the estimated chords (tested)."""
    return dynamics.chord_count_estimate(max_error, resolution) / 0.7


def _finest_fitting(dynamics: LinearTrackingDynamics, max_error: float, resolution: float, limit: int) -> float:
    """A resolution (rounded up to 3 significant digits) whose chord bound is within ``limit``:
    chords grow as 1 / sqrt(resolution) where the grid's longest step does not cap them, so the
    resolution is scaled by (bound / limit)^2 until the bound fits."""
    for _ in range(64):
        bound = _chords_bound(dynamics, max_error, resolution)
        if bound <= limit:
            break
        resolution *= max((bound / limit) ** 2, 1.01)
        unit = 10.0 ** (math.floor(math.log10(resolution)) - 2)
        resolution = math.ceil(resolution / unit) * unit
    return resolution


_ChordGridKey = tuple[bytes, tuple[int, ...], float, float, float]
_CHORD_GRIDS: dict[_ChordGridKey, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
_CHORD_GRIDS_KEPT = 64


class ExactCheck:
    """The sound reachability predicate (DESIGN §2): the truth the quantum oracle marks by.

    A pair (p, c) is reachable iff x(t) = c + expm((A - BK) t)(p - c), t in [0, T], stays in the
    workspace and outside every obstacle. The trajectory is cut into chords on a time grid fine
    enough that the curve stays within ``resolution`` of each chord (``curvature_bound_times``),
    and each chord is tested exactly against the boxes padded by its error bound, through the
    environment's grid index (``collision.trajectories_free``). So every colliding trajectory is
    rejected, and a free one is only rejected if it passes within ``false_rejection_bound``:
    (1 + sqrt(d)) * ``resolution`` of an obstacle, or 2 * ``resolution`` of the boundary.

    ``evaluations`` counts predicate evaluations (pairs) made through this object. Planners do
    their own oracle-call accounting (DESIGN §2); this counter is the raw work done.

    Args:
        env: The ``Environment``.
        dynamics: ``LinearTrackingDynamics`` of the same dimension d (default: the paper's).
        resolution: The collision resolution in length units, > 0 (default 0.01).

    Attributes:
        env: The environment.
        dynamics: The dynamics.
        resolution: The resolution.
        evaluations: Pairs evaluated so far.

    Raises:
        ValueError: A dynamics dimension other than ``env.dim``, a ``resolution`` that is not a
            finite number > 0, or one so fine for the workspace's extent that the chord grid would
            exceed ``max_chords(d)`` chords (estimated by
            ``LinearTrackingDynamics.chord_count_estimate`` before it is built; the message gives
            the finest resolution that fits).
        TypeError: A non-numeric ``resolution``.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits import Environment, ExactCheck
        >>> env = Environment([[0, 10], [0, 10]], [[[4, 0], [6, 6]]])  # one wall from below
        >>> oracle = ExactCheck(env)
        >>> parents = np.array([[1.0, 8.0], [1.0, 1.0]])
        >>> children = np.array([[3.0, 8.0], [8.0, 1.0]])  # the second crosses the wall
        >>> oracle.reachable(parents, children).tolist(), oracle.evaluations
        ([True, False], 2)
    """

    name = "exact"

    def __init__(
        self,
        env: Environment,
        dynamics: LinearTrackingDynamics | None = None,
        resolution: float = 0.01,
    ) -> None:
        dynamics = LinearTrackingDynamics.paper() if dynamics is None else dynamics
        if dynamics.dim != env.dim:
            raise ValueError(
                f"dynamics dimension {dynamics.dim} does not match the environment's d = {env.dim}"
            )
        self.env = env
        self.dynamics = dynamics
        self.resolution = check_positive_float(resolution, "resolution")
        self.evaluations = 0
        extent = env.bounds[:, 1] - env.bounds[:, 0]
        max_error = float(np.linalg.norm(extent)) * 1.0001
        self._times, self._curvature, self._phis = chord_grid(dynamics, max_error, self.resolution,
                                                              max_chords(env.dim))
        self._index = env.grid_index
        self._lower = np.ascontiguousarray(env.boxes[:, 0])
        self._upper = np.ascontiguousarray(env.boxes[:, 1])
        self._bounds = np.ascontiguousarray(env.bounds)

    @property
    def dim(self) -> int:
        """d, the environment's dimension."""
        return self.env.dim

    @property
    def false_rejection_bound(self) -> dict[str, float]:
        """How close a free trajectory must pass to be rejected (the check's only error).

        Returns:
            ``{"obstacle": (1 + sqrt(d)) * resolution, "boundary": 2 * resolution}``: a free
            trajectory that stays farther than these from every obstacle and from the workspace
            boundary is accepted (derivation in ``qrrt_circuits.reachability.collision``).
        """
        return {"obstacle": (1.0 + float(np.sqrt(self.dim))) * self.resolution, "boundary": 2.0 * self.resolution}

    def describe(self) -> dict:
        """Name, resolution, ``sound: True``, the false-rejection bound and the dynamics."""
        return {"name": self.name, "resolution": self.resolution, "sound": True,
                "false_rejection_bound": self.false_rejection_bound,
                "dynamics": self.dynamics.describe()}

    def can_leave(self, point: np.ndarray) -> bool:
        """False where it is certain that no motion from ``point`` can ever be accepted: a point on
        the workspace boundary. Every chord of a trajectory to a child c != point is tested with
        the box padded by its error bound delta > 0 (``collision.trajectories_free``), and the
        bounds test is strict (x - delta < low rejects), so the first chord from a point with
        x_i = low_i or x_i = high_i is always rejected. (Inside the margin but off the boundary,
        a child close enough has a smaller delta and may pass: not decidable here; the planners'
        stall limit ends such plans.)

        Args:
            point: Float (d,), a candidate start.

        Returns:
            False for a point on the workspace boundary, else True.
        """
        point = np.asarray(point, dtype=float).reshape(-1)
        return not bool(np.any((point == self._bounds[:, 0]) | (point == self._bounds[:, 1])))

    def reachable(self, parents: np.ndarray, children: np.ndarray) -> np.ndarray:
        """May each child be reached from its parent without collision? (one evaluation per pair)

        Args:
            parents: Float array (M, d) (a single (d,) point is one pair), finite.
            children: Float array of the same shape.

        Returns:
            Bool array (M,); adds M to ``evaluations``.

        Raises:
            ValueError: Shapes other than (M, d), different shapes, or non-finite coordinates.
        """
        parents, children = as_pairs(parents, children, self.dim)
        out = np.zeros(parents.shape[0], dtype=np.bool_)
        index = self._index
        trajectories_free(
            parents, children, self._times, self._phis, self._curvature, self.resolution,
            self._bounds, self._lower, self._upper, index.origin, index.cell_size, index.shape,
            index.cell_start, index.cell_items, out,
        )
        self.evaluations += int(parents.shape[0])
        return out
