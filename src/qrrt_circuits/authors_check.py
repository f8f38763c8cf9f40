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

The compiled kernels (numba, ``@njit(cache=True, nogil=True)``) integrate each pair, stop after the
50 outputs the test can use, and test the points through the environment's uniform grid
(``qrrt_circuits.collision.GridIndex``); they work in any dimension d.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .dynamics import LinearTrackingDynamics
from .environment import Environment
from .predicate import as_pairs
from .validation import check_int

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
_MAX_ATTEMPTS = 1_000_000  # a guard; the linear, stable systems here take ~20-40 attempts


@njit(cache=True, nogil=True)
def _matvec(M, x, out):
    d = x.shape[0]
    for row in range(d):
        acc = 0.0
        for col in range(d):
            acc += M[row, col] * x[col]
        out[row] = acc


@njit(cache=True, nogil=True)
def _store(count, capacity, t, e, times, states):
    if count < capacity:
        times[count] = t
        for axis in range(e.shape[0]):
            states[count, axis] = e[axis]


@njit(cache=True, nogil=True)
def _ode45_octave(e0, M, horizon, rtol, atol, stop_after, times, states):
    """Octave 7's ode45 (integrate_adaptive + runge_kutta_45_dorpri + starting_stepsize) on
    e' = M e, e(0) = e0, t in [0, horizon]: one output per accepted step (Octave ignores Refine).

    Outputs go to ``times`` / ``states`` (as many as fit); integration stops once ``stop_after``
    outputs exist. Returns the number of outputs produced."""
    d = e0.shape[0]
    capacity = times.shape[0]
    eps = np.finfo(np.float64).eps
    x = e0.copy()
    x_new = np.empty(d)
    x_est = np.empty(d)
    tmp = np.empty(d)
    k = np.empty((7, d))
    count = 0
    _store(count, capacity, 0.0, x, times, states)
    count += 1
    # starting_stepsize (Hairer, Norsett & Wanner), order 5
    _matvec(M, x, k[0])
    d0 = 0.0
    d1 = 0.0
    for axis in range(d):
        d0 = max(d0, abs(x[axis]) / max(atol, rtol * abs(x[axis])))
        d1 = max(d1, abs(k[0, axis]) / max(atol, rtol * abs(k[0, axis])))
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * (d0 / d1)
    for axis in range(d):
        tmp[axis] = x[axis] + h0 * k[0, axis]
    _matvec(M, tmp, x_est)
    d2 = 0.0
    for axis in range(d):
        diff = x_est[axis] - k[0, axis]
        d2 = max(d2, abs(diff) / max(atol, rtol * abs(diff)))
    d2 = (1.0 / h0) * d2
    if max(d1, d2) <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (1e-2 / max(d1, d2)) ** (1.0 / 6.0)
    max_step = 0.1 * horizon
    dt = min(min(100.0 * h0, h1), max_step)
    fac = 0.38 ** (1.0 / 6.0)
    t_old = 0.0
    t_last = 0.0
    comp = 0.0
    attempts = 0
    while t_old < horizon and count < stop_after and attempts < _MAX_ATTEMPTS:
        attempts += 1
        # Kahan-summed new time
        term = dt - comp
        t_new = t_old + term
        comp_new = (t_new - t_old) - term
        # Dormand-Prince stages (k[0] = f(x_old), FSAL); x + k(:, 1:i) * (dt a(i, 1:i))'
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
        err = 0.0
        for axis in range(d):
            acc = x[axis]
            for j in range(7):
                acc += k[j, axis] * (dt * _C4[j])
            x_est[axis] = acc
            sc = max(atol, rtol * max(abs(x_new[axis]), abs(x[axis])))
            err = max(err, abs(x_new[axis] - x_est[axis]) / sc)
        if err <= 1.0:
            _store(count, capacity, t_new, x_new, times, states)
            count += 1
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
            break
        dt = min(dt, horizon - t_old)
    return count


@njit(cache=True, nogil=True)
def _ode45_matlab(e0, M, horizon, rtol, atol, refine, stop_after, times, states):
    """MATLAB's ode45 on e' = M e, e(0) = e0, t in [0, horizon], with ``refine`` outputs per
    accepted step (ntrp45 at fractions 1/refine .. (refine-1)/refine, then the step end).

    Outputs go to ``times`` / ``states`` (as many as fit); integration stops once ``stop_after``
    outputs exist. Returns the number of outputs produced."""
    d = e0.shape[0]
    capacity = times.shape[0]
    power = 1.0 / 5.0
    threshold = atol / rtol
    y = e0.copy()
    y_new = np.empty(d)
    tmp = np.empty(d)
    f = np.empty((7, d))
    count = 0
    _store(count, capacity, 0.0, y, times, states)
    count += 1
    t = 0.0
    t_final = horizon
    hmax = 0.1 * horizon
    hmin = 16.0 * np.spacing(t)
    _matvec(M, y, f[0])
    absh = min(hmax, horizon)
    rh = 0.0
    for axis in range(d):
        rh = max(rh, abs(f[0, axis]) / max(abs(y[axis]), threshold))
    rh = rh / (0.8 * rtol ** power)
    if absh * rh > 1.0:
        absh = 1.0 / rh
    absh = max(absh, hmin)
    done = False
    attempts = 0
    while not done and count < stop_after:
        hmin = 16.0 * np.spacing(t)
        absh = min(hmax, max(hmin, absh))
        h = absh
        if 1.1 * absh >= abs(t_final - t):
            h = t_final - t
            absh = abs(h)
            done = True
        no_failed = True
        err = 0.0
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
                t_new = t_final
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
            if err > rtol:
                if absh <= hmin or attempts >= _MAX_ATTEMPTS:  # MATLAB warns and returns
                    return count
                if no_failed:
                    no_failed = False
                    absh = max(hmin, absh * max(0.1, 0.8 * (rtol / err) ** power))
                else:
                    absh = max(hmin, 0.5 * absh)
                h = absh
                done = False
            else:
                break
        # refine - 1 interpolated outputs (ntrp45), then the step end
        for r in range(1, refine):
            t_ref = t + (t_new - t) * (r / refine)
            s = (t_ref - t) / h
            s2 = s * s
            s3 = s2 * s
            s4 = s3 * s
            for axis in range(d):
                acc = 0.0
                for j in range(7):
                    acc += f[j, axis] * (h * (_BI[j, 0] * s + _BI[j, 1] * s2 + _BI[j, 2] * s3
                                              + _BI[j, 3] * s4))
                tmp[axis] = y[axis] + acc
            _store(count, capacity, t_ref, tmp, times, states)
            count += 1
        _store(count, capacity, t_new, y_new, times, states)
        count += 1
        if done:
            break
        if no_failed:
            temp = 1.25 * (err / rtol) ** power
            if temp > 0.2:
                absh = absh / temp
            else:
                absh = 5.0 * absh
        t = t_new
        for axis in range(d):
            y[axis] = y_new[axis]
            f[0, axis] = f[6, axis]
    return count


@njit(cache=True, nogil=True)
def _in_a_box(point, lower, upper, origin, cell_size, shape, cell_start, cell_items):
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
def _integrate(e0, M, horizon, rtol, atol, refine, stop_after, times, states):
    if refine == 1:
        return _ode45_octave(e0, M, horizon, rtol, atol, stop_after, times, states)
    return _ode45_matlab(e0, M, horizon, rtol, atol, refine, stop_after, times, states)


@njit(cache=True, nogil=True)
def authors_check(parents, children, M, horizon, rtol, atol, refine, rast_num, lower, upper,
                  origin, cell_size, shape, cell_start, cell_items, out):
    """out[i] = dynamicscheck(parents[i], children[i]) (see the module docstring)."""
    d = parents.shape[1]
    capacity = POINT_OUTPUTS + refine
    times = np.empty(capacity)
    states = np.empty((capacity, d))
    e0 = np.empty(d)
    point = np.empty(d)
    for i in range(parents.shape[0]):
        for axis in range(d):
            e0[axis] = parents[i, axis] - children[i, axis]
        n = _integrate(e0, M, horizon, rtol, atol, refine, POINT_OUTPUTS, times, states)
        n = min(n, POINT_OUTPUTS)
        for row in range(n):
            for axis in range(d):
                states[row, axis] += children[i, axis]
        free = not _in_a_box(states[0], lower, upper, origin, cell_size, shape, cell_start, cell_items)
        # outputs 2..25 (0-based rows 1..24): rast_num points of the segment back to the previous one
        row = 1
        while free and row < min(n, SEGMENT_OUTPUTS):
            for j in range(1, rast_num + 1):
                fraction = j / rast_num
                for axis in range(d):
                    point[axis] = states[row, axis] + fraction * (states[row - 1, axis] - states[row, axis])
                if _in_a_box(point, lower, upper, origin, cell_size, shape, cell_start, cell_items):
                    free = False
                    break
            row += 1
        # outputs 26..50: points
        row = SEGMENT_OUTPUTS
        while free and row < n:
            if _in_a_box(states[row], lower, upper, origin, cell_size, shape, cell_start, cell_items):
                free = False
            row += 1
        out[i] = free
    return out


@njit(cache=True, nogil=True)
def ode45_outputs(e0, M, horizon, rtol, atol, refine, times, states):
    """All outputs of the integration of e' = M e from e0 (see ``_integrate``); returns their
    number (the arrays hold the first ``len(times)``)."""
    return _integrate(e0, M, horizon, rtol, atol, refine, 1 << 62, times, states)


class AuthorsCheck:
    """The authors' ``dynamicscheck.m`` as a batch reachability predicate (unsound; see the module
    docstring). ``refine == 1`` reproduces Octave 7's ode45 (the reference verdicts), ``refine >=
    2`` MATLAB's ode45 with that Refine (MATLAB's default is 4)."""

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
        return self.env.dim

    @property
    def integrator(self) -> str:
        """Whose ode45 rules produce the outputs: ``"octave"`` (refine 1) or ``"matlab"``."""
        return "octave" if self.refine == 1 else "matlab"

    def describe(self) -> dict:
        return {"name": self.name, "rast_num": self.rast_num, "refine": self.refine,
                "rel_tol": self.rel_tol, "abs_tol": self.abs_tol, "integrator": self.integrator,
                "sound": False, "dynamics": self.dynamics.describe()}

    def reachable(self, parents: np.ndarray, children: np.ndarray) -> np.ndarray:
        """Bool (M,): does ``dynamicscheck`` accept each (parent, child) pair?"""
        parents, children = as_pairs(parents, children, self.dim)
        out = np.zeros(parents.shape[0], dtype=np.bool_)
        index = self._index
        authors_check(parents, children, self._closed_loop, self.dynamics.horizon, self.rel_tol,
                      self.abs_tol, self.refine, self.rast_num, self._lower, self._upper,
                      index.origin, index.cell_size, index.shape, index.cell_start, index.cell_items,
                      out)
        self.evaluations += int(parents.shape[0])
        return out

    def ode45_outputs(self, parent: np.ndarray, child: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(times (n,), points (n, d))``: every output of the solver for one pair (all n, not
        only the 50 the check uses); points are e + child, the first is the parent at t = 0."""
        parents, children = as_pairs(parent, child, self.dim)
        if parents.shape[0] != 1:
            raise ValueError(f"ode45_outputs takes one pair, got {parents.shape[0]}")
        e0 = parents[0] - children[0]
        capacity = 64 * self.refine
        while True:
            times = np.empty(capacity)
            states = np.empty((capacity, self.dim))
            n = ode45_outputs(e0, self._closed_loop, self.dynamics.horizon, self.rel_tol,
                              self.abs_tol, self.refine, times, states)
            if n <= capacity:
                return times[:n], states[:n] + children[0]
            capacity = n
