"""The coherent oracle's predicate evaluated classically, in integers, with the circuit's rounding.

For entry i (sample grid point u_c, parent grid point u_p, ``lattice``) and each tested integer
matrix e (``motion.SampledMotion.tested``, f fraction bits), the tested point is

    x = floor((2^f u_c + e (u_p - u_c) + rho) / 2^f),   rho = floor(2^(f - 1))

per axis (the exact value u_c + (e / 2^f)(u_p - u_c) rounded to nearest, ties up). The entry is
reachable iff its parent is a tree node (``valid``) and every tested point lies in the workspace
and in no obstacle, both tested exactly on the grid: ``ceil_index(low) <= x <= floor_index(high)``
per axis (``number_format``; boxes are closed, as in ``Environment``). This is the marks the
coherent oracle flips (``reachable_reference``), computed here without the circuit's
decomposition (no digits, no thresholds folded into offsets), so that the two can check each
other.

``compare_with_time_sampled`` measures what the fixed point changes: the fraction of entries where
this predicate and the library's floating-point ``TimeSampledCheck`` (same K times, the unrounded
parent and the sample's grid point) disagree.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .._support.memory import MemoryEstimate, check_fits
from ..reachability.time_sampled import TimeSampledCheck
from ..world.environment import Environment
from .lattice import MAX_ENUMERATED_BITS, DatabaseEntries, LatticeDatabase
from .motion import SampledMotion

#: entries per chunk of the vectorized evaluation (bounded memory whatever 2^n)
CHUNK_ENTRIES = 1 << 16


def grid_limits(env: Environment, database: LatticeDatabase) -> tuple[np.ndarray, np.ndarray]:
    """The workspace and the boxes as integer intervals of grid points.

    Args:
        env: The ``Environment`` (checked against the format: ``FixedPointFormat.check_environment``).
        database: The ``LatticeDatabase`` (its format and d).

    Returns:
        (bounds, boxes): int64 (d, 2) [ceil_index(low), floor_index(high)] per axis, and int64
        (B, 2, d) the same for every box.

    Raises:
        ValueError: A dimension other than the database's, or coordinates outside the format.
    """
    fmt = database.fmt
    if env.dim != database.dim:
        raise ValueError(f"env has d = {env.dim}, the database d = {database.dim}")
    fmt.check_environment(env)
    bounds = np.array([[fmt.ceil_index(low), fmt.floor_index(high)] for low, high in env.bounds], dtype=np.int64)
    boxes = np.array([[[fmt.ceil_index(v) for v in box[0]], [fmt.floor_index(v) for v in box[1]]]
                      for box in env.boxes], dtype=np.int64).reshape(-1, 2, env.dim)
    return bounds, boxes


def tested_points(entries: DatabaseEntries, motion: SampledMotion) -> np.ndarray:
    """The tested points' grid coordinates (module text) of some entries.

    Args:
        entries: ``DatabaseEntries`` (M rows).
        motion: The ``SampledMotion`` (its ``tested`` matrices, P of them).

    Returns:
        Int64 (M, P, d).
    """
    f = motion.fraction_bits
    rounding = (1 << f) >> 1
    u_c, u_p = entries.sample_grid, entries.parent_grid
    delta = u_p - u_c
    matrices = np.stack(motion.tested)  # (P, d, d)
    accumulated = (u_c << f)[:, None, :] + np.einsum("pij,mj->mpi", matrices, delta) + rounding
    return np.floor_divide(accumulated, 1 << f)


def reference_bytes(num_index_bits: int, points: int, dim: int) -> int:
    """Peak bytes ``reachable_reference`` adds over all 2^n entries: the indices and the marks
    (8 + 1 bytes an entry) and one chunk's scratch (its decoded entries, 16 d + 48 bytes a row, and
    its tested points with their comparisons, 40 d bytes a row and point).

    Args:
        num_index_bits: n.
        points: P, the motion's tested points.
        dim: d.

    Returns:
        The bytes.
    """
    rows = min(1 << num_index_bits, CHUNK_ENTRIES)
    return (9 << num_index_bits) + rows * (16 * dim + 48 + 40 * dim * max(points, 1))


def check_reference_fits(database: LatticeDatabase, motion: SampledMotion, extra: Callable[[int], int] | None = None,
                         what: str = "reachable_reference over all 2^n entries") -> None:
    """Refuse (``ValueError``, before any work) an evaluation over all 2^n entries whose estimate
    (``reference_bytes``, plus ``extra(n)``) exceeds the available memory, naming
    ``database.num_index_bits`` and the largest n that fits (``memory.check_fits``).

    Args:
        database: The ``LatticeDatabase``.
        motion: The ``SampledMotion``.
        extra: More bytes as a function of n (a caller's own arrays), or None.
        what: The run, for the message.

    Raises:
        ValueError: The estimate exceeds the available memory.
    """
    points, dim = len(motion.tested), database.dim

    def estimate_for(n: int) -> MemoryEstimate:
        return MemoryEstimate(n, database_bytes=reference_bytes(n, points, dim) + (extra(n) if extra else 0))

    check_fits(estimate_for, database.num_index_bits, what, name="database.num_index_bits")


def reachable_reference(env: Environment, database: LatticeDatabase, motion: SampledMotion,
                        indices: np.ndarray | None = None) -> np.ndarray:
    """The marks of the coherent oracle: is entry i reachable, in the circuit's integer semantics?

    Args:
        env: The ``Environment`` (bounds and boxes inside the format's range).
        database: The ``LatticeDatabase``.
        motion: The ``SampledMotion`` (same d).
        indices: The entries to evaluate (default: all 2^n, n <= ``lattice.MAX_ENUMERATED_BITS``).

    Returns:
        Bool array, one per index (length 2^n by default): valid, and every tested point in
        bounds and in no box.

    Raises:
        ValueError: Mismatched dimensions, a world outside the format, too many entries, or all
            2^n entries asked for where their estimate (``reference_bytes``) exceeds the available
            memory (refused before any work, naming ``database.num_index_bits``).

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits import Environment
        >>> from qrrt_circuits.coherent import (FixedPointFormat, LatticeDatabase, SampledMotion,
        ...                                     reachable_reference)
        >>> env = Environment([[0, 15], [0, 15]], [[[6, 0], [9, 9]]])
        >>> db = LatticeDatabase(FixedPointFormat(4, 0.0, 16.0), 2, np.array([[2.0, 2.0]]))
        >>> marks = reachable_reference(env, db, SampledMotion.straight_line(2, 3, 1))
        >>> marks.reshape(4, 4).astype(int).tolist()  # [y cell][x cell]: the wall at x in [6, 9], y <= 9
        [[1, 0, 0, 0], [1, 0, 0, 0], [1, 1, 0, 0], [1, 1, 0, 0]]
    """
    if motion.dim != database.dim:
        raise ValueError(f"motion has d = {motion.dim}, the database d = {database.dim}")
    bounds, boxes = grid_limits(env, database)
    if indices is None:
        n = database.num_index_bits
        if n > MAX_ENUMERATED_BITS:
            raise ValueError(f"reachable_reference enumerates 2^n entries: database.num_index_bits must be "
                             f"<= {MAX_ENUMERATED_BITS}, got {n} (or pass indices)")
        check_reference_fits(database, motion)
        indices = np.arange(1 << n, dtype=np.int64)
    indices = np.asarray(indices, dtype=np.int64).reshape(-1)
    out = np.zeros(indices.shape[0], dtype=bool)
    for first in range(0, indices.shape[0], CHUNK_ENTRIES):
        chunk = database.entries(indices[first:first + CHUNK_ENTRIES])
        points = tested_points(chunk, motion)  # (M, P, d)
        free = np.all((points >= bounds[:, 0]) & (points <= bounds[:, 1]), axis=(1, 2))
        for box in boxes:
            inside = np.all((points >= box[0]) & (points <= box[1]), axis=2)  # (M, P)
            free &= ~np.any(inside, axis=1)
        out[first:first + CHUNK_ENTRIES] = free & chunk.valid
    return out


@dataclass(frozen=True)
class RoundingComparison:
    """The fixed-point predicate against ``TimeSampledCheck`` on the valid entries.

    Args:
        entries: Valid entries compared.
        reachable_fixed: Of them, reachable in fixed point (``reachable_reference``).
        reachable_float: Reachable under ``TimeSampledCheck`` (floating point).
        fixed_only: Reachable in fixed point only (the rounding admits them).
        float_only: Reachable in floating point only (the rounding rejects them).
    """

    entries: int
    reachable_fixed: int
    reachable_float: int
    fixed_only: int
    float_only: int

    @property
    def differ(self) -> int:
        """Entries whose answer differs."""
        return self.fixed_only + self.float_only

    @property
    def fraction_differing(self) -> float:
        """differ / entries (0 for no entries)."""
        return self.differ / self.entries if self.entries else 0.0


def compare_with_time_sampled(env: Environment, database: LatticeDatabase, motion: SampledMotion,
                              indices: np.ndarray | None = None) -> RoundingComparison:
    """Entries whose answer the fixed point changes, against the library's ``TimeSampledCheck``.

    ``TimeSampledCheck(env, motion.dynamics, time_samples=K)`` tests the same K times in floating
    point, from the parent's given coordinates (not rounded to the grid) to the sample (a grid
    point, so exact), and the sample itself; the difference is the rounding of the parent, of the
    coefficients and of the points, and the boxes' snapping to the grid.

    Args:
        env: The ``Environment``.
        database: The ``LatticeDatabase``.
        motion: A ``SampledMotion`` made by ``from_dynamics`` (it carries the dynamics and K).
        indices: Entries to compare (default all 2^n); invalid ones are skipped.

    Returns:
        The ``RoundingComparison``.

    Raises:
        ValueError: ``motion`` without dynamics, or as ``reachable_reference``.
    """
    if motion.dynamics is None:
        raise ValueError("motion has no dynamics: build it with SampledMotion.from_dynamics")
    if indices is None:
        indices = database.entries().indices
    indices = np.asarray(indices, dtype=np.int64).reshape(-1)
    fixed = reachable_reference(env, database, motion, indices)
    check = TimeSampledCheck(env, motion.dynamics, time_samples=motion.time_samples)
    counts = np.zeros(5, dtype=np.int64)  # entries, fixed, float, fixed only, float only
    for first in range(0, indices.shape[0], CHUNK_ENTRIES):
        chunk = database.entries(indices[first:first + CHUNK_ENTRIES])
        keep = chunk.valid
        ours = fixed[first:first + CHUNK_ENTRIES][keep]
        theirs = check.reachable(chunk.parents[keep], chunk.samples[keep])
        counts += [keep.sum(), ours.sum(), theirs.sum(), (ours & ~theirs).sum(), (theirs & ~ours).sum()]
    return RoundingComparison(*(int(c) for c in counts))
