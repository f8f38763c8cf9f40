"""Each planner's settings, declared once (OMPL's ``declareParam``): a frozen options dataclass
whose fields carry their check, their help and their command-line flag.

A planner is built from its options (``QRRT(num_qubits=6, seed=0)`` builds ``QRRT.Options`` from
the keywords; ``QRRT(options)`` takes them whole); its checks, ``settings()``, the registry's list
of what a planner takes, the ``qrrt plan`` flags and the one planner factory all read these
declarations, so an option means the same thing everywhere and one a planner does not take is
refused by name.

- ``PlannerOptions``: what every planner takes (``goal_bias``, ``max_extension``,
  ``oracle_errors``, ``seed``).
- ``RRTOptions``: and ``look_ahead`` (RRT); ``ParallelOptions``: and ``workers`` (parallel RRT).
- ``QuantumOptions``: and ``backend``, ``num_qubits``, ``search_policy``, ``annealing``,
  ``database`` (q-RRT).
- ``ParallelQuantumOptions``: and ``workers``, ``shared_database`` (Pq-RRT).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass, field, fields
from typing import Any, TypeVar

from .._support.validation import check_bool, check_float, check_instance, check_int, check_seed
from ..reachability.oracle_errors import OracleErrorModel
from ..search.backends.base import QuantumSearchBackend
from ..search.policies.base import IterationPolicy
from .candidates import Candidates
from .database import AnnealingSchedule

__all__ = ["MAX_WORKERS", "ConnectOptions", "OptionSpec", "ParallelOptions", "ParallelQuantumOptions", "PlannerOptions",
           "QuantumOptions", "RRTOptions", "StarOptions", "option_specs"]

#: the most workers a parallel planner takes
MAX_WORKERS = 4096

O = TypeVar("O", bound="PlannerOptions")


@dataclass(frozen=True)
class OptionSpec:
    """One declared option: its name, default, check and description.

    Args:
        name: The keyword.
        default: Its default (None: the planner's own default where ``help`` says so).
        check: ``check(value, name)`` returns the accepted value or raises naming the option and
            its accepted range.
        help: One line for documentation and the command line.
        flag: The ``qrrt plan`` flag (``"--qubits"``), or None for an option given in Python only.
        text: How the flag's text becomes the value before ``check`` (``int``, ``float``; ``str``
            for an object the command line names from a registry).
        describe: The option's value as JSON (default: the value itself).
    """

    name: str
    default: Any
    check: Callable[[Any, str], Any]
    help: str
    flag: str | None = None
    text: Callable[[str], Any] = str
    describe: Callable[[Any], Any] = lambda value: value


def declare(default: Any, check: Callable[[Any, str], Any], help: str, flag: str | None = None,
            text: Callable[[str], Any] = str, describe: Callable[[Any], Any] | None = None) -> Any:
    """A dataclass field that carries its ``OptionSpec`` (the name is the field's)."""
    metadata = {"check": check, "help": help, "flag": flag, "text": text}
    if describe is not None:
        metadata["describe"] = describe
    return field(default=default, metadata=metadata)


#: ``option_specs`` of each options class, read once
_SPECS: dict[type, tuple[OptionSpec, ...]] = {}


def option_specs(options_type: type[PlannerOptions]) -> tuple[OptionSpec, ...]:
    """The declared options of an options class, in declaration order (read once per class).

    Args:
        options_type: ``PlannerOptions`` or a subclass.

    Returns:
        One ``OptionSpec`` per field.
    """
    specs = _SPECS.get(options_type)
    if specs is None:
        specs = _SPECS[options_type] = tuple(
            OptionSpec(item.name, item.default, item.metadata["check"], item.metadata["help"], item.metadata["flag"],
                       item.metadata["text"], item.metadata.get("describe", lambda value: value))
            for item in fields(options_type))
    return specs


def _goal_bias(value: Any, name: str) -> float:
    try:
        bias: float | None = check_float(value, name, 0.0, 1.0)
    except ValueError:
        bias = None
    if bias is None or bias >= 1.0:  # one message for 1, 1.5, -0.5 and NaN: the range is [0, 1)
        raise ValueError(f"{name} must be a finite number in [0.0, 1.0), got {value!r}")
    return bias


def _optional(check: Callable[[Any, str], Any]) -> Callable[[Any, str], Any]:
    return lambda value, name: None if value is None else check(value, name)


def _instance(kind: type, what: str) -> Callable[[Any, str], Any]:
    return lambda value, name: check_instance(value, name, kind, what)


def _workers() -> Any:
    """The ``workers`` option of the parallel planners."""
    return declare(8, lambda value, name: check_int(value, name, 1, MAX_WORKERS),
                   f"workers per round, in [1, {MAX_WORKERS}]", "--workers", int)


def _describe(value: Any) -> Any:
    return None if value is None else value.describe()


def _backend() -> Any:
    """The ``backend`` option of the quantum planners."""
    return declare(None, _optional(_instance(QuantumSearchBackend, "a QuantumSearchBackend")),
                   "the search backend", "--backend", describe=_describe)


def _num_qubits() -> Any:
    """The ``num_qubits`` option of the quantum planners."""
    return declare(8, lambda value, name: check_int(value, name, 1), "database of 2^qubits entries", "--qubits", int)


def _search_policy() -> Any:
    """The ``search_policy`` option of the quantum planners."""
    return declare(None, _optional(_instance(IterationPolicy, "a search policy (PaperIterations(), FixedIterations(k), "
                                                              "KnownOptimal(), BBHT(), Adaptive(), "
                                                              "ThompsonIterations())")),
                   "search policy", "--policy", describe=_describe)


@dataclass(frozen=True, kw_only=True)
class PlannerOptions:
    """What every planner takes (all keyword-only; each checked when the options are built).

    Args:
        goal_bias: Probability in [0, 1) that a candidate is drawn in the goal (with the goal's
            ``sample``) instead of uniformly in the workspace. Default 0 (the paper's uniform
            sampling).
        max_extension: The longest step from a parent (OMPL's RRT ``range``): a candidate farther
            from its nearest node is moved toward it until the distance is ``max_extension``
            (``database.steer``), for the classical tests and the quantum databases alike. A finite
            number > 0, or None (default: the raw samples, as the paper's algorithms take them).
        oracle_errors: An ``OracleErrorModel`` that corrupts the answers the algorithm sees (false
            positives and negatives): the reachability tests of the classical planners, the marks
            of the phase oracle of the quantum planners; or None (default) for exact answers. No
            wrong answer adds a node: a classical planner verifies a positive answer with the true
            predicate (one more verification call) before it adds the node, and a quantum
            planner's finalizer verifies every measured entry, so an error costs oracle calls only.
        seed: Non-negative integer seed of the plan's random streams (``RandomStreams``: a
            generator per (round, worker, stream) for what workers draw, and the classical
            planners' samples drawn in round order, so results do not depend on the executor or
            the order of the calls), or None (default) for fresh entropy.

    Raises:
        TypeError: An option of the wrong type (naming it).
        ValueError: An option out of its range (naming it and the range).
    """

    goal_bias: float = declare(0.0, _goal_bias, "probability of sampling the goal, in [0, 1)", "--goal-bias", float)
    max_extension: float | None = declare(
        None, _optional(lambda value, name: check_float(value, name, 0.0, open_minimum=True)),
        "longest step from a parent (OMPL's RRT range), > 0; None: the raw samples", "--max-extension",
        float)
    oracle_errors: OracleErrorModel | None = declare(
        None, _optional(_instance(OracleErrorModel, "an OracleErrorModel or None")),
        "an OracleErrorModel corrupting the answers the algorithm sees (default: exact answers)",
        describe=_describe)
    seed: int | None = declare(None, lambda value, name: check_seed(value, name), "the plan's seed", "--seed", int)

    def __post_init__(self) -> None:
        for spec in option_specs(type(self)):
            object.__setattr__(self, spec.name, spec.check(getattr(self, spec.name), spec.name))

    @classmethod
    def create(cls: type[O], planner: str, **keywords: Any) -> O:
        """The options of ``planner`` from keywords; one it does not take is refused by name.

        Args:
            planner: The planner's name, for the message.
            **keywords: Options.

        Returns:
            The checked options.

        Raises:
            TypeError: An option this planner does not take (naming it and the ones it takes), or
                what the options' checks refuse.
            ValueError: What the options' checks refuse.
        """
        accepted = [spec.name for spec in option_specs(cls)]
        unknown = sorted(set(keywords) - set(accepted))
        if unknown:
            raise TypeError(f"{planner} does not take {', '.join(unknown)}; it takes {', '.join(accepted)} "
                            "(and executor=)")
        return cls(**keywords)

    def replace(self: O, **changes: Any) -> O:
        """A checked copy with some options changed."""
        return dataclasses.replace(self, **changes)

    def describe(self) -> dict:
        """Every option as JSON (objects by their ``describe()``)."""
        return {spec.name: spec.describe(getattr(self, spec.name)) for spec in option_specs(type(self))}


@dataclass(frozen=True, kw_only=True)
class RRTOptions(PlannerOptions):
    """RRT's options: ``PlannerOptions`` and how its rounds are tested.

    Args:
        look_ahead: Whether rounds are tested in batches ahead of the tree (default True). The
            plan is the same either way; a batch tests rounds a node makes stale
            (``Metrics.wasted_checks``), which costs little with the compiled checks and much with
            an expensive user predicate: False tests one round at a time, so the predicate is
            asked exactly once per oracle call.
    """

    look_ahead: bool = declare(True, check_bool, "test rounds in batches ahead of the tree (the same plan)")


@dataclass(frozen=True, kw_only=True)
class ParallelOptions(RRTOptions):
    """Parallel RRT's options: ``RRTOptions`` and the workers.

    Args:
        workers: Number p of workers, i.e. extensions per round, in [1, ``MAX_WORKERS``] (4096).
            Default 8.
    """

    workers: int = _workers()


@dataclass(frozen=True, kw_only=True)
class QuantumOptions(PlannerOptions):
    """q-RRT's options: ``PlannerOptions`` and the search.

    Args:
        backend: The ``QuantumSearchBackend`` that simulates each Grover search (its ``max_qubits``
            must allow ``num_qubits``), or None (default) for a new ``AerBackend()`` (qiskit-aer
            statevector sampling).
        num_qubits: Qubits n per database, so each database holds N = 2^n (sample, nearest parent)
            entries; an integer >= 1 and at most the backend's ``max_qubits``. ``plan`` refuses an n
            whose round, with the tree, does not fit in the available memory. Default 8.
        search_policy: The ``IterationPolicy`` that decides how each search runs: None (default)
            for the planner's ``default_search_policy()``, ``PaperIterations()`` (the paper's
            schedule: 5 Grover iterations, 3 once the tree has more than 10 nodes),
            ``FixedIterations(k)``, ``KnownOptimal()`` (Eq. 1 with the true m), ``BBHT()``,
            ``Adaptive()``, ``ThompsonIterations()``, ``FixedPointAmplification()``,
            ``EstimatedOptimal()`` or any other ``IterationPolicy``.
        annealing: An ``AnnealingSchedule`` for Quantum Database Annealing (Alg. 4: samples drawn
            in distance bands around the tree that shrink with the temperature index h), or None
            (default) for uniform databases.
        database: How each round's database is built and searched (``planners.candidates``):
            None or ``NearestParents()`` (the paper's samples with their nearest nodes, searched by
            lookup) or ``LatticeCandidates(cell_bits, ..., coherent=...)``.

    Raises:
        ValueError: ``num_qubits`` above the backend's ``max_qubits``, or both ``annealing`` and
            ``database``.
    """

    backend: QuantumSearchBackend | None = _backend()
    num_qubits: int = _num_qubits()
    search_policy: IterationPolicy | None = _search_policy()
    annealing: AnnealingSchedule | None = declare(
        None, _optional(_instance(AnnealingSchedule, "an AnnealingSchedule or None")),
        "Quantum Database Annealing's schedule (default: uniform databases)", describe=_describe)
    database: Candidates | None = declare(
        None, _optional(_instance(Candidates, "NearestParents() (the paper's), LatticeCandidates(...) or None")),
        "how each database is built and searched (default: the paper's)", describe=_describe)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.backend is not None:
            self.backend.check_qubits(self.num_qubits)
        if self.annealing is not None and self.database is not None:
            raise ValueError("annealing draws the paper's database in bands: give annealing or database, not both")


@dataclass(frozen=True, kw_only=True)
class ParallelQuantumOptions(QuantumOptions):
    """Pq-RRT's options: ``QuantumOptions`` and the workers.

    Args:
        workers: Number p of quantum workers per round, in [1, ``MAX_WORKERS``] (4096). Default 8.
        shared_database: True (default): the manager builds one database per round and its p
            workers all search it (Alg. 3 as printed; a solution measured by several workers is
            added once, the extra copies counted as ``duplicates``). False: each worker builds and
            searches its own database. Must be a ``bool``.
    """

    workers: int = _workers()
    shared_database: bool = declare(True, check_bool, "whether the workers search one shared database")


def _rewire_factor(value: Any, name: str) -> float:
    return check_float(value, name, 1.0, 10.0)


@dataclass(frozen=True, kw_only=True)
class ConnectOptions(PlannerOptions):
    """q-RRT-Connect's options: ``PlannerOptions``, the search of q-RRT and the connection database.

    Args:
        backend: The ``QuantumSearchBackend`` of every search (``QuantumOptions``), or None (default)
            for a new ``AerBackend()``.
        num_qubits: Qubits n of each extension database (2^n samples with their nearest node of the
            tree that grows); an integer >= 1 and at most the backend's ``max_qubits``. Default 8.
        search_policy: The ``IterationPolicy`` of the extension and connection searches, or None
            (default) for the planner's ``default_search_policy()``.
        connect_qubits: The connection database holds the 2^q nodes of the other tree nearest to the
            new node (all of them while that tree is smaller, padded with unmarked entries to the
            next power of two); an integer >= 1 and at most the backend's ``max_qubits``, or None
            (default) for ``num_qubits``.

    Raises:
        ValueError: ``num_qubits`` or ``connect_qubits`` above the backend's ``max_qubits``.
    """

    backend: QuantumSearchBackend | None = _backend()
    num_qubits: int = _num_qubits()
    search_policy: IterationPolicy | None = _search_policy()
    connect_qubits: int | None = declare(
        None, _optional(lambda value, name: check_int(value, name, 1)),
        "connection database of the 2^q nearest nodes of the other tree (default: --qubits)", "--connect-qubits",
        int)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.backend is not None:
            self.backend.check_qubits(self.num_qubits)
            if self.connect_qubits is not None:
                self.backend.check_qubits(self.connect_qubits)


@dataclass(frozen=True, kw_only=True)
class StarOptions(PlannerOptions):
    """q-RRT*'s options: ``PlannerOptions``, the search of q-RRT and the near set of RRT*.

    Args:
        backend: The ``QuantumSearchBackend`` of every search, or None (default) for a new
            ``AerBackend()``.
        num_qubits: Qubits n of each extension database; an integer >= 1 and at most the backend's
            ``max_qubits``. Default 8.
        search_policy: The ``IterationPolicy`` of the extension search, or None (default) for the
            planner's ``default_search_policy()``.
        rewire_factor: OMPL's ``rewire_factor`` r in [1, 10] (default 1.1, OMPL's): the near set is
            the k = ceil(r e (1 + 1/d) ln(n + 1)) nearest nodes (OMPL's k-nearest RRT*, its default).

    Raises:
        ValueError: ``num_qubits`` above the backend's ``max_qubits``.
    """

    backend: QuantumSearchBackend | None = _backend()
    num_qubits: int = _num_qubits()
    search_policy: IterationPolicy | None = _search_policy()
    rewire_factor: float = declare(1.1, _rewire_factor, "RRT*'s rewire factor (k-nearest near set), in [1, 10]",
                                   "--rewire-factor", float)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.backend is not None:
            self.backend.check_qubits(self.num_qubits)
