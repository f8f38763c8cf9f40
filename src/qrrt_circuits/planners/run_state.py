"""The mutable bookkeeping of one ``plan`` call: the tree and its nearest-neighbour structure, the
counters and the round history."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from .._support.memory import HISTORY_ROUNDS_CHECKED_UP_FRONT, check_history_growth
from ..problems.goals import Goal, first_satisfying
from .termination import Progress
from .tree import Tree

if TYPE_CHECKING:  # annotations only (context imports the search modules)
    from ..search.policies.base import PolicyState
    from ..world.nearest import NearestNeighbors
    from .classical import LookAhead
    from .context import WorkerContext
    from .workers import DatabaseOutcome

HISTORY_KEYS = ("oracle_calls", "critical_path", "nodes", "entries", "reachable")
#: history keys a planner may add whose values are floats (q-RRT*'s best path cost after each round)
FLOAT_HISTORY_KEYS = ("path_cost",)


class RunState:
    """Counters of DESIGN §2 as a plan accumulates them; ``end_round`` appends the history (and,
    from ``HISTORY_ROUNDS_CHECKED_UP_FRONT`` rounds on, checks at each doubling that the memory
    holds it: ``memory.check_history_growth``).

    Args:
        root: Float (d,), the tree's root.
        goal: The plan's ``Goal``.
        neighbors: The plan's nearest-neighbour structure (``StateSpace.nearest_neighbors``),
            empty: it gets the root and every node the tree gets, at the same index.
    """

    def __init__(self, root: np.ndarray, goal: Goal, neighbors: NearestNeighbors) -> None:
        self.tree = Tree(root)
        neighbors.add(self.tree.nodes)
        self.neighbors = neighbors
        self.goal = goal
        self.goal_node: int | None = 0 if first_satisfying(goal, root.reshape(1, -1)) == 0 else None
        self.rounds = 0
        self.quantum_calls = 0
        self.verification_calls = 0
        self.critical_path = 0
        self.simulation_checks = 0
        self.databases = 0
        self.duplicates = 0
        self.rejected = 0
        self.wasted_checks = 0
        self.rounds_without_new_node = 0
        self.history: dict[str, list] = {key: [] for key in HISTORY_KEYS}
        self.round_entries = 0
        self.round_reachable = 0
        self._nodes_at_round_start = 0
        self._check_history_at = HISTORY_ROUNDS_CHECKED_UP_FRONT  # (memory.check_history_growth)
        self.policy_state: PolicyState | None = None  # quantum planners only
        self.context: WorkerContext | None = None  # the plan's WorkerContext, built once
        self.ahead: LookAhead | None = None  # classical planners only
        self.extra: Any = None  # what a planner's own rounds carry (q-RRT-Connect's second tree, q-RRT*'s costs)

    @property
    def worker_context(self) -> WorkerContext:
        """The plan's worker context (set when the plan starts)."""
        if self.context is None:
            raise RuntimeError("the plan has not started: no worker context yet")
        return self.context

    @property
    def search_policy_state(self) -> PolicyState:
        """The quantum planners' policy state (set when the plan starts)."""
        if self.policy_state is None:
            raise RuntimeError("this plan has no search policy state (a classical planner's)")
        return self.policy_state

    @property
    def tests_ahead(self) -> LookAhead:
        """The classical planners' tests made ahead (set when the plan starts)."""
        if self.ahead is None:
            raise RuntimeError("this plan tests no extensions ahead (a quantum planner's)")
        return self.ahead

    @property
    def oracle_calls(self) -> int:
        return self.quantum_calls + self.verification_calls

    @property
    def nodes(self) -> int:
        """Nodes in the tree, root excluded."""
        return self.tree.size - 1

    def add_node(self, position: np.ndarray, parent: int, in_goal: bool | None = None) -> int:
        """Add one node (``Tree.add``, and to the nearest-neighbour structure); the first node that
        satisfies the goal becomes ``goal_node``. ``in_goal``: whether it does, where the caller
        has asked the goal already (None: asked here)."""
        index = self.tree.add(position, parent)
        self.neighbors.add(position.reshape(1, -1))
        if self.goal_node is None:
            if in_goal is None:
                in_goal = first_satisfying(self.goal, position.reshape(1, -1)) == 0
            if in_goal:
                self.goal_node = index
        return index

    def add_nodes(self, positions: np.ndarray, parents: np.ndarray) -> None:
        """Add nodes in order (``Tree.add_many``), as ``add_node`` one by one would."""
        if parents.shape[0] == 0:
            return
        first = self.tree.add_many(positions, parents)
        self.neighbors.add(positions)
        if self.goal_node is None:
            hit = first_satisfying(self.goal, positions)
            if hit >= 0:
                self.goal_node = first + hit

    def count_database(self, result: DatabaseOutcome) -> tuple[int, np.ndarray, np.ndarray]:
        """Count one searched database's work as DESIGN §2 counts it (``DatabaseOutcome.tally``:
        its entries, quantum calls, verifications, rejected and duplicate measurements); returns
        (the largest oracle calls of one of its workers, the verified children, their parents),
        the nodes for the caller to add to its tree."""
        quantum, verifications, rejected, longest, duplicates, children, parents = result.tally()
        self.databases += 1
        self.simulation_checks += result.entries
        self.round_entries += result.entries
        self.round_reachable += result.reachable_entries
        self.quantum_calls += quantum
        self.verification_calls += verifications
        self.rejected += rejected
        self.duplicates += duplicates
        return longest, children, parents

    def progress(self, elapsed_s: float) -> Progress:
        return Progress(self.oracle_calls, self.critical_path, self.nodes, self.rounds,
                        self.rounds_without_new_node, elapsed_s)

    def end_idle_rounds(self, count: int, calls: int) -> None:
        """Record ``count`` rounds that each tested ``calls`` candidates classically (``calls``
        verification calls, critical path 1), found none reachable and added no node: the counters
        and history ``count`` calls of ``end_round`` after such rounds would leave."""
        if count <= 0:
            return
        history, nodes = self.history, self.tree.size - 1
        calls_before = self.quantum_calls + self.verification_calls
        history["oracle_calls"].extend(range(calls_before + calls, calls_before + (count + 1) * calls, calls))
        history["critical_path"].extend(range(self.critical_path + 1, self.critical_path + count + 1))
        history["nodes"].extend([nodes] * count)
        history["entries"].extend([calls] * count)
        history["reachable"].extend([0] * count)
        self.verification_calls += count * calls
        self.critical_path += count
        self.rounds += count
        self.rounds_without_new_node += count
        while self.rounds >= self._check_history_at:
            self._check_history_at = check_history_growth(self._check_history_at)

    def end_round(self) -> None:
        self.rounds += 1
        nodes = self.tree.size - 1
        self.rounds_without_new_node = 0 if nodes > self._nodes_at_round_start else self.rounds_without_new_node + 1
        self._nodes_at_round_start = nodes
        history = self.history
        history["oracle_calls"].append(self.quantum_calls + self.verification_calls)
        history["critical_path"].append(self.critical_path)
        history["nodes"].append(nodes)
        history["entries"].append(self.round_entries)
        history["reachable"].append(self.round_reachable)
        self.round_entries = self.round_reachable = 0
        if self.rounds >= self._check_history_at:
            self._check_history_at = check_history_growth(self._check_history_at)
