"""What a worker receives: a small picklable context, never the planner.

``WorkerContext`` holds what stays fixed for a whole plan (the world, the predicate, the error
model, the backend, the annealing schedule, the random streams). It is built once per plan and
pickled once: every task carries the same bytes, and a worker process unpickles them only the
first time it sees that plan (a small per-process cache keyed by a random token). ``RoundView``
holds what one round adds (a snapshot of the tree, the goal, the round and temperature indices,
the search policy's state). ``map_tasks`` runs one worker function over a round's tasks, serially
or on any ``concurrent.futures.Executor`` (threads, processes, Dask), in task order, so results
never depend on the executor: every task draws its randomness from streams keyed by (round,
worker).
"""

from __future__ import annotations

import pickle
import uuid
from collections import OrderedDict
from collections.abc import Callable, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass, field
from itertools import repeat
from typing import Any, TypeVar

from .._support.randomness import RandomStreams
from ..problems.goals import Goal
from ..reachability.oracle_errors import OracleErrorModel
from ..reachability.predicate import ReachabilityPredicate
from ..search.backends.base import QuantumSearchBackend
from ..search.policies.base import PolicyState
from ..world.environment import Environment
from ..world.nearest import NearestNeighbors
from ..world.spaces import StateSpace
from .database import AnnealingSchedule
from .tree import Tree

T = TypeVar("T")
R = TypeVar("R")


@dataclass(frozen=True, eq=False)
class WorkerContext:
    """The plan-wide, read-only part of a worker's task."""

    env: Environment
    predicate: ReachabilityPredicate
    space: StateSpace
    streams: RandomStreams
    goal_bias: float = 0.0
    oracle_errors: OracleErrorModel | None = None
    backend: QuantumSearchBackend | None = None
    annealing: AnnealingSchedule | None = None
    database_size: int = 1
    max_extension: float | None = None
    candidates: Any = None  # a quantum planner's ``candidates.Candidates`` (classical planners: None)

    @property
    def search_backend(self) -> QuantumSearchBackend:
        """The quantum planners' backend (classical planners' contexts have none)."""
        if self.backend is None:
            raise RuntimeError("this worker context has no search backend (a classical planner's)")
        return self.backend
    token: str = field(default_factory=lambda: uuid.uuid4().hex, compare=False)

    def __reduce__(self) -> tuple[Callable[[str, bytes], WorkerContext], tuple[str, bytes]]:
        payload = self.__dict__.get("_payload")
        if payload is None:
            state = {key: value for key, value in self.__dict__.items() if key != "_payload"}
            payload = pickle.dumps(state, protocol=pickle.HIGHEST_PROTOCOL)
            object.__setattr__(self, "_payload", payload)
        return _restore_context, (self.token, payload)


#: contexts a worker process has already unpickled, by token (a few plans at a time)
_CONTEXTS: OrderedDict[str, WorkerContext] = OrderedDict()
_CONTEXTS_KEPT = 8


def _restore_context(token: str, payload: bytes) -> WorkerContext:
    context = _CONTEXTS.get(token)
    if context is None:
        context = WorkerContext(**pickle.loads(payload))
        _CONTEXTS[token] = context
        if len(_CONTEXTS) > _CONTEXTS_KEPT:
            _CONTEXTS.popitem(last=False)
    return context


@dataclass(frozen=True, eq=False)
class RoundView:
    """The round's part of a worker's task (the tree and its nearest-neighbour structure are a
    snapshot: workers never change them)."""

    tree: Tree
    neighbors: NearestNeighbors
    goal: Goal
    round_index: int
    temperature_index: int = 0
    policy_state: PolicyState | None = None

    @property
    def search_policy_state(self) -> PolicyState:
        """The quantum planners' policy state (classical planners' rounds have none)."""
        if self.policy_state is None:
            raise RuntimeError("this round has no search policy state (a classical planner's)")
        return self.policy_state

    @property
    def tree_nodes(self) -> int:
        return self.tree.size - 1


def map_tasks(executor: Executor | None, function: Callable[[WorkerContext, RoundView, T], R],
              context: WorkerContext, view: RoundView, tasks: Sequence[T]) -> list[R]:
    """``[function(context, view, task) for task in tasks]``, on ``executor`` if one is given."""
    if executor is None or len(tasks) <= 1:
        return [function(context, view, task) for task in tasks]
    return list(executor.map(function, repeat(context, len(tasks)), repeat(view, len(tasks)), tasks))


