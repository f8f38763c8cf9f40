"""What an interrupted run's Dask cluster logs while it shuts down is left out; anything else is kept."""

from __future__ import annotations

import asyncio
import concurrent.futures
import logging
import sys

import pytest

from qrrt_circuits._support.dask_noise import ShutdownNoise


def _record(error: BaseException | None, message: str = "Exception in callback") -> logging.LogRecord:
    try:
        if error is not None:
            raise error
    except BaseException:
        return logging.LogRecord("tornado.application", logging.ERROR, __file__, 1, message, (), sys.exc_info())
    return logging.LogRecord("distributed.worker", logging.ERROR, __file__, 1, message, (), None)


class CommClosedError(OSError):
    """Named as Dask's (the filter goes by the exception's name: Dask need not be installed)."""


def _chained() -> BaseException:
    try:
        raise CommClosedError("in <TCP (closed)>: Stream is closed")
    except CommClosedError as cause:
        try:
            raise RuntimeError("gather failed") from cause
        except RuntimeError as error:
            return error


@pytest.mark.parametrize(("error", "message", "kept"), [
    (asyncio.CancelledError(), "Exception in callback", False),
    (concurrent.futures.InvalidStateError("CANCELLED: <Future at 0x1 state=cancelled>"), "Exception in callback",
     False),
    (_chained(), "Exception in callback", False),
    (None, "Failed to communicate with scheduler during heartbeat.", False),
    (concurrent.futures.InvalidStateError("FINISHED: <Future>"), "Exception in callback", True),
    (ValueError("a trial failed"), "Compute Failed", True),
    (None, "Worker process still alive", True),
])
def test_shutdown_reports_are_left_out_and_the_rest_kept(error, message, kept):
    assert ShutdownNoise().filter(_record(error, message)) is kept
