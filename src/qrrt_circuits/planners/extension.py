"""What q-RRT-Connect and q-RRT* share: the quantum search settings and one q-RRT extension of a
tree (paper Algorithm 2's round: a database of 2^n samples with their nearest nodes, the phase
oracle from the predicate, the policy's Grover search, the classical finalizer), counted as
DESIGN §2 counts it.

``GrowingTree`` is one tree a plan grows: its nodes, nearest-neighbour structure, worker context
(whose predicate answers in the tree's direction of motion), the goal its samples are biased to and
its search policy state.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .._support.memory import MemoryEstimate, database_bytes, database_resident_bytes
from ..problems.goals import Goal
from ..problems.problem import Problem
from ..search.policies.base import IterationPolicy, PolicyState
from ..search.policies.thompson import ThompsonIterations
from ..world.nearest import NearestNeighbors
from .candidates import NearestParents
from .context import RoundView, WorkerContext
from .quantum import ORACLE_LOOKUP_LABEL
from .run_state import RunState
from .searching import SearchingPlanner
from .tree import Tree
from .workers import search_database

__all__ = ["GrowingTree", "SearchPlanner"]


@dataclass
class GrowingTree:
    """One tree of a plan (module docstring).

    Args:
        tree: Its ``Tree``.
        neighbors: Its nearest-neighbour structure (the tree's nodes at the same indices).
        context: The ``WorkerContext`` of its extensions (its predicate answers ``reachable(tree
            node, candidate)`` in the direction of the tree's edges).
        goal: The goal its goal-biased samples are drawn in.
        policy_state: Its search policy's state.
        add: Adds (children (m, d), parents (m,)) to the tree and its neighbours; returns the first
            new index.
    """

    tree: Tree
    neighbors: NearestNeighbors
    context: WorkerContext
    goal: Goal
    policy_state: PolicyState
    add: Callable[[np.ndarray, np.ndarray], int]


class SearchPlanner(SearchingPlanner):
    """Base of the quantum planners beyond the paper (q-RRT-Connect, q-RRT*): the backend, the
    database size and the search policy (``QuantumOptions``' meanings and defaults), and one q-RRT
    extension of a tree (``_extend``)."""

    @staticmethod
    def default_search_policy() -> IterationPolicy:
        """q-RRT's default policy, ``ThompsonIterations()`` (``QRRT.default_search_policy``)."""
        return ThompsonIterations()

    @property
    def database_size(self) -> int:
        """N = 2^n, the entries of each extension database."""
        return 1 << self.num_qubits

    def memory_estimate(self, num_qubits: int | None = None, *, dim: int) -> MemoryEstimate:
        """Estimated peak memory of one round: one extension database and its search at the
        policy's largest iteration count (``PQRRT.memory_estimate`` for one worker).

        Args:
            num_qubits: Qubits n to estimate for; default the planner's own.
            dim: The problem's dimension d.

        Returns:
            A ``MemoryEstimate``.
        """
        n = self.num_qubits if num_qubits is None else num_qubits
        policy = self.search_policy
        search = self.backend.peak_bytes(n, 1, policy.iterations_bound(1 << n), sequence=policy.runs_sequences)
        return MemoryEstimate(n, database_bytes=database_bytes(n, dim, False),
                              resident_bytes=database_resident_bytes(n, dim), search_bytes=search,
                              policy_bytes=policy.state_bytes(1 << n))

    def _round_memory(self, dim: int) -> tuple[Callable[[int], MemoryEstimate] | None, int]:
        return functools.partial(self.memory_estimate, dim=dim), self.num_qubits

    def _context(self, problem: Problem) -> WorkerContext:
        options = self.options
        return WorkerContext(problem.env, problem.predicate, problem.space, self.streams, options.goal_bias,
                             options.oracle_errors, self.backend, None, self.database_size, options.max_extension,
                             NearestParents())

    def _extend(self, state: RunState, grower: GrowingTree, worker: int = 0) -> int | None:
        """One q-RRT extension of ``grower`` (paper Alg. 2's round), counted in ``state``: a
        database of 2^n samples with their nearest nodes (steered by ``max_extension``), marked by
        the tree's predicate, searched by the policy, the measured entry verified; returns the new
        node's index, or None if no entry verified.

        Args:
            state: The plan's ``RunState`` (its counters and round).
            grower: The tree to extend.
            worker: The stream key of the database (default 0).

        Returns:
            The new node's index in ``grower.tree``, or None.
        """
        view = RoundView(grower.tree, grower.neighbors, grower.goal, state.rounds, 0, grower.policy_state)
        result = search_database(grower.context, view, (worker, 1))
        longest, children, parents = state.count_database(result)  # (one worker: no duplicates)
        state.critical_path += longest
        grower.policy_state.learn([result.outcomes])
        if parents.shape[0] == 0:
            return None
        return grower.add(children, parents)

    def labels(self) -> tuple[str, ...]:
        """The lookup behind the extension's phase oracle, and the policy's and backend's labels."""
        return (ORACLE_LOOKUP_LABEL, *self.search_policy.labels(), *self.backend.labels())


def padded_size(count: int) -> int:
    """The smallest power of two >= max(count, 2): the entries of a database of ``count``
    candidates padded with unmarked entries."""
    return 1 << max(1, int(count - 1).bit_length())


def nearest_rows(space: Any, nodes: np.ndarray, point: np.ndarray, count: int) -> np.ndarray:
    """The rows of the ``count`` nodes nearest to ``point`` under the space's metric, nearest first.

    Args:
        space: The ``StateSpace``.
        nodes: Float (M, d).
        point: Float (d,).
        count: How many (at most M).

    Returns:
        Int (count,).
    """
    distances = space.distance(nodes, point[None, :])
    if count < nodes.shape[0]:
        rows = np.argpartition(distances, count - 1)[:count]
    else:
        rows = np.arange(nodes.shape[0])
    return rows[np.argsort(distances[rows], kind="stable")].astype(np.int64)
