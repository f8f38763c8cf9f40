"""What every planner shares: the round loop, budgets, validation, metrics and the result.

Oracle calls are counted as DESIGN §2 says: classical planners 1 per reachability test; quantum
planners 1 per Grover iteration per worker plus 1 per classical verification of a measured
candidate. Every classical check of one candidate (the finalizer of the quantum planners, the
reachability test of the classical ones) is a ``verification_call``, so
``oracle_calls == quantum_oracle_calls + verification_calls`` for every planner. Evaluating all 2^n
entries to build the phase oracle in simulation is reported as ``simulation_checks``, not as oracle
calls.

Budgets are checked before each round: a round starts only while no budget is reached, so the
last round may overshoot ``max_oracle_calls`` by less than one round's cost and ``max_nodes`` by
fewer than ``workers`` nodes (the paper's cut-offs behave the same way). With no budget at all,
``DEFAULT_MAX_ROUNDS`` applies.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field
from typing import Any

import networkx as nx
import numpy as np

from ..database import Tree
from ..dynamics import LinearTrackingDynamics
from ..environment import Environment
from ..oracle import OracleErrorModel, ReachabilityOracle

DEFAULT_MAX_ROUNDS = 20000


@dataclass(frozen=True)
class Metrics:
    """The counters of DESIGN §2 (readable as attributes or as a mapping)."""

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

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)

    def __getitem__(self, key: str) -> Any:
        return getattr(self, key)

    def keys(self):
        return self.as_dict().keys()


@dataclass(frozen=True, eq=False)
class PlanResult:
    """A finished plan: the tree, the path (if reached), metrics and labels."""

    status: str
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
            "status": self.status,
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


class RunState:
    """Mutable bookkeeping for one ``plan`` call."""

    def __init__(self, root: np.ndarray, goal: np.ndarray, goal_radius: float) -> None:
        self.tree = Tree(root)
        self.goal = goal
        self.goal_radius = goal_radius
        self.goal_node: int | None = None
        self.rounds = 0
        self.quantum_calls = 0
        self.verification_calls = 0
        self.critical_path = 0
        self.simulation_checks = 0
        self.databases = 0
        self.duplicates = 0
        self.rejected = 0
        self.history: dict[str, list] = {"oracle_calls": [], "critical_path": [], "nodes": [],
                                         "entries": [], "reachable": []}
        self.round_entries = 0
        self.round_reachable = 0

    @property
    def oracle_calls(self) -> int:
        return self.quantum_calls + self.verification_calls

    def add_node(self, position: np.ndarray, parent: int) -> int:
        index = self.tree.add(position, parent)
        if self.goal_node is None and np.linalg.norm(position - self.goal) <= self.goal_radius:
            self.goal_node = index
        return index


def _check_count(value, name: str, minimum: int = 1) -> int:
    if isinstance(value, bool) or int(value) != value or value < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(value)


class Planner:
    """Base planner: validates the problem, runs rounds until the goal or a budget, reports."""

    name = "planner"

    def __init__(
        self,
        env: Environment,
        dynamics: LinearTrackingDynamics | None = None,
        oracle_errors: OracleErrorModel | None = None,
        goal_bias: float = 0.0,
        resolution: float = 0.01,
        seed: int | None = None,
        oracle: ReachabilityOracle | None = None,
    ) -> None:
        if not isinstance(env, Environment):
            raise ValueError(f"env must be an Environment, got {type(env).__name__}")
        if oracle is not None:
            if not isinstance(oracle, ReachabilityOracle) or oracle.env is not env:
                raise ValueError("oracle must be a ReachabilityOracle built on this planner's environment")
            if dynamics is not None and dynamics is not oracle.dynamics:
                raise ValueError("give dynamics= or oracle=, not both (the oracle carries its dynamics)")
            dynamics = oracle.dynamics
        dynamics = LinearTrackingDynamics.paper() if dynamics is None else dynamics
        if dynamics.dim != env.dim:
            raise ValueError(
                f"dimension mismatch: the dynamics act in d = {dynamics.dim}, the environment has "
                f"d = {env.dim}"
            )
        if not (0.0 <= float(goal_bias) < 1.0):
            raise ValueError(f"goal_bias must be in [0, 1), got {goal_bias}")
        if oracle_errors is not None and not isinstance(oracle_errors, OracleErrorModel):
            raise ValueError("oracle_errors must be an OracleErrorModel or None")
        if seed is not None and (isinstance(seed, bool) or int(seed) != seed or seed < 0):
            raise ValueError(f"seed must be a non-negative integer or None, got {seed!r}")
        self.env = env
        self.dynamics = dynamics
        self.oracle = oracle if oracle is not None else ReachabilityOracle(env, dynamics, resolution=resolution)
        self.oracle_errors = oracle_errors
        self.goal_bias = float(goal_bias)
        self.seed = seed
        self._entropy = np.random.SeedSequence(seed).entropy

    def __getstate__(self) -> dict:
        """Planners travel to worker processes with their tasks; the executor stays behind."""
        state = self.__dict__.copy()
        state["executor"] = None
        return state

    # ----------------------------------------------------------------- randomness
    def rng(self, round_index: int, worker: int = 0, stream: int = 0) -> np.random.Generator:
        """The generator of one (round, worker, purpose): independent of call order and executor."""
        sequence = np.random.SeedSequence(self._entropy, spawn_key=(round_index, worker, stream))
        return np.random.default_rng(sequence)

    def call_seed(self, round_index: int, worker: int = 0, stream: int = 7) -> int:
        return int(self.rng(round_index, worker, stream).integers(0, 2**62))

    # ----------------------------------------------------------------- planning
    def plan(
        self,
        start: np.ndarray | None = None,
        goal: np.ndarray | None = None,
        goal_radius: float | None = None,
        max_oracle_calls: int | None = None,
        max_nodes: int | None = None,
        max_rounds: int | None = None,
        max_time_s: float | None = None,
    ) -> PlanResult:
        """Grow a tree from ``start`` until a node lands within ``goal_radius`` of ``goal`` or a
        budget is reached. ``start``, ``goal`` and ``goal_radius`` default to the environment's."""
        start, goal, goal_radius = self._check_problem(start, goal, goal_radius)
        budgets = {
            "max_oracle_calls": (
                None if max_oracle_calls is None else _check_count(max_oracle_calls, "max_oracle_calls")
            ),
            "max_nodes": None if max_nodes is None else _check_count(max_nodes, "max_nodes"),
            "max_rounds": None if max_rounds is None else _check_count(max_rounds, "max_rounds"),
            "max_time_s": None,
        }
        if max_time_s is not None:
            if not (math.isfinite(max_time_s) and max_time_s > 0):
                raise ValueError(f"max_time_s must be a finite number > 0, got {max_time_s}")
            budgets["max_time_s"] = float(max_time_s)
        if all(value is None for value in budgets.values()):
            budgets["max_rounds"] = DEFAULT_MAX_ROUNDS
        self._check_ready()
        state = RunState(start, goal, goal_radius)
        state.policy_state = self._start_policy()
        began = time.perf_counter()
        while state.goal_node is None:
            if self._budget_reached(state, budgets, time.perf_counter() - began):
                break
            self._round(state)
            state.rounds += 1
            state.history["oracle_calls"].append(state.oracle_calls)
            state.history["critical_path"].append(state.critical_path)
            state.history["nodes"].append(state.tree.size - 1)
            state.history["entries"].append(state.round_entries)
            state.history["reachable"].append(state.round_reachable)
            state.round_entries = state.round_reachable = 0
        elapsed = time.perf_counter() - began
        return self._result(state, elapsed, start, goal, goal_radius, budgets)

    def _budget_reached(self, state: RunState, budgets: dict, elapsed: float) -> bool:
        return (
            (budgets["max_oracle_calls"] is not None and state.oracle_calls >= budgets["max_oracle_calls"])
            or (budgets["max_nodes"] is not None and state.tree.size - 1 >= budgets["max_nodes"])
            or (budgets["max_rounds"] is not None and state.rounds >= budgets["max_rounds"])
            or (budgets["max_time_s"] is not None and elapsed >= budgets["max_time_s"])
        )

    def _check_problem(self, start, goal, goal_radius):
        env = self.env
        start = env.start if start is None else start
        goal = env.goal if goal is None else goal
        goal_radius = env.goal_radius if goal_radius is None else goal_radius
        if start is None or goal is None or goal_radius is None:
            raise ValueError("start, goal and goal_radius are required (the environment sets none)")
        checked = []
        for name, point in (("start", start), ("goal", goal)):
            point = np.asarray(point, dtype=float).reshape(-1)
            if point.shape != (env.dim,):
                raise ValueError(
                    f"dimension mismatch: {name} has {point.shape[0]} coordinates, the environment "
                    f"has d = {env.dim}"
                )
            if not np.all(np.isfinite(point)):
                raise ValueError(f"{name} must be finite, got {point.tolist()}")
            if not env.in_bounds(point):
                raise ValueError(f"{name} {point.tolist()} is out of bounds {env.bounds.tolist()}")
            if not env.is_free(point):
                raise ValueError(f"{name} {point.tolist()} is in collision with an obstacle")
            checked.append(point)
        goal_radius = float(goal_radius)
        if not (math.isfinite(goal_radius) and goal_radius > 0):
            raise ValueError(f"goal_radius must be a finite number > 0, got {goal_radius}")
        return checked[0], checked[1], goal_radius

    def _check_ready(self) -> None:
        """Subclasses validate their own settings before any work."""

    def _start_policy(self):
        return None

    def _round(self, state: RunState) -> None:
        raise NotImplementedError

    # ----------------------------------------------------------------- reporting
    def settings(self) -> dict:
        return {"planner": self.name, "seed": self.seed, "goal_bias": self.goal_bias,
                "resolution": self.oracle.resolution, "check": self.oracle.check,
                "oracle_errors": None if self.oracle_errors is None else {
                    "false_positive": self.oracle_errors.false_positive,
                    "false_negative": self.oracle_errors.false_negative}}

    def labels(self) -> tuple[str, ...]:
        return ()

    def _result(self, state, elapsed, start, goal, goal_radius, budgets) -> PlanResult:
        tree = state.tree
        path = None
        if state.goal_node is not None:
            chain = [state.goal_node]
            while tree.parents[chain[-1]] >= 0:
                chain.append(int(tree.parents[chain[-1]]))
            path = tree.nodes[chain[::-1]].copy()
        metrics = Metrics(
            oracle_calls=state.oracle_calls,
            quantum_oracle_calls=state.quantum_calls,
            verification_calls=state.verification_calls,
            critical_path_oracle_calls=state.critical_path,
            simulation_checks=state.simulation_checks,
            nodes=tree.size - 1,
            rounds=state.rounds,
            databases=state.databases,
            duplicates=state.duplicates,
            rejected=state.rejected,
            wall_time_s=elapsed,
        )
        settings = self.settings() | {"start": start.tolist(), "goal": goal.tolist(),
                                      "goal_radius": goal_radius, "budgets": budgets,
                                      "environment": self.env.name}
        history = {key: np.asarray(value, dtype=np.int64) for key, value in state.history.items()}
        return PlanResult(
            status="reached" if state.goal_node is not None else "budget_exhausted",
            nodes=tree.nodes.copy(),
            parents=tree.parents.copy(),
            path=path,
            metrics=metrics,
            planner=self.name,
            settings=settings,
            labels=self.labels(),
            history=history,
            goal_node=state.goal_node,
        )
