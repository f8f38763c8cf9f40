"""Reading a ``PlanResult`` into record values: growth curves, cuts at a budget, reachable
fractions, and the JSON encoding of arrays inside a CSV cell."""

from __future__ import annotations

import json

import numpy as np


def growth_curve(result) -> list[list[int]]:
    """[[nodes, oracle_calls, critical_path_calls], ...] at every round that added a node."""
    history = result.history
    curve = []
    last = 0
    for nodes, calls, critical in zip(history["nodes"], history["oracle_calls"],
                                      history["critical_path"], strict=True):
        if nodes > last:
            curve.append([int(nodes), int(calls), int(critical)])
            last = nodes
    return curve


def cut_at(result, budget: int, on: str = "oracle_calls") -> tuple[int, int]:
    """(nodes, calls) of the same run stopped by ``max_oracle_calls=budget``: rounds start only
    while calls < budget, so the run ends after the first round that reaches the budget.
    ``on="critical_path"`` cuts on critical-path calls instead (``max_critical_path_calls``)."""
    calls = result.history[on]
    nodes = result.history["nodes"]
    if len(calls) == 0:
        return 0, 0
    reached = np.flatnonzero(calls >= budget)
    index = int(reached[0]) if reached.size else len(calls) - 1
    return int(nodes[index]), int(calls[index])


def reachable_fraction(result) -> float:
    """Truly reachable candidates / all candidates the run evaluated (RRT: its tests; q-RRT: its
    database entries)."""
    entries = int(result.history["entries"].sum())
    return int(result.history["reachable"].sum()) / entries if entries else 0.0


def dumps(value) -> str:
    return json.dumps(value, separators=(",", ":"))


def loads(text):
    return json.loads(text) if isinstance(text, str) else text


def rounded(points: np.ndarray, digits: int = 3) -> list:
    return np.round(np.asarray(points, dtype=float), digits).tolist()
