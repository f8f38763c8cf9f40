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
    from ..problems.problem import Problem
    from ..search.backends.base import QuantumSearchBackend

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


def make_planner(kind: str, seed: int, backend: str = "aer", workers: int = 8, num_qubits: int = 8,
                 search_policy: IterationPolicy | str | None = None, **options: Any) -> Planner:
    """The registry planner ``kind`` (``RRT``, ``ParallelRRT``, ``QRRT``, ``PQRRT``, ``PQRRT-unshared``
    or their lower-case names) with the experiment's settings.

    The experiment's settings (``seed``, ``backend``, ``workers``, ``num_qubits``,
    ``search_policy``) are shared by every planner of an experiment: each goes to the planners that
    declare it (RRT has no workers, the classical planners no backend). Any further option is passed
    as given and refused by a planner that does not take it (``Registry.create``).

    Args:
        kind: A ``PLANNERS`` name.
        seed: The planner's seed.
        backend: A ``BACKENDS`` name (for the quantum planners).
        workers: Parallel workers (for the planners that take them).
        num_qubits: Qubits per database, 2^n entries (for the quantum planners).
        search_policy: An iteration policy, a ``POLICIES`` name or None: the paper's schedule
            (``PaperIterations()``), pinned here whatever the planners' own default is.
        **options: Further planner options, passed as given.

    Returns:
        The planner.

    Raises:
        ValueError: If a name is unknown or a further option does not apply to ``kind``.
    """
    if search_policy is None:  # the experiments reproduce the paper: its schedule unless they name another
        search_policy = PaperIterations()
    elif isinstance(search_policy, str):
        search_policy = POLICIES.create(search_policy)
    takes = PLANNERS.resolve(kind).options()
    shared: dict[str, Any] = {"seed": seed, "workers": workers, "num_qubits": num_qubits,
                              "search_policy": search_policy}
    if "backend" in takes:
        shared["backend"] = make_backend(backend)
    planner: Planner = PLANNERS.create(kind, **{key: value for key, value in shared.items() if key in takes},
                                       **options)
    return planner


def experiment_problem(settings: dict[str, Any], problem: Problem) -> Problem:
    """``problem`` with the experiment's predicate (``settings["predicate"]``, a ``PREDICATES``
    name built on the problem's world); the problem itself when the settings name none.

    Args:
        settings: The experiment's settings (its ``predicate``, if any).
        problem: The world's problem.

    Returns:
        The problem to plan.

    Raises:
        ValueError: If the predicate's name is unknown.
    """
    name = settings.get("predicate")
    if name is None:
        return problem
    return problem.replace(predicate=PREDICATES.create(name, env=problem.env))
