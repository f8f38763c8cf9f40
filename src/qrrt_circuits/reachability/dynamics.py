"""Closed-loop linear tracking dynamics (DESIGN §2).

The robot obeys xdot = A x + B u with the tracking law u = -K (x - c) + u_ff, where u_ff makes the
target c an equilibrium. The tracking error e = x - c obeys edot = (A - BK) e, so the motion from a
parent p towards a candidate c is

    x(t) = c + expm(M t) (p - c),   M = A - B K,   t in [0, T].

The paper prints a discrete-time update, but its closed loop A - BK = diag(-2.7, -4) is only stable
in continuous time and the authors integrate it with an ODE solver over T = 5 s; we follow the code.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm

from .._support.validation import check_float, check_int

PAPER_A = ((-1.5, -2.0), (1.0, 3.0))
PAPER_B = ((0.5, 0.25), (0.0, 1.0))
PAPER_K = ((1.9, -7.5), (1.0, 7.0))


#: the longest motion duration T accepted (time units; the paper's is 5): far beyond any closed
#: loop's settling time, and small enough that T / 16 squared and the chord grid stay finite
MAX_HORIZON = 1e6
#: the largest array of K x d x d propagators expm(M t_k) (doubles) a predicate keeps: the exact
#: check's chord grid (``oracle.max_chords``) and ``TimeSampledCheck``'s samples
MAX_PROPAGATOR_BYTES = 256 << 20


@dataclass(frozen=True, eq=False)
class LinearTrackingDynamics:
    """Closed-loop linear tracking dynamics (paper §V, DESIGN §2).

    xdot = A x + B u with u = -K (x - c) + u_ff, so the motion from a parent p towards a target c
    is x(t) = c + expm(M t)(p - c), M = A - B K, t in [0, ``horizon``]. M must be Hurwitz.

    Args:
        A: Float (d, d), d >= 1, finite.
        B: Float (d, m), finite.
        K: Float (m, d), finite.
        horizon: T, the motion's duration, in (0, ``MAX_HORIZON``] (the authors integrate over 5 s).

    Raises:
        TypeError: A, B or K not a real numeric matrix (bool included).
        ValueError: Mismatched shapes, non-finite entries, ``horizon`` outside (0, 1e6], or a closed loop
            A - B K with an eigenvalue of non-negative real part.
    """

    A: np.ndarray
    B: np.ndarray
    K: np.ndarray
    horizon: float = 5.0

    def __post_init__(self) -> None:
        for name in ("A", "B", "K"):
            raw = np.asarray(getattr(self, name))
            if raw.dtype.kind not in "biuf" or raw.dtype.kind == "b":
                raise TypeError(f"{name} must be a real numeric matrix, got dtype {raw.dtype}")
        A = np.array(self.A, dtype=float)
        B = np.array(self.B, dtype=float)
        K = np.array(self.K, dtype=float)
        if A.ndim != 2 or A.shape[0] != A.shape[1] or A.shape[0] < 1:
            raise ValueError(f"A must be a square (d, d) matrix, got shape {A.shape}")
        d = A.shape[0]
        if B.ndim != 2 or B.shape[0] != d:
            raise ValueError(f"B must have shape ({d}, m), got {B.shape}")
        if K.shape != (B.shape[1], d):
            raise ValueError(f"K must have shape ({B.shape[1]}, {d}) to match B and A, got {K.shape}")
        for name, mat in (("A", A), ("B", B), ("K", K)):
            if not np.all(np.isfinite(mat)):
                raise ValueError(f"{name} must contain only finite numbers")
        check_float(self.horizon, "horizon", 0.0, MAX_HORIZON, open_minimum=True)
        closed = A - B @ K
        eigenvalues = np.linalg.eigvals(closed)
        if np.max(eigenvalues.real) >= 0:
            raise ValueError(
                "K does not stabilise the system: the closed loop A - B K must be Hurwitz "
                f"(all eigenvalues with negative real part), got eigenvalues {np.round(eigenvalues, 6)}"
            )
        for name, mat in (("A", A), ("B", B), ("K", K)):
            mat.setflags(write=False)
            object.__setattr__(self, name, mat)
        object.__setattr__(self, "horizon", float(self.horizon))

    @classmethod
    def paper(cls, horizon: float = 5.0) -> LinearTrackingDynamics:
        """The paper's dynamics (§V): A = [[-1.5, -2], [1, 3]], B = [[0.5, 0.25], [0, 1]],
        K = [[1.9, -7.5], [1, 7]]; closed loop A - B K = diag(-2.7, -4).

        Args:
            horizon: T, in (0, ``MAX_HORIZON``] (the authors' code integrates over 5 s).

        Returns:
            The ``LinearTrackingDynamics`` in d = 2.

        Raises:
            ValueError: ``horizon`` outside (0, ``MAX_HORIZON``].
            TypeError: A non-numeric ``horizon``.
        """
        return cls(np.array(PAPER_A), np.array(PAPER_B), np.array(PAPER_K), horizon=horizon)

    @property
    def dim(self) -> int:
        """d, the state dimension."""
        return int(self.A.shape[0])

    def describe(self) -> dict:
        """A, B, K and the horizon as plain lists (recorded in every plan's settings)."""
        return {"A": self.A.tolist(), "B": self.B.tolist(), "K": self.K.tolist(), "horizon": self.horizon}

    @classmethod
    def from_description(cls, description: dict) -> LinearTrackingDynamics:
        """The inverse of ``describe``.

        Args:
            description: A dict with ``"A"``, ``"B"``, ``"K"`` (nested lists) and ``"horizon"``.

        Returns:
            The dynamics.

        Raises:
            KeyError: A missing key.
            ValueError: As the constructor (shapes, finiteness, a closed loop that is not Hurwitz).

        Example:
            >>> from qrrt_circuits import LinearTrackingDynamics
            >>> paper = LinearTrackingDynamics.paper()
            >>> LinearTrackingDynamics.from_description(paper.describe()).closed_loop.tolist()
            [[-2.7, 0.0], [0.0, -4.0]]
        """
        return cls(np.array(description["A"]), np.array(description["B"]), np.array(description["K"]),
                   horizon=description["horizon"])

    @property
    def closed_loop(self) -> np.ndarray:
        """M = A - B K."""
        return self.A - self.B @ self.K

    def propagators(self, times: np.ndarray) -> np.ndarray:
        """expm(M t) for each t: shape (len(times), d, d).

        Args:
            times: Float array of times (any shape; flattened).

        Returns:
            Float array (len(times), d, d).
        """
        times = np.asarray(times, dtype=float).reshape(-1)
        return expm(times[:, None, None] * self.closed_loop[None])

    def positions(self, parent: np.ndarray, child: np.ndarray, times: np.ndarray) -> np.ndarray:
        """x(t) = c + expm(M t)(p - c) at the given times: shape (len(times), d).

        Args:
            parent: p, (d,).
            child: c, the target, (d,).
            times: Float array of times.

        Returns:
            Float array (len(times), d).

        Raises:
            ValueError: ``parent`` or ``child`` without d coordinates.

        Example:
            >>> import numpy as np
            >>> from qrrt_circuits import LinearTrackingDynamics
            >>> x = LinearTrackingDynamics.paper().positions([1.0, 1.0], [3.0, 2.0], [0.0, 5.0])
            >>> np.round(x, 4).tolist()  # starts at p, ends (numerically) at c
            [[1.0, 1.0], [3.0, 2.0]]
        """
        parent, child = self._pair(parent, child)
        phis = self.propagators(times)
        return child + phis @ (parent - child)

    def trajectory(
        self, parent: np.ndarray, child: np.ndarray, num: int = 100, dense: int = 4000
    ) -> np.ndarray:
        """``num`` points along x(t) = c + expm(M t)(p - c), t in [0, T], evenly spaced in arc length.

        Arc length is integrated on ``dense`` time samples (``dense_times``: geometric near t = 0,
        where the motion is fastest) and inverted by linear interpolation. The ends (the parent at
        t = 0 and x(T)) are included; a motion of zero length repeats the parent.

        Args:
            parent: p, (d,) (any shape with d elements).
            child: c, the target, (d,).
            num: Points returned, 2 .. 10 000 000.
            dense: Time samples for the arc-length integration.

        Returns:
            Float array (num, d).

        Raises:
            ValueError: ``num`` out of range, or ``parent`` / ``child`` without d coordinates.
            TypeError: A non-integer ``num``.
        """
        check_int(num, "num", 2, 10_000_000)
        times = self.dense_times(dense)
        points = self.positions(parent, child, times)
        steps = np.linalg.norm(np.diff(points, axis=0), axis=1)
        length = np.concatenate([[0.0], np.cumsum(steps)])
        if length[-1] <= 0:
            return np.repeat(points[:1], int(num), axis=0)
        targets = np.linspace(0.0, length[-1], int(num))
        sample_times = np.interp(targets, length, times)
        return self.positions(parent, child, sample_times)

    def dense_times(self, count: int = 4000) -> np.ndarray:
        """Times in [0, T] that are dense where the motion is fast (a mix of linear and geometric).

        Args:
            count: About how many times (half geometric from a small first time, half linear).

        Returns:
            Sorted unique float array, starting at 0 and ending at T.
        """
        slowest = float(np.min(-np.linalg.eigvals(self.closed_loop).real))
        fastest = float(np.max(np.abs(np.linalg.eigvals(self.closed_loop))))
        first = min(self.horizon, 1e-3 / max(fastest, 1e-9))
        geometric = np.geomspace(first, self.horizon, count // 2)
        linear = np.linspace(0.0, min(self.horizon, 8.0 / max(slowest, 1e-9)), count // 2)
        return np.unique(np.concatenate([[0.0], geometric, linear, [self.horizon]]))

    def chord_count_estimate(self, max_error: float, resolution: float, max_step: float | None = None,
                             samples: int = 64) -> float:
        """About how many intervals ``curvature_bound_times(max_error, resolution, max_step)``
        makes, from ``samples`` evaluations of ``||M^2 expm(M t)||_2`` instead of one per interval:
        the integral over [0, T] of 1 / h(t), h(t) = min(``max_step``, sqrt(8 ``resolution`` /
        (``max_error`` ``||M^2 expm(M t)||``))), the interval that keeps the chord error within
        ``resolution`` (the grid's own intervals are up to 1 / 0.7 shorter, its steps being
        ``max_step`` x 0.7^j, so it has up to 1 / 0.7 times this many).

        Args:
            max_error: The largest tracking error ``|e|`` to cover.
            resolution: The chord error to keep below (> 0).
            max_step: The longest interval (default T / 16).
            samples: Evaluation times, evenly spaced (midpoints).

        Returns:
            The estimated interval count (a float).
        """
        closed = self.closed_loop
        m2 = closed @ closed
        horizon = self.horizon
        max_step = horizon / 16 if max_step is None else max_step
        width = horizon / samples
        total = 0.0
        for t in (np.arange(samples) + 0.5) * width:
            base = float(np.linalg.norm(m2 @ expm(closed * t), 2))
            curve = base * max_error
            step = max_step if curve <= 0 else min(max_step, float(np.sqrt(8 * resolution / curve)))
            total += width / step
        return total

    def curvature_bound_times(
        self, max_error: float, resolution: float, max_step: float | None = None, max_intervals: int | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """A time grid and per-interval bounds ``a_i >= max ||M^2 expm(M t)||_2`` on ``[t_i, t_{i+1}]``.

        On an interval of length h the curve stays within ``h^2/8 * |e| * a_i`` of its chord
        (interpolation error bound with ``|x''(t)| = |M^2 expm(M t) e|``). The grid is fine enough
        that this is <= ``resolution`` for every ``|e| <= max_error``; callers merge intervals for
        smaller ``|e|``. The bound uses ||expm(M s)|| <= exp(mu s), mu the logarithmic norm of M.

        Args:
            max_error: The largest tracking error ``|e| = |p - c|`` to cover.
            resolution: The chord error the grid must keep below.
            max_step: The longest interval (default T / 16).
            max_intervals: Refuse (``ValueError``) a grid of more intervals than this (default: no
                limit; callers estimate first with ``chord_count_estimate``).

        Returns:
            (times, bounds): the grid t_0 = 0 .. T and one bound a_i per interval.

        Raises:
            ValueError: More than ``max_intervals`` intervals.
        """
        closed = self.closed_loop
        mu = max(float(np.max(np.linalg.eigvalsh((closed + closed.T) / 2))), 0.0)
        m2 = closed @ closed
        horizon = self.horizon
        max_step = horizon / 16 if max_step is None else max_step
        times = [0.0]
        bounds = []
        t = 0.0
        while t < horizon - 1e-12:
            base = float(np.linalg.norm(m2 @ expm(closed * t), 2))
            step = max_step
            while True:
                a = base * np.exp(mu * step)
                if step**2 / 8 * max_error * a <= resolution or step < 1e-9:
                    break
                step *= 0.7
            step = min(step, horizon - t)
            bounds.append(base * np.exp(mu * step))
            t = t + step
            times.append(t)
            if max_intervals is not None and len(bounds) > max_intervals:
                raise ValueError(f"the chord grid needs more than {max_intervals} intervals for resolution = "
                                 f"{resolution} and a tracking error of {max_error:.6g}")
        times_arr = np.array(times)
        times_arr[-1] = horizon
        return times_arr, np.array(bounds)

    def _pair(self, parent: np.ndarray, child: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        parent = np.asarray(parent, dtype=float).reshape(-1)
        child = np.asarray(child, dtype=float).reshape(-1)
        if parent.shape != (self.dim,) or child.shape != (self.dim,):
            raise ValueError(
                f"parent and child must have {self.dim} coordinates (the dynamics' d), got "
                f"{parent.shape[0]} and {child.shape[0]}"
            )
        return parent, child
