"""Occupancy-image worlds: a map drawn as an image, one square cell per pixel (ROS ``map_server``'s
convention, the usual way geometric planners such as OMPL's are given a 2-D map).

``OccupancyGrid.from_image(path, pixel_size, free_threshold=0.5, negate=False)`` reads a PNG
(through ``matplotlib.image.imread``, a core dependency) or a PGM / PPM file (binary ``P5`` /
``P6`` or ASCII ``P2`` / ``P3``, read by the small reader of this module; the format is told by the
file's first bytes, not by its name). Each pixel's grey value is the mean of its colour channels
(an alpha channel is ignored), normalized to [0, 1] by the format's largest sample value
(``maxval`` for PGM / PPM, 255 or 65535 for PNG; a 16-bit colour PNG is read at 8 bits per
channel, as Pillow reads it, a 16-bit greyscale PNG at its 16 bits). A pixel is **free where grey
>= free_threshold** (white free, black occupied); ``negate=True`` reads 1 - grey instead (black
free). Every cell is free or occupied: there is no unknown cell.

ROS ``map_server`` reads the same images with two thresholds on the occupancy p = 1 - grey (p =
grey with its ``negate``): free where p < ``free_thresh`` (default 0.196), occupied where p >
``occupied_thresh`` (default 0.65), unknown between. Here a cell is free iff p <= 1 -
``free_threshold``, so ``free_threshold = 1 - free_thresh`` (0.804 for ROS's default) frees the
cells ROS calls free (a pixel exactly at ROS's threshold aside) and makes the unknown ones
occupied, as a check that must never accept a collision should; the default 0.5 splits the grey
range in the middle instead.

Geometry: pixel (row, col) of the image is the closed square
[ox + col s, ox + (col + 1) s] x [oy + (rows - 1 - row) s, oy + (rows - row) s], with s the
``pixel_size`` and (ox, oy) the ``origin``, the world position of the image's bottom-left corner:
**image row 0 is the top** of the map, and world y grows upward. The map's bounds are
[ox, ox + cols s] x [oy, oy + rows s].

Images larger than ``MAX_CELLS`` pixels, or wider or taller than ``MAX_SIDE``, are refused from
their header, before their pixels are read. The motion check over such a grid is
``qrrt_circuits.reachability.grid_check.GridCheck``.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .._support.validation import check_bool, check_float, check_positive_float, check_real_array
from .environment import MAX_EXTENT

__all__ = ["MAX_CELLS", "MAX_SIDE", "OccupancyGrid"]

#: the most pixels (cells) an occupancy image may have (4096 x 4096)
MAX_CELLS = 1 << 24

#: the most pixels an occupancy image may have along one side (keeps the motion check's cell
#: coordinates small enough for its rounding bound, ``grid_check.EPSILON``)
MAX_SIDE = 1 << 16

#: what ``from_image`` accepts, for the error messages
ACCEPTED = "a PNG file, or a PGM / PPM file (binary P5 / P6 or ASCII P2 / P3)"

_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_PNM_CHANNELS = {b"P2": 1, b"P3": 3, b"P5": 1, b"P6": 3}
_PNM_HEADER_BYTES = 1 << 20  # a PGM / PPM header (comments included) longer than this is refused
_PNM_NUMBER_DIGITS = 9  # a width, height or maxval of more digits is refused (no number fits in fewer)
#: bytes an ASCII (P2 / P3) sample may take with its whitespace: a file whose raster is longer than
#: this per declared sample, plus ``_PNM_SLACK_BYTES``, is refused
_ASCII_SAMPLE_BYTES = 16
#: bytes a PGM / PPM file may hold beyond what its header declares before it is refused
_PNM_SLACK_BYTES = 1 << 16


@dataclass(frozen=True, eq=False)
class OccupancyGrid:
    """A 2-D map of square cells, free or occupied (see the module docstring for the geometry).

    Args:
        free: Bool array (rows, cols), True where the cell is free, in image orientation: row 0
            is the top of the map. Stored read-only.
        pixel_size: s, the side of a cell in world units (a finite number > 0).
        origin: (ox, oy), the world position of the map's bottom-left corner (default (0, 0)).
        metadata: Where the grid came from (``from_image`` records the path, format, threshold
            and ``negate``); JSON-able.

    Raises:
        ValueError: ``free`` not a 2-D array of booleans with at least one cell, more than
            ``MAX_CELLS`` cells or a side longer than ``MAX_SIDE``, a ``pixel_size`` that is not
            finite and > 0, an ``origin`` that is not two finite numbers, or bounds beyond
            ``environment.MAX_EXTENT``.
        TypeError: A non-numeric ``pixel_size``.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits import OccupancyGrid
        >>> grid = OccupancyGrid(np.array([[True, False], [True, True]]), pixel_size=0.5)
        >>> grid.bounds().tolist()  # 2 cells of 0.5 on each axis
        [[0.0, 1.0], [0.0, 1.0]]
        >>> grid.pixel_center(0, 1)  # the occupied cell: top row, right column
        (0.75, 0.75)
    """

    free: np.ndarray
    pixel_size: float
    origin: tuple[float, float] = (0.0, 0.0)
    metadata: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        free = np.asarray(self.free)
        if free.dtype != np.bool_ or free.ndim != 2 or free.size == 0:
            raise ValueError("free must be a 2-D array of booleans (True = free cell) with at least one cell, "
                             f"got dtype {free.dtype} and shape {free.shape}")
        _check_size(free.shape[1], free.shape[0], "free")
        pixel_size = check_positive_float(self.pixel_size, "pixel_size")
        origin = _check_origin(self.origin)
        _check_extent(origin, pixel_size, free.shape[1], free.shape[0])
        free = np.array(free, dtype=bool, order="C")
        free.setflags(write=False)
        object.__setattr__(self, "free", free)
        object.__setattr__(self, "pixel_size", pixel_size)
        object.__setattr__(self, "origin", origin)
        if not isinstance(self.metadata, dict):
            raise ValueError(f"metadata must be a dict, got {self.metadata!r}")
        object.__setattr__(self, "metadata", dict(self.metadata))

    @classmethod
    def from_image(cls, path: str | Path, pixel_size: float, free_threshold: float = 0.5,
                   negate: bool = False, origin: tuple[float, float] = (0.0, 0.0)) -> OccupancyGrid:
        """Read an occupancy image (see the module docstring for the formats and conventions).

        Every argument, the file's format and its size (from its header) are checked before its
        pixels are read.

        Args:
            path: A PNG, PGM or PPM file (told by its first bytes).
            pixel_size: s, the side of a pixel in world units (a finite number > 0).
            free_threshold: A pixel is free where its grey value (in [0, 1]) is >= this; a number
                in [0, 1] (default 0.5).
            negate: Read 1 - grey instead of grey (black free); default False (white free).
            origin: (ox, oy), the world position of the image's bottom-left corner (default (0, 0)).

        Returns:
            The ``OccupancyGrid``; its ``metadata`` records the path, format, ``free_threshold``
            and ``negate``.

        Raises:
            ValueError: ``pixel_size`` not finite and > 0, ``free_threshold`` outside [0, 1], an
                ``origin`` that is not two finite numbers, a ``path`` that is missing or not a
                file, a file that is not one of the accepted formats or is unreadable (truncated,
                bad header, samples above ``maxval``), an image with more than ``MAX_CELLS`` pixels
                or a side longer than ``MAX_SIDE``, or bounds beyond ``environment.MAX_EXTENT``;
                each message names the argument and what is accepted.
            TypeError: A non-numeric ``pixel_size`` or ``free_threshold``, or ``negate`` not a bool.

        Example:
            >>> import numpy as np, tempfile, os
            >>> from qrrt_circuits import OccupancyGrid
            >>> path = os.path.join(tempfile.mkdtemp(), "map.pgm")
            >>> with open(path, "wb") as handle:  # 3 x 2 pixels, the middle of the top row black
            ...     _ = handle.write(b"P5 3 2 255\\n" + bytes([255, 0, 255, 255, 255, 255]))
            >>> OccupancyGrid.from_image(path, pixel_size=0.1).free.tolist()
            [[True, False, True], [True, True, True]]
        """
        pixel_size = check_positive_float(pixel_size, "pixel_size")
        free_threshold = check_float(free_threshold, "free_threshold", 0.0, 1.0)
        negate = check_bool(negate, "negate")
        origin = _check_origin(origin)
        path = _check_path(path)
        kind, width, height = _header(path)
        _check_size(width, height, "path")
        _check_extent(origin, pixel_size, width, height)
        samples, maxval = _read_png(path) if kind == "PNG" else _read_pnm(path, kind)
        grey = _grey(samples, maxval)
        if negate:
            grey = 1.0 - grey
        metadata = {"path": str(path), "format": kind, "free_threshold": free_threshold, "negate": negate}
        return cls(grey >= free_threshold, pixel_size, origin, metadata)

    @property
    def rows(self) -> int:
        """The number of pixel rows (the map's height in cells)."""
        return int(self.free.shape[0])

    @property
    def cols(self) -> int:
        """The number of pixel columns (the map's width in cells)."""
        return int(self.free.shape[1])

    @property
    def free_fraction(self) -> float:
        """The fraction of free cells."""
        return float(np.mean(self.free))

    def bounds(self) -> np.ndarray:
        """Float (2, 2): [[ox, ox + cols s], [oy, oy + rows s]], the map's closed extent."""
        ox, oy = self.origin
        return np.array([[ox, ox + self.cols * self.pixel_size], [oy, oy + self.rows * self.pixel_size]])

    def pixel_center(self, row: int, col: int) -> tuple[float, float]:
        """The world position (x, y) of the centre of image pixel (``row``, ``col``), row 0 the top.

        Args:
            row: An image row in [0, rows).
            col: An image column in [0, cols).

        Returns:
            (ox + (col + 0.5) s, oy + (rows - row - 0.5) s).

        Raises:
            ValueError: A row or column outside the image.
        """
        if not (0 <= row < self.rows and 0 <= col < self.cols):
            raise ValueError(f"(row, col) must lie in [0, {self.rows}) x [0, {self.cols}), got ({row}, {col})")
        ox, oy = self.origin
        return (ox + (col + 0.5) * self.pixel_size, oy + (self.rows - row - 0.5) * self.pixel_size)

    def describe(self) -> dict:
        """The grid as JSON-able settings: its shape, pixel size, origin, free cells, a SHA-256 of
        the free mask (which identifies the map) and its metadata."""
        digest = hashlib.sha256(np.packbits(self.free).tobytes() + repr(self.free.shape).encode()).hexdigest()
        return {"rows": self.rows, "cols": self.cols, "pixel_size": self.pixel_size, "origin": list(self.origin),
                "free_cells": int(np.count_nonzero(self.free)), "free_sha256": digest, **self.metadata}

    def __repr__(self) -> str:
        return (f"OccupancyGrid({self.rows} x {self.cols} cells of {self.pixel_size:g}, origin={self.origin}, "
                f"free={self.free_fraction:.3f})")


def _check_size(width: int, height: int, name: str) -> None:
    """Refuse an image with more than ``MAX_CELLS`` pixels or a side longer than ``MAX_SIDE``."""
    if width < 1 or height < 1:
        raise ValueError(f"{name}: an occupancy image must have at least one pixel, got {width} x {height}")
    if width * height > MAX_CELLS or max(width, height) > MAX_SIDE:
        raise ValueError(f"{name}: the image has {width} x {height} pixels; accepted are at most {MAX_CELLS} "
                         f"pixels (MAX_CELLS, 4096 x 4096) and at most {MAX_SIDE} along a side (MAX_SIDE)")


def _check_origin(origin: Any) -> tuple[float, float]:
    """``origin`` as two finite floats, else a ``ValueError`` naming it."""
    try:
        array = check_real_array(origin, "origin").reshape(-1)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"origin must be two finite numbers (x, y) of the map's bottom-left corner, "
                         f"got {origin!r}") from exc
    if array.shape != (2,) or not np.all(np.isfinite(array)):
        raise ValueError(f"origin must be two finite numbers (x, y) of the map's bottom-left corner, "
                         f"got {origin!r}")
    return float(array[0]), float(array[1])


def _check_extent(origin: tuple[float, float], pixel_size: float, width: int, height: int) -> None:
    """Refuse a map whose bounds reach beyond ``environment.MAX_EXTENT``."""
    top = (origin[0] + pixel_size * width, origin[1] + pixel_size * height)
    if max(abs(origin[0]), abs(origin[1]), abs(top[0]), abs(top[1])) > MAX_EXTENT:
        raise ValueError(f"the map's bounds must lie within [-{MAX_EXTENT:g}, {MAX_EXTENT:g}]: origin "
                         f"{list(origin)} with pixel_size {pixel_size:g} and {width} x {height} pixels reaches "
                         f"{list(top)}")


def _check_path(path: Any) -> Path:
    if not isinstance(path, str | Path):
        raise ValueError(f"path must be a file path (str or Path) to {ACCEPTED}, got {path!r}")
    path = Path(path)
    if not path.exists():
        raise ValueError(f"path {str(path)!r} does not exist (accepted: {ACCEPTED})")
    if not path.is_file():
        raise ValueError(f"path {str(path)!r} is not a file (accepted: {ACCEPTED})")
    return path


def _unreadable(path: Path, why: str) -> ValueError:
    return ValueError(f"path {str(path)!r} is not a readable image ({why}); accepted: {ACCEPTED}")


def _header(path: Path) -> tuple[str, int, int]:
    """(format, width, height) from the file's first bytes: ``"PNG"`` (its IHDR chunk) or the
    PGM / PPM magic number ``"P2"``, ``"P3"``, ``"P5"`` or ``"P6"`` (its header)."""
    with path.open("rb") as handle:
        head = handle.read(_PNM_HEADER_BYTES)
    if head.startswith(_PNG_SIGNATURE):
        if len(head) < 24 or head[12:16] != b"IHDR":
            raise _unreadable(path, "a PNG signature without an IHDR chunk")
        return "PNG", int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")
    if head[:2] in _PNM_CHANNELS:
        magic, width, height, _, _ = _pnm_header(path, head)
        return magic, width, height
    raise _unreadable(path, "unknown format: neither a PNG signature nor a P2 / P3 / P5 / P6 magic number")


def _pnm_header(path: Path, data: bytes) -> tuple[str, int, int, int, int]:
    """(magic, width, height, maxval, offset of the raster) of a PGM / PPM file's bytes: the magic
    number, then three decimal integers separated by whitespace and ``#`` comments, then one
    whitespace byte before a binary raster."""
    values: list[int] = []
    position = 2
    while len(values) < 3:
        while position < len(data) and (data[position:position + 1].isspace() or data[position] == ord("#")):
            if data[position] == ord("#"):
                end = data.find(b"\n", position)
                position = len(data) if end < 0 else end + 1
            else:
                position += 1
        start = position
        while position < len(data) and data[position:position + 1].isdigit():
            position += 1
        if position == start:
            raise _unreadable(path, "a PGM / PPM header without its width, height and maxval")
        if position - start > _PNM_NUMBER_DIGITS:
            name = ("width", "height", "maxval")[len(values)]
            raise _unreadable(path, f"a PGM / PPM header {name} of {position - start} digits, more than "
                                    f"{_PNM_NUMBER_DIGITS}")
        values.append(int(data[start:position]))
    if position >= len(data) or not data[position:position + 1].isspace():
        raise _unreadable(path, "a PGM / PPM header not followed by whitespace")
    width, height, maxval = values
    if not 1 <= maxval <= 65535:
        raise _unreadable(path, f"maxval {maxval} outside [1, 65535]")
    return data[:2].decode(), width, height, maxval, position + 1


def _read_pnm(path: Path, magic: str) -> tuple[np.ndarray, int]:
    """The samples (height, width, channels) and maxval of a PGM / PPM file, reading only the raster
    its header declares; a file far longer than that (``_PNM_SLACK_BYTES`` beyond it) is refused
    before its raster is read."""
    import os

    with path.open("rb") as handle:
        data = handle.read(_PNM_HEADER_BYTES)
        _, width, height, maxval, offset = _pnm_header(path, data)
        channels = _PNM_CHANNELS[magic.encode()]
        count = width * height * channels
        binary = magic in ("P5", "P6")
        size = 1 if maxval < 256 else 2
        declared = count * size if binary else count * _ASCII_SAMPLE_BYTES
        length = os.fstat(handle.fileno()).st_size
        if length > offset + declared + _PNM_SLACK_BYTES:
            raise _unreadable(path, f"{length} bytes, far more than the {offset + declared} its header declares "
                                    f"({width} x {height} x {channels} samples)")
        handle.seek(offset)
        raster = handle.read(count * size if binary else length - offset)
    if binary:
        if len(raster) < count * size:
            raise _unreadable(path, f"truncated: {len(raster)} of {count * size} raster bytes")
        samples = np.frombuffer(raster, dtype=np.uint8 if size == 1 else ">u2").astype(np.int64)
    else:
        if raster.translate(None, b"0123456789 \t\n\v\f\r"):  # anything but digits and whitespace
            raise _unreadable(path, "an ASCII sample that is not a non-negative integer")
        # (numpy's text parser: no Python object per sample, unlike bytes.split)
        samples = np.fromstring(raster.decode("ascii"), dtype=np.int64, sep=" ")
        if samples.size < count:
            raise _unreadable(path, f"truncated: {samples.size} of {count} samples")
        samples = samples[:count]
    if np.any(samples > maxval):
        raise _unreadable(path, f"a sample above maxval {maxval}")
    return samples.reshape(height, width, channels), maxval


def _read_png(path: Path) -> tuple[np.ndarray, int]:
    """The samples (height, width, channels) and maxval of a PNG file, through matplotlib (which
    returns floats in [0, 1]; they are rounded back to the integer samples of the file's depth)."""
    import matplotlib.image

    with path.open("rb") as handle:
        depth = handle.read(25)[24:25]
    if not depth:
        raise _unreadable(path, "a PNG header shorter than 25 bytes")
    try:
        image = np.asarray(matplotlib.image.imread(path, format="png"))
    except Exception as exc:  # Pillow's and matplotlib's errors for a damaged file vary
        raise _unreadable(path, f"{type(exc).__name__}: {exc}") from exc
    maxval = 65535 if depth[0] == 16 else 255
    if image.dtype.kind in "ui":
        image = image / np.iinfo(image.dtype).max
    samples = np.rint(np.asarray(image, dtype=float) * maxval).astype(np.int64)
    if samples.ndim == 2:
        samples = samples[:, :, None]
    elif samples.shape[2] in (2, 4):  # an alpha channel is not occupancy
        samples = samples[:, :, :-1]
    return samples, maxval


def _grey(samples: np.ndarray, maxval: int) -> np.ndarray:
    """Float (height, width): the mean of the colour channels over ``maxval``, in [0, 1] (computed
    as an integer sum over ``channels * maxval``, so the same samples give the same grey in every
    format)."""
    channels = samples.shape[2]
    return samples.sum(axis=2) / float(channels * maxval)
