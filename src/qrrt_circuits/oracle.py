"""The reachability predicate (the oracle's truth) and the optional oracle error model (DESIGN §2).

``check="time_samples"`` replaces the sound check by one that tests only evenly spaced time
samples (like the output of the authors' ODE solver); it is unsound and exists to measure that.

Candidate (c, p) is reachable iff the closed-loop trajectory x(t) = c + expm(M t)(p - c),
t in [0, T], stays in the workspace and outside every obstacle. The check is conservative at a
documented ``resolution`` (default 0.01 length units): any trajectory that touches an obstacle is
rejected, and a collision-free one is only rejected if it passes within ``resolution`` of an
obstacle or of the workspace boundary (see ``qrrt_circuits.collision``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .collision import trajectories_free
from .dynamics import LinearTrackingDynamics
from .environment import Environment


class ReachabilityOracle:
    """Vectorized batch reachability test with a spatial index and an evaluation counter.

    ``evaluations`` counts predicate evaluations (pairs) made through this object. Planners do
    their own oracle-call accounting (DESIGN §2); this counter is the raw work done.
    """

    def __init__(
        self,
        env: Environment,
        dynamics: LinearTrackingDynamics | None = None,
        resolution: float = 0.01,
        check: str = "exact",
        time_samples: int = 50,
    ) -> None:
        dynamics = LinearTrackingDynamics.paper() if dynamics is None else dynamics
        if dynamics.dim != env.dim:
            raise ValueError(
                f"dynamics dimension {dynamics.dim} does not match the environment's d = {env.dim}"
            )
        if not (np.isfinite(resolution) and resolution > 0):
            raise ValueError(f"resolution must be a finite number > 0, got {resolution}")
        if check not in ("exact", "time_samples"):
            raise ValueError(f"check must be 'exact' or 'time_samples', got {check!r}")
        if int(time_samples) != time_samples or time_samples < 2:
            raise ValueError(f"time_samples must be an integer >= 2, got {time_samples}")
        self.check = check
        self.time_samples = int(time_samples)
        self.env = env
        self.dynamics = dynamics
        self.resolution = float(resolution)
        self.evaluations = 0
        extent = env.bounds[:, 1] - env.bounds[:, 0]
        max_error = float(np.linalg.norm(extent)) * 1.0001
        self._times, self._curvature = dynamics.curvature_bound_times(max_error, self.resolution)
        self._phis = np.ascontiguousarray(dynamics.propagators(self._times))
        self._index = env.grid_index
        self._lower = np.ascontiguousarray(env.boxes[:, 0])
        self._upper = np.ascontiguousarray(env.boxes[:, 1])
        self._bounds = np.ascontiguousarray(env.bounds)

    def reachable(self, parents: np.ndarray, children: np.ndarray) -> np.ndarray:
        """Bool (M,): may each child be reached from its parent without collision?"""
        parents = np.ascontiguousarray(parents, dtype=float)
        children = np.ascontiguousarray(children, dtype=float)
        d = self.env.dim
        if parents.ndim == 1:
            parents = parents.reshape(1, -1)
        if children.ndim == 1:
            children = children.reshape(1, -1)
        if parents.shape[-1] != d or children.shape[-1] != d:
            raise ValueError(
                f"parents and children must have shape (M, {d}), got {parents.shape} and "
                f"{children.shape}"
            )
        if parents.shape[0] != children.shape[0] and parents.shape[0] == 1:
            parents = np.ascontiguousarray(np.broadcast_to(parents, children.shape))
        if parents.shape != children.shape:
            raise ValueError(
                f"parents and children must have the same shape, got {parents.shape} and "
                f"{children.shape}"
            )
        if not (np.all(np.isfinite(parents)) and np.all(np.isfinite(children))):
            raise ValueError("parents and children must be finite")
        if self.check == "time_samples":
            self.evaluations += int(parents.shape[0])
            return self._time_sample_check(parents, children)
        out = np.zeros(parents.shape[0], dtype=np.bool_)
        index = self._index
        trajectories_free(
            parents, children, self._times, self._phis, self._curvature, self.resolution,
            self._bounds, self._lower, self._upper, index.origin, index.cell_size, index.shape,
            index.cell_start, index.cell_items, out,
        )
        self.evaluations += int(parents.shape[0])
        return out


    def _time_sample_check(self, parents: np.ndarray, children: np.ndarray) -> np.ndarray:
        """Only x(t_j) at ``time_samples`` evenly spaced times in [0, T] are tested, as an ODE
        solver's output would be: NOT a sound check (it steps over corners and thin obstacles).
        Offered to study how much such a check accepts; see the oracle-check experiment."""
        times = np.linspace(0.0, self.dynamics.horizon, self.time_samples)
        phis = self.dynamics.propagators(times)  # (K, d, d)
        points = children[:, None, :] + np.einsum("kij,mj->mki", phis, parents - children)
        free = self.env.is_free(points.reshape(-1, self.env.dim)).reshape(points.shape[:2])
        return free.all(axis=1) & self.env.is_free(children)


@dataclass(frozen=True)
class OracleErrorModel:
    """Oracle mistakes applied to the marks only (the verification uses the true predicate).

    Each truly unreachable entry is marked good with probability ``false_positive`` and each
    reachable one is marked bad with probability ``false_negative``. (The paper's q = (1 - m1)/m is
    a typo for q = (m - m1)/m.)
    """

    false_positive: float = 0.0
    false_negative: float = 0.0
    seed: int | None = None
    _rng: np.random.Generator = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        for name in ("false_positive", "false_negative"):
            value = getattr(self, name)
            if not (np.isfinite(value) and 0.0 <= value <= 1.0):
                raise ValueError(f"{name} must be a probability in [0, 1], got {value}")
        object.__setattr__(self, "_rng", np.random.default_rng(self.seed))

    @property
    def is_exact(self) -> bool:
        return self.false_positive == 0.0 and self.false_negative == 0.0

    def apply(self, truth: np.ndarray, rng: np.random.Generator | None = None) -> np.ndarray:
        """Noisy marks for the true reachability ``truth`` (bool array)."""
        truth = np.asarray(truth, dtype=bool)
        if self.is_exact:
            return truth.copy()
        rng = self._rng if rng is None else rng
        flips = rng.random(truth.shape)
        return np.where(truth, flips >= self.false_negative, flips < self.false_positive)
