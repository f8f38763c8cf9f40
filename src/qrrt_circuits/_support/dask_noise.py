"""What a local Dask cluster logs while an interrupted run shuts it down, and the filter that
leaves it out.

An interrupted run cancels its tasks, then closes the client, the scheduler and the workers. On the
way, Dask's event loops report every cancelled task and every closed connection (the client's
``tornado.application`` errors, a worker's "Failed to communicate with scheduler during heartbeat"
once the scheduler has gone, its state machine's warnings on cancelled tasks): tracebacks that say
nothing about the run's results. ``ShutdownNoise`` leaves out a record whose exception (or one in
its chain) is one of ``SHUTDOWN_EXCEPTIONS`` or a result refused for a cancelled task
(``CANCELLED_STATE``), or whose message is one of ``SHUTDOWN_MESSAGES``;
``quiet_workers()`` sets it on the worker loggers (the fork server calls it, so every worker it forks
has it), and ``execution`` sets it on the client's loggers while its cluster lives.
"""

from __future__ import annotations

import logging

#: exceptions that only say that a task was cancelled or a connection closed
SHUTDOWN_EXCEPTIONS = frozenset({"CancelledError", "FutureCancelledError", "CommClosedError", "StreamClosedError"})
#: an exception of this type whose text starts so: a result that came back for a task already
#: cancelled (``concurrent.futures`` refuses to set it)
CANCELLED_STATE = ("InvalidStateError", "CANCELLED")
#: messages a worker logs once its scheduler has gone
SHUTDOWN_MESSAGES = ("Failed to communicate with scheduler during heartbeat",)
#: the loggers of a worker process that report a shutdown (its state machine warns of each
#: cancelled task)
WORKER_LOGGERS = ("distributed.worker", "distributed.worker.state_machine", "distributed.core", "distributed.nanny",
                  "tornado.application")


class ShutdownNoise(logging.Filter):
    """Leaves out a record of a shutdown (module text)."""

    def filter(self, record: logging.LogRecord) -> bool:
        if record.getMessage().startswith(SHUTDOWN_MESSAGES):
            return False
        error = record.exc_info[1] if record.exc_info else None
        seen = 0
        while error is not None and seen < 32:
            name = type(error).__name__
            if name in SHUTDOWN_EXCEPTIONS or (name, str(error)[:len(CANCELLED_STATE[1])]) == CANCELLED_STATE:
                return False
            error, seen = error.__cause__ or error.__context__, seen + 1
        return True


#: the one filter set on every logger (setting it again is a no-op)
SHUTDOWN_NOISE = ShutdownNoise()


def quiet_workers() -> None:
    """Set ``SHUTDOWN_NOISE`` on ``WORKER_LOGGERS``, and the state machine's warnings (on cancelled
    tasks) at ERROR, in this process and in those it forks."""
    for name in WORKER_LOGGERS:
        logging.getLogger(name).addFilter(SHUTDOWN_NOISE)
    logging.getLogger("distributed.worker.state_machine").setLevel(logging.ERROR)
