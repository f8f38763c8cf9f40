"""Fixed-point coordinates: workspace coordinates as unsigned b-bit integers.

A ``FixedPointFormat(bits, lo, hi)`` divides [lo, hi) into 2^b steps of s = (hi - lo) / 2^b; grid
point q (0 <= q < 2^b) is the coordinate lo + q s, on every axis alike. The rules, all exact (the
arithmetic is done in rationals of the floats given, never in rounded floats):

- a coordinate x in [lo, hi) is stored as q = floor((x - lo) / s), the grid point at or below it
  (``encode``); a coordinate outside [lo, hi) is refused, naming the argument and the range;
- a closed interval [v_lo, v_hi] (a box's side, the workspace's bounds) contains the grid point q
  exactly when ``ceil_index(v_lo) <= q <= floor_index(v_hi)``, with ``ceil_index(v) = ceil((v -
  lo) / s)`` and ``floor_index(v) = floor((v - lo) / s)``: the box tests of the coherent oracle
  compare integers against these two constants and are exact for grid points.

The trajectory points the oracle tests are computed from these integers (``motion``,
``reference``): they are rounded to the grid there, and may leave [0, 2^b) (then the bounds test
rejects them).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import TYPE_CHECKING

import numpy as np

from .._support.validation import check_float, check_int, check_real_array

if TYPE_CHECKING:
    from ..world.environment import Environment

#: the widest coordinate accepted (bits per coordinate); the reference's int64 arithmetic needs
#: the products of coefficients and coordinates below 2^62 (``motion.SampledMotion``)
MAX_BITS = 24


@dataclass(frozen=True)
class FixedPointFormat:
    """Unsigned b-bit fixed-point coordinates over [lo, hi) (module text).

    Args:
        bits: b, 1 .. ``MAX_BITS``: grid points 0 .. 2^b - 1 per axis.
        lo: The coordinate of grid point 0 (finite).
        hi: The end of the range, > lo (finite, exclusive): the step is (hi - lo) / 2^b.

    Raises:
        TypeError: A non-integer ``bits`` or a non-real ``lo`` / ``hi``.
        ValueError: ``bits`` out of range, ``lo`` / ``hi`` not finite, or hi <= lo.

    Example:
        >>> from qrrt_circuits.coherent import FixedPointFormat
        >>> fmt = FixedPointFormat(4, 0.0, 16.0)  # step 1
        >>> fmt.encode([[0.0, 15.99], [3.5, 7.0]], "points").tolist()
        [[0, 15], [3, 7]]
        >>> fmt.ceil_index(2.5), fmt.floor_index(2.5)
        (3, 2)
    """

    bits: int
    lo: float
    hi: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "bits", check_int(self.bits, "bits", 1, MAX_BITS))
        lo = check_float(self.lo, "lo")
        hi = check_float(self.hi, "hi")
        if not hi > lo:
            raise ValueError(f"hi must be > lo, got lo={lo}, hi={hi}")
        object.__setattr__(self, "lo", lo)
        object.__setattr__(self, "hi", hi)

    @property
    def levels(self) -> int:
        """2^b, the number of grid points per axis."""
        return 1 << self.bits

    @property
    def step(self) -> float:
        """s = (hi - lo) / 2^b, the distance between grid points (as a float)."""
        return (self.hi - self.lo) / self.levels

    def _scaled(self, value: float) -> Fraction:
        """(value - lo) / s as an exact rational."""
        return (Fraction(value) - Fraction(self.lo)) * self.levels / (Fraction(self.hi) - Fraction(self.lo))

    def ceil_index(self, value: float) -> int:
        """ceil((value - lo) / s): the smallest grid index whose point is >= ``value`` (exact)."""
        return math.ceil(self._scaled(float(value)))

    def floor_index(self, value: float) -> int:
        """floor((value - lo) / s): the largest grid index whose point is <= ``value`` (exact)."""
        return math.floor(self._scaled(float(value)))

    def encode(self, values: np.ndarray, name: str = "values") -> np.ndarray:
        """Coordinates in [lo, hi) as grid indices floor((x - lo) / s) (exact; module text).

        Args:
            values: Real array of any shape.
            name: The argument's name, for the error message.

        Returns:
            An int64 array of the same shape, each entry in [0, 2^b).

        Raises:
            ValueError: Non-real or non-finite values, or a value outside [lo, hi) (named with
                its position and the range).
        """
        array = check_real_array(values, name)
        flat = array.reshape(-1)
        outside = ~np.isfinite(flat) | (flat < self.lo) | (flat >= self.hi)
        if np.any(outside):
            where = int(np.argmax(outside))
            position = np.unravel_index(where, array.shape) if array.ndim else ()
            raise ValueError(f"{name}{list(map(int, position))} = {float(flat[where])!r} is outside the fixed-point "
                             f"range [{self.lo}, {self.hi}) of {self.bits}-bit coordinates")
        scaled = (flat - self.lo) * (self.levels / (self.hi - self.lo))
        result = np.floor(scaled).astype(np.int64)
        # float rounding can only matter within a hair of an integer: settle those exactly
        near = np.flatnonzero(np.abs(scaled - np.rint(scaled)) < 1e-6 * np.maximum(1.0, np.abs(scaled)))
        for i in near:
            result[i] = self.floor_index(float(flat[i]))
        return np.clip(result, 0, self.levels - 1).reshape(array.shape)

    def decode(self, indices: np.ndarray) -> np.ndarray:
        """Grid indices as coordinates lo + q s (floats; q may lie outside [0, 2^b)).

        Args:
            indices: Integer array of any shape.

        Returns:
            A float array of the same shape.
        """
        return self.lo + np.asarray(indices, dtype=np.float64) * self.step

    def check_environment(self, env: Environment) -> None:
        """Refuse a world whose coordinates the format cannot represent.

        The workspace bounds and every box corner must lie in [lo, hi) (so every state does).

        Args:
            env: The ``Environment``.

        Raises:
            ValueError: The first coordinate outside [lo, hi), named (``env.bounds``,
                ``env.boxes[i]``) with the range.
        """
        items: list[tuple[str, np.ndarray]] = [("env.bounds", env.bounds.reshape(-1))]
        items += [(f"env.boxes[{i}]", box.reshape(-1)) for i, box in enumerate(env.boxes)]
        for name, coordinates in items:
            bad = (coordinates < self.lo) | (coordinates >= self.hi)
            if np.any(bad):
                value = float(coordinates[int(np.argmax(bad))])
                raise ValueError(
                    f"{name} has the coordinate {value!r}, outside the fixed-point range "
                    f"[{self.lo}, {self.hi}): choose a format covering the world "
                    f"(FixedPointFormat.covering(env, bits))")

    @classmethod
    def covering(cls, env: Environment, bits: int) -> FixedPointFormat:
        """The format of ``bits`` whose range just covers the world: lo = the smallest coordinate of
        the bounds and boxes, and hi such that the largest one is grid point 2^b - 1.

        Args:
            env: The ``Environment``.
            bits: b, 1 .. ``MAX_BITS``.

        Returns:
            The ``FixedPointFormat``.

        Raises:
            TypeError: A non-integer ``bits``.
            ValueError: ``bits`` out of range.

        Example:
            >>> from qrrt_circuits import Environment
            >>> from qrrt_circuits.coherent import FixedPointFormat
            >>> env = Environment([[0, 15], [0, 15]], [[[4, 0], [6, 6]]])
            >>> FixedPointFormat.covering(env, 4)
            FixedPointFormat(bits=4, lo=0.0, hi=16.0)
        """
        bits = check_int(bits, "bits", 1, MAX_BITS)
        coordinates = [env.bounds.reshape(-1), env.boxes.reshape(-1)]
        values = np.concatenate(coordinates)
        lo, top = float(values.min()), float(values.max())
        hi = lo + (top - lo) * (1 << bits) / ((1 << bits) - 1)
        while hi <= top:  # (a float rounding of a tiny range)
            hi = math.nextafter(hi, math.inf)
        return cls(bits, lo, hi)
