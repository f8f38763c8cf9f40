"""Planners for the experiments, built through the registry with the experiments' defaults
(8 workers, 2^8 databases, the paper's search schedule, one Aer thread per process so that trials can
run side by side)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ..registry import BACKENDS, PLANNERS, POLICIES, PREDICATES
from ..search.policies.base import IterationPolicy
from ..search.policies.schedules import PaperIterations

if TYPE_CHECKING:
    from ..planners.base import Planner
    from ..reachability.predicate import ReachabilityPredicate
    from ..search.backends.base import QuantumSearchBackend
    from ..world.environment import Environment

#: how each backend is described in summaries
BACKEND_LABEL = {
    "aer": "Aer statevector simulator (gate-level circuits)",
    "statevector": "exact statevector (ideal; same statistics as Aer)",
    "sampler": "Aer SamplerV2 (transpiled grover_operator circuits)",
}

#: the experiments' options for each backend
BACKEND_OPTIONS = {"aer": {"max_parallel_threads": 1}}


def make_backend(name: str) -> QuantumSearchBackend:
    """The ``BACKENDS`` backend ``name`` with the experiments' options (one Aer thread).

    Args:
        name: A ``qrrt_circuits.registry.BACKENDS`` name.

    Returns:
        A new backend.

    Raises:
        ValueError: If ``name`` is not a backend.
    """
    backend: QuantumSearchBackend = BACKENDS.create( name, **BACKEND_OPTIONS.get(BACKENDS.canonical(name), {}))
    return backend


def make_planner(kind: str, env: Environment, seed: int, backend: str = "aer", workers: int = 8,
                 num_qubits: int = 8, search_policy: IterationPolicy | str | None = None,
                 predicate: ReachabilityPredicate | str | None = None, **options: Any) -> Planner:
    """The registry planner ``kind`` (``RRT``, ``ParallelRRT``, ``QRRT``, ``PQRRT``, ``PQRRT-unshared``
    or their lower-case names). Options a planner does not take (a backend for RRT, workers for
    q-RRT) are left out; ``options`` are passed as given. ``predicate`` is a predicate object, a
    ``PREDICATES`` name (built on ``env``) or None (the planner's default, the exact check).

    Args:
        kind: A ``PLANNERS`` name.
        env: The world to plan in.
        seed: The planner's seed.
        backend: A ``BACKENDS`` name (quantum planners only).
        workers: Parallel workers (planners that take them).
        num_qubits: Qubits per database, 2^n entries (quantum planners only).
        search_policy: An iteration policy, a ``POLICIES`` name or None: the paper's schedule
            (``PaperIterations()``), pinned here whatever the planners' own default is.
        predicate: A predicate, a ``PREDICATES`` name or None (the exact check).
        **options: Further planner options, passed as given.

    Returns:
        The planner.

    Raises:
        ValueError: If a name is unknown or an option does not apply to ``kind``.
    """
    if search_policy is None:  # the experiments reproduce the paper: its schedule unless they name another
        search_policy = PaperIterations()
    elif isinstance(search_policy, str):
        search_policy = POLICIES.create(search_policy)
    if isinstance(predicate, str):
        predicate = PREDICATES.create(predicate, env=env)
    if predicate is not None:
        options["predicate"] = predicate
    defaults: dict[str, Any] = {"workers": workers, "num_qubits": num_qubits, "search_policy": search_policy,
                                "seed": seed}
    if "quantum" in PLANNERS.resolve(kind).tags:
        defaults["backend"] = make_backend(backend)
    planner: Planner = PLANNERS.create(kind, env=env, **PLANNERS.applicable(kind, defaults), **options)
    return planner


def planner_for(settings: dict[str, Any], kind: str, env: Environment, seed: int, backend: str = "aer",
                workers: int = 8, num_qubits: int = 8, **options: Any) -> Planner:
    """``make_planner`` with the experiment's predicate (``settings["predicate"]``; the exact check
    when the settings name none).

    Args:
        settings: The experiment's settings (its ``predicate``, if any).
        kind: A ``PLANNERS`` name.
        env: The world to plan in.
        seed: The planner's seed.
        backend: A ``BACKENDS`` name (quantum planners only).
        workers: Parallel workers (planners that take them).
        num_qubits: Qubits per database (quantum planners only).
        **options: Further ``make_planner`` options.

    Returns:
        The planner.

    Raises:
        ValueError: If a name is unknown or an option does not apply to ``kind``.
    """
    return make_planner(kind, env, seed, backend, workers, num_qubits, predicate=settings.get("predicate"),
                        **options)
