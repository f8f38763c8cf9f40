"""Writing JSON whose large parts are numpy arrays, in chunks, with Python's C encoder.

``json.dump`` streams, but always through the pure-Python encoder (CPython uses its C encoder only
for ``json.dumps`` without ``indent``), and ``json.dump(result.to_dict(), handle, indent=1)`` first
makes every node a Python list, so its memory grows with the tree on top of the arrays.
``dump_streamed`` writes the same JSON value (equal after
``json.load``): the small values as ``json.dumps(value, indent=1)``, each array ``CHUNK_ROWS`` rows
at a time through ``json.dumps`` without indent (the C encoder), one row of a 2-D array per line
and ``VALUES_PER_LINE`` values of a 1-D array per line. Only one chunk's lists exist at a time.
Numbers are written as ``json.dumps`` writes Python's (``repr`` of a float, ``NaN`` and
``Infinity`` for non-finite ones), so the values read back are the arrays' own.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import IO, Any

import numpy as np

#: rows of an array converted to Python lists at once
CHUNK_ROWS = 4096
#: values of a 1-D array on one line
VALUES_PER_LINE = 16


def dump_streamed(data: Mapping[str, Any], handle: IO[str]) -> None:
    """Write ``data`` as a JSON object to ``handle``; numpy arrays anywhere in nested mappings are
    written chunk by chunk (see the module docstring), as their ``tolist()``; every other value
    must be what ``json.dumps`` accepts, and keys what it accepts as keys (strings, or ints,
    floats, booleans and None, written as strings).

    Args:
        data: A mapping with keys as above; values JSON-serialisable, numpy arrays (any shape;
            2-D arrays of numbers or booleans are split into rows fastest) or nested such mappings.
        handle: A text file open for writing.

    Raises:
        TypeError: A value ``json.dumps`` cannot write (what came before it is then written).
    """
    _write_mapping(data, handle, 0)
    handle.write("\n")


def _write_mapping(data: Mapping[str, Any], handle: IO[str], level: int) -> None:
    inner = " " * (level + 1)
    if not data:
        handle.write("{}")
        return
    handle.write("{")
    for index, (key, value) in enumerate(data.items()):
        handle.write(("," if index else "") + "\n" + inner + _key(key) + ": ")
        _write_value(value, handle, level + 1)
    handle.write("\n" + " " * level + "}")


def _key(key: Any) -> str:
    """A mapping key as ``json`` writes it: a string as itself, an int, float, bool or None as its
    JSON text in quotes; any other key raises ``TypeError``, as in ``json.dumps``."""
    text = json.dumps({key: None})
    return text[1:text.rindex(":")]


def _write_value(value: Any, handle: IO[str], level: int) -> None:
    if isinstance(value, np.ndarray):
        _write_array(value, handle, level)
    elif isinstance(value, Mapping) and _holds_array(value):
        _write_mapping(value, handle, level)
    else:  # indented as json.dump(..., indent=1) would at this level (strings hold no raw newline)
        handle.write(json.dumps(value, indent=1).replace("\n", "\n" + " " * level))


def _holds_array(value: Mapping[str, Any]) -> bool:
    return any(isinstance(item, np.ndarray) or (isinstance(item, Mapping) and _holds_array(item))
               for item in value.values())


def _write_array(array: np.ndarray, handle: IO[str], level: int) -> None:
    """An array as nested JSON lists: 0-D as its value, 1-D ``VALUES_PER_LINE`` values per line,
    higher ranks one row (a nested list) per line."""
    if array.ndim == 0:
        handle.write(json.dumps(array.tolist()))
        return
    rows = array.shape[0]
    if rows == 0:
        handle.write(json.dumps(array.tolist()))
        return
    inner = "\n" + " " * (level + 1)
    handle.write("[")
    for start in range(0, rows, CHUNK_ROWS):
        values = array[start:start + CHUNK_ROWS].tolist()
        if array.ndim == 2 and array.dtype.kind in "biuf":  # one encoding of the chunk, split into rows
            # (in a chunk of numbers "], [" occurs only between rows; strings could hold it)
            text = json.dumps(values)[1:-1].replace("], [", "]," + inner + "[")
        elif array.ndim == 1:
            text = ("," + inner).join(json.dumps(values[first:first + VALUES_PER_LINE])[1:-1]
                                      for first in range(0, len(values), VALUES_PER_LINE))
        else:
            text = ("," + inner).join(json.dumps(row) for row in values)
        handle.write(("," if start else "") + inner + text)
    handle.write("\n" + " " * level + "]")
