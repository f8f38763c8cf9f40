"""The memory guard: a plan or a direct search is sized once, before anything large is allocated,
and refused (``ValueError``) if it would not fit; one that runs out of memory all the same ends with
one ``OutOfMemory``.

What is sized, in bytes *added* to the running process (the interpreter and the imported libraries
are already resident, so they are already missing from the available memory), from sizes the
parts expose as plain numbers:

- a plan (``PlanSize``, checked once by ``Planner.plan`` before the plan allocates anything): its
  tree and round history up to the node and round limits in force (``plan_bytes``) and, for a
  quantum planner, one round at its peak (``MemoryEstimate``): the databases of 2^n candidates
  alive at once (samples, nearest parents, the predicate's answers, the oracle's marks and the
  scratch arrays that build them), the backend's search of them at the policy's largest iteration
  count (``QuantumSearchBackend.peak_bytes`` of ``IterationPolicy.iterations_bound``) and the
  search policy's state (``IterationPolicy.state_bytes``). The plan's searches make no check of
  their own (``QuantumSearchBackend.run``).
- a direct search (``QuantumSearchBackend.search``, ``search_many``, ``search_sequence``;
  ``SearchSize``): the backend's ``peak_bytes``, all the searches of one call checked at once.

What is available is probed in ``available_memory`` (the smallest of ``MemAvailable``, the memory
control groups' room and the address space left under ``RLIMIT_AS``). The estimates count resident
bytes: address space that a library reserves without touching it (thread stacks, allocator arenas)
is not in them, so a run sized close to the ``RLIMIT_AS`` room can still fail.

A ``MemoryError`` raised while a plan or a direct search runs (numpy's ``_ArrayMemoryError`` is
one) is raised again as an ``OutOfMemory`` whose message is one line: the size that did not fit
(``num_qubits``, or the node or round limit), what the allocator reported, the estimate, and the
largest smaller size whose estimate fits in the memory available after the failure.

The per-entry constants are calibrated, not derived: upper bounds of the measured peak resident set
of real runs, rounded up.
"""

from __future__ import annotations

import gc
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import TypeVar

from . import available_memory as probe

MIB = 1 << 20

#: database of one round, bytes per entry, 26 + 16 d: samples and their scratch, nearest-parent
#: indices, the (parent, child) pairs handed to the predicate, its answers and the marks (a
#: calibrated upper bound of the measured peak)
DATABASE_BYTES_PER_ENTRY = 26
DATABASE_BYTES_PER_COORDINATE = 16
#: with Quantum Database Annealing (Alg. 4) candidates are moved along their parent's direction:
#: 46 + 38 d bytes per entry (calibrated in the same way)
ANNEALING_BYTES_PER_ENTRY = 46
ANNEALING_BYTES_PER_COORDINATE = 38
#: fixed allowance: the nearest-node grid of the tree (``world.nearest.GridNearest``) and allocator slack
SCRATCH_BYTES = 64 * MIB


def database_bytes(num_qubits: int, dim: int, annealing: bool = False) -> int:
    """Peak bytes of building one database of 2^n candidates in d dimensions and evaluating the
    predicate on it (paper Algorithm 1, lines 4-8; Algorithm 4, line 7, with ``annealing``).

    (26 + 16 d) 2^n bytes, or (46 + 38 d) 2^n with annealing: calibrated per-entry constants
    (``DATABASE_BYTES_PER_ENTRY`` and the others).

    Args:
        num_qubits: n (the database holds 2^n candidates).
        dim: d, the dimension of the states.
        annealing: Whether Quantum Database Annealing moves the candidates (default False).

    Returns:
        The estimated peak bytes.

    Example:
        >>> from qrrt_circuits._support.memory import database_bytes
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
        >>> from qrrt_circuits._support.memory import database_resident_bytes
        >>> database_resident_bytes(20, 2) // 2**20  # MiB: 26 bytes per entry
        26
    """
    return (10 + 8 * dim) << num_qubits


@dataclass(frozen=True)
class MemoryEstimate:
    """A run's estimated peak memory, in bytes added to the running process, by part.

    The database's build scratch is freed before the search starts, so a round's peak is the larger
    of building the databases and searching them while they are kept; a plan's tree, its output and
    its round history are held beside it:
    ``max(database_bytes, resident_bytes + search_bytes) + policy_bytes + scratch_bytes +
    tree_bytes + output_bytes + history_bytes``.

    Args:
        num_qubits: n, the database's qubits (0 for a plan without databases).
        database_bytes: Peak of building one round's databases (``database_bytes``).
        resident_bytes: The databases kept while they are searched (``database_resident_bytes``).
        search_bytes: The backend's search (``QuantumSearchBackend.peak_bytes``).
        policy_bytes: The search policy's state (``IterationPolicy.state_bytes``).
        scratch_bytes: Fixed allowance (default ``SCRATCH_BYTES``, 64 MiB).
        tree_bytes: A plan's tree at its node limit (``plan_bytes``; default 0).
        output_bytes: What writing a plan's result adds at that limit (default 0).
        history_bytes: A plan's round history at its round limit (default 0).

    Example:
        >>> from qrrt_circuits._support.memory import MemoryEstimate, database_bytes, database_resident_bytes
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
    tree_bytes: int = 0
    output_bytes: int = 0
    history_bytes: int = 0

    @property
    def round_bytes(self) -> int:
        """One round's peak: ``max(database, resident + search) + policy + scratch`` bytes."""
        searched = self.resident_bytes + self.search_bytes
        return max(self.database_bytes, searched) + self.policy_bytes + self.scratch_bytes

    @property
    def limits_bytes(self) -> int:
        """What a plan's limits bound: ``tree + output + history`` bytes."""
        return self.tree_bytes + self.output_bytes + self.history_bytes

    @property
    def total_bytes(self) -> int:
        """The estimated peak: ``round_bytes + limits_bytes``."""
        return self.round_bytes + self.limits_bytes

    def describe(self) -> dict:
        """The parts and ``total_bytes`` as a JSON-able dict."""
        return {"num_qubits": self.num_qubits, "database_bytes": self.database_bytes,
                "resident_bytes": self.resident_bytes, "search_bytes": self.search_bytes,
                "policy_bytes": self.policy_bytes, "scratch_bytes": self.scratch_bytes,
                "tree_bytes": self.tree_bytes, "output_bytes": self.output_bytes,
                "history_bytes": self.history_bytes, "total_bytes": self.total_bytes}

    def breakdown(self) -> str:
        """The non-zero parts in words (bytes, KiB, MiB or GiB), for error messages."""
        parts = [("database build", self.database_bytes), ("database kept", self.resident_bytes),
                 ("search", self.search_bytes), ("search policy", self.policy_bytes),
                 ("scratch", self.scratch_bytes), ("tree", self.tree_bytes),
                 ("its JSON output", self.output_bytes), ("round history", self.history_bytes)]
        return ", ".join(f"{name} {_size(value)}" for name, value in parts if value)


def _size(value: float) -> str:
    if value >= 1 << 1000:  # (an integer this large overflows a float division)
        return f"about 10^{len(str(int(value))) - 1} bytes"
    if value >= 1 << 30:
        return f"{value / (1 << 30):.1f} GiB"
    if value >= MIB:
        return f"{value / MIB:.0f} MiB"
    if value >= 1024:
        return f"{value / 1024:.0f} KiB"
    return f"{int(value)} bytes"


#: n is never tried beyond this when looking for the largest n that fits (2^64 entries)
_LARGEST_TRIED = 64


class OutOfMemory(MemoryError):
    """A plan or a direct search ran out of memory: its message is one line naming the size that
    did not fit (``num_qubits``, or the node or round limit), what the allocator reported, the
    estimate, and the largest smaller size whose estimate fits in the memory available after the
    failure. The ``MemoryError`` it replaces is its ``__cause__`` (without its traceback, whose
    frames held the run's arrays)."""


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
        >>> from qrrt_circuits._support.memory import MemoryEstimate, database_bytes, largest_fitting
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


def _memory_text(measured: tuple[int, str], when: str = "") -> str:
    """``"the 1.0 GiB of memory available (MemAvailable)"``: the figure and where it comes from."""
    figure, source = measured
    return f"the {_size(figure)} of memory available{when}{f' ({source})' if source else ''}"


def check_fits(estimate_for: Callable[[int], MemoryEstimate], num_qubits: int, what: str,
               available: int | None = None, source: str = "", name: str = "num_qubits") -> MemoryEstimate:
    """Refuse (``ValueError``) a run whose estimated peak exceeds the available memory, naming
    ``num_qubits``, the estimate, the available memory (and which figure bounds it) and the largest
    n that fits. ``what`` names the run ("this aer search (8 shots, 5 iterations)"). Returns the
    estimate when it fits. The available memory is read at most once.

    Estimates up to ``available_memory.always_fits_bytes()`` (256 MiB, less in a small container or under a small
    ``RLIMIT_AS``) are accepted without reading the available memory; so is any estimate when the
    available memory is unknown.

    Args:
        estimate_for: The run's ``MemoryEstimate`` as a function of n.
        num_qubits: The n asked for.
        what: The run's name for the message.
        available: The available bytes; None (default) for ``available_memory.available_memory()``.
        source: Which figure ``available`` is, for the message (``available_memory``'s second
            item; default none named).
        name: The argument n is, for the message (default ``"num_qubits"``).

    Returns:
        ``estimate_for(num_qubits)``.

    Raises:
        ValueError: The estimate exceeds the available memory (the message names the largest n
            that fits).

    Example:
        >>> from qrrt_circuits._support.memory import MemoryEstimate, check_fits, database_bytes
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
    if estimate.total_bytes <= probe.always_fits_bytes():
        return estimate
    measured = probe.available_memory() if available is None else (available, source)
    if measured is None or estimate.total_bytes <= measured[0]:
        return estimate
    largest = largest_fitting(estimate_for, measured[0], num_qubits)
    raise ValueError(
        f"{name} = {num_qubits}: {what} needs about {_size(estimate.total_bytes)} at its peak "
        f"({estimate.breakdown()}), more than {_memory_text(measured)}; the largest {name} that fits is "
        f"{largest}{' (none does)' if largest == 0 else ''}")


def _released(error: MemoryError) -> None:
    """Drop the traceback of a failed run (its frames hold the run's arrays) and collect, so that
    memory read afterwards is read without them."""
    error.__traceback__ = None
    gc.collect()


def _out_of_memory(error: MemoryError, name: str, value: int, what: str, estimate: MemoryEstimate,
                   largest_below: Callable[[int], int], measured: tuple[int, str] | None,
                   given: str = "") -> OutOfMemory:
    """The ``OutOfMemory`` of a run of ``name = value`` that raised ``error``: ``largest_below``
    gives the largest value below ``value`` whose estimate fits in a number of bytes (0: none);
    ``measured`` is the memory available when the run started, or None to read it now."""
    _released(error)
    reason = " ".join(str(error).split()) or type(error).__name__  # one line
    head = (f"{name} = {value}{given}: {what} ran out of memory ({reason}) with an estimated peak of about "
            f"{_size(estimate.total_bytes)} ({estimate.breakdown()})")
    when = " when it started"
    if measured is None:
        measured, when = probe.available_memory(), " now"
    if measured is None:
        return OutOfMemory(f"{head}; the memory available cannot be read: try a smaller {name}")
    largest = largest_below(measured[0])
    room = _memory_text(measured, when)
    if largest:
        return OutOfMemory(f"{head}; the largest {name} below {value} whose estimate fits in {room} is {largest}")
    return OutOfMemory(f"{head}; no {name} below {value} has an estimate that fits in {room}")


def out_of_memory(error: MemoryError, estimate_for: Callable[[int], MemoryEstimate], num_qubits: int,
                  what: str, measured: tuple[int, str] | None = None) -> OutOfMemory:
    """The one-line ``OutOfMemory`` that replaces a ``MemoryError`` raised by a run of
    ``num_qubits`` sized by ``estimate_for`` (a direct search, ``qrrt search``).

    Drops ``error``'s traceback (its frames hold the run's arrays) before any memory is read.

    Args:
        error: The ``MemoryError`` (numpy's ``_ArrayMemoryError`` is one).
        estimate_for: The run's ``MemoryEstimate`` as a function of n.
        num_qubits: The n that ran out of memory.
        what: The run's name for the message.
        measured: The memory available when the run started, as ``available_memory.available_memory()`` gave it
            (what a new run would find; memory that a failed run leaves behind, such as arrays
            that compiled code keeps after an exception, is not in it), or None (default) to read
            it now.

    Returns:
        The ``OutOfMemory`` to raise (``raise out_of_memory(...) from error``): it names n, what the
        allocator reported, the estimate and the largest n below it whose estimate fits in that
        memory (the estimate fell short at n, so a smaller n than that may be needed).
    """
    return _out_of_memory(error, "num_qubits", num_qubits, what, estimate_for(num_qubits),
                          lambda available: largest_fitting(estimate_for, available, num_qubits), measured)


@dataclass(frozen=True)
class SearchSize:
    """What a direct search's memory check sizes: one search of 2^n entries, by the peak its backend
    reports (``QuantumSearchBackend.peak_bytes`` at the search's shots and iterations).

    Args:
        peak: The search's peak bytes as a function of (n, m), m the marked entries or None for
            the bound over every m.
        num_qubits: n.
        backend: The backend's name, for the messages.
        shots: The search's shots, for the messages.
        iterations: Its iterations (or generalized iterates), for the messages.
        marked: m where it is known, else None; called only where the bound over every m does not
            fit (counting the marks is a pass over them).

    Example:
        >>> from qrrt_circuits._support.memory import SearchSize, check_searches
        >>> size = SearchSize(lambda n, m: 16 << n, 30, "statevector", 8, 5, lambda: None)
        >>> check_searches([size], available=2**30)  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        ValueError: num_qubits = 30: this statevector search (8 shots, 5 iterations) needs about 16.0 GiB ...
    """

    peak: Callable[[int, int | None], int]
    num_qubits: int
    backend: str
    shots: int
    iterations: int
    marked: Callable[[], int | None]

    def estimate_for(self, marked: int | None) -> Callable[[int], MemoryEstimate]:
        """The search's ``MemoryEstimate`` as a function of n, for m = ``marked`` (None: every m)."""
        def estimate(width: int) -> MemoryEstimate:
            return MemoryEstimate(width, search_bytes=self.peak(width, marked), scratch_bytes=0)

        return estimate

    def what(self, marked: int | None = None) -> str:
        """``"this aer search (8 shots, 5 iterations, 12 marked)"``: the search in words."""
        count = "" if marked is None else f", {marked} marked"
        return f"this {self.backend} search ({self.shots} shots, {self.iterations} iterations{count})"

    def check(self, measured: tuple[int, str]) -> None:
        """Refuse (``ValueError``, ``check_fits``) the search if its bound over every m exceeds
        ``measured`` (the available bytes and their source) and the estimate for its known m, where
        that is smaller, does too (the message names m only where m lowered the estimate)."""
        bound = self.peak(self.num_qubits, None)
        if bound <= measured[0]:
            return
        marked = self.marked()
        if marked is not None and self.peak(self.num_qubits, marked) >= bound:
            marked = None  # the count cannot lower the estimate: the message names none
        check_fits(self.estimate_for(marked), self.num_qubits, self.what(marked), *measured)

    def out_of_memory(self, error: MemoryError, measured: tuple[int, str] | None) -> OutOfMemory:
        """The one-line ``OutOfMemory`` of this search (``out_of_memory``, the bound over every m)."""
        return out_of_memory(error, self.estimate_for(None), self.num_qubits, self.what(), measured)


def check_searches(sizes: Sequence[SearchSize], available: int | None = None) -> tuple[int, str] | None:
    """A direct search's one memory check, for the searches of one call run one after the other:
    each refused (``ValueError``) as ``SearchSize.check`` says. The available memory is read at most
    once, and not at all where every bound is at most ``available_memory.always_fits_bytes()``.

    Args:
        sizes: The searches' ``SearchSize``.
        available: The available bytes; None (default) for ``available_memory.available_memory()``.

    Returns:
        What was read (``available_memory()``'s ``(bytes, source)``), or None where nothing was.

    Raises:
        ValueError: A search whose estimate exceeds the available memory.
    """
    bounds = [size.peak(size.num_qubits, None) for size in sizes]
    if available is None and (not bounds or max(bounds) <= probe.always_fits_bytes()):
        return None
    measured = probe.available_memory() if available is None else (available, "")
    if measured is not None:
        for size in sizes:
            size.check(measured)
    return measured


_Result = TypeVar("_Result")


def run_checked(sizes: Sequence[SearchSize], runs: Sequence[Callable[[], _Result]]) -> tuple[_Result, ...]:
    """Direct searches: ``check_searches(sizes)`` once, then ``runs`` one after the other, a
    ``MemoryError`` raised by run i raised again as the one-line ``OutOfMemory`` of ``sizes[i]``
    (naming n, what the allocator reported and the largest smaller n whose bound fits in the memory
    the check read, or in what is available then where it read none).

    Args:
        sizes: One ``SearchSize`` per search.
        runs: One callable per search, in the same order.

    Returns:
        The runs' results, in order.

    Raises:
        ValueError: A search refused by the check (before any runs).
        OutOfMemory: A ``MemoryError`` while a search ran.
    """
    measured = check_searches(sizes)
    results = []
    for size, run in zip(sizes, runs, strict=True):
        try:
            results.append(run())
        except OutOfMemory:
            raise
        except MemoryError as error:  # (its frames, and the search's arrays, are released before the message)
            raise size.out_of_memory(error, measured) from error
    return tuple(results)


#: a plan's tree, bytes per node besides its coordinates (parents in the tree and the result, the
#: nearest-node grid's order, the history of nodes, allocator slack): with the coordinates,
#: 96 + 48 d, a calibrated upper bound, with a margin, of the measured peak of a parallel-RRT plan
#: whose goal is walled in
TREE_BYTES_PER_NODE = 96
#: a plan's tree, bytes per node and coordinate (positions in the tree, its nearest-neighbour
#: structure, the grid and the result)
TREE_BYTES_PER_COORDINATE = 48
#: a plan's round history (``RunState.end_round``: five Python integers a round in lists, and the
#: result's copies), bytes per round: a calibrated upper bound of the measured peak of long RRT
#: plans from a walled-in start, rounded up
HISTORY_BYTES_PER_ROUND = 256
#: the rounds of history a plan's check before its first round counts at most (1 GiB at
#: ``HISTORY_BYTES_PER_ROUND``): a budget allows far more rounds than most plans run, so the history
#: beyond them is checked as it grows (``check_history_growth``), not refused up front
HISTORY_ROUNDS_CHECKED_UP_FRONT = 1 << 22


def check_history_growth(rounds: int) -> int:
    """Check, when a plan's history reaches ``rounds`` rounds, that the memory available holds as
    many more; returns the round count at which to check again (twice ``rounds``).

    Args:
        rounds: The rounds recorded (a checkpoint: ``HISTORY_ROUNDS_CHECKED_UP_FRONT`` and its
            doublings).

    Returns:
        2 ``rounds``.

    Raises:
        OutOfMemory: The memory available (``available_memory``) holds less than ``rounds``
            more rounds of history, naming the rounds run and the limits to lower.
    """
    needed = rounds * HISTORY_BYTES_PER_ROUND
    reading = probe.available_memory()
    if reading is not None and reading[0] < needed:
        raise OutOfMemory(f"the plan has run {rounds} rounds and its round history would need about "
                          f"{_size(needed)} more to double, more than {_memory_text(reading)}: give a smaller "
                          "max_rounds or oracle-call budget, or a stall_rounds limit")
    return 2 * rounds


#: writing a plan's result as ``json.dump(result.to_dict(), ...)`` (the Python lists of ``to_dict``),
#: bytes per node besides the tree's: 128 + 48 d, a calibrated upper bound of the measured peak, with
#: a margin. For callers that write ``to_dict()`` themselves (``plan_bytes``'
#: ``output_bytes_per_node``); ``qrrt plan --json`` writes with ``PlanResult.write_json``, which
#: streams the arrays and adds a bounded amount whatever the node count, so it charges nothing per
#: node.
JSON_BYTES_PER_NODE = 128
JSON_BYTES_PER_COORDINATE = 48


def plan_bytes(max_nodes: int, nodes_per_round: int, max_rounds: int | None, dim: int,
               output_bytes_per_node: int = 0) -> tuple[int, int]:
    """The most a plan's tree and its round history can hold, in bytes: (tree, history); the history
    up to ``HISTORY_ROUNDS_CHECKED_UP_FRONT`` rounds (beyond, ``check_history_growth`` checks it as the
    plan runs).

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
        >>> from qrrt_circuits._support.memory import plan_bytes
        >>> plan_bytes(1000, 1, 20000, 2)
        (192192, 5120000)
        >>> plan_bytes(1000, 8, 10, 2)  # 10 rounds of 8 workers: at most 80 nodes
        (15552, 2560)
    """
    nodes = _tree_nodes(max_nodes, nodes_per_round, max_rounds)
    tree = nodes * (TREE_BYTES_PER_NODE + TREE_BYTES_PER_COORDINATE * dim + output_bytes_per_node)
    history = 0 if max_rounds is None else min(max_rounds, HISTORY_ROUNDS_CHECKED_UP_FRONT) * HISTORY_BYTES_PER_ROUND
    return tree, history


def _tree_nodes(max_nodes: int, nodes_per_round: int, max_rounds: int | None) -> int:
    """The most nodes a plan's tree holds, the root included (``plan_bytes``)."""
    nodes = max_nodes + nodes_per_round
    return nodes if max_rounds is None else min(nodes, max_rounds * nodes_per_round + 1)


def _largest(fits: Callable[[int], bool], upto: int) -> int:
    """The largest v in [1, upto] with ``fits(v)`` (``fits`` monotone: true up to some v), else 0."""
    if upto < 1 or not fits(1):
        return 0
    low, high = 1, upto  # fits(low) holds
    while low < high:
        middle = (low + high + 1) // 2
        if fits(middle):
            low = middle
        else:
            high = middle - 1
    return low


@dataclass
class PlanSize:
    """What one plan's memory check sizes: its tree and round history up to the limits in force
    and, for a quantum planner, one round at its peak as a function of n.

    ``check`` is the plan's one memory check (``Planner.plan`` makes it before the plan allocates
    anything); ``out_of_memory`` words a ``MemoryError`` raised while the plan ran. Both name one
    size to lower: ``num_qubits`` where the round needs at least as much as the tree and history or
    lowering the limits alone cannot make the plan fit, else ``max_nodes`` (where the tree needs at
    least as much as the history and a tree of one node would fit) or ``max_rounds``.

    Args:
        max_nodes: The node limit in force.
        nodes_per_round: The most nodes one round adds.
        max_rounds: The round limit in force (None: not counted, see ``plan_bytes``).
        dim: The workspace dimension d.
        round_estimate: One round's ``MemoryEstimate`` as a function of n, or None (default) for a
            plan without databases (the classical planners).
        num_qubits: The plan's n (default 0: none).
        default_nodes: Whether ``max_nodes`` is the default limit (the caller gave none).
        default_rounds: Whether ``max_rounds`` is the default limit.
        output_bytes_per_node: What writing the result adds per node (``plan_bytes``).

    Attributes:
        measured: The memory available as the last ``check`` read it (``available_memory.available_memory()``'s
            ``(bytes, source)``), or None where it read none.

    Example:
        >>> from qrrt_circuits._support.memory import MemoryEstimate, PlanSize, database_bytes
        >>> size = PlanSize(1000, 1, 100, 2,
        ...                 round_estimate=lambda n: MemoryEstimate(n, database_bytes=database_bytes(n, 2)),
        ...                 num_qubits=26)
        >>> size.estimate().breakdown()
        'database build 3.6 GiB, scratch 64 MiB, tree 19 KiB, round history 25 KiB'
        >>> size.check(available=2**30)  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        ValueError: num_qubits = 26: this plan could need about 3.7 GiB ...; the largest num_qubits that fits is 24
    """

    max_nodes: int
    nodes_per_round: int
    max_rounds: int | None
    dim: int
    round_estimate: Callable[[int], MemoryEstimate] | None = None
    num_qubits: int = 0
    default_nodes: bool = False
    default_rounds: bool = False
    output_bytes_per_node: int = 0
    measured: tuple[int, str] | None = field(default=None, init=False, repr=False, compare=False)

    def estimate(self, num_qubits: int | None = None) -> MemoryEstimate:
        """The plan's estimated peak (``MemoryEstimate``: the round's parts, the tree, its output
        and the round history).

        Args:
            num_qubits: n (default the plan's own).

        Returns:
            The estimate at the plan's limits.
        """
        n = self.num_qubits if num_qubits is None else num_qubits
        base = MemoryEstimate(n, scratch_bytes=0) if self.round_estimate is None else self.round_estimate(n)
        return self._at(base, self.max_nodes, self.max_rounds)

    def _at(self, base: MemoryEstimate, max_nodes: int, max_rounds: int | None) -> MemoryEstimate:
        """``base`` (a round) with the tree, output and history of these limits."""
        nodes = _tree_nodes(max_nodes, self.nodes_per_round, max_rounds)
        tree, history = plan_bytes(max_nodes, self.nodes_per_round, max_rounds, self.dim)
        return replace(base, tree_bytes=tree, output_bytes=nodes * self.output_bytes_per_node,
                       history_bytes=history)

    def check(self, available: int | None = None) -> MemoryEstimate:
        """Refuse (``ValueError``) a plan whose estimated peak exceeds the available memory, naming
        the size to lower (see the class), whether a limit is the default one, the estimate, the
        available memory (and which figure bounds it) and the largest value of that size that
        fits. The available memory is read at most once.

        Estimates up to ``available_memory.always_fits_bytes()`` are accepted without reading the available memory;
        so is any estimate when the available memory is unknown.

        Args:
            available: The available bytes; None (default) for ``available_memory.available_memory()``.

        Returns:
            The plan's ``estimate()`` when it fits.

        Raises:
            ValueError: The estimate exceeds the available memory.
        """
        self.measured = None
        estimate = self.estimate()
        if estimate.total_bytes <= probe.always_fits_bytes():
            return estimate
        measured = self.measured = (available, "") if available is not None else probe.available_memory()
        if measured is None or estimate.total_bytes <= measured[0]:
            return estimate
        name, value, given = self._size_to_lower(estimate, measured[0])
        largest = self._largest_below(name, estimate, measured[0], value + 1)
        about = "" if name == "num_qubits" else "about "
        if largest:
            fits = f"the largest {name} that fits is {about}{largest}"
        elif name == "num_qubits":
            fits = "the largest num_qubits that fits is 0 (none does)"
        else:
            fits = f"no {name} fits ({_size(measured[0])} is less than one round needs)"
        raise ValueError(
            f"{name} = {value}{given}: this plan could need about {_size(estimate.total_bytes)} at its peak "
            f"({estimate.breakdown()}), more than {_memory_text(measured)}; {fits}")

    def out_of_memory(self, error: MemoryError) -> OutOfMemory:
        """The one-line ``OutOfMemory`` that replaces a ``MemoryError`` raised while the plan ran.

        Drops ``error``'s traceback (its frames hold the plan's arrays) before any memory is read.

        Args:
            error: The ``MemoryError`` (numpy's ``_ArrayMemoryError`` is one).

        Returns:
            The ``OutOfMemory`` to raise (``raise size.out_of_memory(error) from error``): it names
            the size to lower (see the class), what the allocator reported, the estimate and the
            largest value below the plan's whose estimate fits in the memory available when the
            plan started (``measured``; read now where the check read none). The estimate fell
            short at the plan's value, so a smaller one than that may be needed.
        """
        estimate = self.estimate()
        _released(error)
        figure = self.measured if self.measured is not None else probe.available_memory()
        name, value, given = self._size_to_lower(estimate, None if figure is None else figure[0])
        return _out_of_memory(error, name, value, "this plan", estimate,
                              lambda available: self._largest_below(name, estimate, available, value),
                              self.measured, given)

    def _size_to_lower(self, estimate: MemoryEstimate, available: int | None) -> tuple[str, int, str]:
        """(name, value, "the default" note) of the size a message names (see the class)."""
        if self.round_estimate is not None:
            least = self._at(estimate, 1, None if self.max_rounds is None else 1).total_bytes
            if estimate.round_bytes >= estimate.limits_bytes or (available is not None and least > available):
                return "num_qubits", self.num_qubits, ""
        one_node = self._at(estimate, 1, self.max_rounds).total_bytes
        tree_first = estimate.tree_bytes + estimate.output_bytes >= estimate.history_bytes
        if self.max_rounds is None or (tree_first and (available is None or one_node <= available)):
            default = self.default_nodes
            name, value = "max_nodes", self.max_nodes
        else:  # the history's limit (a lower one also bounds the tree)
            default = self.default_rounds
            name, value = "max_rounds", self.max_rounds
        return name, value, " (the default: the plan was given none)" if default else ""

    def _largest_below(self, name: str, estimate: MemoryEstimate, available: int, below: int) -> int:
        """The largest value below ``below`` of the size ``name`` whose estimate fits (0: none)."""
        if name == "num_qubits":
            return largest_fitting(self.estimate, available, below)
        if name == "max_nodes":
            return _largest(lambda nodes: self._at(estimate, nodes, self.max_rounds).total_bytes <= available,
                            below - 1)
        return _largest(lambda rounds: self._at(estimate, self.max_nodes, rounds).total_bytes <= available, below - 1)


def check_plan_fits(max_nodes: int, nodes_per_round: int, max_rounds: int | None, dim: int,
                    available: int | None = None, *, default_nodes: bool = False,
                    default_rounds: bool = False, output_bytes_per_node: int = 0,
                    round_estimate: Callable[[int], MemoryEstimate] | None = None,
                    num_qubits: int = 0) -> MemoryEstimate:
    """A plan's one memory check (``PlanSize.check``): refuse (``ValueError``) limits and a round
    whose tree, round history and round peak together could exceed the available memory, naming
    the size to lower (``num_qubits``, ``max_nodes`` or ``max_rounds``, see ``PlanSize``), whether
    that limit is the default one, the estimate, the available memory and the largest value of that
    size that fits.

    Estimates up to ``available_memory.always_fits_bytes()`` are accepted without reading the available memory; so is
    any estimate when the available memory is unknown.

    Args:
        max_nodes: The node limit in force.
        nodes_per_round: The most nodes one round adds.
        max_rounds: The round limit in force (None: not counted, see ``plan_bytes``).
        dim: The workspace dimension d.
        available: The available bytes; None (default) for ``available_memory.available_memory()``.
        default_nodes: Whether ``max_nodes`` is the default limit (the caller gave none).
        default_rounds: Whether ``max_rounds`` is the default limit.
        output_bytes_per_node: What writing the result adds per node (``plan_bytes``).
        round_estimate: One round's ``MemoryEstimate`` as a function of n (a quantum planner's
            ``memory_estimate``), or None (default) for a plan without databases.
        num_qubits: The plan's n (with ``round_estimate``).

    Returns:
        The plan's ``MemoryEstimate`` when it fits.

    Raises:
        ValueError: The estimate exceeds the available memory.

    Example:
        >>> from qrrt_circuits._support.memory import check_plan_fits
        >>> check_plan_fits(10**6, 1, 20000, 2, available=2**30).breakdown()  # 20 001 nodes at most
        'tree 4 MiB, round history 5 MiB'
        >>> check_plan_fits(10**6, 1, 10**9, 2, available=2**30)  # doctest: +ELLIPSIS
        Traceback (most recent call last):
        ...
        ValueError: max_rounds = 1000000000: this plan could need about 1.2 GiB ...
    """
    return PlanSize(max_nodes, nodes_per_round, max_rounds, dim, round_estimate, num_qubits, default_nodes,
                    default_rounds, output_bytes_per_node).check(available)
