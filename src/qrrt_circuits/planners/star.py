"""q-RRT*: Karaman and Frazzoli's RRT* (IJRR 2011; OMPL's ``RRTstar`` with its default k-nearest
near set) with a q-RRT round as the extension, Dürr-Høyer minimum finding as the choice of parent
and a Grover search for all improving rewires.

A round: (1) extend the tree by one q-RRT round (paper Algorithm 2; ``SearchPlanner._extend``),
which adds x_new below its nearest node; (2) the near set: the k = ceil(r e (1 + 1/d) ln(n + 1))
nodes nearest to x_new (r = ``rewire_factor``, n the tree's nodes; OMPL's ``k_rrt``); (3) choose
the parent: Dürr-Høyer minimum finding (``search.minimum_finding``) over the near set of the cost
c(v) + |v x_new|, an entry qualifying when the motion v -> x_new is free and its cost is below the
threshold, the threshold starting at the nearest node's (already verified); (4) rewire: a search for
all near nodes v with a free motion x_new -> v and c(x_new) + |x_new v| < c(v)
(``search.all_marked``: about 2 c sqrt(N M) + cap sqrt(N) calls for M improving among N, against N
classical checks), each found node reparented to x_new and the change of its cost carried to its
descendants. Costs are path lengths under the space's metric; after every round every node's cost
is the sum of its edges' lengths to the root, and the tree has no cycle (a rewire needs a strictly
lower cost, which an ancestor of x_new cannot get through it).

The plan is anytime: it runs until its termination condition and reports the best path to the goal
found (``status`` "reached" if there is one); ``history["path_cost"]`` is the best path's cost after
each round (NaN before the first), against ``history["oracle_calls"]``.

Oracle calls (DESIGN §2, §9): each Grover iteration of any search is one quantum oracle call (the
choose-parent and rewire oracles evaluate the predicate and a cost comparison coherently: one call);
each classical check of a measured entry (the predicate, and the cost comparison) one verification
call. The predicate's evaluations that build the phase oracles, and the classical lookup of costs
behind the choose-parent and rewire oracles, are simulation work (``simulation_checks`` counts the
predicate's), labelled in every result.

**Parallel workers.** No Pq variant: the choose-parent step is a sequence of threshold searches,
each depending on the last, and the rewire step's searches each remove what the one before found,
so the manager/worker form of Algorithm 3 (independent workers measuring one database) does not
apply to them; it applies to the extension alone, as in ``PQRRT``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from .._support.randomness import Stream
from ..problems.goals import first_satisfying
from ..reachability.predicate import check_answers
from ..search.all_marked import find_all_marked
from ..search.minimum_finding import DurrHoyer
from .extension import GrowingTree, SearchPlanner, nearest_rows, padded_size
from .options import PlannerOptions, StarOptions
from .run_state import RunState
from .termination import PlanStatus

__all__ = ["QRRTStar", "StarTree", "near_count"]


def near_count(rewire_factor: float, dim: int, nodes: int) -> int:
    """OMPL's k-nearest RRT* near-set size: ceil(r e (1 + 1/d) ln(n + 1)).

    Args:
        rewire_factor: r.
        dim: d.
        nodes: n, the tree's nodes.

    Returns:
        k >= 1.
    """
    return max(1, int(math.ceil(rewire_factor * math.e * (1.0 + 1.0 / dim) * math.log(nodes + 1))))


@dataclass
class StarTree:
    """q-RRT*'s bookkeeping beside the tree: each node's cost, its children, and the nodes that
    satisfy the goal."""

    grower: GrowingTree
    costs: list[float] = field(default_factory=lambda: [0.0])
    children: list[list[int]] = field(default_factory=lambda: [[]])
    goal_nodes: list[int] = field(default_factory=list)

    def added(self, state: RunState, first: int) -> None:
        """Record nodes ``first ..`` the tree just got: their costs, children and goal membership."""
        tree = state.tree
        space = self.grower.context.space
        for node in range(first, tree.size):
            parent = int(tree.parents[node])
            step = float(space.distance(tree.nodes[parent][None, :], tree.nodes[node])[0])
            self.costs.append(self.costs[parent] + step)
            self.children.append([])
            self.children[parent].append(node)
            if first_satisfying(state.goal, tree.nodes[node][None, :]) == 0:
                self.goal_nodes.append(node)

    def reparent(self, state: RunState, node: int, parent: int, cost: float) -> None:
        """Make ``parent`` the parent of ``node`` at cost ``cost``, and move every descendant's cost
        by the same change."""
        old = int(state.tree.parents[node])
        self.children[old].remove(node)
        self.children[parent].append(node)
        state.tree.reparent(node, parent)
        change = cost - self.costs[node]
        stack = [node]
        while stack:
            current = stack.pop()
            self.costs[current] += change
            stack.extend(self.children[current])

    def best_goal_node(self) -> int | None:
        """The goal node of least cost, or None."""
        if not self.goal_nodes:
            return None
        return min(self.goal_nodes, key=lambda node: self.costs[node])


class QRRTStar(SearchPlanner):
    """q-RRT* (module docstring): q-RRT extensions, Dürr-Høyer choice of parent, a search for all
    improving rewires; anytime.

    Its options are ``StarOptions`` (``backend``, ``num_qubits``, ``search_policy``,
    ``rewire_factor`` and what every planner takes). The extension's search follows
    ``search_policy``; the choice of parent and the rewire search with ``BBHT`` (unknown numbers of
    marked entries), as Dürr and Høyer's algorithm does. An ``oracle_errors`` model corrupts the
    extension databases' marks; the choose-parent and rewire oracles are exact.
    """

    name = "QRRTStar"
    Options: ClassVar[type[PlannerOptions]] = StarOptions
    #: the minimum finding of the choice of parent
    minimum = DurrHoyer(below_threshold_only=True)

    def _start_rounds(self, state: RunState) -> None:
        context = state.worker_context
        grower = GrowingTree(state.tree, state.neighbors, context, state.goal,
                             self.search_policy.start(self.database_size), lambda c, p: self._add(state, c, p))
        state.extra = StarTree(grower)
        state.history["path_cost"] = []
        if state.goal_node is not None:
            state.extra.goal_nodes.append(0)

    @staticmethod
    def _add(state: RunState, children: np.ndarray, parents: np.ndarray) -> int:
        first = state.tree.size
        state.add_nodes(children, parents)
        state.extra.added(state, first)
        return first

    def _finished(self, state: RunState) -> bool:
        """Never before the condition: q-RRT* is anytime."""
        return False

    def _status(self, state: RunState, ended: PlanStatus) -> PlanStatus:
        """"reached" if the plan holds a path to the goal, else the condition that ended it."""
        return PlanStatus.REACHED if state.goal_node is not None else ended

    def _round(self, state: RunState) -> None:
        star: StarTree = state.extra
        node = self._extend(state, star.grower)
        if node is not None:
            near = self._near(state, node)
            if near.shape[0] > 1:
                self._choose_parent(state, star, node, near)
                self._rewire(state, star, node, near)
        state.goal_node = star.best_goal_node()
        state.history["path_cost"].append(math.nan if state.goal_node is None else star.costs[state.goal_node])

    def _near(self, state: RunState, node: int) -> np.ndarray:
        """The near set of ``node``: its k nearest other nodes (``near_count``), nearest first."""
        count = min(node, near_count(self.options.rewire_factor, state.tree.dim, state.tree.size - 1))
        return nearest_rows(state.worker_context.space, state.tree.nodes[:node], state.tree.nodes[node], count)

    def _choose_parent(self, state: RunState, star: StarTree, node: int, near: np.ndarray) -> None:
        """Dürr-Høyer over the near set: the feasible entry of least cost-to-come through it."""
        context = state.worker_context
        tree = state.tree
        point = tree.nodes[node]
        count = near.shape[0]
        size = padded_size(count)
        feasible = np.zeros(size, dtype=bool)
        answers = context.predicate.reachable(tree.nodes[near], np.repeat(point[None], count, 0))
        feasible[:count] = check_answers(answers, count, f"the predicate {context.predicate.name!r}")
        values = np.full(size, math.inf)
        steps = context.space.distance(tree.nodes[near], point)
        values[:count] = np.asarray(star.costs, dtype=float)[near] + steps
        parent = int(tree.parents[node])
        start = np.flatnonzero(near == parent)
        outcome = self.minimum.run(values, feasible, context.search_backend,
                                   context.streams.generator(state.rounds, 1, Stream.POLICY),
                                   int(start[0]) if start.size else None)
        self._count(state, count, outcome.quantum_calls, outcome.verifications)
        if outcome.index is not None and int(near[outcome.index]) != parent and \
                values[outcome.index] < star.costs[node]:
            star.reparent(state, node, int(near[outcome.index]), float(values[outcome.index]))

    def _rewire(self, state: RunState, star: StarTree, node: int, near: np.ndarray) -> None:
        """Search for every near node whose cost falls through ``node``, and reparent them."""
        context = state.worker_context
        tree = state.tree
        point = tree.nodes[node]
        near = near[near != int(tree.parents[node])]
        count = near.shape[0]
        if count == 0:
            return
        costs = np.asarray(star.costs, dtype=float)
        through = star.costs[node] + context.space.distance(tree.nodes[near], point)
        improving = through < costs[near]  # (the costs are classical data: only these can be marked)
        near, count = near[improving], int(np.count_nonzero(improving))
        if count == 0:
            return
        marks = np.zeros(padded_size(count), dtype=bool)
        marks[:count] = check_answers(context.predicate.reachable(np.repeat(point[None], count, 0), tree.nodes[near]),
                                      count, f"the predicate {context.predicate.name!r}")
        outcome = find_all_marked(marks, context.search_backend,
                                  context.streams.generator(state.rounds, 2, Stream.POLICY), self.minimum.search)
        self._count(state, count, outcome.quantum_calls, outcome.verifications)
        for index in outcome.indices:
            neighbour = int(near[index])
            cost = star.costs[node] + float(context.space.distance(tree.nodes[neighbour][None], point)[0])
            if cost < star.costs[neighbour]:  # (a rewire found before it in this round may have lowered it)
                star.reparent(state, neighbour, node, cost)

    @staticmethod
    def _count(state: RunState, entries: int, quantum: int, verifications: int) -> None:
        state.databases += 1
        state.simulation_checks += entries
        state.quantum_calls += quantum
        state.verification_calls += verifications
        state.critical_path += quantum + verifications

    def settings(self) -> dict:
        return super().settings() | {"minimum_finding": self.minimum.describe()}

    def labels(self) -> tuple[str, ...]:
        """The extension's labels and the lookups behind the choose-parent and rewire oracles."""
        return (*super().labels(),
                "simulation: the choose-parent and rewire oracles are built from a classical lookup of the motion "
                "to or from every near node and of the nodes' costs (the predicate's evaluations reported as "
                "simulation_checks, not as oracle calls)")
