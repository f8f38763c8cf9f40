"""The motion the coherent oracle checks: K time samples of a closed-loop linear motion, with its
coefficients in fixed point.

The library's motion from a parent p towards a sample c is x(t) = c + E(t) (p - c) with
E(t) = expm((A - BK) t) (``reachability.dynamics``, DESIGN §2): p is the parent (the tree node),
c the sample (the target the tracking law steers to). ``TimeSampledCheck`` tests it at the K times
t_j = j T / (K - 1), j = 0 .. K - 1, and tests c itself; ``SampledMotion.from_dynamics`` takes
the same K matrices E_j = E(t_j). Straight-line motion is E_j = (1 - j / (K - 1)) I
(``straight_line``): x(t_0) = p, x(t_{K-1}) = c.

In fixed point each matrix is stored with f fraction bits, rounded to nearest with ties up:
e_j = floor(E_j 2^f + 1/2) (integers, ``coefficients``). The points tested are those of the
distinct matrices among e_0 .. e_{K-1} and the zero matrix (the sample c itself, as
``TimeSampledCheck`` tests it), in that order (``tested``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._support.validation import check_int, check_real_array
from ..reachability.dynamics import LinearTrackingDynamics

#: the most time samples K accepted
MAX_TIME_SAMPLES = 4096
#: the most fraction bits f of the coefficients
MAX_FRACTION_BITS = 24
#: the largest |e| = |E 2^f| accepted (the reference's int64 products stay below 2^62)
MAX_COEFFICIENT = 1 << 32


@dataclass(frozen=True, eq=False)
class SampledMotion:
    """K motion matrices E_j with their f-fraction-bit integers e_j (module text).

    Args:
        propagators: Float (K, d, d), K in 2 .. ``MAX_TIME_SAMPLES``, d >= 1, finite.
        fraction_bits: f, 0 .. ``MAX_FRACTION_BITS``.
        dynamics: The ``LinearTrackingDynamics`` the matrices sample (None for other motions);
            ``reference.compare_with_time_sampled`` needs it.

    Raises:
        TypeError: A non-integer ``fraction_bits``.
        ValueError: A wrong shape, non-finite entries, K or f out of range, or a coefficient
            |E 2^f| of ``MAX_COEFFICIENT`` or more.

    Example:
        >>> from qrrt_circuits.coherent import SampledMotion
        >>> motion = SampledMotion.straight_line(2, time_samples=3, fraction_bits=1)
        >>> [m.diagonal().tolist() for m in motion.tested]  # E = I, I / 2, 0
        [[2, 2], [1, 1], [0, 0]]
    """

    propagators: np.ndarray
    fraction_bits: int
    dynamics: LinearTrackingDynamics | None = None

    def __post_init__(self) -> None:
        matrices = check_real_array(self.propagators, "propagators")
        if matrices.ndim != 3 or matrices.shape[1] != matrices.shape[2] or matrices.shape[1] < 1:
            raise ValueError(f"propagators must have shape (K, d, d), got {matrices.shape}")
        check_int(matrices.shape[0], "the number of time samples K", 2, MAX_TIME_SAMPLES)
        if not np.all(np.isfinite(matrices)):
            raise ValueError("propagators must contain only finite numbers")
        fraction_bits = check_int(self.fraction_bits, "fraction_bits", 0, MAX_FRACTION_BITS)
        largest = float(np.max(np.abs(matrices))) * 2.0**fraction_bits
        if largest >= MAX_COEFFICIENT:
            raise ValueError(f"a coefficient |E 2^f| = {largest:.4g} is {MAX_COEFFICIENT} or more: lower fraction_bits "
                             f"(got {fraction_bits})")
        matrices.setflags(write=False)
        object.__setattr__(self, "propagators", matrices)
        object.__setattr__(self, "fraction_bits", fraction_bits)
        if self.dynamics is not None and self.dynamics.dim != matrices.shape[1]:
            raise ValueError(f"dynamics has d = {self.dynamics.dim}, the propagators d = {matrices.shape[1]}")

    @classmethod
    def from_dynamics(cls, dynamics: LinearTrackingDynamics, time_samples: int, fraction_bits: int
                      ) -> SampledMotion:
        """E_j = expm((A - BK) t_j) at ``TimeSampledCheck``'s times t_j = j T / (K - 1).

        Args:
            dynamics: The ``LinearTrackingDynamics``.
            time_samples: K, 2 .. ``MAX_TIME_SAMPLES``.
            fraction_bits: f, 0 .. ``MAX_FRACTION_BITS``.

        Returns:
            The ``SampledMotion`` (``dynamics`` kept).

        Raises:
            TypeError: A non-integer K or f.
            ValueError: K or f out of range.
        """
        time_samples = check_int(time_samples, "time_samples", 2, MAX_TIME_SAMPLES)
        times = np.linspace(0.0, dynamics.horizon, time_samples)
        return cls(dynamics.propagators(times), fraction_bits, dynamics)

    @classmethod
    def straight_line(cls, dim: int, time_samples: int, fraction_bits: int) -> SampledMotion:
        """E_j = (1 - j / (K - 1)) I: K evenly spaced points of the segment from p to c.

        Args:
            dim: d, 1 .. 64.
            time_samples: K, 2 .. ``MAX_TIME_SAMPLES``.
            fraction_bits: f, 0 .. ``MAX_FRACTION_BITS`` (exact when K - 1 divides 2^f).

        Returns:
            The ``SampledMotion`` (no ``dynamics``).

        Raises:
            TypeError: A non-integer argument.
            ValueError: An argument out of range.
        """
        dim = check_int(dim, "dim", 1, 64)
        time_samples = check_int(time_samples, "time_samples", 2, MAX_TIME_SAMPLES)
        weights = 1.0 - np.arange(time_samples) / (time_samples - 1)
        return cls(weights[:, None, None] * np.eye(dim)[None], fraction_bits)

    @property
    def dim(self) -> int:
        """d."""
        return int(self.propagators.shape[1])

    @property
    def time_samples(self) -> int:
        """K."""
        return int(self.propagators.shape[0])

    @property
    def coefficients(self) -> np.ndarray:
        """e_j = floor(E_j 2^f + 1/2): int64 (K, d, d)."""
        return np.floor(self.propagators * 2.0**self.fraction_bits + 0.5).astype(np.int64)

    @property
    def tested(self) -> tuple[np.ndarray, ...]:
        """The distinct integer matrices among e_0 .. e_{K-1} and 0 (the sample itself), in order."""
        seen: dict[bytes, np.ndarray] = {}
        for matrix in [*self.coefficients, np.zeros((self.dim, self.dim), dtype=np.int64)]:
            seen.setdefault(matrix.tobytes(), matrix)
        return tuple(seen.values())
