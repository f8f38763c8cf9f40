"""A check of evenly spaced time samples only: NOT sound, offered to study what such a check does.

``TimeSampledCheck`` tests x(t_j) at ``time_samples`` evenly spaced times in [0, T], as a naive
reading of an ODE solver's output would: it steps over corners and thin obstacles between samples.
It is the "points-only" variant the ``oracle-check`` experiment measures. (The authors' own
``dynamicscheck.m`` also rasterizes the segments between its solver's outputs, which makes it
nearly exact; see DESIGN §2.)
"""

from __future__ import annotations

import numpy as np

from .._support.validation import check_int
from ..world.environment import Environment
from .dynamics import MAX_PROPAGATOR_BYTES, LinearTrackingDynamics
from .predicate import as_pairs

#: sample coordinates (pairs x K x d doubles: 16 MiB) of one chunk of ``TimeSampledCheck.reachable``;
#: with the obstacle test's scratch a few times that, whatever M, K and d
CHUNK_COORDINATES = 1 << 21


class TimeSampledCheck:
    """Reachability predicate testing only ``time_samples`` evenly spaced samples of x(t) (unsound).

    A pair (p, c) is accepted iff x(t_j) = c + expm((A - BK) t_j)(p - c) is free at t_j =
    j T / (K - 1), j = 0 .. K - 1, and c is free. DESIGN §2 explains why this is not enough: the
    segments between samples are never tested, so corners and thin obstacles are stepped over.

    Args:
        env: The ``Environment``.
        dynamics: ``LinearTrackingDynamics`` of the same dimension (default: the paper's).
        time_samples: K, 2 .. 1 000 000 (keyword only), with the K x d x d propagators within
            ``MAX_PROPAGATOR_BYTES`` (256 MiB). ``reachable`` samples ``CHUNK_COORDINATES``
            coordinates at a time, so its memory does not grow with M x K.

    Attributes:
        time_samples: K.
        evaluations: Pairs evaluated so far.

    Raises:
        ValueError: A dynamics dimension other than ``env.dim``, K out of range, or propagators
            larger than ``MAX_PROPAGATOR_BYTES``.
        TypeError: A non-integer K.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits import Environment, ExactCheck, TimeSampledCheck
        >>> env = Environment([[0, 10], [0, 10]], [[[5, 0], [5.01, 10]]])  # a thin wall
        >>> parent, child = np.array([[2.0, 5.0]]), np.array([[8.0, 5.0]])
        >>> TimeSampledCheck(env, time_samples=50).reachable(parent, child).tolist()  # stepped over
        [True]
        >>> ExactCheck(env).reachable(parent, child).tolist()
        [False]
    """

    name = "time-samples"

    def __init__(self, env: Environment, dynamics: LinearTrackingDynamics | None = None, *,
                 time_samples: int = 50) -> None:
        dynamics = LinearTrackingDynamics.paper() if dynamics is None else dynamics
        if dynamics.dim != env.dim:
            raise ValueError(f"dynamics dimension {dynamics.dim} does not match the environment's d = {env.dim}")
        self.env = env
        self.dynamics = dynamics
        self.time_samples = check_int(time_samples, "time_samples", 2, 1_000_000)
        propagator_bytes = 8 * self.time_samples * env.dim * env.dim
        if propagator_bytes > MAX_PROPAGATOR_BYTES:
            raise ValueError(
                f"time_samples = {self.time_samples} in d = {env.dim} needs {propagator_bytes / 2**20:.0f} MiB of "
                f"propagators (K x d x d doubles), more than the {MAX_PROPAGATOR_BYTES >> 20} MiB allowed: use at "
                f"most {MAX_PROPAGATOR_BYTES // (8 * env.dim * env.dim)} time samples")
        self.evaluations = 0
        times = np.linspace(0.0, dynamics.horizon, self.time_samples)
        self._phis = dynamics.propagators(times)  # (K, d, d)

    @property
    def dim(self) -> int:
        """d, the environment's dimension."""
        return self.env.dim

    def describe(self) -> dict:
        """Name, K, ``sound: False`` and the dynamics."""
        return {"name": self.name, "time_samples": self.time_samples, "sound": False,
                "dynamics": self.dynamics.describe()}

    def reachable(self, parents: np.ndarray, children: np.ndarray) -> np.ndarray:
        """Are all K samples of each pair's trajectory free?

        Args:
            parents: Float array (M, d), finite.
            children: Float array of the same shape.

        Returns:
            Bool array (M,); adds M to ``evaluations``.

        Raises:
            ValueError: Shapes other than (M, d), different shapes, or non-finite coordinates.
        """
        parents, children = as_pairs(parents, children, self.dim)
        count = parents.shape[0]
        samples_free = np.empty(count, dtype=bool)
        step = max(1, CHUNK_COORDINATES // (self.time_samples * self.dim))  # pairs per chunk: bounded memory
        for first in range(0, count, step):
            rows = slice(first, first + step)
            points = children[rows, None, :] + np.einsum("kij,mj->mki", self._phis, parents[rows] - children[rows])
            free = self.env.is_free(points.reshape(-1, self.dim)).reshape(points.shape[:2])
            samples_free[rows] = free.all(axis=1)
        self.evaluations += int(count)
        return samples_free & self.env.is_free(children)
