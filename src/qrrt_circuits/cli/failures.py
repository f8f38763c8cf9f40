"""Failures: the exit statuses of ``qrrt`` and the one line on stderr a failure prints."""

from __future__ import annotations

import os
import signal
import sys
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:

    pass

from .signals import _chain

#: the exit status of a command whose output was closed under it: 128 + SIGPIPE, as a shell reports it
CLOSED_OUTPUT = 128 + getattr(signal, "SIGPIPE", 13)

#: ``qrrt``'s exit statuses (every one but 0 and a closed output comes with one line on stderr)
EXIT_STATUSES = {
    0: "done",
    1: "the environment failed: a file that cannot be read or written, an unreachable Dask scheduler, "
       "out of memory, or numba's compiled-function cache unreadable or corrupt",
    2: "bad input (the line names the argument and what it accepts)",
    128 + signal.SIGINT: "interrupted (Ctrl-C, SIGINT)",
    128 + signal.SIGTERM: "terminated (SIGTERM)",
    **({128 + signal.SIGHUP: "terminated (SIGHUP: the terminal closed)"} if hasattr(signal, "SIGHUP") else {}),
    CLOSED_OUTPUT: "the output's reader closed it early (a pipe into head); nothing more is printed",
}



def _command_in(words: list[str]) -> str | None:
    """The command named in ``words`` (the first word that is not an option), if it is one."""
    first = next((word for word in words if not word.startswith("-")), None)
    return first if first in ("search", "plan", "reproduce") else None




#: numba's module that reads and writes its on-disk cache of compiled functions
_NUMBA_CACHING = os.path.join("numba", "core", "caching.py")


def _numba_cache_failure(exc: BaseException) -> tuple[BaseException, str | None] | None:
    """The error in ``exc``'s chain that numba raised while loading a compiled function from its
    on-disk cache (an index ``*.nbi`` or data ``*.nbc`` file it could not read or unpickle), with the
    folder of the file it was reading where the traceback shows it; None for any other error. An
    error raised in a worker process is recognised by the text of its traceback (which
    ``concurrent.futures`` attaches as its cause)."""
    for error in _chain(exc):
        loading, folder = False, None
        tb = error.__traceback__
        while tb is not None:
            code, names = tb.tb_frame.f_code, tb.tb_frame.f_locals
            if code.co_filename.endswith(_NUMBA_CACHING) and "load" in code.co_name:
                loading = True
                read = getattr(names.get("f"), "name", None) or names.get("path")  # the file being read
                folder = os.path.dirname(read) if isinstance(read, str) else folder
            tb = tb.tb_next
        if loading:
            return error, folder
        remote = error.__cause__
        text = str(remote) if type(remote).__name__ == "_RemoteTraceback" else ""
        if _NUMBA_CACHING in text and any(f"in {name}\n" in text for name in
                                          ("load_overload", "_load_overload", "_load_index", "_load_data")):
            return error, None
    return None


def _numba_cache_text(error: BaseException, folder: str | None) -> str:
    """One line for a failed load from numba's cache: where the cache is, and what to do."""
    import numba

    reason = f"{type(error).__name__}: {' '.join(str(error).split())}".rstrip(": ")
    cache_dir = getattr(numba.config, "CACHE_DIR", "")  # NUMBA_CACHE_DIR: every cached function is under it
    if cache_dir:
        return (f"numba's compiled-function cache in {cache_dir} is unreadable or corrupt "
                f"({reason}); delete that folder (or unset NUMBA_CACHE_DIR) and run again")
    where = (folder if folder is not None else
             f"the __pycache__ folders under {Path(__file__).resolve().parent.parent}")
    return (f"numba's compiled-function cache in {where} is unreadable or corrupt ({reason}); delete its "
            f"*.nbi and *.nbc files (or set NUMBA_CACHE_DIR to an empty folder) and run again")




def _closed_output() -> int:
    """A closed standard output (``qrrt plan | head``): point stdout at the null device, so that the
    interpreter's flush at exit raises nothing more, and return ``CLOSED_OUTPUT`` quietly."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())
    os.close(devnull)
    return CLOSED_OUTPUT


def _exit(command: str | None, exc: Exception) -> None:
    """Exit with ``exc`` as one line on stderr and its status, if it is a failure ``qrrt`` reports
    (``EXIT_STATUSES``); return for any other (a bug, which keeps its traceback)."""
    prefix = f"qrrt{f' {command}' if command else ''}: error:"
    cache = _numba_cache_failure(exc)
    if cache is not None:
        status, text = 1, _numba_cache_text(*cache)
    elif isinstance(exc, ValueError | TypeError):
        status, text = 2, str(exc)
    elif isinstance(exc, OSError):  # unreadable files, an unreachable Dask scheduler, a full disk
        status, text = 1, f"{type(exc).__name__}: {exc}"
    elif isinstance(exc, MemoryError):  # a plan's or a search's is a one-line memory.OutOfMemory naming the size
        status, text = 1, _memory_error_text(exc)
    else:
        return
    print(f"{prefix} {text}", file=sys.stderr)
    raise SystemExit(status)


def _memory_error_text(exc: MemoryError) -> str:
    """One line for a ``MemoryError``: an ``OutOfMemory``'s own message (the size that did not fit
    and the largest smaller one whose estimate fits), else what the allocator reported."""
    from .._support.memory import OutOfMemory

    text = " ".join(str(exc).split())
    return text if isinstance(exc, OutOfMemory) and text else f"out of memory ({text or 'MemoryError'})"
