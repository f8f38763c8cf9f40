"""What memory a run can still take: the smallest of the figures the system gives, each probed here.

- ``MemAvailable`` from ``/proc/meminfo`` (Linux: free memory plus the page cache and slabs the
  kernel can reclaim, i.e. what can be allocated without swapping); elsewhere
  ``os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")`` (free pages only, a lower figure);
- the room left in the process's memory control groups (``cgroup_available_bytes``: inside a
  container the kernel kills the process at its group's limit, whatever the machine has free);
- the address space left under ``RLIMIT_AS`` (``ulimit -v``; ``address_space_available_bytes``):
  the soft limit less the process's virtual size, the first field of ``/proc/self/statm`` times
  the page size (not taken where that file cannot be read).

A figure that cannot be read is left out; where none can, ``available_memory`` is None and no check
refuses. ``always_fits_bytes`` is the size a check accepts without reading any figure (reading
them for every small search would cost as much as the search). ``psutil`` is not a runtime
dependency, so it is not used. The checks that compare estimates with these figures are in
``memory``.
"""

from __future__ import annotations

import functools
import os
from pathlib import Path

from .control_groups import group_folders

MIB = 1 << 20

#: estimates up to this size are accepted without reading the figures (``always_fits_bytes``)
ALWAYS_FITS_BYTES = 256 * MIB

#: where each figure of ``available_memory`` comes from, as its messages name it
MACHINE_SOURCE = "MemAvailable"
CGROUP_SOURCE = "the memory control group's room"
ADDRESS_SPACE_SOURCE = "the address space left under RLIMIT_AS, ulimit -v"


def available_memory() -> tuple[int, str] | None:
    """The memory a run can still take, in bytes, and which figure bounds it.

    Returns:
        ``(bytes, source)``: the smallest of the figures that can be read (the module docstring):
        the machine's (``MemAvailable``, or free pages where there is no ``/proc/meminfo``;
        ``MACHINE_SOURCE``), the room of the memory control groups (``cgroup_available_bytes``;
        ``CGROUP_SOURCE``) and the address space left under ``RLIMIT_AS``
        (``address_space_available_bytes``; ``ADDRESS_SPACE_SOURCE``); None if none can.
    """
    figures = [(figure, source) for figure, source in ((_machine_available_bytes(), MACHINE_SOURCE),
                                                       (cgroup_available_bytes(), CGROUP_SOURCE),
                                                       (address_space_available_bytes(), ADDRESS_SPACE_SOURCE))
               if figure is not None]
    return min(figures, key=lambda figure: figure[0]) if figures else None


def available_memory_bytes() -> int | None:
    """The bytes of ``available_memory`` (None if no figure can be read).

    Returns:
        The smallest of ``MemAvailable`` (or free pages), the control groups' room and the address
        space left under ``RLIMIT_AS``, whichever are known; None if none is.
    """
    found = available_memory()
    return None if found is None else found[0]


#: the process's sizes in pages: total virtual size first (Linux)
PROC_STATM = "/proc/self/statm"


def virtual_memory_bytes() -> int | None:
    """The process's virtual size (what ``RLIMIT_AS`` limits), in bytes; None where it cannot be
    read.

    Returns:
        The first field of ``/proc/self/statm`` times the page size, or None (no such file).
    """
    try:
        with open(PROC_STATM, encoding="ascii") as statm:
            pages = int(statm.read().split()[0])
        return pages * int(os.sysconf("SC_PAGE_SIZE"))
    except (OSError, ValueError, IndexError, AttributeError):
        return None


def address_space_limit() -> int | None:
    """The soft ``RLIMIT_AS`` (``ulimit -v``) in bytes; None where there is none (unlimited, or no
    ``resource`` module).

    Returns:
        The limit, or None.
    """
    try:
        import resource
    except ImportError:  # not POSIX
        return None
    soft = resource.getrlimit(resource.RLIMIT_AS)[0]
    return None if soft == resource.RLIM_INFINITY or soft < 0 else int(soft)


def address_space_available_bytes() -> int | None:
    """The address space the process can still map under ``RLIMIT_AS``: the soft limit less the
    process's virtual size (``virtual_memory_bytes``), at least 0.

    Returns:
        The bytes; None without a limit, or where the virtual size cannot be read.
    """
    limit = address_space_limit()
    if limit is None:
        return None
    size = virtual_memory_bytes()
    return None if size is None else max(limit - size, 0)


def _machine_available_bytes() -> int | None:
    try:
        with open("/proc/meminfo", encoding="ascii") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return None


#: the process's control groups (``hierarchy:controllers:path`` lines) and where their file systems
#: are mounted (cgroup v2 at the root, or at ``unified`` beside v1's ``memory``)
PROC_CGROUP = "/proc/self/cgroup"
CGROUP_ROOT = "/sys/fs/cgroup"
#: per version: the limit, the usage, the statistics, the statistics of the page cache (which the
#: kernel reclaims before it kills), and the limit and usage of memory + swap (v1 only)
_V2_FILES = ("memory.max", "memory.current", "memory.stat", ("active_file", "inactive_file"), None)
_V1_FILES = ("memory.limit_in_bytes", "memory.usage_in_bytes", "memory.stat",
             ("total_active_file", "total_inactive_file"),
             ("memory.memsw.limit_in_bytes", "memory.memsw.usage_in_bytes"))
#: a cgroup v1 limit at or above this is "no limit" (the kernel writes about 2^63)
_UNLIMITED = 1 << 60

_GroupFiles = tuple[str, str, str, tuple[str, str], "tuple[str, str] | None"]


def cgroup_available_bytes() -> int | None:
    """The room left in the process's memory control group and its ancestors: for each group with
    a limit, its limit less its usage, the usage counted without the page cache (active and
    inactive file pages, which the kernel reclaims before it would kill); in v1 also the limit of
    memory and swap less their usage, and the ``hierarchical_memory_limit`` of ancestors the
    process cannot see (a container's mount). The smallest, in bytes; None without any limit
    (``max`` in v2, about 2^63 in v1) or where the groups cannot be read (not Linux, no memory
    controller).

    The groups are found from ``/proc/self/cgroup`` (in a container with its own cgroup
    namespace, the container's group is the mount's root).

    Returns:
        The smallest room, or None.
    """
    rooms = [room for folder, files in _memory_groups() if (room := _room(folder, files)) is not None]
    return min(rooms) if rooms else None


def smallest_cgroup_limit() -> int | None:
    """The smallest memory limit among the process's groups and their ancestors (None without
    one), read once per process: it decides how large an estimate is accepted without reading the
    available memory (``always_fits_bytes``)."""
    return _smallest_limit_cached()


@functools.lru_cache(maxsize=1)
def _smallest_limit_cached() -> int | None:
    limits = [limit for folder, files in _memory_groups() if (limit := _limit(folder, files)) is not None]
    return min(limits) if limits else None


def always_fits_bytes() -> int:
    """Estimates up to this are accepted without reading the machine's or the control groups'
    figures: ``ALWAYS_FITS_BYTES``, or an eighth of the smallest control-group limit where that is
    less, and never more than the address space left under ``RLIMIT_AS`` where there is such a
    limit (read on every call: the limit is a system call, the virtual size one small file)."""
    limit = smallest_cgroup_limit()
    fits = ALWAYS_FITS_BYTES if limit is None else min(ALWAYS_FITS_BYTES, limit // 8)
    room = address_space_available_bytes()
    return fits if room is None else min(fits, room)


def _memory_groups() -> list[tuple[Path, _GroupFiles]]:
    """(folder, file names) of the process's memory groups, from its own up to the mount's root."""
    return [(folder, _V2_FILES if version == 2 else _V1_FILES)
            for folder, version in group_folders("memory", PROC_CGROUP, CGROUP_ROOT)]


def _read_int(path: Path) -> int | None:
    try:
        return int(path.read_text(encoding="ascii").split()[0])
    except (OSError, ValueError, IndexError):  # absent, or "max" (v2: no limit)
        return None


def _statistics(folder: Path, files: _GroupFiles) -> dict[str, int]:
    values: dict[str, int] = {}
    try:
        for line in (folder / files[2]).read_text(encoding="ascii").splitlines():
            key, _, value = line.partition(" ")
            if value.strip().isdigit():
                values[key] = int(value)
    except (OSError, UnicodeDecodeError):
        pass
    return values


def _limit(folder: Path, files: _GroupFiles) -> int | None:
    """One group's memory limit (v1: also its ``hierarchical_memory_limit``), or None."""
    limits = [_read_int(folder / files[0])]
    if files[4] is not None:
        limits.append(_statistics(folder, files).get("hierarchical_memory_limit"))
    present = [limit for limit in limits if limit is not None and limit < _UNLIMITED]
    return min(present) if present else None


def _room(folder: Path, files: _GroupFiles) -> int | None:
    """One group's room (``cgroup_available_bytes``), or None (no limit, or unreadable)."""
    limit = _limit(folder, files)
    usage = _read_int(folder / files[1])
    if limit is None or usage is None:
        return None
    statistics = _statistics(folder, files)
    cache = sum(statistics.get(key, 0) for key in files[3])
    room = max(limit - max(usage - cache, 0), 0)
    if files[4] is not None:  # v1 with swap accounting: memory + swap have their own limit
        swap_limit, swap_usage = _read_int(folder / files[4][0]), _read_int(folder / files[4][1])
        if swap_limit is not None and swap_usage is not None and swap_limit < _UNLIMITED:
            room = min(room, max(swap_limit - max(swap_usage - cache, 0), 0))
    return room
