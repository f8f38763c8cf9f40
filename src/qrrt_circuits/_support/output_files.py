"""The command line's output files: checked before any work, written whole after it.

``check_output_file`` refuses, before a plan runs, a path that cannot be written (a folder, a
missing folder, a loop of symbolic links, a file without write permission), by opening it the way
the write will, without changing it: a new file is created exclusively and removed again, an
existing regular file is opened for writing without truncation (so an append-only file, which the
write could not replace, is refused), and a device or a pipe is only checked for write permission
(opening a pipe would hand its reader an end of file).

``write_replacing`` writes a finished result so that a failed write (a full disk) leaves no partial
file: into a temporary file beside the target, which keeps the target's permission bits and is then
renamed over it. Where a rename would lose something the file is written in place instead (and a
failed in-place write says that the file may be left partial):

- a descriptor the process inherited (``/dev/stdout``, ``/dev/stderr``, ``/dev/fd/N``,
  ``/proc/self/fd/N``: ``--json /dev/stdout > log``, ``--json /dev/fd/3 3>>log``): written through
  that descriptor, after what it already holds;
- a device or a pipe;
- a file with hard links (a rename would detach them), or owned by another user, or by another
  group outside a set-group-ID folder (a rename would make it the writer's);
- a folder that takes no new file, or a rename the system refuses (a sticky folder, a bind mount).

A path that is the file the standard output or error already goes to (``--json log > log``) is
refused before the work: the two would overwrite each other.
"""

from __future__ import annotations

import contextlib
import errno
import os
import re
import stat
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any

#: a rename that fails with one of these falls back to writing in place
_RENAME_REFUSED = frozenset({errno.EPERM, errno.EACCES, errno.EBUSY, errno.EXDEV})


def check_output_file(path: str | None, option: str, suffixes: tuple[str, ...] | None = None) -> None:
    """Refuse (``ValueError``, naming ``option``) an output path that cannot be written, before
    any work, without changing what is there.

    Args:
        path: The path given, or None (nothing to check).
        option: The command-line option, for the message (``"--json"``).
        suffixes: The accepted file name endings (lower case), or None for any.

    Raises:
        ValueError: An empty path, ``-``, a folder, a missing folder, a wrong ending, or a path
            that cannot be written (a loop of symbolic links included).
    """
    if path is None:
        return
    if str(path) in ("", "-"):
        raise ValueError(f"{option} must name a file (for the standard output, /dev/stdout), got {path!r}")
    if str(path).endswith(("/", os.sep)):
        raise ValueError(f"{option}: {path!r} names a folder (it ends in a slash), not a file")
    descriptor = _descriptor_of(path)
    if descriptor is not None:  # an inherited descriptor: it must be open
        try:
            os.fstat(descriptor)
        except OSError:
            raise ValueError(f"{option}: {path!r} names descriptor {descriptor}, which is not open") from None
        return
    target = Path(path)
    stream = _standard_stream(target)
    if stream is not None:
        name, label = ("/dev/stdout", "output") if stream is sys.stdout else ("/dev/stderr", "error")
        raise ValueError(f"{option}: {path!r} is the file the standard {label} goes to (the two would "
                         f"overwrite each other); name {name} to write the output there")
    if target.is_dir():
        raise ValueError(f"{option}: {path!r} is a folder, not a file name")
    real = Path(os.path.realpath(target))  # (a loop of links stays a path that cannot be opened)
    if not real.parent.is_dir():
        raise ValueError(f"{option}: the folder of {path!r} does not exist")
    if suffixes is not None and target.suffix.lower() not in suffixes:
        raise ValueError(f"{option}: {path!r} must end in one of {', '.join(suffixes)}")
    try:
        _probe(real)
    except OSError as exc:
        raise ValueError(f"{option}: {path!r} cannot be written ({exc.strerror or exc})") from None


def _probe(real: Path) -> None:
    """Open ``real`` for writing without changing it (``check_output_file``)."""
    if real.exists() and not real.is_file():  # a device or a pipe: permission only
        if not os.access(real, os.W_OK):
            raise PermissionError(errno.EACCES, "Permission denied")
        return
    try:
        descriptor = os.open(real, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
    except FileExistsError:  # an existing file (or one made meanwhile): opened for writing, unchanged
        descriptor = os.open(real, os.O_WRONLY)  # (not O_APPEND: an append-only file is refused here)
    else:
        os.close(descriptor)
        os.remove(real)  # only the file this call created
        return
    os.close(descriptor)


def same_file(first: str, second: str) -> bool:
    """Whether two output paths name one file: the same resolved path, or (both existing) the
    same file through hard links."""
    if Path(first).resolve() == Path(second).resolve():
        return True
    try:
        return os.path.samefile(first, second)
    except OSError:  # one does not exist yet
        return False


def write_replacing(path: Path, write: Callable[[IO[Any]], None], binary: bool = False) -> None:
    """Call ``write`` with an open file for ``path`` and make it ``path``'s content: replaced
    whole where possible, else written in place (see the module docstring).

    Args:
        path: The output path.
        write: Writes the content to the file object it is given.
        binary: Whether ``write`` writes bytes.

    Raises:
        OSError: The write failed; an in-place write's message says that the file may be left
            partial.
    """
    descriptor = _descriptor_of(path)
    if descriptor is not None:
        _through_descriptor(descriptor, write, binary)
        return
    if _write_in_place(path):
        _in_place(path, write, binary)
        return
    real = Path(os.path.realpath(path))  # through a symbolic link: the file it names is replaced
    try:
        descriptor, temporary = tempfile.mkstemp(dir=real.parent, prefix=".qrrt-", suffix=".tmp")
    except OSError:  # a folder that takes no new file (the file itself was checked writable)
        _in_place(path, write, binary)
        return
    try:
        with os.fdopen(descriptor, "wb" if binary else "w") as handle:
            write(handle)
            handle.flush()
            os.fsync(handle.fileno())  # on disk before it replaces the old file
        os.chmod(temporary, _mode_for(real))
        try:
            os.replace(temporary, real)
        except OSError as exc:
            if exc.errno not in _RENAME_REFUSED:
                raise
            Path(temporary).unlink(missing_ok=True)
            _in_place(path, write, binary)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise


def remove_stale_temporaries(folder: Path) -> list[Path]:
    """Remove the temporary files (``.qrrt-*.tmp``) that ``write_replacing`` left in ``folder`` when
    its process was killed between creating one and renaming it. Only a process that holds the
    folder's lock (``folder_lock``), so that no other writer's file is in flight, may call it.

    Args:
        folder: The folder.

    Returns:
        The files removed.
    """
    removed = []
    for stale in Path(folder).glob(".qrrt-*.tmp"):
        with contextlib.suppress(OSError):
            stale.unlink()
            removed.append(stale)
    return removed


def write_result_file(path: Path, write: Callable[[IO[Any]], None], binary: bool = False) -> None:
    """``write_replacing`` for a file a run produces (a summary, a figure): a failed write's error
    names the file.

    Args:
        path: The output path.
        write: Writes the content to the file object it is given.
        binary: Whether ``write`` writes bytes.

    Raises:
        OSError: The write failed (a full disk, say), naming ``path``; a replaced file is then left
            as it was and no temporary file remains.
    """
    try:
        write_replacing(Path(path), write, binary)
    except OSError as exc:
        raise OSError(exc.errno, f"could not write {path}: {exc.strerror or exc}") from exc


#: /dev/fd/N and /proc/self/fd/N; /dev/stdout and /dev/stderr
_DESCRIPTOR_PATH = re.compile(r"^/(?:dev/fd|proc/self/fd)/(\d+)$")
_STANDARD_PATHS = {"/dev/stdout": 1, "/dev/stderr": 2}


def _descriptor_of(path: str | Path) -> int | None:
    """The descriptor a path names (``/dev/stdout`` 1, ``/dev/fd/3`` 3, ...), else None."""
    text = str(path)
    if text in _STANDARD_PATHS:
        return _STANDARD_PATHS[text]
    match = _DESCRIPTOR_PATH.match(text)
    return int(match.group(1)) if match else None


def _through_descriptor(descriptor: int, write: Callable[[IO[Any]], None], binary: bool) -> None:
    """Write through a copy of an inherited descriptor, after what it holds (never truncated)."""
    for stream in (sys.stdout, sys.stderr):  # what Python has buffered goes first
        stream.flush()
    duplicate = os.dup(descriptor)

    def run() -> None:
        with os.fdopen(duplicate, "wb" if binary else "w") as handle:
            write(handle)

    if stat.S_ISREG(os.fstat(duplicate).st_mode):  # a file (a redirection) may be left partial
        _in_place_guarded(run)
    else:
        run()


def _standard_stream(path: Path) -> Any:
    """``sys.stdout`` or ``sys.stderr`` if ``path`` is the file it writes to, else None."""
    try:
        status = os.stat(path)
    except (OSError, ValueError):
        return None
    for stream in (sys.stdout, sys.stderr):
        try:
            if os.path.samestat(status, os.fstat(stream.fileno())):
                return stream
        except (OSError, ValueError, AttributeError):  # a stream without a descriptor (e.g. captured)
            continue
    return None


def _write_in_place(path: Path) -> bool:
    """Whether ``path`` is written in place rather than replaced (the module docstring's cases)."""
    try:
        status = os.stat(path)
    except OSError:  # a new file
        return False
    if not Path(path).is_file():  # a device or a pipe
        return True
    if status.st_nlink > 1 or status.st_uid != os.geteuid():
        return True
    folder_setgid = bool(os.stat(Path(os.path.realpath(path)).parent).st_mode & 0o2000)
    return status.st_gid != os.getegid() and not folder_setgid  # (a set-group-ID folder gives its group)


def _mode_for(real: Path) -> int:
    """The permission bits of the file being replaced, or those a new file gets."""
    if real.exists():
        return real.stat().st_mode & 0o7777
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def _in_place(path: Path, write: Callable[[IO[Any]], None], binary: bool) -> None:
    def run() -> None:
        with Path(path).open("wb" if binary else "w") as handle:
            write(handle)

    if Path(path).is_file():  # a file is truncated first: a failure may leave part of the output
        _in_place_guarded(run)
    else:  # a device or a pipe keeps nothing
        run()


def _in_place_guarded(run: Callable[[], None]) -> None:
    """Run an in-place write; a failure says that the file may be left partial."""
    try:
        run()
    except OSError as exc:
        raise OSError(exc.errno, f"{exc.strerror or exc}; written in place, so the file may be left partial") from None
