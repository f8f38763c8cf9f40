"""The processor cores a simulation may take without crowding the machine: the cores this process
may run on less what the other work on the machine already keeps busy.

A state update parallelised over more threads than there are idle cores waits on the busy ones
(``benchmarks/bench_aer_threads.py`` times a search on one thread, on every core and on the free
cores). ``free_cores()`` reads the one-minute system load
(``os.getloadavg``: the runnable threads, this process's own included) once per call.
"""

from __future__ import annotations

import math
import os

__all__ = ["free_cores", "usable_cores"]


def usable_cores() -> int:
    """The cores this process may run on: its CPU affinity where the platform has one, else
    ``os.cpu_count()`` (at least 1)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # (no affinity on this platform)
        return max(1, os.cpu_count() or 1)


def free_cores() -> int:
    """The usable cores that other work does not keep busy: ``usable_cores()`` less the one-minute
    system load beyond this process's own running thread (load - 1), rounded to the nearest whole
    core (a core counts as free when other work keeps it busy less than half the time), at least
    1; ``usable_cores()`` where the platform has no system load.

    Rounding to the nearest core rather than down keeps the cores when the load is only the tail
    of this process's own earlier work: a search on all cores raises the one-minute load for a
    minute after it ends, and a rule that gave up a core for any load beyond 1 would then run the
    next searches on fewer threads than the idle machine has.

    Example:
        >>> from qrrt_circuits._support.free_cores import free_cores, usable_cores
        >>> 1 <= free_cores() <= usable_cores()
        True
    """
    usable = usable_cores()
    try:
        load = os.getloadavg()[0]
    except (AttributeError, OSError):  # (no system load on this platform)
        return usable
    others = max(0.0, load - 1.0)
    return max(1, min(usable, math.floor(usable - others + 0.5)))
