"""One registry of everything that is chosen by name: planners, backends, search policies,
scenarios and reachability predicates.

The CLI's choices and help text and the experiments build objects through these registries, so a
name means the same thing everywhere. An unknown name is refused with the list of choices. Planner
names are lower case (``rrt``, ``prrt``, ``qrrt``, ``pqrrt``, ``pqrrt-unshared``); the class-style
names (``RRT``, ``ParallelRRT``, ``QRRT``, ``PQRRT``, ``PQRRT-unshared``) are aliases of them. A
parametric entry is written ``name:VALUE`` (``fixed:2``, ``time-samples:50``).
"""

from __future__ import annotations

import functools
import inspect
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np
    from qiskit_aer.noise import NoiseModel

    from .planners.base import Planner
    from .reachability.authors_check import AuthorsCheck
    from .reachability.dynamics import LinearTrackingDynamics
    from .reachability.exact import ExactCheck
    from .reachability.time_sampled import TimeSampledCheck
    from .search import AerBackend, SamplerBackend, StatevectorBackend
    from .search.policies.estimated import EstimatedOptimal
    from .search.policies.fixed_point_amplification import FixedPointAmplification
    from .search.policies.schedules import FixedIterations
    from .search.policies.thompson import ThompsonIterations
    from .world.environment import Environment


@dataclass(frozen=True)
class Entry:
    """One named choice: ``factory(**options)`` builds it (``factory(value, **options)`` for a
    parametric entry written ``name:VALUE``).

    Args:
        name: The canonical name (``"qrrt"``, ``"fixed"``, ...).
        factory: The callable that builds the object.
        help: One line for the CLI's help.
        aliases: Other names that resolve to this entry (the planners' class-style names, ...).
        parameter: The parameter's placeholder for a parametric entry (``"K"`` for ``fixed:K``), or
            None.
        tags: Free labels (``"classical"``, ``"quantum"``, ``"parallel"``).
        parameter_optional: Whether the parameter may be left out (``fixed-point`` or
            ``fixed-point:0.3``); the factory then gets None.
        declared: The keyword options the factory takes, where it declares them (a planner's
            ``Options``); None to read them from the factory's signature.
        specs: The declarations of those options (``planners.options.OptionSpec``: check, help,
            flag), for a planner; empty otherwise.

    Example:
        >>> from qrrt_circuits.registry import POLICIES
        >>> entry = POLICIES.resolve("fixed-point:0.3")
        >>> entry.name, entry.label, entry.accepts(None)
        ('fixed-point', 'fixed-point[:DELTA]', True)
    """

    name: str
    factory: Callable[..., Any]
    help: str
    aliases: tuple[str, ...] = ()
    parameter: str | None = None  # e.g. "K" for "fixed:K"
    tags: frozenset[str] = field(default_factory=frozenset)
    parameter_optional: bool = False
    declared: frozenset[str] | None = None
    specs: tuple[Any, ...] = ()

    @property
    def label(self) -> str:
        """The name as a user types it: ``name``, ``name:PARAM`` or ``name[:PARAM]`` (optional)."""
        if self.parameter is None:
            return self.name
        return f"{self.name}[:{self.parameter}]" if self.parameter_optional else f"{self.name}:{self.parameter}"

    def accepts(self, value: str | None) -> bool:
        """Whether ``name:VALUE`` (or the bare name, for value None) is this entry's form.

        Args:
            value: The text after the colon, or None for the bare name.

        Returns:
            True for a bare name of a plain entry, a value for a parametric one, or a bare name of
            an entry whose parameter is optional.
        """
        if self.parameter is None:
            return value is None
        return value is not None or self.parameter_optional

    def options(self) -> frozenset[str]:
        """The keyword options the factory accepts.

        Returns:
            The declared options, or the names of the factory's keyword (or positional-or-keyword)
            parameters, looking through ``functools.partial``.

        Raises:
            ValueError: A factory without an inspectable signature (a builtin type).
        """
        if self.declared is not None:
            return self.declared
        target = self.factory
        while isinstance(target, functools.partial):
            target = target.func
        parameters = inspect.signature(target).parameters.values()
        return frozenset(p.name for p in parameters if p.kind in (p.KEYWORD_ONLY, p.POSITIONAL_OR_KEYWORD))


class Registry:
    """Named factories of one kind (``kind`` is used in error messages: "planner", ...).

    The module's registries are ``PLANNERS``, ``BACKENDS``, ``POLICIES``, ``SCENARIOS`` and
    ``PREDICATES``; the CLI and the experiments build objects through them, so a name means the
    same thing everywhere. An unknown name is refused with the list of choices.

    Args:
        kind: What the entries are, for error messages (``"planner"``, ``"search policy"``, ...).

    Example:
        >>> from qrrt_circuits.registry import PLANNERS, POLICIES
        >>> PLANNERS.names()
        ('rrt', 'prrt', 'qrrt', 'pqrrt', 'pqrrt-unshared', 'qrrt-connect', 'qrrt-star')
        >>> PLANNERS.canonical("PQRRT"), "qrrt" in PLANNERS, "astar" in PLANNERS
        ('pqrrt', True, False)
        >>> POLICIES.labels()
        ('paper', 'optimal', 'bbht', 'adaptive', 'thompson', 'fixed:K', 'fixed-point[:DELTA]', 'estimated')
        >>> POLICIES.create("fixed:2")
        FixedIterations(k=2)
        >>> PLANNERS.resolve("astar")
        Traceback (most recent call last):
        ...
        ValueError: unknown planner 'astar'; choose one of rrt, prrt, qrrt, pqrrt, pqrrt-unshared, qrrt-connect, ...
    """

    def __init__(self, kind: str) -> None:
        self.kind = kind
        self._entries: dict[str, Entry] = {}
        self._lookup: dict[str, str] = {}

    def register(self, name: str, factory: Callable[..., Any], help: str, *, aliases: tuple[str, ...] = (),
                 parameter: str | None = None, tags: tuple[str, ...] = (),
                 parameter_optional: bool = False, declared: frozenset[str] | None = None,
                 specs: tuple[Any, ...] = ()) -> Entry:
        """Add a named factory.

        Args:
            name: The canonical name.
            factory: Builds the object: ``factory(**options)``, or ``factory(value, **options)``
                for a parametric entry.
            help: One line for the CLI's help.
            aliases: Other names for the same entry.
            parameter: The parameter's placeholder (``"K"``) for an entry written ``name:VALUE``.
            tags: Free labels.
            parameter_optional: Whether the bare name is accepted too (the factory gets None).
            declared: The options the factory takes, where it declares them (else its signature's).
            specs: Their declarations (a planner's option specifications, ``OptionSpec``).

        Returns:
            The new ``Entry``.

        Raises:
            ValueError: ``name`` or an alias already registered.
        """
        entry = Entry(name, factory, help, tuple(aliases), parameter, frozenset(tags), parameter_optional, declared,
                      specs)
        for key in (name, *aliases):
            if key in self._lookup:
                raise ValueError(f"{self.kind} name {key!r} is registered twice")
            self._lookup[key] = name
        self._entries[name] = entry
        return entry

    def names(self) -> tuple[str, ...]:
        """Canonical names, in registration order."""
        return tuple(self._entries)

    def labels(self) -> tuple[str, ...]:
        """Names as a user types them (``fixed:K`` for a parametric entry)."""
        return tuple(entry.label for entry in self._entries.values())

    def __iter__(self) -> Iterator[str]:
        return iter(self._entries)

    def __contains__(self, name: object) -> bool:
        try:
            self.resolve(name)  # type: ignore[arg-type]
        except (ValueError, TypeError):
            return False
        return True

    def __len__(self) -> int:
        return len(self._entries)

    def _split(self, name: str) -> tuple[str, str | None]:
        if not isinstance(name, str):
            raise TypeError(f"{self.kind} must be a name (one of {', '.join(self.labels())}), got {name!r}")
        base, _, value = name.partition(":")
        return base, (value if _ else None)

    def resolve(self, name: str) -> Entry:
        """The entry for ``name`` (canonical, alias, or ``name:VALUE``).

        Args:
            name: A canonical name, an alias, or ``name:VALUE`` for a parametric entry.

        Returns:
            The ``Entry``.

        Raises:
            TypeError: ``name`` is not a string.
            ValueError: No entry has that name or form (the message lists the choices).
        """
        base, value = self._split(name)
        key = self._lookup.get(base)
        entry = None if key is None else self._entries[key]
        if entry is None or not entry.accepts(value):
            raise ValueError(f"unknown {self.kind} {name!r}; choose one of {', '.join(self.labels())}")
        return entry

    def canonical(self, name: str) -> str:
        """The canonical spelling of ``name`` (aliases resolved, a parameter kept).

        Args:
            name: A canonical name, an alias, or ``name:VALUE``.

        Returns:
            ``entry.name``, or ``entry.name:VALUE`` for a parametric entry.

        Raises:
            TypeError: ``name`` is not a string.
            ValueError: An unknown name.
        """
        entry = self.resolve(name)
        _, value = self._split(name)
        return entry.name if value is None else f"{entry.name}:{value}"

    def create(self, name: str, /, **options: Any) -> Any:
        """Build the object ``name`` stands for, with ``options``; an option the entry does not
        take is refused, naming it.

        Args:
            name: A canonical name, an alias, or ``name:VALUE`` (the value is passed to the factory
                as text).
            **options: Keyword arguments for the factory.

        Returns:
            What the factory returns (a planner, backend, policy, ``Environment`` or predicate).

        Raises:
            TypeError: ``name`` is not a string.
            ValueError: An unknown name, an option the entry does not take, or a parameter that is
                not a number; the factory's own ``ValueError`` / ``TypeError`` for a bad option.
        """
        entry = self.resolve(name)
        unknown = set(options) - entry.options()
        if unknown:
            raise ValueError(f"option(s) {sorted(unknown)} do not apply to {self.kind} {entry.name!r} "
                             f"(it takes {sorted(entry.options())})")
        _, value = self._split(name)
        if entry.parameter is not None:
            return entry.factory(value, **options)
        return entry.factory(**options)

    def help_text(self) -> str:
        """``label: help`` for every entry, joined by ``"; "`` (CLI help).

        Returns:
            One line of text.
        """
        return "; ".join(f"{entry.label}: {entry.help}" for entry in self._entries.values())


# ----------------------------------------------------------------------------------------- planners
def register_planner(registry: Registry, name: str, planner: type[Planner], help: str, *,
                     fixed: dict[str, Any] | None = None, aliases: tuple[str, ...] = (),
                     tags: tuple[str, ...] = ()) -> Entry:
    """Register a planner class under ``name``: its factory is the class with ``fixed`` options
    bound, and what it takes is what its ``Options`` declare (and ``executor`` where it takes one),
    less the fixed ones. A planner written outside the package registers the same way.

    Args:
        registry: ``PLANNERS`` (or another planner registry).
        name: The canonical name.
        planner: A ``Planner`` subclass.
        help: One line for the CLI's help.
        fixed: Options this entry binds (``shared_database=False``), no longer given by the user.
        aliases: Other names.
        tags: Free labels (``"classical"``, ``"quantum"``, ``"parallel"``).

    Returns:
        The new ``Entry``.
    """
    from .planners.options import option_specs

    fixed = fixed or {}
    specs = tuple(spec for spec in option_specs(planner.Options) if spec.name not in fixed)
    declared = frozenset({spec.name for spec in specs} | ({"executor"} if planner.takes_executor else set()))
    return registry.register(name, functools.partial(planner, **fixed) if fixed else planner, help,
                             aliases=aliases, tags=tags, declared=declared, specs=specs)


def _planners() -> Registry:
    from .planners import PQRRT, QRRT, RRT, ParallelRRT, QRRTConnect, QRRTStar

    registry = Registry("planner")
    register_planner(registry, "rrt", RRT, "classical RRT, 1 reachability test a round", aliases=("RRT",),
                     tags=("classical",))
    register_planner(registry, "prrt", ParallelRRT, "manager-worker parallel RRT (workers tests a round)",
                     aliases=("ParallelRRT", "parallel-rrt"), tags=("classical", "parallel"))
    register_planner(registry, "qrrt", QRRT, "q-RRT: Grover search of one database a round", aliases=("QRRT",),
                     tags=("quantum",))
    register_planner(registry, "pqrrt", PQRRT, "Pq-RRT: workers measure one shared database",
                     fixed={"shared_database": True}, aliases=("PQRRT", "pqrrt-shared"), tags=("quantum", "parallel"))
    register_planner(registry, "pqrrt-unshared", PQRRT, "Pq-RRT: each worker builds and searches its own database",
                     fixed={"shared_database": False}, aliases=("PQRRT-unshared",), tags=("quantum", "parallel"))
    register_planner(registry, "qrrt-connect", QRRTConnect,
                     "q-RRT-Connect: two trees, q-RRT extensions, a Grover-searched connection",
                     aliases=("QRRTConnect",), tags=("quantum", "bidirectional"))
    register_planner(registry, "qrrt-star", QRRTStar,
                     "q-RRT*: q-RRT extensions, Durr-Hoyer choice of parent, searched rewires (anytime)",
                     aliases=("QRRTStar",), tags=("quantum", "optimizing"))
    return registry


# ----------------------------------------------------------------------------------------- backends
def _aer(seed: int | np.random.Generator | None = None, max_parallel_threads: int | None = None,
         method: str = "statevector", noise_model: NoiseModel | None = None, device: str = "CPU") -> AerBackend:
    from .search import AerBackend

    return AerBackend(seed=seed, method=method, noise_model=noise_model, device=device,
                      max_parallel_threads=max_parallel_threads)


def _statevector(seed: int | np.random.Generator | None = None, closed_form: bool = True) -> StatevectorBackend:
    from .search import StatevectorBackend

    return StatevectorBackend(seed=seed, closed_form=closed_form)


def _aer_sampler(seed: int | np.random.Generator | None = None) -> SamplerBackend:
    from qiskit_aer.primitives import SamplerV2

    from .search import SamplerBackend

    return SamplerBackend(SamplerV2(), seed=seed)


def _backends() -> Registry:
    registry = Registry("backend")
    registry.register("aer", _aer, "Grover circuits on qiskit-aer's AerSimulator (gate level)")
    registry.register("statevector", _statevector, "exact statevector (ideal; same statistics as Aer)")
    registry.register("sampler", _aer_sampler, "the grover_operator circuit, transpiled, through Aer's SamplerV2")
    return registry


# ----------------------------------------------------------------------------------------- policies
def _fixed(value: str) -> FixedIterations:
    from .search.policies.schedules import FixedIterations

    try:
        k = int(value)
    except ValueError:
        raise ValueError(f"policy fixed:K needs an integer K >= 0, got 'fixed:{value}'") from None
    return FixedIterations(k)


def _fixed_point(value: str | None) -> FixedPointAmplification:
    from .search.policies.fixed_point_amplification import FixedPointAmplification

    if value is None:
        return FixedPointAmplification()
    try:
        delta = float(value)
    except ValueError:
        raise ValueError(f"policy fixed-point:DELTA needs a number DELTA in (0, 1), "
                         f"got 'fixed-point:{value}'") from None
    return FixedPointAmplification(delta=delta)


def _thompson() -> ThompsonIterations:
    from .search.policies.thompson import ThompsonIterations

    return ThompsonIterations()


def _estimated() -> EstimatedOptimal:
    from .search.policies.estimated import EstimatedOptimal

    return EstimatedOptimal()


def _policies() -> Registry:
    from .search.policies.adaptive import Adaptive
    from .search.policies.bbht import BBHT
    from .search.policies.schedules import KnownOptimal, PaperIterations

    registry = Registry("search policy")
    registry.register("paper", PaperIterations, "5 iterations, 3 after 10 nodes (the authors' code)")
    registry.register("optimal", KnownOptimal, "optimal k for the true m (simulation knowledge)")
    registry.register("bbht", BBHT, "Boyer-Brassard-Hoyer-Tapp for unknown m")
    registry.register("adaptive", Adaptive, "k from a posterior over m/N learned from verified outcomes")
    registry.register("thompson", _thompson, "k per database from a bandit over the plan's own databases")
    registry.register("fixed", _fixed, "always K iterations", parameter="K")
    registry.register("fixed-point", _fixed_point,
                      "fixed-point amplitude amplification (Yoder et al. 2014), P >= 1 - DELTA^2 for "
                      "marked fractions >= 0.05 (DELTA 0.5 by default)", parameter="DELTA", parameter_optional=True)
    registry.register("estimated", _estimated,
                      "amplitude estimation of m per database (its shots counted as oracle calls), "
                      "then the optimal k")
    return registry


# ----------------------------------------------------------------------------------------- scenarios
def _scenarios() -> Registry:
    from .problems import scenarios

    registry = Registry("scenario")
    registry.register("paper_clutter", scenarios.paper_clutter, "20 x 20, 525 boxes (paper Fig. 9-12)")
    registry.register("narrow_corridor", scenarios.narrow_corridor, "a 0.4 x 4 channel (paper §V.C)")
    registry.register("annealing_field", scenarios.annealing_field, "about 68 x 68, 6025 boxes (paper §V.D)")
    registry.register("lattice", scenarios.lattice, "72 x 72 cells, half blocked (predecessor paper)")
    return registry


# ----------------------------------------------------------------------------------------- predicates
def _exact(env: Environment, dynamics: LinearTrackingDynamics | None = None,
           resolution: float = 0.01) -> ExactCheck:
    from .reachability.exact import ExactCheck

    return ExactCheck(env, dynamics, resolution=resolution)


def _time_samples(value: str, env: Environment, dynamics: LinearTrackingDynamics | None = None) -> TimeSampledCheck:
    from .reachability.time_sampled import TimeSampledCheck

    try:
        count = int(value)
    except ValueError:
        raise ValueError(f"predicate time-samples:K needs an integer K >= 2, got 'time-samples:{value}'") from None
    return TimeSampledCheck(env, dynamics, time_samples=count)


def _authors(env: Environment, dynamics: LinearTrackingDynamics | None = None) -> AuthorsCheck:
    from .reachability.authors_check import AuthorsCheck

    return AuthorsCheck(env, dynamics, refine=4)


def _authors_octave(env: Environment, dynamics: LinearTrackingDynamics | None = None) -> AuthorsCheck:
    from .reachability.authors_check import AuthorsCheck

    return AuthorsCheck(env, dynamics, refine=1)


def _predicates() -> Registry:
    registry = Registry("predicate")
    registry.register("exact", _exact, "sound check, exact up to the resolution (ours)")
    registry.register("authors", _authors,
                      "the authors' dynamicscheck.m under MATLAB's ode45 (Refine 4; unsound, tail untested)")
    registry.register("authors-octave", _authors_octave,
                      "the authors' dynamicscheck.m under Octave's ode45 (1 output a step; unsound, nearly exact)")
    registry.register("time-samples", _time_samples, "K evenly spaced time samples only (unsound; for study)",
                      parameter="K")
    return registry


class _Lazy:
    """A registry built on first use (the planners import the registry's users)."""

    def __init__(self, build: Callable[[], Registry]) -> None:
        self._build = build
        self._registry: Registry | None = None

    def __getattr__(self, name: str) -> Any:
        if self._registry is None:
            self._registry = self._build()
        return getattr(self._registry, name)

    def __iter__(self) -> Iterator[str]:
        return iter(self.__getattr__("names")())

    def __contains__(self, name: object) -> bool:
        return self.__getattr__("__contains__")(name)

    def __len__(self) -> int:
        return len(self.__getattr__("names")())


#: the planners by name: ``rrt``, ``prrt``, ``qrrt``, ``pqrrt``, ``pqrrt-unshared`` (the class names are aliases)
PLANNERS: Registry = _Lazy(_planners)  # type: ignore[assignment]
#: the search backends by name: ``aer``, ``statevector``, ``sampler``
BACKENDS: Registry = _Lazy(_backends)  # type: ignore[assignment]
#: the iteration policies by name: ``paper``, ``optimal``, ``bbht``, ``adaptive``, ``fixed:K``, ...
POLICIES: Registry = _Lazy(_policies)  # type: ignore[assignment]
#: the scenarios by name: ``paper_clutter``, ``narrow_corridor``, ``annealing_field``, ``lattice``
SCENARIOS: Registry = _Lazy(_scenarios)  # type: ignore[assignment]
#: the reachability predicates by name: ``exact``, ``authors``, ``authors-octave``, ``time-samples:K``
PREDICATES: Registry = _Lazy(_predicates)  # type: ignore[assignment]
