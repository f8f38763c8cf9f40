"""Strict JSON written whole: the format of ``settings.json`` and ``summary.json``.

``strict(value)`` is ``value`` with every non-finite number (NaN, +-Infinity, which strict parsers
such as a browser's ``JSON.parse`` refuse) replaced by ``null`` and numpy scalars and arrays turned
into Python numbers and lists. ``write_json`` writes ``json.dumps(strict(value), indent=1)``
through ``output_files.write_result_file`` (a temporary file in the target's folder, flushed to disk
and renamed over the target), so a reader finds the old file or the new one, never a part of either.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import IO, Any

import numpy as np

from .output_files import write_result_file


def strict(value: Any) -> Any:
    """``value`` with non-finite floats as None and numpy values as Python ones (dicts, lists and
    tuples walked; tuples become lists, as JSON writes them)."""
    if isinstance(value, dict):
        return {key: strict(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [strict(item) for item in value]
    if isinstance(value, np.ndarray):
        return strict(value.tolist())
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def dumps(value: Any) -> str:
    """Strict JSON text of ``value`` (``strict``), indented by 1.

    Raises:
        TypeError: A value JSON cannot write.
    """
    return json.dumps(strict(value), indent=1, allow_nan=False)


def write_json(path: Path, value: Any) -> None:
    """Write ``dumps(value)`` to ``path`` whole (``output_files.write_result_file``: a temporary file,
    fsync, rename).

    Raises:
        OSError: The write failed (a full disk, say), naming ``path``; the target is then left as it
            was and no temporary file remains.
    """
    text = dumps(value)

    def write(handle: IO[Any]) -> None:
        handle.write(text)

    write_result_file(Path(path), write)
