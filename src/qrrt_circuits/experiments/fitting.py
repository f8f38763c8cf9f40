"""Least-squares fits used by the experiments (the paper reports least-squares slopes)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike


@dataclass(frozen=True)
class LineFit:
    """A least-squares line ``y = slope x + intercept``.

    Attributes:
        slope: The fitted slope.
        intercept: The fitted intercept.
        slope_stderr: The standard error of the slope.
        points: How many points were fitted.
    """

    slope: float
    intercept: float
    slope_stderr: float
    points: int


def linear_fit(x: ArrayLike, y: ArrayLike) -> LineFit:
    """Ordinary least squares y = a x + b, with the standard error of a.

    Args:
        x: 1-D abscissae (at least two distinct values).
        y: 1-D ordinates, as many as ``x``.

    Returns:
        The fit; ``slope_stderr`` = sqrt(s^2 / sum (x - mean x)^2) with s^2 the residual variance
        on max(n - 2, 1) degrees of freedom.

    Raises:
        ValueError: If ``x`` and ``y`` are not 1-D of equal length, or ``x`` has fewer than two
            distinct values.
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    if x.shape != y.shape or x.ndim != 1:
        raise ValueError(f"x and y must be 1-D arrays of equal length, got {x.shape} and {y.shape}")
    if x.size < 2 or np.ptp(x) == 0:
        raise ValueError("a line fit needs at least two distinct x values")
    design = np.stack([x, np.ones_like(x)], axis=1)
    coef, *_ = np.linalg.lstsq(design, y, rcond=None)
    residual = y - design @ coef
    dof = max(x.size - 2, 1)
    sigma2 = float(residual @ residual) / dof
    stderr = float(np.sqrt(sigma2 / np.sum((x - x.mean()) ** 2)))
    return LineFit(float(coef[0]), float(coef[1]), stderr, int(x.size))


def slope_through_origin(x: ArrayLike, y: ArrayLike) -> float:
    """Least squares y = a x: a = sum(x y) / sum(x^2).

    Args:
        x: Abscissae.
        y: Ordinates, as many as ``x``.

    Returns:
        The slope a.

    Raises:
        ValueError: If every x is 0.
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    denominator = float(np.sum(x * x))
    if denominator == 0:
        raise ValueError("a fit through the origin needs some x != 0")
    return float(np.sum(x * y) / denominator)


def power_law_exponent(x: ArrayLike, y: ArrayLike) -> LineFit:
    """Fit y = C x^alpha by least squares on log y = alpha log x + log C (x, y > 0).

    Args:
        x: Abscissae; points with x <= 0 or y <= 0 are left out.
        y: Ordinates, as many as ``x``.

    Returns:
        The line fit in log-log space: ``slope`` is alpha, ``intercept`` is log C.

    Raises:
        ValueError: If fewer than two distinct positive x (with positive y) remain.
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    keep = (x > 0) & (y > 0)
    return linear_fit(np.log(x[keep]), np.log(y[keep]))
