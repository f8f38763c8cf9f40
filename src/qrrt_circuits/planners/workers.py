"""Work one worker does in one round, as module-level functions so any executor (threads,
processes, Dask) can run them. Every task carries its own seeds, so results never depend on which
executor ran it or in what order."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..database import Tree, build_database


@dataclass(frozen=True)
class ExtensionOutcome:
    """One classical RRT extension: the candidate, its parent, the test's answer and the truth."""

    child: np.ndarray
    parent: int
    answer: bool
    truth: bool


def classical_extension(planner, tree: Tree, goal, goal_radius, round_index: int, worker: int):
    """Sample (with goal bias), nearest node, one reachability test (Alg. 1 with a 1-entry database)."""
    rng = planner.rng(round_index, worker, 1)
    db = build_database(tree, 1, planner.env, rng, goal, goal_radius, planner.goal_bias)
    child, parent = db.children[0], int(db.parents[0])
    truth = bool(planner.oracle.reachable(tree.nodes[parent][None], child[None])[0])
    answer = truth
    if planner.oracle_errors is not None:
        answer = bool(planner.oracle_errors.apply(np.array([truth]), planner.rng(round_index, worker, 2))[0])
    return ExtensionOutcome(child, parent, answer, truth)


@dataclass(frozen=True)
class QuantumOutcome:
    """One quantum worker on its own database (unshared Pq-RRT)."""

    child: np.ndarray | None
    parent: int
    verified: bool
    iterations: int
    quantum_calls: int
    verifications: int
    simulation_checks: int
    reachable_entries: int
    observations: tuple[tuple[int, bool], ...]


def unshared_worker(planner, tree: Tree, goal, goal_radius, round_index: int, worker: int,
                    iterations: int | None, h: int) -> QuantumOutcome:
    """Build a database, search it, measure one index and verify it (Alg. 2 run by one worker)."""
    db, truth, marks = planner.make_database(tree, goal, goal_radius, round_index, worker, h)
    index, spent, verifications, observations, used = planner.search_database(
        marks, truth, round_index, worker, shots=1, iterations=iterations)[0]
    verified = index is not None and bool(truth[index])
    return QuantumOutcome(
        child=None if index is None else db.children[index],
        parent=-1 if index is None else int(db.parents[index]),
        verified=verified,
        iterations=used,
        quantum_calls=spent,
        verifications=verifications,
        simulation_checks=truth.shape[0],
        reachable_entries=int(np.count_nonzero(truth)),
        observations=observations,
    )
