"""Reading a ``PlanResult`` into record values: growth curves, cuts at a budget, reachable
fractions, and the JSON encoding of arrays inside a CSV cell."""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from ..planners.result import PlanResult


def growth_curve(result: PlanResult) -> list[list[int]]:
    """[[nodes, oracle_calls, critical_path_calls], ...] at every round that added a node.

    Args:
        result: A finished plan (its per-round ``history``).

    Returns:
        One ``[nodes, oracle_calls, critical_path_calls]`` triple per round that added a node.
    """
    history = result.history
    curve: list[list[int]] = []
    last = 0
    for nodes, calls, critical in zip(history["nodes"], history["oracle_calls"],
                                      history["critical_path"], strict=True):
        if nodes > last:
            curve.append([int(nodes), int(calls), int(critical)])
            last = nodes
    return curve


def cut_at(result: PlanResult, budget: int, on: str = "oracle_calls") -> tuple[int, int]:
    """(nodes, calls) of the same run stopped by ``max_oracle_calls=budget``: rounds start only
    while calls < budget, so the run ends after the first round that reaches the budget.
    ``on="critical_path"`` cuts on critical-path calls instead (``max_critical_path_calls``).

    Args:
        result: A finished plan (its per-round ``history``).
        budget: The call budget to cut at.
        on: The ``history`` counter compared with ``budget``.

    Returns:
        ``(nodes, calls)`` after the first round whose count reaches ``budget`` (the last round
        if none does); ``(0, 0)`` for a plan without rounds.
    """
    calls = result.history[on]
    nodes = result.history["nodes"]
    if len(calls) == 0:
        return 0, 0
    reached = np.flatnonzero(calls >= budget)
    index = int(reached[0]) if reached.size else len(calls) - 1
    return int(nodes[index]), int(calls[index])


def reachable_at(result: PlanResult, budget: int, on: str = "oracle_calls") -> tuple[int, int]:
    """(truly reachable candidates, all candidates) the run evaluated up to the cut of ``cut_at``:
    summed over its rounds up to and including the first round whose ``on`` count reaches
    ``budget`` (every round if none does).

    Args:
        result: A finished plan (its per-round ``history``).
        budget: The call budget to cut at.
        on: The ``history`` counter compared with ``budget``.

    Returns:
        ``(reachable, entries)``; ``(0, 0)`` for a plan without rounds.
    """
    calls = result.history[on]
    if len(calls) == 0:
        return 0, 0
    reached = np.flatnonzero(calls >= budget)
    stop = int(reached[0]) + 1 if reached.size else len(calls)
    return int(result.history["reachable"][:stop].sum()), int(result.history["entries"][:stop].sum())


def reachable_fraction(result: PlanResult) -> float:
    """Truly reachable candidates / all candidates the run evaluated (RRT: its tests; q-RRT: its
    database entries).

    Args:
        result: A finished plan (its per-round ``history``).

    Returns:
        The fraction in [0, 1]; 0.0 when the run evaluated no candidate.
    """
    entries = int(result.history["entries"].sum())
    return int(result.history["reachable"].sum()) / entries if entries else 0.0


def dumps(value: Any) -> str:
    """Compact JSON (no spaces) for an array or list stored in one CSV cell.

    Args:
        value: A JSON-able value.

    Returns:
        Its JSON text.
    """
    return json.dumps(value, separators=(",", ":"))


def loads(text: Any) -> Any:
    """Read back a cell written by ``dumps``.

    Args:
        text: The cell: JSON text, or a value ``read_records`` already converted (a number).

    Returns:
        The decoded value (``text`` itself when it is not a string).
    """
    return json.loads(text) if isinstance(text, str) else text


def rounded(points: np.ndarray, digits: int = 3) -> list[Any]:
    """Points rounded for storage in a record.

    Args:
        points: An array of coordinates (any shape).
        digits: Decimal digits kept.

    Returns:
        The rounded array as nested lists of floats.
    """
    return np.round(np.asarray(points, dtype=float), digits).tolist()
