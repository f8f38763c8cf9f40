"""The ``qrrt`` command line: ``search``, ``plan`` and ``reproduce``.

Every choice (planners, backends, search policies, scenarios, predicates) and its help text comes
from ``qrrt_circuits.registry``, so the command line and the library mean the same thing by a name.

Every failure is one line on stderr, and the exit status says what happened (``EXIT_STATUSES``):
0 done, 1 the environment failed (a file that cannot be read or written, an unreachable Dask
scheduler, out of memory, an unreadable or corrupt numba cache), 2 bad input, 130 interrupted
(Ctrl-C, SIGINT), 143 and 129 terminated (SIGTERM, SIGHUP): 128 + the signal's number; 141 the
output's reader closed it early (a pipe into ``head``), without a line.

Importing it imports only the standard library; the package's heavy dependencies (numpy, numba,
scipy, Qiskit) are imported inside ``main`` once its signal handlers are installed, so an
interrupt during those imports is reported like any other.

The package: ``parser`` (``build_parser``), ``commands`` (one module per command), ``signals`` (stop
signals and the report of a stopped command), ``failures`` (exit statuses and the one-line report
of a failure); ``main`` here runs them.
"""

from __future__ import annotations

import argparse
import sys

from .failures import EXIT_STATUSES, _closed_output, _command_in, _exit
from .failures import _numba_cache_failure as _numba_cache_failure  # (the tests read it here)
from .parser import build_parser
from .signals import STOP_SIGNALS, Terminated, _interrupt_in, _stop_signals, _stopped

__all__ = ["EXIT_STATUSES", "STOP_SIGNALS", "Terminated", "build_parser", "main"]


def main(argv: list[str] | None = None) -> int:
    """Run ``qrrt`` with ``argv`` (default: ``sys.argv[1:]``) and return its exit status.

    A failure prints one line on stderr and exits with its status (``EXIT_STATUSES``): bad input 2,
    an environment error 1, through ``SystemExit``. While it runs, SIGTERM and SIGHUP stop the
    command as Ctrl-C does (``Terminated``), from the first moment: the handlers are installed
    before anything else is imported. A stopped command reports what was kept in one line and
    returns 128 + the signal's number; the previous signal handlers are restored on return.
    """
    words = sys.argv[1:] if argv is None else list(argv)
    args: argparse.Namespace | None = None
    with _stop_signals() as received:
        try:
            with received.deferred():  # the parser's registries import numpy, numba and scipy
                parser = build_parser()
            args = parser.parse_args(argv)
            status: int = args.func(args)
            return status
        except KeyboardInterrupt as stop:
            return _stopped(stop, args.command if args is not None else _command_in(words), args)
        except BrokenPipeError:  # the reader of the output closed it (a pipe into head)
            return _closed_output()
        except Exception as exc:
            command = args.command if args is not None else _command_in(words)
            stop_in_chain = _interrupt_in(exc) or received.stop()  # (an error a signal caused)
            if stop_in_chain is not None:
                return _stopped(stop_in_chain, command, args)
            _exit(command, exc)
            raise
