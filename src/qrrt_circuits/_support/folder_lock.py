"""One writer per output folder: an exclusive lock on a file inside it, naming its holder.

``FolderLock(folder)`` takes an advisory ``flock`` on ``folder/.qrrt-lock`` without waiting and
writes the holder's PID into it; a second process that asks for the same folder is refused at
once (``FolderInUse``, naming the folder and the holder's PID) instead of writing beside the first.
The kernel drops the lock when its holder exits, however it ends (SIGKILL included), so a lock is
never left stale; the file itself stays (removing it would let a third process lock a new file
while a second one still holds the old). Where ``fcntl`` is missing (Windows) no lock is taken.
"""

from __future__ import annotations

import contextlib
import os
from pathlib import Path
from types import TracebackType

#: the lock file's name inside the folder
LOCK_NAME = ".qrrt-lock"


class FolderInUse(OSError):
    """Another process holds the folder's lock; the message names the folder and its PID."""


class FolderLock:
    """An exclusive, non-blocking lock on ``folder`` (module text); a context manager.

    Args:
        folder: An existing folder.
        what: The option that named it, for the message (default ``"--out"``).

    Raises:
        FolderInUse: On ``acquire``, where another process holds it.
    """

    def __init__(self, folder: Path, what: str = "--out") -> None:
        self.path = Path(folder) / LOCK_NAME
        self.what = what
        self._descriptor: int | None = None

    def acquire(self) -> FolderLock:
        """Take the lock, or refuse (``FolderInUse``) at once where another process holds it."""
        try:
            import fcntl
        except ImportError:  # (no advisory locks here)
            return self
        descriptor = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.read(descriptor, 32).decode("ascii", errors="replace").strip() or "unknown"
            os.close(descriptor)
            raise FolderInUse(f"{self.what} {self.path.parent} is in use by another qrrt run (PID {holder}); "
                              f"wait for it to finish, or use another {self.what}") from None
        with contextlib.suppress(OSError):  # (a full disk: the lock holds, its PID is left unnamed)
            os.ftruncate(descriptor, 0)
            os.write(descriptor, f"{os.getpid()}\n".encode())
        self._descriptor = descriptor
        return self

    def release(self) -> None:
        """Drop the lock (closing the file drops it); again is a no-op."""
        if self._descriptor is not None:
            os.close(self._descriptor)
            self._descriptor = None

    def __enter__(self) -> FolderLock:
        return self.acquire()

    def __exit__(self, kind: type[BaseException] | None, error: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.release()
