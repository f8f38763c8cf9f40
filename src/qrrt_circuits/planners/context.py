"""What a worker receives: a small picklable context, never the planner.

``WorkerContext`` holds what stays fixed for a whole plan (the world, the predicate, the error
model, the backend, the annealing schedule, the random streams); ``RoundView`` what one round
adds (a snapshot of the tree, the goal, the round and temperature indices, the search policy's
state). ``map_tasks`` runs one worker function over a round's tasks, serially or on any
``concurrent.futures.Executor`` (threads, processes, Dask), in task order, so results never depend
on the executor: every task draws its randomness from streams keyed by (round, worker).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass
from itertools import repeat
from typing import TypeVar

import numpy as np

from ..database import AnnealingSchedule
from ..environment import Environment
from ..oracle_errors import OracleErrorModel
from ..predicate import ReachabilityPredicate
from ..randomness import RandomStreams
from ..search.backend import QuantumSearchBackend
from ..search.policies import PolicyState
from ..tree import Tree

T = TypeVar("T")
R = TypeVar("R")


@dataclass(frozen=True, eq=False)
class WorkerContext:
    """The plan-wide, read-only part of a worker's task."""

    env: Environment
    predicate: ReachabilityPredicate
    streams: RandomStreams
    goal_bias: float = 0.0
    oracle_errors: OracleErrorModel | None = None
    backend: QuantumSearchBackend | None = None
    annealing: AnnealingSchedule | None = None
    database_size: int = 1


@dataclass(frozen=True, eq=False)
class RoundView:
    """The round's part of a worker's task (the tree is a snapshot: workers never change it)."""

    tree: Tree
    goal: np.ndarray
    goal_radius: float
    round_index: int
    temperature_index: int = 0
    policy_state: PolicyState | None = None

    @property
    def tree_nodes(self) -> int:
        return self.tree.size - 1


def map_tasks(executor: Executor | None, function: Callable[[WorkerContext, RoundView, T], R],
              context: WorkerContext, view: RoundView, tasks: Sequence[T]) -> list[R]:
    """``[function(context, view, task) for task in tasks]``, on ``executor`` if one is given."""
    if executor is None or len(tasks) <= 1:
        return [function(context, view, task) for task in tasks]
    return list(executor.map(function, repeat(context, len(tasks)), repeat(view, len(tasks)), tasks))


