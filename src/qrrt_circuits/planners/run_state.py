"""The mutable bookkeeping of one ``plan`` call: the tree, the counters and the round history."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ..termination import Progress
from ..tree import Tree

if TYPE_CHECKING:  # annotations only (context imports the search modules)
    from ..search.policies import PolicyState
    from .context import WorkerContext
    from .fused_round import FusedRound

HISTORY_KEYS = ("oracle_calls", "critical_path", "nodes", "entries", "reachable")


class RunState:
    """Counters of DESIGN §2 as a plan accumulates them; ``end_round`` appends the history."""

    def __init__(self, root: np.ndarray, goal: np.ndarray, goal_radius: float) -> None:
        self.tree = Tree(root)
        self.goal = goal
        self.goal_radius = goal_radius
        self.goal_node: int | None = 0 if np.linalg.norm(root - goal) <= goal_radius else None
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
        self.policy_state: PolicyState | None = None  # quantum planners only
        self.context: WorkerContext | None = None  # the plan's WorkerContext, built once
        self.fused_round: FusedRound | None = None  # quantum planners whose rounds can be fused

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
    def oracle_calls(self) -> int:
        return self.quantum_calls + self.verification_calls

    @property
    def nodes(self) -> int:
        """Nodes in the tree, root excluded."""
        return self.tree.size - 1

    def add_node(self, position: np.ndarray, parent: int) -> int:
        index = self.tree.add(position, parent)
        if self.goal_node is None:
            offset = position - self.goal  # math.sqrt(offset @ offset) is np.linalg.norm's own formula
            if math.sqrt(float(offset.dot(offset))) <= self.goal_radius:
                self.goal_node = index
        return index

    def progress(self, elapsed_s: float) -> Progress:
        return Progress(self.oracle_calls, self.critical_path, self.nodes, self.rounds,
                        self.rounds_without_new_node, elapsed_s)

    def end_round(self) -> None:
        self.rounds += 1
        added = self.nodes - self._nodes_at_round_start
        self.rounds_without_new_node = 0 if added else self.rounds_without_new_node + 1
        self._nodes_at_round_start = self.nodes
        self.history["oracle_calls"].append(self.oracle_calls)
        self.history["critical_path"].append(self.critical_path)
        self.history["nodes"].append(self.nodes)
        self.history["entries"].append(self.round_entries)
        self.history["reachable"].append(self.round_reachable)
        self.round_entries = self.round_reachable = 0
