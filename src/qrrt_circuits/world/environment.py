"""The world: an axis-aligned bounding box with axis-aligned box obstacles, in any dimension d >= 2.

Obstacles are closed boxes: a point on a box's boundary is in collision. The workspace is the
closed box ``bounds``. Environments round-trip through a documented JSON format::

    {
      "format": "qrrt-environment", "version": 1, "name": "paper_clutter",
      "bounds": [[low_0, high_0], ..., [low_{d-1}, high_{d-1}]],
      "boxes": [[[lower_0, ..., lower_{d-1}], [upper_0, ..., upper_{d-1}]], ...],
      "metadata": {...}
    }

A scenario file is this format with the problem's ``"start"``, ``"goal"`` and ``"goal_radius"``
beside the geometry (``problems.families.box_world`` reads it, ``save_box_world`` writes it);
``Environment.load`` reads the geometry of such a file.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numba import njit

from .._support.validation import check_int, check_real_array

if TYPE_CHECKING:
    from ..reachability.collision import GridIndex

FORMAT_NAME = "qrrt-environment"
FORMAT_VERSION = 1


#: the largest workspace extent accepted on any axis (beyond it extents and distances overflow)
MAX_EXTENT = 1e12


def _as_float_array(value: Any, name: str) -> np.ndarray:
    if value is None or isinstance(value, str | bytes):
        raise ValueError(f"{name} must be an array of numbers, got {value!r}")
    array = check_real_array(value, name)  # booleans and strings refused, not read as numbers
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must contain only finite numbers (no NaN or inf)")
    return array


@njit(cache=True, nogil=True)
def _box_points(unit: np.ndarray, low: np.ndarray, span: np.ndarray) -> np.ndarray:
    """low + span u for each row u of ``unit`` (M, d), a new array (compiled: numpy's broadcast
    over a short last axis costs more than the arithmetic)."""
    out = np.empty(unit.shape)
    for row in range(unit.shape[0]):
        for axis in range(unit.shape[1]):
            out[row, axis] = low[axis] + span[axis] * unit[row, axis]
    return out


def _metadata(value: Any) -> dict:
    if value is None:
        return {}
    if not isinstance(value, dict):
        raise ValueError(f"'metadata' must be an object, got {value!r}")
    return dict(value)


@dataclass(frozen=True, eq=False)
class Environment:
    """The world (DESIGN §3, §4): workspace ``bounds`` (d, 2) and box obstacles ``boxes`` (k, 2, d).

    ``boxes[i, 0]`` is the lower corner of box i and ``boxes[i, 1]`` its upper corner; boxes and
    the workspace are closed. The environment is geometry only: the start and the goal belong to
    the ``Problem``. Arrays are stored read-only; the object is frozen.

    Args:
        bounds: Float (d, 2), d >= 2: low < high per axis, within [-1e12, 1e12] (``MAX_EXTENT``).
        boxes: Float (k, 2, d), k >= 0: lower corner <= upper corner on every axis.
        name: The scenario's name (``"custom"`` by default).
        metadata: Free-form JSON-serialisable dict (scenario parameters).

    Raises:
        ValueError: Non-numeric or non-finite arrays, wrong shapes, low >= high on an axis, bounds
            beyond ``MAX_EXTENT``, or a box with lower > upper.
    """

    bounds: np.ndarray
    boxes: np.ndarray
    name: str = "custom"
    metadata: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        bounds = _as_float_array(self.bounds, "bounds")
        if bounds.ndim != 2 or bounds.shape[1] != 2 or bounds.shape[0] < 2:
            raise ValueError(f"bounds must have shape (d, 2) with d >= 2, got {bounds.shape}")
        if np.any(bounds[:, 0] >= bounds[:, 1]):
            axis = int(np.argmax(bounds[:, 0] >= bounds[:, 1]))
            raise ValueError(
                f"bounds[{axis}]: low must be < high, got low={bounds[axis, 0]}, "
                f"high={bounds[axis, 1]}"
            )
        if np.any(np.abs(bounds) > MAX_EXTENT):
            raise ValueError(f"bounds must lie within [-{MAX_EXTENT:g}, {MAX_EXTENT:g}] on every axis, got "
                             f"{bounds.tolist()}")
        d = bounds.shape[0]
        if self.boxes is None or not hasattr(self.boxes, "__len__") or isinstance(self.boxes, str | bytes):
            raise ValueError(f"boxes must be an array of shape (k, 2, {d}), got {self.boxes!r}")
        boxes = _as_float_array(self.boxes if len(self.boxes) else np.zeros((0, 2, d)), "boxes")
        if boxes.ndim != 3 or boxes.shape[1:] != (2, d):
            raise ValueError(f"boxes must have shape (k, 2, {d}), got {boxes.shape}")
        bad = np.any(boxes[:, 0] > boxes[:, 1], axis=1)
        if np.any(bad):
            i = int(np.argmax(bad))
            raise ValueError(
                f"boxes[{i}]: lower corner must be <= upper corner on every axis, got "
                f"lower={boxes[i, 0].tolist()}, upper={boxes[i, 1].tolist()}"
            )
        bounds.setflags(write=False)
        boxes = np.ascontiguousarray(boxes)
        boxes.setflags(write=False)
        object.__setattr__(self, "bounds", bounds)
        object.__setattr__(self, "boxes", boxes)

    @cached_property
    def _low(self) -> np.ndarray:
        return np.ascontiguousarray(self.bounds[:, 0])

    @cached_property
    def _span(self) -> np.ndarray:
        return self.bounds[:, 1] - self.bounds[:, 0]

    @property
    def dim(self) -> int:
        """Dimension d of the configuration space."""
        return int(self.bounds.shape[0])

    @property
    def num_boxes(self) -> int:
        """k, the number of boxes."""
        return int(self.boxes.shape[0])

    @property
    def volume(self) -> float:
        """The workspace's volume, the product of its side lengths (obstacles not subtracted)."""
        return float(np.prod(self.bounds[:, 1] - self.bounds[:, 0]))

    def in_bounds(self, points: np.ndarray) -> np.ndarray:
        """True where ``points`` lie in the closed workspace box (obstacles ignored).

        Args:
            points: Float array (..., d); non-finite coordinates are allowed and never in bounds.

        Returns:
            Bool array of shape ``points.shape[:-1]``.

        Raises:
            ValueError: The last dimension is not d.
        """
        points = self._check_points(points)
        return np.all((points >= self.bounds[:, 0]) & (points <= self.bounds[:, 1]), axis=-1)  # NaN: False

    def is_free(self, points: np.ndarray) -> np.ndarray:
        """True where ``points`` are inside the bounds and outside every (closed) box.

        Uses the grid index (``grid_index``); a point on a box's boundary is in collision.

        Args:
            points: Float array (..., d); non-finite coordinates are allowed and never free.

        Returns:
            Bool array of shape ``points.shape[:-1]``.

        Raises:
            ValueError: The last dimension is not d.
        """
        from ..reachability.collision import points_free

        points = self._check_points(points)
        shape = points.shape[:-1]
        flat = np.ascontiguousarray(points.reshape(-1, self.dim))
        index = self.grid_index
        out = np.zeros(flat.shape[0], dtype=np.bool_)
        lower, upper = self.__dict__["_lower"], self.__dict__["_upper"]  # set with the grid index
        points_free(flat, self.bounds, lower, upper, index.origin, index.cell_size,
                    index.shape, index.cell_start, index.cell_items, out)
        out &= np.all(np.isfinite(flat), axis=1)  # a non-finite point is never free
        return out.reshape(shape)

    @property
    def grid_index(self) -> GridIndex:
        """Uniform-grid spatial index of the boxes (built once, on first use)."""
        from ..reachability.collision import GridIndex

        index = self.__dict__.get("_grid_index")
        if index is None:
            index = GridIndex.build(self.bounds, self.boxes)
            object.__setattr__(self, "_grid_index", index)
            object.__setattr__(self, "_lower", np.ascontiguousarray(self.boxes[:, 0]))
            object.__setattr__(self, "_upper", np.ascontiguousarray(self.boxes[:, 1]))
        return index

    def sample_uniform(self, count: int, rng: np.random.Generator) -> np.ndarray:
        """``count`` points uniform in the workspace box (obstacles ignored).

        Args:
            count: How many points (>= 0).
            rng: The ``numpy.random.Generator`` to draw from.

        Returns:
            Float array (count, d).
        """
        return self.box_points(rng.random((count, self.dim)))

    def box_points(self, unit: np.ndarray) -> np.ndarray:
        """The workspace points low + (high - low) u of points u of the unit cube.

        Args:
            unit: Float (M, d), each row in [0, 1)^d (the values are not checked).

        Returns:
            A new float array (M, d).

        Raises:
            ValueError: ``unit`` not of shape (M, d) for the environment's d.
        """
        unit = np.asarray(unit, dtype=float)
        if unit.ndim != 2 or unit.shape[1] != self.dim:
            raise ValueError(f"unit must have shape (M, {self.dim}), got {unit.shape}")
        return _box_points(unit, self._low, self._span)

    def sample_free(
        self, count: int, rng: np.random.Generator, max_attempts: int = 1000
    ) -> np.ndarray:
        """``count`` points uniform over free space (``is_free``), by rejection sampling.

        Draws batches of max(2 (count - found), 16) uniform points and keeps the free ones.

        Args:
            count: How many points (>= 0).
            rng: The ``numpy.random.Generator`` to draw from.
            max_attempts: How many batches to draw at most.

        Returns:
            Float array (count, d).

        Raises:
            TypeError: A non-integer ``count``.
            ValueError: A negative ``count``, or ``rng`` not a ``numpy.random.Generator``.
            RuntimeError: Fewer than ``count`` free points after ``max_attempts`` batches (the free
                space is (nearly) empty).
        """
        check_int(count, "count", 0)
        if not isinstance(rng, np.random.Generator):
            raise ValueError("rng must be a numpy.random.Generator (use np.random.default_rng)")
        count = int(count)
        found: list[np.ndarray] = []
        have = 0
        for _ in range(max_attempts):
            if have >= count:
                break
            batch = self.sample_uniform(max(2 * (count - have), 16), rng)
            batch = batch[self.is_free(batch)]
            found.append(batch)
            have += len(batch)
        if have < count:
            raise RuntimeError(
                f"could not draw {count} free points in {max_attempts} batches: "
                "the free space is (nearly) empty"
            )
        return np.concatenate(found)[:count] if found else np.zeros((0, self.dim))

    def free_fraction(self, samples: int = 20000, seed: int = 0) -> float:
        """Monte-Carlo estimate of the free fraction of the workspace.

        Args:
            samples: Uniform samples (default 20 000).
            seed: Seed of the samples' own generator (default 0).

        Returns:
            The fraction of samples outside every box.

        Example:
            >>> from qrrt_circuits import Environment
            >>> env = Environment([[0, 10], [0, 10]], [[[4, 0], [6, 6]]])  # 12 % blocked
            >>> env.free_fraction()
            0.8815
        """
        rng = np.random.default_rng([0xF4EE, seed])
        return float(np.mean(self.is_free(self.sample_uniform(samples, rng))))

    def _check_points(self, points: np.ndarray) -> np.ndarray:
        """Points as a float array (..., d). Non-finite coordinates are allowed here and are never
        in bounds or free."""
        if isinstance(points, np.ndarray) and points.dtype.kind == "f":
            points = np.asarray(points, dtype=float)
        else:  # booleans and strings refused, not read as numbers
            points = check_real_array(points, "points")
        if points.shape[-1:] != (self.dim,):
            raise ValueError(
                f"points must have last dimension {self.dim} (the environment's d), "
                f"got shape {points.shape}"
            )
        return points

    # ------------------------------------------------------------------ JSON
    def to_dict(self) -> dict:
        """The environment as JSON-able data in the format of the module docstring.

        Returns:
            A dict with ``format``, ``version``, ``name``, ``bounds``, ``boxes`` and ``metadata``.
        """
        return {
            "format": FORMAT_NAME,
            "version": FORMAT_VERSION,
            "name": self.name,
            "bounds": self.bounds.tolist(),
            "boxes": self.boxes.tolist(),
            "metadata": dict(self.metadata),
        }

    @classmethod
    def from_dict(cls, data: dict) -> Environment:
        """The inverse of ``to_dict`` (what ``load`` reads).

        Args:
            data: A dict with ``"format": "qrrt-environment"``, ``"version": 1``, ``bounds`` and
                ``boxes`` (the other keys optional; a scenario file's ``start``, ``goal`` and
                ``goal_radius`` are the problem's, read by ``problems.families.box_world``).

        Returns:
            The ``Environment``.

        Raises:
            ValueError: Not a dict, a wrong format or version, a missing ``bounds`` / ``boxes``,
                ``boxes`` not a list, bad metadata, or any value the constructor refuses.
            TypeError: A value of the wrong type the constructor refuses.

        Example:
            >>> from qrrt_circuits import Environment
            >>> env = Environment([[0, 10], [0, 10]], [[[4, 0], [6, 6]]])
            >>> Environment.from_dict(env.to_dict()).boxes.tolist()
            [[[4.0, 0.0], [6.0, 6.0]]]
        """
        if not isinstance(data, dict):
            raise ValueError("environment JSON must be an object")
        if data.get("format") != FORMAT_NAME:
            raise ValueError(f"'format' must be {FORMAT_NAME!r}, got {data.get('format')!r}")
        if isinstance(data.get("version"), bool) or data.get("version") != FORMAT_VERSION:  # (true == 1 in Python)
            raise ValueError(f"'version' must be {FORMAT_VERSION}, got {data.get('version')!r}")
        for key in ("bounds", "boxes"):
            if key not in data:
                raise ValueError(f"environment JSON is missing {key!r}")
        bounds = _as_float_array(data["bounds"], "bounds")
        boxes = data["boxes"]
        if not isinstance(boxes, list):
            raise ValueError(f"'boxes' must be a list of [[lower...], [upper...]] pairs, got {boxes!r}")
        if len(boxes) == 0:
            boxes = np.zeros((0, 2, bounds.shape[0] if bounds.ndim == 2 else 2))
        return cls(
            bounds=bounds,
            boxes=boxes,
            name=str(data.get("name", "custom"))[:200],
            metadata=_metadata(data.get("metadata")),
        )

    def save(self, path: str | Path) -> Path:
        """Write the environment in the JSON format of the module docstring (``to_dict``).

        Args:
            path: The file to write (overwritten).

        Returns:
            The path written, as a ``Path``.

        Raises:
            OSError: The file cannot be written.
        """
        path = Path(path)
        path.write_text(json.dumps(self.to_dict(), indent=1))
        return path

    @classmethod
    def load(cls, path: str | Path) -> Environment:
        """Read an environment saved by ``save`` (the JSON format of the module docstring).

        Args:
            path: A UTF-8 JSON file with ``"format": "qrrt-environment"`` and ``"version": 1``.

        Returns:
            The ``Environment`` (validated as by the constructor).

        Raises:
            ValueError: Missing, not a regular file, larger than ``MAX_INPUT_BYTES``, not UTF-8,
                not valid JSON, a wrong format or version, a missing ``bounds`` / ``boxes``, or any
                value the constructor refuses; the message names the path and never quotes the
                file (``_support.input_files``).
        """
        from .._support.input_files import read_json_file

        data = read_json_file(path, "scenario file")
        try:
            return cls.from_dict(data)
        except (ValueError, TypeError) as exc:
            raise ValueError(f"{path}: {exc}") from exc

    def __repr__(self) -> str:
        return f"Environment(name={self.name!r}, d={self.dim}, boxes={self.num_boxes})"
