"""Stop signals: SIGTERM and SIGHUP stop a command the way Ctrl-C does (``Terminated``), and a
stopped command reports what it kept in one line and exits with 128 + the signal's number."""

from __future__ import annotations

import argparse
import contextlib
import os
import signal
import sys
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

#: code called back where an exception is printed and dropped (llvmlite's object-cache notification
#: while numba compiles; Dask's garbage-collection callback, which the interpreter calls): a signal
#: handled inside one is delivered again
FOREIGN_CALLBACKS = (os.path.join("llvmlite", "binding"), os.path.join("distributed", "gc.py"))
#: the delay before a signal that landed in a foreign callback is delivered again
REDELIVERY_S = 0.01

#: the signals that stop a command the way Ctrl-C does, besides SIGINT
STOP_SIGNALS = tuple(getattr(signal, name) for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name))


class Terminated(KeyboardInterrupt):
    """Raised in the main thread by a signal of ``STOP_SIGNALS`` while ``main`` runs.

    A ``KeyboardInterrupt``, so that it travels the way Ctrl-C's does: ``except Exception`` does not
    catch it, and every ``with`` block and ``finally`` clause on the way out runs (worker pools and
    Dask clusters are shut down, the progress bar is closed). ``signum`` is the signal's number.
    """

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


class _Received:
    """The first stop signal received while ``main`` runs (its number), or None; while
    ``deferring`` is set, a signal is only recorded, and ``deferred`` raises it at the block's end."""

    signum: int | None = None
    deferring: bool = False
    redelivering: bool = False

    @contextlib.contextmanager
    def deferred(self) -> Iterator[None]:
        """Hold stop signals back while the block runs (an interrupt inside a C extension's import
        is printed and turned into an ``ImportError`` by numba), then raise the one received."""
        self.deferring = True
        try:
            yield
        finally:
            self.deferring = False
        stop = self.stop()
        if stop is not None:
            raise stop

    def stop(self) -> KeyboardInterrupt | None:
        """The interrupt that signal stands for, or None."""
        if self.signum is None:
            return None
        return KeyboardInterrupt() if self.signum == signal.SIGINT else Terminated(self.signum)


@contextlib.contextmanager
def _stop_signals() -> Iterator[_Received]:
    """While the block runs, each signal of ``STOP_SIGNALS`` whose disposition is the default raises
    ``Terminated`` (once: a repeat while the command shuts down is ignored, so the shut-down
    finishes); a signal that is ignored (``nohup``) or has a handler of the caller's keeps it.
    Ctrl-C keeps Python's ``KeyboardInterrupt``, recorded too. The block gets the record
    (``_Received``): a library that turns an interrupt into an error of its own (numba's C import
    does) cannot hide that the command was stopped. The previous dispositions are restored on exit.
    Outside the main thread (where Python cannot set handlers) nothing changes."""
    received = _Received()

    def stop(signum: int, frame: Any) -> None:
        if received.signum is None or received.redelivering:
            received.signum = signum
            received.redelivering = False
            if _in_foreign_callback(frame):
                _deliver_again(signum, received)
            elif not received.deferring:
                raise Terminated(signum)

    def interrupt(signum: int, frame: Any) -> None:
        if received.signum is None:
            received.signum = signum
        received.redelivering = False
        if _in_foreign_callback(frame):
            _deliver_again(signum, received)
        elif not received.deferring:
            raise KeyboardInterrupt

    saved: dict[int, Any] = {}
    try:
        for signum in STOP_SIGNALS:
            if signal.getsignal(signum) == signal.SIG_DFL:
                signal.signal(signum, stop)
                saved[signum] = signal.SIG_DFL
        if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            signal.signal(signal.SIGINT, interrupt)
            saved[signal.SIGINT] = signal.default_int_handler
    except ValueError:  # not the main thread
        pass
    try:
        yield received
    finally:
        for signum, previous in saved.items():
            signal.signal(signum, previous)


def _in_foreign_callback(frame: Any) -> bool:
    """Whether the handler interrupted Python code that a C library called (``FOREIGN_CALLBACKS``)
    or a finalizer (``__del__``) runs, at any depth: an exception raised there would be printed as
    "Exception ignored" and lost."""
    while frame is not None:
        code = frame.f_code
        if code.co_name == "__del__" or any(part in code.co_filename for part in FOREIGN_CALLBACKS):
            return True
        frame = frame.f_back
    return False


def _deliver_again(signum: int, received: _Received) -> None:
    """Send ``signum`` to this process again after ``REDELIVERY_S``, once the callback has returned."""
    received.redelivering = True
    timer = threading.Timer(REDELIVERY_S, os.kill, (os.getpid(), signum))
    timer.daemon = True
    timer.start()


def _chain(exc: BaseException) -> Iterator[BaseException]:
    """``exc`` and its causes and contexts, each once."""
    seen: set[int] = set()
    current: BaseException | None = exc
    while current is not None and id(current) not in seen:
        seen.add(id(current))
        yield current
        current = current.__cause__ or current.__context__


def _interrupt_in(exc: BaseException) -> KeyboardInterrupt | None:
    """The ``KeyboardInterrupt`` (or ``Terminated``) in ``exc``'s chain of causes and contexts, if any:
    numba wraps one raised while a compiled function runs in ``SystemError: ... returned a result
    with an exception set``, and an error raised while an interrupt was being handled is its
    consequence."""
    return next((error for error in _chain(exc) if isinstance(error, KeyboardInterrupt)), None)




def _what_is_kept(command: str | None, args: argparse.Namespace | None) -> str:
    """What an interrupted command leaves behind, and what to do about it."""
    if command != "reproduce":
        return "nothing was written"
    if args is None:  # stopped before the arguments were read
        where = "records.csv under the --out folder"
    elif args.experiment == "all":
        where = f"each experiment's records.csv under {args.out}"
    else:
        where = str(Path(args.out) / args.experiment / "records.csv")
    return f"finished trials are kept in {where}; run the same command again to resume"


def _stopped(stop: KeyboardInterrupt, command: str | None, args: argparse.Namespace | None) -> int:
    """Report a command stopped by a signal in one line; the exit status 128 + the signal's number
    (130 for Ctrl-C, 143 for SIGTERM, 129 for SIGHUP).

    CPython (3.11 to 3.13 at least) marks a ``KeyboardInterrupt`` that escaped code run by ``exec``
    of a string (``dataclasses`` and ``collections.namedtuple`` build their methods that way, so an
    interrupt during the imports is often one), and a process started with ``python -m`` then dies
    by SIGINT at exit instead of exiting with the status returned here, although the interrupt was
    handled. An ``exec`` of a string that runs to its end clears the mark, hence the empty one."""
    exec("")  # (see the docstring)
    signum = stop.signum if isinstance(stop, Terminated) else signal.SIGINT
    how = "interrupted" if signum == signal.SIGINT else f"terminated ({signal.Signals(signum).name})"
    print(f"qrrt{f' {command}' if command else ''}: {how}; {_what_is_kept(command, args)}", file=sys.stderr)
    return 128 + signum
