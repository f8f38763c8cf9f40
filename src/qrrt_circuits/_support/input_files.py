"""Input files read safely: regular files only, of bounded size, never echoed, and names inside a
folder.

``read_json_file(path, what)`` opens ``path`` without blocking (a FIFO does not hang the open),
refuses anything but a regular file (a device such as ``/dev/zero``, a FIFO, a folder) and a file
larger than ``MAX_INPUT_BYTES``, and parses it as UTF-8 JSON; every refusal is a one-line
``ValueError`` that starts with the path and never quotes the file's content.

``inside_folder(folder, name, field, source, allow_outside)`` resolves a file name that an input
file gives (``"scenario"``, ``"image"``) against that file's folder and refuses an absolute name or
one that leads outside the folder (``..``, or a symbolic link pointing out), unless
``allow_outside``.
"""

from __future__ import annotations

import json
import os
import stat
from pathlib import Path
from typing import Any

#: the largest JSON input file read (a problem or scenario file); larger ones are refused unread
MAX_INPUT_BYTES = 64 << 20


def check_regular_file(path: Path, what: str) -> int:
    """The size of ``path`` if it is a regular file, else a ``ValueError`` naming ``what``.

    Args:
        path: The file.
        what: Its role, for the message (``"--problem"``, ``"scenario"``).

    Returns:
        Its size in bytes.

    Raises:
        ValueError: Missing, unreadable, or not a regular file.
    """
    try:
        descriptor = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except FileNotFoundError:
        raise ValueError(f"{what}: no such file {str(path)!r}") from None
    except OSError as exc:
        raise ValueError(f"{what}: cannot open {str(path)!r} ({exc.strerror})") from None
    try:
        status = os.fstat(descriptor)
    finally:
        os.close(descriptor)
    if not stat.S_ISREG(status.st_mode):
        kind = "a folder" if stat.S_ISDIR(status.st_mode) else "not a regular file"
        raise ValueError(f"{what}: {str(path)!r} is {kind}; a regular file is accepted")
    return int(status.st_size)


def read_json_file(path: str | Path, what: str, limit: int = MAX_INPUT_BYTES) -> Any:
    """The parsed JSON of a regular UTF-8 file of at most ``limit`` bytes (module text).

    Args:
        path: The file.
        what: Its role, for the messages.
        limit: The most bytes read (default ``MAX_INPUT_BYTES``).

    Returns:
        The parsed value.

    Raises:
        ValueError: Missing, not a regular file, too large, not UTF-8, not JSON, or nested too deep;
            the message names the path and never quotes the file.
    """
    path = Path(path)
    size = check_regular_file(path, what)
    if size > limit:
        raise ValueError(f"{what}: {str(path)!r} has {size} bytes, more than the {limit} accepted")
    with path.open("rb") as handle:
        raw = handle.read(limit + 1)
    if len(raw) > limit:
        raise ValueError(f"{what}: {str(path)!r} has more than the {limit} bytes accepted")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ValueError(f"{what}: {str(path)!r} is not a UTF-8 text file (byte {exc.start})") from None
    try:
        return json.loads(text)
    except RecursionError:
        raise ValueError(f"{what}: {str(path)!r} is not a JSON file this reads (nested too deeply)") from None
    except json.JSONDecodeError as exc:
        raise ValueError(f"{what}: {str(path)!r} is not valid JSON ({exc.msg} at line {exc.lineno}, "
                         f"column {exc.colno})") from None
    except ValueError:  # an integer beyond the interpreter's digit limit
        raise ValueError(f"{what}: {str(path)!r} holds an integer with too many digits") from None


def inside_folder(folder: Path, name: str, field: str, source: Path, allow_outside: bool = False) -> Path:
    """``folder / name``, refused where ``name`` leads outside ``folder`` (module text).

    Args:
        folder: The folder of the file that names ``name``.
        name: The file name it gives.
        field: The field that gives it, for the message.
        source: The file that gives it, for the message.
        allow_outside: Accept absolute names and names outside the folder (default False).

    Returns:
        The path (relative names joined to ``folder``).

    Raises:
        ValueError: An absolute name or one outside the folder, without ``allow_outside``.
    """
    path = folder / name
    if allow_outside:
        return path
    if Path(name).is_absolute():
        raise ValueError(f'{source}: "{field}" must name a file inside the problem file\'s folder, got an absolute '
                         f"path (allow_outside=True, or qrrt plan --allow-outside-files, accepts it)")
    if not path.resolve().is_relative_to(folder.resolve()):
        raise ValueError(f'{source}: "{field}" leads outside the problem file\'s folder (allow_outside=True, or '
                         "qrrt plan --allow-outside-files, accepts it)")
    return path
