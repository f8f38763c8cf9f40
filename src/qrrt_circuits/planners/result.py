"""What a plan returns: the tree, the path, the counters of DESIGN §2, the status and labels."""

from __future__ import annotations

from collections.abc import KeysView
from dataclasses import asdict, dataclass, field
from typing import Any

import networkx as nx
import numpy as np

from ..termination import PlanStatus


@dataclass(frozen=True)
class Metrics:
    """The counters of DESIGN §2 (readable as attributes or as a mapping).

    ``oracle_calls == quantum_oracle_calls + verification_calls`` always holds;
    ``critical_path_oracle_calls`` sums, over rounds, the largest count of one worker (the time of
    p parallel quantum devices); ``simulation_checks`` are the 2^n predicate evaluations per
    database the simulated phase oracle needs (not oracle calls); ``wasted_checks`` the predicate
    evaluations the batched classical planners made for rounds that never ran (not oracle calls)."""

    oracle_calls: int
    quantum_oracle_calls: int
    verification_calls: int
    critical_path_oracle_calls: int
    simulation_checks: int
    nodes: int
    rounds: int
    databases: int
    duplicates: int
    rejected: int
    wall_time_s: float
    #: predicate evaluations done ahead of time and thrown away (batched RRT: candidates of rounds
    #: after the round that changed the tree); raw work, never oracle calls
    wasted_checks: int = 0

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)

    def __getitem__(self, key: str) -> Any:
        return getattr(self, key)

    def keys(self) -> KeysView[str]:
        return self.as_dict().keys()


@dataclass(frozen=True, eq=False)
class PlanResult:
    """A finished plan.

    ``status`` is a ``PlanStatus``: ``"reached"`` or the name of the termination condition that
    ended the plan. ``nodes`` (N+1, d) with the root in row 0, ``parents`` (N+1,) with
    ``parents[0] == -1``; ``path`` root .. goal node or None. ``settings`` records the planner, the
    predicate (and the dynamics it follows), the problem and the termination condition;
    ``labels`` every simulation shortcut the numbers depend on; ``history`` per-round arrays."""

    status: PlanStatus
    nodes: np.ndarray
    parents: np.ndarray
    path: np.ndarray | None
    metrics: Metrics
    planner: str
    settings: dict
    labels: tuple[str, ...]
    history: dict[str, np.ndarray] = field(repr=False)
    goal_node: int | None = None

    @property
    def reached(self) -> bool:
        return self.status is PlanStatus.REACHED

    @property
    def budget_exhausted(self) -> bool:
        """0.1's status "budget_exhausted": a termination condition ended the plan."""
        return not self.reached

    @property
    def tree(self) -> nx.DiGraph:
        """The tree as a networkx DiGraph (edges parent -> child, node attribute ``pos``)."""
        graph = nx.DiGraph()
        for index, position in enumerate(self.nodes):
            graph.add_node(index, pos=tuple(position))
        for child, parent in enumerate(self.parents):
            if parent >= 0:
                graph.add_edge(int(parent), child)
        return graph

    def to_dict(self) -> dict:
        return {
            "status": str(self.status),
            "planner": self.planner,
            "settings": self.settings,
            "labels": list(self.labels),
            "metrics": self.metrics.as_dict(),
            "nodes": self.nodes.tolist(),
            "parents": self.parents.tolist(),
            "path": None if self.path is None else self.path.tolist(),
            "goal_node": self.goal_node,
            "history": {key: value.tolist() for key, value in self.history.items()},
        }
