"""The paper authors' own reachability check, ported: ``dynamicscheck.m`` + ``pointobscheck.m``.

The paper (§V) decides whether a candidate child c is reachable from its parent p by simulating the
closed loop and testing the simulated path against the obstacles. The authors' MATLAB function
``dynamicscheck.m`` does it as follows (``pointobscheck.m`` is its point-in-box test):

1. integrate the tracking error e' = (A - B K) e from e(0) = p - c over t in [0, T] (T = 5) with
   ``ode45`` and its default options (RelTol = 1e-3, AbsTol = 1e-6); the outputs y(1..n) are
   e + c, y(1) being the parent (as (p - c) + c, i.e. up to rounding);
2. test y(1) as a point;
3. for i = 2 .. min(n, 25) test the ``rast_num`` (37) points y(i) + (j / rast_num)(y(i-1) - y(i)),
   j = 1 .. rast_num, of the segment between consecutive outputs (so y(i-1) is tested and y(i)
   is not, until the next segment; y(25) is never tested);
4. for i = 26 .. min(n, 50) test y(i) as a point; later outputs are not tested at all;
5. a point collides if it lies in a closed box (xlo <= x <= xhi on every axis); the workspace
   bounds are not tested; the first colliding point rejects the pair, otherwise it is accepted.

It is NOT sound: it tests points, not the curve (``sound: False`` in ``describe()``). Under
Octave it is nearly exact (the segments between its ~22 outputs are rasterized densely); under
MATLAB's ``Refine = 4`` output it leaves the tail of the trajectory untested.

**MATLAB versus Octave.** The verdict depends on which ``ode45`` produced the outputs, and the two
differ in documented ways. ``refine`` selects the behaviour:

- ``refine >= 2`` (default 4): MATLAB's ``ode45.m`` (Dormand-Prince 5(4), Shampine & Reichelt,
  "The MATLAB ODE Suite", 1997). Initial step: ``absh = min(hmax, |tspan|)``, ``rh = ||f0 ./
  max(|y0|, threshold)||_inf / (0.8 rtol^(1/5))`` with ``threshold = AbsTol / RelTol``, ``absh =
  1/rh`` if ``absh rh > 1``, ``absh = max(absh, hmin)``; ``hmax = 0.1 |tspan|``, ``hmin =
  16 eps(t)``. A step within 10 % of the end is stretched to hit it (``1.1 absh >= |T - t|``).
  Error ``err = absh ||(f E) ./ max(max(|y|, |ynew|), threshold)||_inf`` with the DP5(4) error
  coefficients E; a step fails if ``err > rtol``: the first failure shrinks ``absh = max(hmin,
  absh max(0.1, 0.8 (rtol/err)^(1/5)))``, later failures of the same step halve it. After a step
  without failures ``temp = 1.25 (err/rtol)^(1/5)``, ``absh = absh / temp`` if ``temp > 0.2``
  else ``5 absh`` (no growth after a step that failed). Output: ``refine`` points per accepted
  step, the refine - 1 points at fractions 1/refine .. (refine-1)/refine of the step from DP5's
  continuous extension (``ntrp45``), then the step end (MATLAB's default ``Refine = 4``).
- ``refine == 1``: GNU Octave 7's ``ode45`` (the reference verdicts were computed with Octave
  7.3.0), whose rules differ from MATLAB's as its source (``scripts/ode/ode45.m``,
  ``private/starting_stepsize.m``, ``private/integrate_adaptive.m``,
  ``private/runge_kutta_45_dorpri.m``, ``private/AbsRel_norm.m``) documents:
  it ignores ``Refine`` ("FIXME: Refine is not correctly implemented yet") and returns only the
  accepted steps; its initial step is Hairer-Norsett-Wanner's (d0 = ||x0||, d1 = ||f(x0)||,
  h0 = 0.01 d0/d1 (1e-6 if either < 1e-5), one Euler step gives d2 = ||f(x0 + h0 f0) - f0|| /
  h0, h1 = (0.01 / max(d1, d2))^(1/6), h = min(100 h0, h1), all norms scaled by
  max(AbsTol, RelTol |x|)), capped at MaxStep = 0.1 |tspan|; a step is accepted if
  ``max |x5 - x4| / max(AbsTol, RelTol max(|x_new|, |x_old|)) <= 1`` (the same test as MATLAB's);
  after every attempt, accepted or not, ``dt *= min(1.5, max(0.8, 0.38^(1/6) (1/(err + eps))^(1/6)))``,
  then ``dt = min(dt, MaxStep, T - t)`` (no stretching: a short last step is possible); times are
  Kahan-summed. Our times agree with the reference data's Octave times to ~1e-12 (the remaining
  differences are the summation order of Octave's BLAS in the error estimate).

One compiled kernel (numba, ``@njit(cache=True, nogil=True)``, any dimension d) integrates each pair
step by step (resumable integrators), tests each output as soon as it exists, and stops at the
first colliding point or after the 50 outputs the test can use. Boxes come from the environment's
uniform grid (``qrrt_circuits.reachability.collision.GridIndex``); a segment's ``rast_num`` points are tested only
against the boxes the segment meets when padded by 1e-9 of its coordinates' magnitude (far above
the points' rounding, so the verdict is the same as testing every point against every box).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .._support.validation import check_int
from ..world.environment import Environment
from .collision import _segment_hits_box
from .dynamics import LinearTrackingDynamics
from .predicate import as_pairs

__all__ = ["AuthorsCheck"]

REL_TOL = 1e-3  # ode45's default RelTol
ABS_TOL = 1e-6  # ode45's default AbsTol
SEGMENT_OUTPUTS = 25  # outputs 2..25: the segments ending there are rasterized
POINT_OUTPUTS = 50  # outputs 26..50 are tested as points; later ones are not tested

# Dormand-Prince 5(4): stage coefficients a[i, j] (row i is stage i + 1), 5th-order weights B5,
# Octave's embedded 4th-order weights C4 (7 stages, FSAL), MATLAB's error coefficients E = B5 - C4
# (as ode45.m writes them) and ntrp45's continuous-extension matrix BI (7 x 4, powers s .. s^4).
_A = np.array([
    [0.0, 0.0, 0.0, 0.0, 0.0],
    [1 / 5, 0.0, 0.0, 0.0, 0.0],
    [3 / 40, 9 / 40, 0.0, 0.0, 0.0],
    [44 / 45, -56 / 15, 32 / 9, 0.0, 0.0],
    [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729, 0.0],
    [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656],
])
_B5 = np.array([35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84])
_C4 = np.array([5179 / 57600, 0.0, 7571 / 16695, 393 / 640, -92097 / 339200, 187 / 2100, 1 / 40])
_E = np.array([71 / 57600, 0.0, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40])
_BI = np.array([
    [1.0, -183 / 64, 37 / 12, -145 / 128],
    [0.0, 0.0, 0.0, 0.0],
    [0.0, 1500 / 371, -1000 / 159, 1000 / 371],
    [0.0, -125 / 32, 125 / 12, -375 / 64],
    [0.0, 9477 / 3392, -729 / 106, 25515 / 6784],
    [0.0, -11 / 7, 11 / 3, -55 / 28],
    [0.0, 3 / 2, -4.0, 5 / 2],
])
_MAX_ATTEMPTS = 1_000_000  # a guard against a step size that never settles


# The scalar state of a resumable integration, kept in a small float array
_T = 0  # time reached (Octave's t_old, MATLAB's t)
_STEP = 1  # the next step: Octave's dt, MATLAB's absh
_COMP = 2  # Octave: Kahan compensation of the time sum
_LAST = 3  # Octave: time of the last output (its stop test uses eps(ode_t(end)))
_DONE = 4  # 1.0 once the integration has ended
_SCALARS = 5


@njit(cache=True, nogil=True)
def _matvec(M: np.ndarray, x: np.ndarray, out: np.ndarray) -> None:
    d = x.shape[0]
    for row in range(d):
        acc = 0.0
        for col in range(d):
            acc += M[row, col] * x[col]
        out[row] = acc


@njit(cache=True, nogil=True)
def _store(count: int, t: float, e: np.ndarray, offset: np.ndarray, times: np.ndarray, states: np.ndarray) -> None:
    """Output number ``count`` (0-based) is (t, e + offset), if the arrays have room for it."""
    if count < times.shape[0]:
        times[count] = t
        for axis in range(e.shape[0]):
            states[count, axis] = e[axis] + offset[axis]


@njit(cache=True, nogil=True)
def _octave_start(e0: np.ndarray, M: np.ndarray, horizon: float, rtol: float, atol: float, x: np.ndarray, k: np.ndarray,
                  tmp: np.ndarray, scalars: np.ndarray) -> None:
    """Octave: x = e0, k[0] = f(x) and the first step from starting_stepsize (Hairer, Norsett &
    Wanner, order 5), capped at MaxStep = 0.1 |tspan|."""
    d = e0.shape[0]
    for axis in range(d):
        x[axis] = e0[axis]
    _matvec(M, x, k[0])
    d0 = 0.0
    d1 = 0.0
    for axis in range(d):  # AbsRel_norm (x, x, AbsTol, RelTol), without NormControl
        d0 = max(d0, abs(x[axis]) / max(atol, rtol * abs(x[axis])))
        d1 = max(d1, abs(k[0, axis]) / max(atol, rtol * abs(k[0, axis])))
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * (d0 / d1)
    for axis in range(d):
        tmp[axis] = x[axis] + h0 * k[0, axis]
    _matvec(M, tmp, k[1])  # scratch: f(x0 + h0 f0)
    d2 = 0.0
    for axis in range(d):
        diff = k[1, axis] - k[0, axis]
        d2 = max(d2, abs(diff) / max(atol, rtol * abs(diff)))
    d2 = (1.0 / h0) * d2
    if max(d1, d2) <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (1e-2 / max(d1, d2)) ** (1.0 / 6.0)
    scalars[_T] = 0.0
    scalars[_STEP] = min(min(100.0 * h0, h1), 0.1 * horizon)
    scalars[_COMP] = 0.0
    scalars[_LAST] = 0.0
    scalars[_DONE] = 0.0


@njit(cache=True, nogil=True)
def _octave_advance(M: np.ndarray, horizon: float, rtol: float, atol: float, x: np.ndarray, k: np.ndarray,
                    x_new: np.ndarray, x_est: np.ndarray, tmp: np.ndarray, scalars: np.ndarray, offset: np.ndarray,
                    times: np.ndarray, states: np.ndarray, count: int) -> int:
    """Octave's integrate_adaptive with runge_kutta_45_dorpri: attempt steps until one is accepted
    (its end becomes output ``count``) or the integration ends. Returns the new output count."""
    d = x.shape[0]
    eps = np.finfo(np.float64).eps
    fac = 0.38 ** (1.0 / 6.0)
    max_step = 0.1 * horizon
    t_old = scalars[_T]
    dt = scalars[_STEP]
    comp = scalars[_COMP]
    t_last = scalars[_LAST]
    attempts = 0
    accepted = False
    while not accepted:
        if not t_old < horizon or attempts >= _MAX_ATTEMPTS:
            scalars[_DONE] = 1.0
            break
        attempts += 1
        term = dt - comp  # Kahan-summed new time
        t_new = t_old + term
        comp_new = (t_new - t_old) - term
        # stages: x + k(:, 1:i) * (dt a(i, 1:i))' (k[0] = f(x_old), FSAL)
        for stage in range(1, 6):
            for axis in range(d):
                acc = x[axis]
                for j in range(stage):
                    acc += k[j, axis] * (dt * _A[stage, j])
                tmp[axis] = acc
            _matvec(M, tmp, k[stage])
        for axis in range(d):
            acc = x[axis]
            for j in range(6):
                acc += k[j, axis] * (dt * _B5[j])
            x_new[axis] = acc
        _matvec(M, x_new, k[6])
        err = 0.0  # AbsRel_norm (x_new, x_old, AbsTol, RelTol, false, x_est)
        for axis in range(d):
            acc = x[axis]
            for j in range(7):
                acc += k[j, axis] * (dt * _C4[j])
            x_est[axis] = acc
            sc = max(atol, rtol * max(abs(x_new[axis]), abs(x[axis])))
            err = max(err, abs(x_new[axis] - x_est[axis]) / sc)
        if err <= 1.0:
            _store(count, t_new, x_new, offset, times, states)
            count += 1
            accepted = True
            t_old = t_new
            t_last = t_new
            comp = comp_new
            for axis in range(d):
                x[axis] = x_new[axis]
                k[0, axis] = k[6, axis]
        err += eps
        dt *= min(1.5, max(0.8, fac * (1.0 / err) ** (1.0 / 6.0)))
        dt = min(dt, max_step)
        if not dt > np.spacing(t_last):
            scalars[_DONE] = 1.0
            break
        dt = min(dt, horizon - t_old)
    if not t_old < horizon:
        scalars[_DONE] = 1.0
    scalars[_T] = t_old
    scalars[_STEP] = dt
    scalars[_COMP] = comp
    scalars[_LAST] = t_last
    return count


@njit(cache=True, nogil=True)
def _matlab_start(e0: np.ndarray, M: np.ndarray, horizon: float, rtol: float, atol: float, y: np.ndarray, f: np.ndarray,
                  scalars: np.ndarray) -> None:
    """MATLAB: y = e0, f[0] = f(y) and ode45's initial step (absh = min(hmax, |tspan|), then 1/rh
    if smaller, at least hmin)."""
    d = e0.shape[0]
    for axis in range(d):
        y[axis] = e0[axis]
    _matvec(M, y, f[0])
    threshold = atol / rtol
    absh = min(0.1 * horizon, horizon)
    rh = 0.0
    for axis in range(d):
        rh = max(rh, abs(f[0, axis]) / max(abs(y[axis]), threshold))
    rh = rh / (0.8 * rtol ** (1.0 / 5.0))
    if absh * rh > 1.0:
        absh = 1.0 / rh
    scalars[_T] = 0.0
    scalars[_STEP] = max(absh, 16.0 * np.spacing(0.0))
    scalars[_DONE] = 0.0


@njit(cache=True, nogil=True)
def _matlab_advance(M: np.ndarray, horizon: float, rtol: float, atol: float, refine: int, y: np.ndarray,
                    f: np.ndarray, y_new: np.ndarray, tmp: np.ndarray, scalars: np.ndarray, offset: np.ndarray,
                    times: np.ndarray, states: np.ndarray, count: int) -> int:
    """One pass of ode45.m's main loop: attempt the step until accepted, then output ``refine``
    points (ntrp45 at fractions 1/refine .. (refine-1)/refine, then the step end) from output
    ``count`` on. Returns the new output count."""
    d = y.shape[0]
    power = 1.0 / 5.0
    threshold = atol / rtol
    hmax = 0.1 * horizon
    t = scalars[_T]
    absh = scalars[_STEP]
    hmin = 16.0 * np.spacing(t)
    absh = min(hmax, max(hmin, absh))
    h = absh
    done = False
    if 1.1 * absh >= abs(horizon - t):  # stretch the step to hit the end
        h = horizon - t
        absh = abs(h)
        done = True
    no_failed = True
    err = 0.0
    t_new = t
    attempts = 0
    while True:
        attempts += 1
        for stage in range(1, 6):
            for axis in range(d):
                acc = 0.0
                for j in range(stage):
                    acc += _A[stage, j] * f[j, axis]
                tmp[axis] = y[axis] + h * acc
            _matvec(M, tmp, f[stage])
        t_new = t + h
        if done:
            t_new = horizon
        h = t_new - t
        for axis in range(d):
            acc = 0.0
            for j in range(6):
                acc += _B5[j] * f[j, axis]
            y_new[axis] = y[axis] + h * acc
        _matvec(M, y_new, f[6])
        err = 0.0
        for axis in range(d):
            acc = 0.0
            for j in range(7):
                acc += f[j, axis] * _E[j]
            err = max(err, abs(acc) / max(max(abs(y[axis]), abs(y_new[axis])), threshold))
        err = absh * err
        if err <= rtol:
            break
        if absh <= hmin or attempts >= _MAX_ATTEMPTS:  # MATLAB warns and returns what it has
            scalars[_DONE] = 1.0
            return count
        if no_failed:
            no_failed = False
            absh = max(hmin, absh * max(0.1, 0.8 * (rtol / err) ** power))
        else:
            absh = max(hmin, 0.5 * absh)
        h = absh
        done = False
    for r in range(1, refine):  # ntrp45
        t_ref = t + (t_new - t) * (r / refine)
        s = (t_ref - t) / h
        s2 = s * s
        s3 = s2 * s
        s4 = s3 * s
        for axis in range(d):
            acc = 0.0
            for j in range(7):
                acc += f[j, axis] * (h * (_BI[j, 0] * s + _BI[j, 1] * s2 + _BI[j, 2] * s3 + _BI[j, 3] * s4))
            tmp[axis] = y[axis] + acc
        _store(count, t_ref, tmp, offset, times, states)
        count += 1
    _store(count, t_new, y_new, offset, times, states)
    count += 1
    if done:
        scalars[_T] = t_new
        scalars[_DONE] = 1.0
        return count
    if no_failed:  # grow the step only after a step without failures
        temp = 1.25 * (err / rtol) ** power
        if temp > 0.2:
            absh = absh / temp
        else:
            absh = 5.0 * absh
    scalars[_T] = t_new
    scalars[_STEP] = absh
    for axis in range(d):
        y[axis] = y_new[axis]
        f[0, axis] = f[6, axis]
    return count


@njit(cache=True, nogil=True)
def _in_a_box(point: np.ndarray, lower: np.ndarray, upper: np.ndarray, origin: np.ndarray, cell_size: np.ndarray,
              shape: np.ndarray, cell_start: np.ndarray, cell_items: np.ndarray) -> bool:
    """pointobscheck: does ``point`` lie in a closed box? (Workspace bounds are not tested.)"""
    d = point.shape[0]
    cell = 0
    for axis in range(d):
        c = int(np.floor((point[axis] - origin[axis]) / cell_size[axis]))
        c = min(max(c, 0), shape[axis] - 1)
        cell = cell * shape[axis] + c
    for item in range(cell_start[cell], cell_start[cell + 1]):
        box = cell_items[item]
        inside = True
        for axis in range(d):
            if point[axis] < lower[box, axis] or point[axis] > upper[box, axis]:
                inside = False
                break
        if inside:
            return True
    return False


@njit(cache=True, nogil=True)
def _segment_collides(a: np.ndarray, b: np.ndarray, rast_num: int, lower: np.ndarray, upper: np.ndarray,
                      origin: np.ndarray, cell_size: np.ndarray, shape: np.ndarray, cell_start: np.ndarray,
                      cell_items: np.ndarray, stamp: np.ndarray, stamp_id: int, lo_cell: np.ndarray,
                      hi_cell: np.ndarray, cursor: np.ndarray) -> bool:
    """Is one of the points b + (j / rast_num)(a - b), j = 1 .. rast_num, in a closed box?

    Exactly that test, done fast: the points lie on the segment [b, a] up to a few ulps, so only a
    box that the segment meets when padded by ``pad`` (1e-9 of the coordinates' magnitude, far
    above rounding) can hold one; the points are tested against those boxes only. Boxes come from
    the grid cells under the segment's padded bounding box (``stamp`` skips repeats)."""
    d = a.shape[0]
    scale = 1.0
    for axis in range(d):
        scale = max(scale, abs(a[axis]), abs(b[axis]))
    pad = 1e-9 * scale
    for axis in range(d):
        low = int(np.floor((min(a[axis], b[axis]) - pad - origin[axis]) / cell_size[axis]))
        high = int(np.floor((max(a[axis], b[axis]) + pad - origin[axis]) / cell_size[axis]))
        lo_cell[axis] = min(max(low, 0), shape[axis] - 1)
        hi_cell[axis] = min(max(high, 0), shape[axis] - 1)
        cursor[axis] = lo_cell[axis]
    while True:
        cell = 0
        for axis in range(d):
            cell = cell * shape[axis] + cursor[axis]
        for item in range(cell_start[cell], cell_start[cell + 1]):
            box = cell_items[item]
            if stamp[box] == stamp_id:
                continue
            stamp[box] = stamp_id
            if not _segment_hits_box(b, a, lower[box], upper[box], pad):
                continue
            for j in range(1, rast_num + 1):
                fraction = j / rast_num
                inside = True
                for axis in range(d):
                    x = b[axis] + fraction * (a[axis] - b[axis])
                    if x < lower[box, axis] or x > upper[box, axis]:
                        inside = False
                        break
                if inside:
                    return True
        axis = d - 1
        while axis >= 0:
            cursor[axis] += 1
            if cursor[axis] <= hi_cell[axis]:
                break
            cursor[axis] = lo_cell[axis]
            axis -= 1
        if axis < 0:
            return False


@njit(cache=True, nogil=True)
def authors_check(parents: np.ndarray, children: np.ndarray, M: np.ndarray, horizon: float, rtol: float, atol: float,
                  refine: int, rast_num: int, test: bool, lower: np.ndarray, upper: np.ndarray, origin: np.ndarray,
                  cell_size: np.ndarray, shape: np.ndarray, cell_start: np.ndarray, cell_items: np.ndarray,
                  times: np.ndarray, ys: np.ndarray, out: np.ndarray) -> np.ndarray:
    """The one compiled kernel (one compile, not one per use).

    ``test`` true: out[i] = 1 if dynamicscheck accepts (parents[i], children[i]), else 0 (see the
    module docstring); ``times`` / ``ys`` are scratch for at least 50 + refine outputs. The outputs
    are tested as the integration produces them, so a pair stops at its first colliding point, and
    the integration stops after the 50 outputs the test can use.

    ``test`` false: integrate each pair to the end, keeping its outputs (t, e + child) in ``times``
    / ``ys`` (as many as fit; for one pair, the last pair's otherwise); out[i] = their number.

    Args:
        parents: Float (M, d).
        children: Float (M, d).
        M: Float (d, d), the closed loop A - B K.
        horizon: T, the integration's end time.
        rtol: ode45's relative tolerance.
        atol: ode45's absolute tolerance.
        refine: 1 for Octave's output rule, else MATLAB's Refine.
        rast_num: Points tested per segment.
        test: Whether to test (True) or only integrate (False).
        lower: Float (k, d), the boxes' lower corners.
        upper: Float (k, d), the boxes' upper corners.
        origin: ``GridIndex.origin``.
        cell_size: ``GridIndex.cell_size``.
        shape: ``GridIndex.shape``.
        cell_start: ``GridIndex.cell_start``.
        cell_items: ``GridIndex.cell_items``.
        times: Float scratch / output of the output times.
        ys: Float (len(times), d) scratch / output of the output points.
        out: Int (M,), written in place.

    Returns:
        ``out``.
    """
    d = parents.shape[1]
    e0 = np.empty(d)
    y = np.empty(d)
    y_new = np.empty(d)
    y_est = np.empty(d)
    tmp = np.empty(d)
    f = np.empty((7, d))
    scalars = np.zeros(_SCALARS)
    stamp = np.full(lower.shape[0], -1, dtype=np.int64)
    stamp_id = 0
    lo_cell = np.zeros(d, dtype=np.int64)
    hi_cell = np.zeros(d, dtype=np.int64)
    cursor = np.zeros(d, dtype=np.int64)
    for i in range(parents.shape[0]):
        child = children[i]
        for axis in range(d):
            e0[axis] = parents[i, axis] - child[axis]
        if refine == 1:
            _octave_start(e0, M, horizon, rtol, atol, y, f, tmp, scalars)
        else:
            _matlab_start(e0, M, horizon, rtol, atol, y, f, scalars)
        _store(0, 0.0, y, child, times, ys)
        count = 1
        free = True
        if test:
            free = not _in_a_box(ys[0], lower, upper, origin, cell_size, shape, cell_start, cell_items)
        row = 1
        while free:
            if test:
                limit = min(count, POINT_OUTPUTS)
                while free and row < limit:
                    if row < SEGMENT_OUTPUTS:  # outputs 2..25: the segment back to the previous output
                        stamp_id += 1
                        free = not _segment_collides(ys[row - 1], ys[row], rast_num, lower, upper, origin,
                                                     cell_size, shape, cell_start, cell_items, stamp,
                                                     stamp_id, lo_cell, hi_cell, cursor)
                    else:  # outputs 26..50: the output itself
                        free = not _in_a_box(ys[row], lower, upper, origin, cell_size, shape, cell_start,
                                             cell_items)
                    row += 1
                if count >= POINT_OUTPUTS:
                    break
            if not free or scalars[_DONE] != 0.0:
                break
            if refine == 1:
                count = _octave_advance(M, horizon, rtol, atol, y, f, y_new, y_est, tmp, scalars, child, times,
                                        ys, count)
            else:
                count = _matlab_advance(M, horizon, rtol, atol, refine, y, f, y_new, tmp, scalars, child,
                                        times, ys, count)
        out[i] = (1 if free else 0) if test else count
    return out


class AuthorsCheck:
    """The authors' ``dynamicscheck.m`` as a batch reachability predicate (unsound; DESIGN §2).

    Integrates the tracking error with a port of ``ode45`` and tests the parent, the rasterized
    segments between the first 25 outputs and the outputs 26 .. 50 against the closed boxes (the
    workspace bounds are not tested); see the module docstring for the exact rules.

    Args:
        env: The ``Environment``.
        dynamics: ``LinearTrackingDynamics`` of the same dimension (default: the paper's).
        rast_num: Points tested per segment, 1 .. 1 000 000 (the authors' 37).
        refine: 1 reproduces Octave 7's ode45 (the reference verdicts); 2 .. 10 000 MATLAB's
            ode45 with that Refine (MATLAB's default, and ours, is 4). The class attributes
            ``rel_tol`` (1e-3) and ``abs_tol`` (1e-6) are ode45's default tolerances.

    Attributes:
        name: ``"authors-octave"`` (refine 1) or ``"authors"``.
        evaluations: Pairs evaluated so far.

    Raises:
        TypeError: ``env`` not an ``Environment``, ``dynamics`` not a ``LinearTrackingDynamics``,
            or a non-integer ``rast_num`` / ``refine``.
        ValueError: A dynamics dimension other than ``env.dim``, or ``rast_num`` / ``refine`` out
            of range.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits import AuthorsCheck, Environment
        >>> env = Environment([[0, 10], [0, 10]], [[[4, 0], [6, 6]]])  # one wall from below
        >>> check = AuthorsCheck(env, refine=1)
        >>> parents = np.array([[1.0, 8.0], [1.0, 1.0]])
        >>> check.name, check.reachable(parents, np.array([[3.0, 8.0], [8.0, 1.0]])).tolist()
        ('authors-octave', [True, False])
    """

    rel_tol = REL_TOL
    abs_tol = ABS_TOL

    def __init__(self, env: Environment, dynamics: LinearTrackingDynamics | None = None,
                 rast_num: int = 37, refine: int = 4) -> None:
        if not isinstance(env, Environment):
            raise TypeError(f"env must be an Environment, got {type(env).__name__}")
        dynamics = LinearTrackingDynamics.paper() if dynamics is None else dynamics
        if not isinstance(dynamics, LinearTrackingDynamics):
            raise TypeError(f"dynamics must be a LinearTrackingDynamics or None, got {type(dynamics).__name__}")
        if dynamics.dim != env.dim:
            raise ValueError(f"dynamics dimension {dynamics.dim} does not match the environment's d = {env.dim}")
        self.env = env
        self.dynamics = dynamics
        self.rast_num = check_int(rast_num, "rast_num", 1, 1_000_000)
        self.refine = check_int(refine, "refine", 1, 10_000)
        self.name = "authors-octave" if self.refine == 1 else "authors"
        self.evaluations = 0
        self._closed_loop = np.ascontiguousarray(dynamics.closed_loop, dtype=float)
        self._index = env.grid_index
        self._lower = np.ascontiguousarray(env.boxes[:, 0])
        self._upper = np.ascontiguousarray(env.boxes[:, 1])

    @property
    def dim(self) -> int:
        """d, the environment's dimension."""
        return self.env.dim

    @property
    def integrator(self) -> str:
        """Whose ode45 rules produce the outputs: ``"octave"`` (refine 1) or ``"matlab"``."""
        return "octave" if self.refine == 1 else "matlab"

    def describe(self) -> dict:
        """Name, rast_num, refine, tolerances, integrator, ``sound: False`` and the dynamics."""
        return {"name": self.name, "rast_num": self.rast_num, "refine": self.refine,
                "rel_tol": self.rel_tol, "abs_tol": self.abs_tol, "integrator": self.integrator,
                "sound": False, "dynamics": self.dynamics.describe()}

    def reachable(self, parents: np.ndarray, children: np.ndarray) -> np.ndarray:
        """Does ``dynamicscheck`` accept each (parent, child) pair?

        Args:
            parents: Float array (M, d), finite.
            children: Float array of the same shape.

        Returns:
            Bool array (M,); adds M to ``evaluations``.

        Raises:
            ValueError: Shapes other than (M, d), different shapes, or non-finite coordinates.
        """
        parents, children = as_pairs(parents, children, self.dim)
        out = np.zeros(parents.shape[0], dtype=np.int64)
        capacity = POINT_OUTPUTS + self.refine
        self._run(parents, children, True, np.empty(capacity), np.empty((capacity, self.dim)), out)
        self.evaluations += int(parents.shape[0])
        return out.astype(np.bool_)

    def ode45_outputs(self, parent: np.ndarray, child: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Every output of the ported ode45 for one pair (all n, not only the 50 the check uses).

        Args:
            parent: One point (d,) (or (1, d)).
            child: One point of the same shape.

        Returns:
            ``(times (n,), points (n, d))``; points are e + child, the first the parent at t = 0.

        Raises:
            ValueError: More than one pair, bad shapes or non-finite coordinates.
        """
        parents, children = as_pairs(parent, child, self.dim)
        if parents.shape[0] != 1:
            raise ValueError(f"ode45_outputs takes one pair, got {parents.shape[0]}")
        capacity = 64 * self.refine
        out = np.zeros(1, dtype=np.int64)
        while True:
            times = np.empty(capacity)
            states = np.empty((capacity, self.dim))
            self._run(parents, children, False, times, states, out)
            n = int(out[0])
            if n <= capacity:
                return times[:n], states[:n]
            capacity = n

    def _run(self, parents: np.ndarray, children: np.ndarray, test: bool, times: np.ndarray, states: np.ndarray,
             out: np.ndarray) -> None:
        index = self._index
        authors_check(parents, children, self._closed_loop, self.dynamics.horizon, self.rel_tol, self.abs_tol,
                      self.refine, self.rast_num, test, self._lower, self._upper, index.origin, index.cell_size,
                      index.shape, index.cell_start, index.cell_items, times, states, out)
