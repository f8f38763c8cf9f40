"""Planners for the experiments, built through the registry with the experiments' defaults
(8 workers, 2^8 databases, one Aer thread per process so that trials can run side by side)."""

from __future__ import annotations

from ..registry import BACKENDS, PLANNERS, POLICIES, PREDICATES
from ..search.policies import IterationPolicy

#: how each backend is described in summaries
BACKEND_LABEL = {
    "aer": "Aer statevector simulator (gate-level circuits)",
    "statevector": "exact statevector (ideal; same statistics as Aer)",
    "sampler": "Aer SamplerV2 (transpiled grover_operator circuits)",
}

#: the experiments' options for each backend
BACKEND_OPTIONS = {"aer": {"max_parallel_threads": 1}}


def make_backend(name: str):
    return BACKENDS.create(name, **BACKEND_OPTIONS.get(BACKENDS.canonical(name), {}))


def make_planner(kind: str, env, seed: int, backend: str = "aer", workers: int = 8, num_qubits: int = 8,
                 search_policy: IterationPolicy | str | None = None, predicate=None, **options):
    """The registry planner ``kind`` (``RRT``, ``ParallelRRT``, ``QRRT``, ``PQRRT``, ``PQRRT-unshared``
    or their lower-case names). Options a planner does not take (a backend for RRT, workers for
    q-RRT) are left out; ``options`` are passed as given. ``predicate`` is a predicate object, a
    ``PREDICATES`` name (built on ``env``) or None (the planner's default, the exact check)."""
    if isinstance(search_policy, str):
        search_policy = POLICIES.create(search_policy)
    if isinstance(predicate, str):
        predicate = PREDICATES.create(predicate, env=env)
    if predicate is not None:
        options["predicate"] = predicate
    defaults = {"workers": workers, "num_qubits": num_qubits, "search_policy": search_policy, "seed": seed}
    if "quantum" in PLANNERS.resolve(kind).tags:
        defaults["backend"] = make_backend(backend)
    return PLANNERS.create(kind, env=env, **PLANNERS.applicable(kind, defaults), **options)


def planner_for(settings: dict, kind: str, env, seed: int, *args, **options):
    """``make_planner`` with the experiment's predicate (``settings["predicate"]``; the exact check
    when the settings name none, as 0.1's did)."""
    return make_planner(kind, env, seed, *args, predicate=settings.get("predicate"), **options)
