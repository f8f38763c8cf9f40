"""The processor cores a simulation may take without crowding the machine: the cores this process
may run on less what the other work on the machine already keeps busy.

A state update parallelised over more threads than there are idle cores waits on the busy ones
(``benchmarks/bench_aer_threads.py`` times a search on one thread, on every core and on the free
cores, with and without a competing process).

How busy other work keeps the usable cores is measured where the kernel counts CPU time (Linux:
``/proc/stat`` per CPU, ``/proc/self/stat`` for this process), by ``BusyMeter``: between two
readings at least ``MIN_INTERVAL_S`` apart, the busy time of the usable CPUs (user, nice, system,
irq, softirq and steal, in clock ticks) less this process's own CPU time (all its threads, user and
system), over the interval. A reading taken sooner keeps the last measured value; the interval
since a reading spans whatever the process did in between, its own searches included, which the
subtraction takes out. Before the first interval ends, and where the platform has no such
counters, the one-minute system load stands in for it (``os.getloadavg``: the runnable threads,
this process's own running thread included, so the load beyond 1).

A container may run on every CPU of its host with a CPU quota (``docker --cpus``: the control
group's ``cpu.max`` in v2, ``cpu.cfs_quota_us`` / ``cpu.cfs_period_us`` in v1): the kernel then
stops its threads once they have used quota / period CPU-seconds a second, so more threads than
that only wait. ``usable_cores`` counts the smallest quota of the process's groups, rounded up.
"""

from __future__ import annotations

import math
import os
import threading
from collections.abc import Callable, Collection
from dataclasses import dataclass
from pathlib import Path

from .control_groups import group_folders

__all__ = ["MIN_INTERVAL_S", "BusyMeter", "CpuTimes", "busy_cores", "cpu_quota_cores", "free_cores", "read_cpu_times",
           "usable_cores", "usable_cpus"]

#: the shortest interval a measurement spans (the kernel counts CPU time in ticks of 1 / CLK_TCK s,
#: 10 ms on most Linux systems: over 0.25 s a tick's rounding is 4 % of a core)
MIN_INTERVAL_S = 0.25


def usable_cpus() -> frozenset[int]:
    """The CPUs this process may run on: its CPU affinity where the platform has one, else
    ``0 .. os.cpu_count() - 1``."""
    try:
        return frozenset(os.sched_getaffinity(0))
    except (AttributeError, OSError):  # (no affinity on this platform)
        return frozenset(range(max(1, os.cpu_count() or 1)))


#: the process's control groups and where their file systems are mounted (``control_groups``)
PROC_CGROUP = "/proc/self/cgroup"
CGROUP_ROOT = "/sys/fs/cgroup"


def cpu_quota_cores() -> float | None:
    """The smallest CPU quota of the process's control groups, in cores (quota / period: 1.5 for
    ``docker --cpus 1.5``); None without a quota (``max`` in v2, -1 in v1) or where the groups
    cannot be read."""
    quotas = []
    for folder, version in group_folders("cpu", PROC_CGROUP, CGROUP_ROOT):
        if version == 2:
            fields = _read_fields(folder / "cpu.max")
        else:
            fields = _read_fields(folder / "cpu.cfs_quota_us") + _read_fields(folder / "cpu.cfs_period_us")
        try:
            quota, period = int(fields[0]), int(fields[1])
        except (IndexError, ValueError):  # absent, or "max" (v2: no quota)
            continue
        if quota > 0 and period > 0:  # (v1 writes -1 for no quota)
            quotas.append(quota / period)
    return min(quotas) if quotas else None


def _read_fields(path: Path) -> list[str]:
    try:
        return path.read_text(encoding="ascii").split()
    except (OSError, UnicodeDecodeError):
        return []


def usable_cores() -> int:
    """The cores this process may run on: its CPU affinity where the platform has one, else
    ``os.cpu_count()``, and no more than its control groups' CPU quota rounded up
    (``cpu_quota_cores``); at least 1."""
    cores = len(usable_cpus())
    quota = cpu_quota_cores()
    return max(1, cores if quota is None else min(cores, math.ceil(quota)))


@dataclass(frozen=True)
class CpuTimes:
    """One reading of the kernel's CPU time counters, in clock ticks.

    Args:
        busy: Ticks the usable CPUs spent busy (user, nice, system, irq, softirq, steal), summed.
        total: Ticks the usable CPUs counted in any state (busy, idle, iowait), summed.
        own: Ticks this process's threads ran (user and system).
        cpus: The usable CPUs read.
        pid: The process the reading belongs to (a forked child starts its own count).
    """

    busy: int
    total: int
    own: int
    cpus: int
    pid: int


#: ``/proc/stat``'s per-CPU columns (after the name) counted busy, and those counted idle
_BUSY_COLUMNS = (0, 1, 2, 5, 6, 7)  # user, nice, system, irq, softirq, steal
_IDLE_COLUMNS = (3, 4)  # idle, iowait


def read_cpu_times(cpus: Collection[int] | None = None) -> CpuTimes | None:
    """The busy and total ticks of ``cpus`` (default: the usable CPUs) from ``/proc/stat`` and this
    process's own ticks from ``/proc/self/stat``; None where the platform has no such files or a
    usable CPU has no line (its counters cannot be read).

    Args:
        cpus: CPU numbers, or None for ``usable_cpus()``.

    Returns:
        A ``CpuTimes``, or None.
    """
    wanted = usable_cpus() if cpus is None else frozenset(cpus)
    try:
        with open("/proc/stat", encoding="ascii") as stat:
            lines = stat.read().splitlines()
        with open("/proc/self/stat", encoding="ascii", errors="replace") as own:
            # fields after the command name (which may hold spaces and any bytes), from field 3 on
            fields = own.read().rsplit(")", 1)[-1].split()
    except (OSError, UnicodeDecodeError):
        return None
    busy = total = seen = 0
    for line in lines:
        name, _, rest = line.partition(" ")
        if not (name.startswith("cpu") and name[3:].isdigit() and int(name[3:]) in wanted):
            continue
        columns = [int(value) for value in rest.split()]
        if len(columns) < 8:
            return None
        cpu_busy = sum(columns[index] for index in _BUSY_COLUMNS)
        busy += cpu_busy
        total += cpu_busy + sum(columns[index] for index in _IDLE_COLUMNS)
        seen += 1
    if seen != len(wanted) or len(fields) < 13 or not (fields[11].isdigit() and fields[12].isdigit()):
        return None
    return CpuTimes(busy, total, int(fields[11]) + int(fields[12]), seen, os.getpid())  # utime, stime


class BusyMeter:
    """The cores other work keeps busy, measured between readings of the kernel's CPU time counters
    (module docstring).

    Args:
        read: Returns a ``CpuTimes`` reading, or None where none can be taken (default
            ``read_cpu_times``).
        min_interval_ticks: The shortest interval, in clock ticks per CPU, a measurement spans
            (default ``MIN_INTERVAL_S`` in the system's ticks).

    Example:
        >>> from qrrt_circuits._support.free_cores import BusyMeter, CpuTimes
        >>> readings = iter([CpuTimes(0, 0, 0, 2, 1), CpuTimes(130, 200, 30, 2, 1)])
        >>> meter = BusyMeter(lambda: next(readings), min_interval_ticks=25)
        >>> meter.others() is None, meter.others()  # 100 ticks a CPU; others ran 100 of them
        (True, 1.0)
    """

    def __init__(self, read: Callable[[], CpuTimes | None] = read_cpu_times,
                 min_interval_ticks: float | None = None) -> None:
        if min_interval_ticks is None:
            min_interval_ticks = MIN_INTERVAL_S * _clock_ticks_per_second()
        self.read, self.min_interval_ticks = read, float(min_interval_ticks)
        self._last: CpuTimes | None = None
        self._others: float | None = None
        self._lock = threading.Lock()

    def others(self) -> float | None:
        """The cores other work kept busy on average over the last interval of at least the minimum
        length (a fraction, >= 0), or None before one has been measured or without counters."""
        now = self.read()
        with self._lock:
            if now is None:
                return None
            last = self._last
            if last is None or last.pid != now.pid or last.cpus != now.cpus:  # (a new count starts)
                self._last, self._others = now, None
                return None
            elapsed = (now.total - last.total) / now.cpus  # ticks per CPU
            if elapsed >= self.min_interval_ticks:
                others = (now.busy - last.busy) - (now.own - last.own)
                self._others = max(0.0, others / elapsed)
                self._last = now
            return self._others


def _clock_ticks_per_second() -> float:
    """The kernel's clock ticks per second (``SC_CLK_TCK``; 100 where it cannot be read)."""
    try:
        return float(os.sysconf("SC_CLK_TCK"))
    except (AttributeError, ValueError, OSError):
        return 100.0


#: the process's meter: how busy other work keeps the cores is one fact for the whole process
_METER = BusyMeter()


def busy_cores() -> float | None:
    """The cores other work kept busy, as the process's meter last measured them (``BusyMeter.others``:
    a reading now, a new value once ``MIN_INTERVAL_S`` has passed since the last measured one);
    None before a first interval or without the kernel's counters."""
    return _METER.others()


def free_cores() -> int:
    """The usable cores that other work does not keep busy: the CPUs this process may run on less
    the cores other work kept busy on them since a reading at least ``MIN_INTERVAL_S`` ago
    (``BusyMeter``), rounded to the nearest whole core (a core counts as free when other work keeps
    it busy less than half the time), at most ``usable_cores()`` (the CPU quota), at least 1.
    Until that interval has been measured, or without the kernel's counters, the one-minute system
    load less this process's own running thread (load - 1) stands for the busy cores;
    ``usable_cores()`` where the platform has no system load either.

    Rounding to the nearest core rather than down keeps the cores when other work only touches
    them: a core busy a third of the time still runs a share of a parallel state update sooner
    than the other cores run it alone.

    Example:
        >>> from qrrt_circuits._support.free_cores import free_cores, usable_cores
        >>> 1 <= free_cores() <= usable_cores()
        True
    """
    usable, cpus = usable_cores(), len(usable_cpus())
    others = busy_cores()
    if others is None:
        try:
            load = os.getloadavg()[0]
        except (AttributeError, OSError):  # (no system load on this platform)
            return usable
        others = max(0.0, load - 1.0)
    return max(1, min(usable, math.floor(cpus - others + 0.5)))
