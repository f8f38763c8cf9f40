"""q-RRT-Connect: Kuffner and LaValle's RRT-Connect (ICRA 2000; OMPL's ``RRTConnect``) with a
q-RRT round as each extension and Grover search of the connection.

Two trees, one rooted at the start, one at a goal state; rounds alternate between them. A round
extends its tree by one q-RRT round (paper Algorithm 2: a database of 2^n samples with their nearest
nodes of that tree, steered by ``max_extension``, the phase oracle from the motion predicate,
Grover search by the plan's policy, the classical finalizer). The start tree's edges are motions
from parent to child; the goal tree's from child to parent, so its predicate is asked in reverse
(``Reversed``). When a node x is added, the **connection step** searches the other tree: a database
of its 2^q nodes nearest to x (q = ``connect_qubits``; all of them while that tree is smaller,
padded with unmarked entries to a power of two), an entry marked when the motion between x and it
(from the start side to the goal side) is free. A verified entry connects the trees and ends the
plan: the goal tree's path from the connected node to its root is grafted onto the start tree.

Oracle calls (DESIGN §2, §9): each Grover iteration of an extension or connection search is one
quantum oracle call, each classical check of a measured entry one verification call. The
predicate's evaluations that build the phase oracles (2^n per extension database, one per real
connection candidate) are ``simulation_checks``.

**The connection step's cost** (Lemma 1): with m connecting pairs among the N = 2^q' entries and
k Grover iterations, one search finds a connection with probability P = sin^2((2k+1) theta),
sin^2 theta = m / N, for k + 1 oracle calls; with k = floor(pi / (4 theta)) (Eq. 1) P >= 1 - m/N
for about (pi/4) sqrt(N/m) + 1 calls, where checking the candidates classically in a random order
until the first connecting one costs (N + 1) / (m + 1) checks on average. The search pays when m
is small against N (few connecting pairs among many candidates) and costs k + 1 calls for nothing
when m = 0, which a classical connect attempt toward the nearest node answers with one check.

**Parallel workers.** No Pq variant: the manager/worker form of Algorithm 3 would apply to the
extension (p workers measuring one database, as ``PQRRT``), but the connection step ends the plan
at its first verified entry, so p workers on it only shorten the critical path, by the chance
1 - (1 - P)^p that one of them finds it; that variant is not built.
"""

from __future__ import annotations

import dataclasses
import uuid
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from ..problems.goals import Goal, GoalState, ball_of, check_reachable_by
from ..problems.problem import Problem
from ..reachability.predicate import ReachabilityPredicate, check_answers, valid_states
from ..search.oracles import LookupOracle
from ..search.policies.base import PolicyState
from ..search.problem import DatabaseSearch, SearchOutcome
from .extension import GrowingTree, SearchPlanner, nearest_rows, padded_size
from .options import ConnectOptions, PlannerOptions
from .run_state import RunState
from .tree import Tree

__all__ = ["ConnectionSearch", "QRRTConnect", "Reversed", "connection_search"]

#: goal states drawn to find the goal tree's root where the goal's centre is not valid
GOAL_ROOT_DRAWS = 256


@dataclass(frozen=True)
class Reversed:
    """A predicate asked in reverse: ``reachable(a, b)`` is ``predicate.reachable(b, a)`` (the goal
    tree's edges are motions from a child to its parent)."""

    predicate: ReachabilityPredicate

    @property
    def dim(self) -> int:
        return int(self.predicate.dim)

    @property
    def name(self) -> str:
        return str(self.predicate.name)

    def reachable(self, parents: np.ndarray, children: np.ndarray) -> np.ndarray:
        return self.predicate.reachable(children, parents)

    def describe(self) -> dict:
        return self.predicate.describe()


@dataclass(frozen=True)
class ConnectionSearch:
    """One connection step's database and search.

    Args:
        rows: Int (count,), the other tree's candidate nodes, nearest first.
        truth: Bool (N,), N = ``padded_size(count)``: whether the motion between the new node and
            each candidate is free (padding entries False).
        outcome: The policy's ``SearchOutcome`` (one worker).
    """

    rows: np.ndarray
    truth: np.ndarray
    outcome: SearchOutcome

    @property
    def connected(self) -> int | None:
        """The other tree's node the search connected to, or None."""
        index = self.outcome.index
        return None if index is None else int(self.rows[index])


def connection_search(grower: GrowingTree, other: GrowingTree, node: int, most: int, policy_state: PolicyState,
                      round_index: int, worker: int = 1) -> ConnectionSearch:
    """The connection step from ``grower``'s node ``node`` to ``other`` (module docstring).

    The database holds ``other``'s min(``most``, its size) nodes nearest to the node, padded with
    unmarked entries to N = ``padded_size(count)``; an entry is marked when
    ``grower.context.predicate.reachable(node, candidate)`` (the grower's predicate answers in its
    tree's direction: from the start side to the goal side). The search is the policy's
    (``PolicyState.run``, one worker) on the ``DatabaseSearch`` of these marks, seeded from the
    plan's streams at (``round_index``, ``worker``).

    Args:
        grower: The tree the node was added to.
        other: The other tree.
        node: The new node's index in ``grower.tree``.
        most: The most candidates, 2^q.
        policy_state: The policy state of connection databases of this size.
        round_index: The round (the seeds' key).
        worker: The worker key of the seeds (default 1).

    Returns:
        The ``ConnectionSearch``.
    """
    context = grower.context
    point = grower.tree.nodes[node]
    count = min(most, other.tree.size)
    rows = nearest_rows(context.space, other.tree.nodes, point, count)
    truth = np.zeros(padded_size(count), dtype=bool)
    truth[:count] = check_answers(context.predicate.reachable(np.repeat(point[None, :], count, axis=0),
                                                              other.tree.nodes[rows]), count,
                                  f"the predicate {context.predicate.name!r}")
    problem = DatabaseSearch(LookupOracle(truth), truth, context.search_backend, context.streams, round_index, worker)
    outcome = policy_state.run(problem, 1, grower.tree.size - 1)[0]
    policy_state.learn([(outcome,)])
    return ConnectionSearch(rows, truth, outcome)


@dataclass
class ConnectTrees:
    """What q-RRT-Connect's rounds carry: the start tree and the goal tree (``GrowingTree``), the
    policy states of the connection databases by size, and the most candidates of one."""

    start: GrowingTree
    goal: GrowingTree
    connection_states: dict[int, PolicyState]
    most: int

    def connection_state(self, size: int, make: Any) -> PolicyState:
        """The policy state of connection databases of ``size`` entries (a new one the first time)."""
        if size not in self.connection_states:
            self.connection_states[size] = make(size)
        return self.connection_states[size]


class QRRTConnect(SearchPlanner):
    """q-RRT-Connect (module docstring): two trees, q-RRT extensions, a Grover-searched connection.

    Its options are ``ConnectOptions`` (``backend``, ``num_qubits``, ``search_policy``,
    ``connect_qubits`` and what every planner takes); the goal must give a goal state: its centre
    (``GoalBall``, ``GoalState``) if valid, else one of its ``sample`` draws. The result's tree is
    the start tree with the connected goal-tree path grafted on (every edge a motion from parent to
    child); ``second_tree`` holds the goal tree. ``goal_bias`` draws the start tree's samples in the
    goal and the goal tree's at the start. An ``oracle_errors`` model corrupts the extension
    databases' marks; the connection oracle is exact.
    """

    name = "QRRTConnect"
    Options: ClassVar[type[PlannerOptions]] = ConnectOptions

    @property
    def connect_qubits(self) -> int:
        """q: a connection database holds at most 2^q candidates."""
        value = self.options.connect_qubits
        return self.num_qubits if value is None else int(value)

    def _check_goal(self, problem: Problem) -> None:
        """A goal without volume serves (the goal tree is rooted in it); one drawn from where
        ``goal_bias > 0`` must have ``sample`` (``check_reachable_by``)."""
        if self.options.goal_bias > 0:
            check_reachable_by(problem.goal, self.options.goal_bias)

    def _check_serves(self, problem: Problem) -> None:
        """Refuse a goal without a goal state (``_goal_root``), before any work."""
        self._goal_root(problem.goal, problem.predicate)

    def _goal_root(self, goal: Goal, predicate: ReachabilityPredicate) -> np.ndarray:
        """The goal tree's root: the goal's centre if it satisfies the goal and is valid, else the
        first valid of ``GOAL_ROOT_DRAWS`` draws of its ``sample``."""
        ball = ball_of(goal)
        candidates = [ball[0][None, :]] if ball is not None else []
        sample = getattr(goal, "sample", None)
        if sample is not None:
            candidates.append(np.asarray(sample(GOAL_ROOT_DRAWS, self.rng(0, 2)), dtype=float))
        if not candidates:
            raise TypeError(f"{self.name} needs a goal state: a goal with a centre or sample(count, rng), got "
                            f"{type(goal).__name__}")
        points = np.concatenate(candidates)
        good = valid_states(predicate, points) & np.asarray(goal.is_satisfied(points), dtype=bool)
        if not good.any():
            raise ValueError(f"{self.name} found no valid goal state (the goal's centre and {GOAL_ROOT_DRAWS} draws "
                             "of its sample are invalid)")
        return points[int(np.argmax(good))]

    def _start_rounds(self, state: RunState) -> None:
        """The two trees: the plan's tree (the start tree) and a goal tree at ``_goal_root``."""
        context = state.worker_context
        policy = self.search_policy
        size = self.database_size
        start = GrowingTree(state.tree, state.neighbors, context, state.goal, policy.start(size),
                            lambda children, parents: self._add_start(state, children, parents))
        root = self._goal_root(state.goal, context.predicate)
        goal_tree = Tree(root)
        neighbors = context.space.nearest_neighbors()
        neighbors.add(goal_tree.nodes)
        reverse = dataclasses.replace(context, predicate=Reversed(context.predicate), token=uuid.uuid4().hex)
        start_state = GoalState(state.tree.nodes[0], 1e-9)
        goal = GrowingTree(goal_tree, neighbors, reverse, start_state, policy.start(size),
                           lambda children, parents: _add(goal_tree, neighbors, children, parents))
        state.extra = ConnectTrees(start, goal, {}, 1 << self.connect_qubits)

    @staticmethod
    def _add_start(state: RunState, children: np.ndarray, parents: np.ndarray) -> int:
        first = state.tree.size
        state.add_nodes(children, parents)
        return first

    def _round(self, state: RunState) -> None:
        """Extend one tree (the start tree in even rounds), then search the connection from its new node."""
        trees: ConnectTrees = state.extra
        grower, other = (trees.start, trees.goal) if state.rounds % 2 == 0 else (trees.goal, trees.start)
        node = self._extend(state, grower)
        if node is None or state.goal_node is not None:
            return
        size = padded_size(min(trees.most, other.tree.size))
        found = connection_search(grower, other, node, trees.most,
                                  trees.connection_state(size, self.search_policy.start), state.rounds)
        outcome = found.outcome
        state.databases += 1
        state.simulation_checks += found.rows.shape[0]
        state.quantum_calls += outcome.quantum_calls
        state.verification_calls += outcome.verifications
        state.rejected += outcome.rejected
        state.critical_path += outcome.oracle_calls
        connected = found.connected
        if connected is None:
            return
        start_node, goal_node = (node, connected) if grower is trees.start else (connected, node)
        self._graft(state, trees.goal.tree, start_node, goal_node)

    @staticmethod
    def _graft(state: RunState, goal_tree: Tree, start_node: int, goal_node: int) -> None:
        """Append the goal tree's path from ``goal_node`` to its root to the start tree below
        ``start_node`` (each goal-tree edge child -> parent is a verified motion)."""
        previous, node = start_node, goal_node
        while node >= 0 and state.goal_node is None:
            previous = state.add_node(goal_tree.nodes[node], previous)
            node = int(goal_tree.parents[node])

    def _second_tree(self, state: RunState) -> tuple[np.ndarray, np.ndarray] | None:
        trees: ConnectTrees = state.extra
        return trees.goal.tree.nodes.copy(), trees.goal.tree.parents.copy()

    def settings(self) -> dict:
        return super().settings() | {"connect_qubits": self.connect_qubits}

    def labels(self) -> tuple[str, ...]:
        """The extension's labels and the lookup behind the connection oracle."""
        return (*super().labels(),
                "simulation: the connection oracle is built from a classical lookup of the motion to each of the "
                "other tree's 2^q nearest nodes (reported as simulation_checks, not as oracle calls)")


def _add(tree: Tree, neighbors: Any, children: np.ndarray, parents: np.ndarray) -> int:
    first = tree.add_many(children, parents)
    neighbors.add(children)
    return first
