"""The memory guard: estimate a run's peak memory before anything large is allocated, and refuse a
run that would not fit (issue 10, defect 2).

A quantum planner's round holds, at its peak, one database of N = 2^n candidates (samples,
nearest parents, the predicate's answers, the oracle's marks and the scratch arrays that build
them), plus what one Grover search of it costs on the backend (``QuantumSearchBackend.peak_bytes``:
each backend reports its own footprint) and the search policy's own state
(``IterationPolicy.state_bytes``). The estimate is the sum, in bytes *added* to the running
process (the interpreter and the imported libraries are already resident, so they are already
missing from the available memory).

Available memory is ``MemAvailable`` from ``/proc/meminfo`` (Linux: free memory plus the page cache
and slabs the kernel can reclaim, i.e. what can be allocated without swapping); elsewhere
``os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")`` (free pages only, a lower figure); if
neither exists, no check is made. Inside a container or any memory-limited control group, the
machine's figure overstates what the process may use (the kernel kills it at the group's limit),
so the group's room is taken where it is smaller (``cgroup_available_bytes``: the limit less the
usage, the usage without the inactive page cache the kernel reclaims first; cgroup v2 and v1).
``psutil`` is not a runtime dependency, so it is not used.

The per-entry constants are calibrated, not derived: ``benchmarks/bench_memory.py`` measures the
peak resident set of real runs (``resource.getrusage``, in a fresh subprocess per case) against
this estimate for n = 16..22 on both backends; the constants below are the measured bytes per
entry rounded up (d = 2, 4, 6 fitted linearly in d for the database).
"""

from __future__ import annotations

import functools
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

MIB = 1 << 20

#: database of one round, bytes per entry: samples and their scratch, nearest-parent indices, the
#: (parent, child) pairs handed to the predicate, its answers and the marks. Measured 57 / 89 /
#: 120 B per entry for d = 2 / 4 / 6 at n = 20 (``bench_memory.py --database``): 26 + 16 d.
DATABASE_BYTES_PER_ENTRY = 26
DATABASE_BYTES_PER_COORDINATE = 16
#: with Quantum Database Annealing (Alg. 4) candidates are moved along their parent's direction:
#: measured 122 / 193 / 273 B per entry for d = 2 / 4 / 6: 46 + 38 d.
ANNEALING_BYTES_PER_ENTRY = 46
ANNEALING_BYTES_PER_COORDINATE = 38
#: fixed allowance: the nearest-node grid of the tree (``tree.Tree``) and allocator slack
SCRATCH_BYTES = 64 * MIB


def available_memory_bytes() -> int | None:
    """Memory that can still be allocated without swapping, in bytes (None if unknown).

    Returns:
        The smaller of the machine's figure (``MemAvailable`` of ``/proc/meminfo`` on Linux, else
        free pages times the page size) and the room left in the process's memory control group
        (``cgroup_available_bytes``), whichever are known; None if neither is.
    """
    figures = [figure for figure in (_machine_available_bytes(), cgroup_available_bytes()) if figure is not None]
    return min(figures) if figures else None


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
    """Estimates up to this are accepted without reading the available memory: ``ALWAYS_FITS_BYTES``,
    or an eighth of the smallest control-group limit where that is less (in a 130 MB container a
    180 MiB estimate went unchecked and the kernel killed the run)."""
    limit = smallest_cgroup_limit()
    return ALWAYS_FITS_BYTES if limit is None else min(ALWAYS_FITS_BYTES, limit // 8)


def _memory_groups() -> list[tuple[Path, _GroupFiles]]:
    """(folder, file names) of the process's memory groups, from its own up to the mount's root."""
    try:
        with open(PROC_CGROUP, encoding="utf-8", errors="surrogateescape") as handle:  # any group name
            lines = handle.read().splitlines()
    except OSError:
        return []
    groups: list[tuple[Path, _GroupFiles]] = []
    for line in lines:
        parts = line.split(":", 2)
        if len(parts) != 3:
            continue
        controllers, path = parts[1], parts[2].lstrip("/")
        mounts: list[tuple[Path, _GroupFiles]]
        if controllers == "":  # the v2 hierarchy
            mounts = [(Path(CGROUP_ROOT), _V2_FILES), (Path(CGROUP_ROOT) / "unified", _V2_FILES)]
        elif "memory" in controllers.split(","):
            mounts = [(Path(CGROUP_ROOT) / "memory", _V1_FILES)]
        else:
            continue
        for root, files in mounts:
            folder = root / path
            while True:
                groups.append((folder, files))
                if folder == root or root not in folder.parents:
                    break
                folder = folder.parent
    return groups


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


def database_bytes(num_qubits: int, dim: int, annealing: bool = False) -> int:
    """Peak bytes of building one database of 2^n candidates in d dimensions and evaluating the
    predicate on it (Alg. 1 lines 4-8; Alg. 4 line 7 with ``annealing``).

    (26 + 16 d) 2^n bytes, or (46 + 38 d) 2^n with annealing: per-entry constants calibrated by
    ``benchmarks/bench_memory.py`` (see the module docstring).

    Args:
        num_qubits: n (the database holds 2^n candidates).
        dim: d, the dimension of the states.
        annealing: Whether Quantum Database Annealing moves the candidates (default False).

    Returns:
        The estimated peak bytes.

    Example:
        >>> from qrrt_circuits.memory import database_bytes
        >>> database_bytes(20, 2) == (26 + 16 * 2) * 2**20
        True
        >>> database_bytes(20, 2, annealing=True) == (46 + 38 * 2) * 2**20
        True
    """
    if annealing:
        per_entry = ANNEALING_BYTES_PER_ENTRY + ANNEALING_BYTES_PER_COORDINATE * dim
    else:
        per_entry = DATABASE_BYTES_PER_ENTRY + DATABASE_BYTES_PER_COORDINATE * dim
    return per_entry << num_qubits


def database_resident_bytes(num_qubits: int, dim: int) -> int:
    """Bytes one built database keeps while it is searched: candidates (8 d), parent indices (8),
    the predicate's answers and the marks (1 + 1).

    Args:
        num_qubits: n.
        dim: d.

    Returns:
        (10 + 8 d) 2^n bytes.

    Example:
        >>> from qrrt_circuits.memory import database_resident_bytes
        >>> database_resident_bytes(20, 2) // 2**20  # MiB: 26 bytes per entry
        26
    """
    return (10 + 8 * dim) << num_qubits


@dataclass(frozen=True)
class MemoryEstimate:
    """A run's estimated peak memory, in bytes added to the running process, by part.

    The database's build scratch is freed before the search starts, so the peak is the larger of
    building the databases and searching them while they are kept:
    ``max(database_bytes, resident_bytes + search_bytes) + policy_bytes + scratch_bytes``.

    Args:
        num_qubits: n, the database's qubits.
        database_bytes: Peak of building one round's databases (``database_bytes``).
        resident_bytes: The databases kept while they are searched (``database_resident_bytes``).
        search_bytes: The backend's search (``QuantumSearchBackend.peak_bytes``).
        policy_bytes: The search policy's state (``IterationPolicy.state_bytes``).
        scratch_bytes: Fixed allowance (default ``SCRATCH_BYTES``, 64 MiB).

    Example:
        >>> from qrrt_circuits.memory import MemoryEstimate, database_bytes, database_resident_bytes
        >>> estimate = MemoryEstimate(20, database_bytes=database_bytes(20, 2),
        ...                           resident_bytes=database_resident_bytes(20, 2),
        ...                           search_bytes=16 * 2**20)
        >>> estimate.total_bytes // 2**20  # max(58, 26 + 16) + 64 MiB
        122
        >>> estimate.breakdown()
        'database build 58 MiB, database kept 26 MiB, search 16 MiB, scratch 64 MiB'
    """

    num_qubits: int
    database_bytes: int = 0
    resident_bytes: int = 0
    search_bytes: int = 0
    policy_bytes: int = 0
    scratch_bytes: int = SCRATCH_BYTES

    @property
    def total_bytes(self) -> int:
        """The estimated peak: ``max(database, resident + search) + policy + scratch`` bytes."""
        return (max(self.database_bytes, self.resident_bytes + self.search_bytes) + self.policy_bytes
                + self.scratch_bytes)

    def describe(self) -> dict:
        """The parts and ``total_bytes`` as a JSON-able dict."""
        return {"num_qubits": self.num_qubits, "database_bytes": self.database_bytes,
                "resident_bytes": self.resident_bytes, "search_bytes": self.search_bytes,
                "policy_bytes": self.policy_bytes, "scratch_bytes": self.scratch_bytes,
                "total_bytes": self.total_bytes}

    def breakdown(self) -> str:
        """The non-zero parts in words (MiB or GiB), for error messages."""
        parts = [("database build", self.database_bytes), ("database kept", self.resident_bytes),
                 ("search", self.search_bytes), ("search policy", self.policy_bytes),
                 ("scratch", self.scratch_bytes)]
        return ", ".join(f"{name} {_size(value)}" for name, value in parts if value)


def _size(value: float) -> str:
    if value >= 1 << 1000:  # (an integer this large overflows a float division)
        return f"about 10^{len(str(int(value))) - 1} bytes"
    if value >= 1 << 30:
        return f"{value / (1 << 30):.1f} GiB"
    return f"{value / MIB:.0f} MiB"


#: estimates up to this size are not checked (reading /proc/meminfo on every small search would
#: cost as much as the search)
ALWAYS_FITS_BYTES = 256 * MIB

#: n is never tried beyond this when looking for the largest n that fits (2^64 entries)
_LARGEST_TRIED = 64


def largest_fitting(estimate_for: Callable[[int], MemoryEstimate], available: int, below: int) -> int:
    """The largest n < ``below`` whose estimate fits in ``available`` bytes (0 if none does).

    Args:
        estimate_for: The run's ``MemoryEstimate`` as a function of n.
        available: The available bytes.
        below: Exclusive upper bound on n (n is never tried beyond 63).

    Returns:
        The largest fitting n, every n < ``below`` tried (an estimate need not grow with n: an
        Aer search of m marked entries changes its oracle's form with n; an n for which
        ``estimate_for`` raises ``ValueError`` does not fit); 0 if none fits.

    Example:
        >>> from qrrt_circuits.memory import MemoryEstimate, database_bytes, largest_fitting
        >>> def estimate_for(n):
        ...     return MemoryEstimate(n, database_bytes=database_bytes(n, 2))
        >>> largest_fitting(estimate_for, available=2**30, below=30)
        24
    """
    best = 0
    for n in range(1, min(below, _LARGEST_TRIED)):
        try:
            fits = estimate_for(n).total_bytes <= available
        except ValueError:  # a run this n cannot hold (m marked entries among fewer than m)
            fits = False
        best = n if fits else best
    return best


def check_fits(estimate_for: Callable[[int], MemoryEstimate], num_qubits: int, what: str,
               available: int | None = None) -> MemoryEstimate:
    """Refuse (``ValueError``) a run whose estimated peak exceeds the available memory, naming
    ``num_qubits``, the estimate, the available memory and the largest n that fits. ``what`` names
    the run ("this plan", "this search"). Returns the estimate when it fits.

    Estimates up to ``always_fits_bytes()`` (256 MiB, less in a small container) are accepted
    without reading the available memory; so is any estimate when the available memory is unknown.

    Args:
        estimate_for: The run's ``MemoryEstimate`` as a function of n.
        num_qubits: The n asked for.
        what: The run's name for the message.
        available: The available bytes; None (default) for ``available_memory_bytes()``.

    Returns:
        ``estimate_for(num_qubits)``.

    Raises:
        ValueError: The estimate exceeds the available memory (the message names the largest n
            that fits).

    Example:
        >>> from qrrt_circuits.memory import MemoryEstimate, check_fits, database_bytes
        >>> def estimate_for(n):
        ...     return MemoryEstimate(n, database_bytes=database_bytes(n, 2))
        >>> check_fits(estimate_for, 10, "this plan", available=2**30).num_qubits
        10
        >>> check_fits(estimate_for, 26, "this plan", available=2**30)  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        ValueError: num_qubits = 26: this plan needs about 3.7 GiB ...; the largest num_qubits that fits is 24
    """
    estimate = estimate_for(num_qubits)
    if estimate.total_bytes <= always_fits_bytes():
        return estimate
    available = available_memory_bytes() if available is None else available
    if available is None or estimate.total_bytes <= available:
        return estimate
    largest = largest_fitting(estimate_for, available, num_qubits)
    raise ValueError(
        f"num_qubits = {num_qubits}: {what} needs about {_size(estimate.total_bytes)} at its peak "
        f"({estimate.breakdown()}), more than the {_size(available)} of memory available "
        f"(MemAvailable, or the memory control group's room where smaller); the largest num_qubits "
        f"that fits is {largest}"
        f"{' (none does)' if largest == 0 else ''}")


#: a plan's tree, bytes per node besides its coordinates (parents in the tree and the result, the
#: nearest-node grid's order, the history of nodes, allocator slack). Measured with
#: ``python benchmarks/bench_memory.py --only-plan-limits`` (4 096 parallel-RRT workers filling a
#: world whose goal is walled in, 200 000 and 600 000 nodes): 122-126 B per node at d = 2 and
#: 200-211 at d = 4 in the committed run (182-216 at d = 4 in earlier ones); the estimate,
#: 96 + 48 d, is 1.4-1.6 times that.
TREE_BYTES_PER_NODE = 96
#: a plan's tree, bytes per node and coordinate (positions in the tree, the grid and the result)
TREE_BYTES_PER_COORDINATE = 48
#: a plan's round history (``RunState.end_round``: five Python integers a round in lists, and the
#: result's copies), bytes per round: 180 measured over 10^6 RRT rounds from a start walled in a
#: small cube (the same command; 3 % of the rounds added a node there), rounded up
HISTORY_BYTES_PER_ROUND = 256


#: writing a plan's result as ``json.dump(result.to_dict(), ...)`` (the Python lists of ``to_dict``),
#: bytes per node besides the tree's: 176 measured at d = 2 (``bench_memory.py --only-plan-limits``,
#: ``output-dump``) and about 232 at d = 4 (a helper's tracemalloc); 128 + 48 d is 1.3-1.4 times that.
#: For callers that write ``to_dict()`` themselves (``plan_bytes``' ``output_bytes_per_node``);
#: ``qrrt plan --json`` writes with ``PlanResult.write_json``, which adds about 2 MiB whatever the
#: node count (``output-stream``), so it charges nothing per node.
JSON_BYTES_PER_NODE = 128
JSON_BYTES_PER_COORDINATE = 48


def plan_bytes(max_nodes: int, nodes_per_round: int, max_rounds: int | None, dim: int,
               output_bytes_per_node: int = 0) -> tuple[int, int]:
    """The most a plan's tree and its round history can hold, in bytes: (tree, history).

    A round adds at most ``nodes_per_round`` nodes (1, or p workers) and the node limit is checked
    before each round, so the tree ends with at most min(``max_nodes + nodes_per_round - 1``,
    ``max_rounds * nodes_per_round``) nodes besides the root (counted as that bound + 1).

    Args:
        max_nodes: The node limit in force (``TerminationCondition.node_limit``).
        nodes_per_round: The most nodes one round adds.
        max_rounds: The round limit in force; None where a condition bounds rounds without saying
            how many (a user's own condition): the history is then not counted.
        dim: The workspace dimension d.
        output_bytes_per_node: What writing the result adds per node (``JSON_BYTES_PER_NODE +
            JSON_BYTES_PER_COORDINATE * d`` for ``json.dump`` of ``to_dict()``; 0 by default), counted
            with the tree.

    Returns:
        ``(tree_bytes, history_bytes)``.

    Example:
        >>> from qrrt_circuits.memory import plan_bytes
        >>> plan_bytes(1000, 1, 20000, 2)
        (192192, 5120000)
        >>> plan_bytes(1000, 8, 10, 2)  # 10 rounds of 8 workers: at most 80 nodes
        (15552, 2560)
    """
    nodes = max_nodes + nodes_per_round
    if max_rounds is not None:
        nodes = min(nodes, max_rounds * nodes_per_round + 1)
    tree = nodes * (TREE_BYTES_PER_NODE + TREE_BYTES_PER_COORDINATE * dim + output_bytes_per_node)
    history = 0 if max_rounds is None else max_rounds * HISTORY_BYTES_PER_ROUND
    return tree, history


def _largest(fits: Callable[[int], bool], upto: int) -> int:
    """The largest v in [1, upto] with ``fits(v)`` (``fits`` monotone: true up to some v), else 0."""
    if not fits(1):
        return 0
    low, high = 1, upto  # fits(low) holds
    while low < high:
        middle = (low + high + 1) // 2
        if fits(middle):
            low = middle
        else:
            high = middle - 1
    return low


def check_plan_fits(max_nodes: int, nodes_per_round: int, max_rounds: int | None, dim: int,
                    available: int | None = None, *, default_nodes: bool = False,
                    default_rounds: bool = False, output_bytes_per_node: int = 0) -> None:
    """Refuse (``ValueError``) limits whose tree and round history could exceed the available
    memory (``plan_bytes``), naming the limit to lower (``max_nodes`` where the tree needs at least
    as much as the history and lowering it alone can make the plan fit, else ``max_rounds``),
    whether that limit is the default one, the estimate, the available memory and the largest value
    of that limit that fits.

    Estimates up to ``always_fits_bytes()`` are accepted without reading the available memory; so is
    any estimate when the available memory is unknown.

    Args:
        max_nodes: The node limit in force.
        nodes_per_round: The most nodes one round adds.
        max_rounds: The round limit in force (None: not counted, see ``plan_bytes``).
        dim: The workspace dimension d.
        available: The available bytes; None (default) for ``available_memory_bytes()``.
        default_nodes: Whether ``max_nodes`` is the default limit (the caller gave none).
        default_rounds: Whether ``max_rounds`` is the default limit.
        output_bytes_per_node: What writing the result adds per node (``plan_bytes``).

    Raises:
        ValueError: The estimate exceeds the available memory.

    Example:
        >>> from qrrt_circuits.memory import check_plan_fits
        >>> check_plan_fits(10**6, 1, 20000, 2, available=2**30)
        >>> check_plan_fits(10**6, 1, 10**9, 2, available=2**30)  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        ValueError: max_rounds = 1000000000: this plan's tree and round history could need about 238.6 GiB ...
    """
    tree, history = plan_bytes(max_nodes, nodes_per_round, max_rounds, dim, output_bytes_per_node)
    if tree + history <= always_fits_bytes():
        return
    available = available_memory_bytes() if available is None else available
    if available is None or tree + history <= available:
        return

    def total(nodes: int, rounds: int | None) -> int:
        return sum(plan_bytes(nodes, nodes_per_round, rounds, dim, output_bytes_per_node))

    if max_rounds is None or (tree >= history and total(1, max_rounds) <= available):  # the tree's limit
        name, value, default = "max_nodes", max_nodes, default_nodes
        largest = _largest(lambda nodes: total(nodes, max_rounds) <= available, max_nodes)
    else:  # the history's limit (a lower one also bounds the tree)
        name, value, default = "max_rounds", max_rounds, default_rounds
        largest = _largest(lambda rounds: total(max_nodes, rounds) <= available, max_rounds)
    given = " (the default: the plan was given none)" if default else ""
    fits = (f"the largest {name} that fits is about {largest}" if largest else
            f"no {name} fits ({_size(available)} is less than one round needs)")
    output = " and its JSON output" if output_bytes_per_node else ""
    raise ValueError(
        f"{name} = {value}{given}: this plan's tree{output} and round history could need about "
        f"{_size(tree + history)} (tree {_size(tree)}, history {_size(history)}), more than the "
        f"{_size(available)} of memory available (MemAvailable, or the memory control group's room where "
        f"smaller); {fits}")
