"""What a plan returns: the tree, the path, the counters of DESIGN §2, the status and labels."""

from __future__ import annotations

from collections.abc import Callable, KeysView
from dataclasses import asdict, dataclass, field
from typing import IO, TYPE_CHECKING, Any

import numpy as np

from .termination import PlanStatus

if TYPE_CHECKING:
    import networkx as nx


@dataclass(frozen=True)
class Metrics:
    """The counters of DESIGN §2 (readable as attributes or as a mapping).

    ``oracle_calls == quantum_oracle_calls + verification_calls`` always holds;
    ``critical_path_oracle_calls`` sums, over rounds, the largest count of one worker (the time of
    p parallel quantum devices); ``simulation_checks`` are the 2^n predicate evaluations per
    database the simulated phase oracle needs (not oracle calls); ``wasted_checks`` the predicate
    evaluations the batched classical planners made for rounds that never ran (not oracle calls).

    Args:
        oracle_calls: All oracle calls: ``quantum_oracle_calls + verification_calls``.
        quantum_oracle_calls: Phase-oracle queries: k per worker per Grover search of k iterations,
            plus k_i + 1 per amplitude-estimation shot of ``EstimatedOptimal``.
        verification_calls: Classical reachability tests: every RRT test, and every measured
            q-RRT / Pq-RRT candidate verified by the finalizer.
        critical_path_oracle_calls: Sum over rounds of the largest oracle-call count of one worker.
        simulation_checks: Predicate evaluations that build the simulated phase oracle (2^n per
            database); a simulation cost, not oracle calls.
        nodes: Nodes added to the tree (root excluded).
        rounds: Rounds run.
        databases: Databases built (0 for the classical planners).
        duplicates: Verified candidates measured by more than one worker of a shared database and
            added once.
        rejected: Candidates the verification refused (a measured entry that is not reachable, or
            an answer corrupted by the ``OracleErrorModel``).
        wall_time_s: Wall-clock time of the plan in seconds (not reproducible).
        wasted_checks: Predicate evaluations done ahead of time and thrown away (batched RRT:
            candidates of rounds after the round that changed the tree); raw work, never oracle
            calls.

    Example:
        >>> from qrrt_circuits import QRRT, Environment, PaperIterations, Problem, StatevectorBackend
        >>> problem = Problem.build(Environment([[0, 10], [0, 10]], []), [1, 1], [9, 9], 1.0)
        >>> planner = QRRT(backend=StatevectorBackend(seed=0), num_qubits=3, seed=0,
        ...                search_policy=PaperIterations())
        >>> metrics = planner.plan(problem, max_rounds=5).metrics
        >>> metrics.oracle_calls, metrics.quantum_oracle_calls, metrics.verification_calls
        (6, 5, 1)
        >>> metrics["simulation_checks"]  # 2^3 predicate evaluations built the phase oracle
        8
    """

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
    wasted_checks: int = 0

    def as_dict(self) -> dict[str, Any]:
        """The counters as a plain dict (field name to value), in field order.

        Returns:
            A new ``dict`` (JSON-serialisable: ints and one float).
        """
        return asdict(self)

    def __getitem__(self, key: str) -> Any:
        return getattr(self, key)

    def keys(self) -> KeysView[str]:
        """The counter names, in field order (with ``__getitem__``, ``dict(metrics)`` works).

        Returns:
            The keys view of ``as_dict()``.
        """
        return self.as_dict().keys()


@dataclass(frozen=True, eq=False)
class PlanResult:
    """A finished plan: the tree, the path, the counters, why it ended and how it was run.

    What ``Planner.plan`` returns (paper Alg. 1-4). ``settings`` records the planner, the predicate
    (and the dynamics it follows), the problem and the termination condition; ``labels`` every
    simulation shortcut the numbers depend on.

    Args:
        status: A ``PlanStatus``: ``"reached"`` or the name of the termination condition that ended
            the plan.
        nodes: Float (N+1, d), the tree's nodes with the root in row 0.
        parents: Int (N+1,), the parent row of each node; ``parents[0] == -1``.
        path: Float (L, d), the nodes from the root to the goal node, or None if not reached.
        metrics: The ``Metrics`` (oracle calls counted as in DESIGN §2).
        planner: The planner's name (``"RRT"``, ``"ParallelRRT"``, ``"QRRT"``, ``"PQRRT"``, ...).
        settings: JSON-able dict of the planner's settings, the problem and the termination.
        labels: Every simulation shortcut the numbers depend on, as sentences.
        history: Per-round arrays (name to array of one value per round).
        goal_node: The row of the node inside the goal ball, or None if not reached.
        safety_limit: Whether the condition that ended the plan is a safety limit the library
            added (``termination.safety_limits``: a round, stall or node limit the caller did not
            set), not one of the caller's.
        second_tree: A bidirectional planner's second tree (q-RRT-Connect's, rooted in the goal):
            (nodes (M, d), parents (M,)), each edge a motion from the child to its parent; or None.

    Example:
        >>> from qrrt_circuits import QRRT, Environment, PaperIterations, Problem, StatevectorBackend
        >>> problem = Problem.build(Environment([[0, 10], [0, 10]], []), [1, 1], [9, 9], 1.0)
        >>> planner = QRRT(backend=StatevectorBackend(seed=0), num_qubits=3, seed=0,
        ...                search_policy=PaperIterations())
        >>> result = planner.plan(problem, max_rounds=5)
        >>> result.status, result.reached
        (<PlanStatus.REACHED: 'reached'>, True)
        >>> result.nodes.shape, result.parents.tolist(), result.goal_node
        ((2, 2), [-1, 0], 1)
        >>> len(result.path), result.tree.number_of_edges()
        (2, 1)
    """

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
    safety_limit: bool = False
    second_tree: tuple[np.ndarray, np.ndarray] | None = field(default=None, repr=False)

    @property
    def reached(self) -> bool:
        """Whether the goal was reached (``status is PlanStatus.REACHED``)."""
        return self.status is PlanStatus.REACHED

    @property
    def status_text(self) -> str:
        """Why the plan ended, in words; a safety limit is named as one, with the keyword that
        changes it.

        Example:
            >>> from qrrt_circuits import RRT, Environment, Problem
            >>> ring = [[[4, 4], [6, 4.99]], [[4, 5.01], [6, 6]], [[4, 4.99], [4.99, 5.01]], [[5.01, 4.99], [6, 5.01]]]
            >>> problem = Problem.build(Environment([[0, 10], [0, 10]], ring), [5, 5], [9, 9], 0.5)
            >>> result = RRT(seed=0).plan(problem, max_nodes=5)  # the start is walled in
            >>> result.safety_limit, result.status_text[:71]
            (True, 'ended by a safety limit, not one you set: 5000 rounds in a row added no')
        """
        if self.reached:
            return "reached the goal"
        termination = self.settings.get("termination", {})
        key = {PlanStatus.STALLED: "stall_rounds"}.get(self.status, str(self.status))
        limit = termination.get(key)
        what = {PlanStatus.STALLED: f"{limit} rounds in a row added no node",
                PlanStatus.MAX_ROUNDS: f"{limit} rounds ran",
                PlanStatus.MAX_NODES: f"the tree reached {limit} nodes",
                PlanStatus.MAX_ORACLE_CALLS: f"{limit} oracle calls were spent",
                PlanStatus.MAX_CRITICAL_PATH_CALLS: f"{limit} critical-path oracle calls were spent",
                PlanStatus.MAX_TIME: "the time limit passed"}.get(self.status, str(self.status))
        if not self.safety_limit:
            return f"ended by a limit you set: {what} ({key}={limit})"
        return (f"ended by a safety limit, not one you set: {what} ({key}={limit}; pass {key}, or a budget "
                f"such as max_oracle_calls or max_time_s, to change it)")

    @property
    def tree(self) -> nx.DiGraph:
        """The tree as a networkx DiGraph (edges parent -> child, node attribute ``pos``)."""
        import networkx as nx

        graph = nx.DiGraph()
        for index, position in enumerate(self.nodes):
            graph.add_node(index, pos=tuple(position))
        for child, parent in enumerate(self.parents):
            if parent >= 0:
                graph.add_edge(int(parent), child)
        return graph

    def to_dict(self) -> dict:
        """The result as JSON-serialisable data (arrays as nested lists, status as its string).

        Returns:
            A dict with keys ``status``, ``planner``, ``settings``, ``labels``, ``metrics``,
            ``nodes``, ``parents``, ``path``, ``goal_node``, ``safety_limit`` and ``history``.
        """
        return self._data(lambda array: array.tolist())

    def write_json(self, handle: IO[str]) -> None:
        """Write ``to_dict()`` as JSON to ``handle``, its arrays chunk by chunk
        (``json_stream.dump_streamed``: the same value after ``json.load``, written by the C
        encoder, without the whole tree as Python lists; ``qrrt plan --json``'s writer). A numpy
        array that ``to_dict`` leaves as it is (inside ``settings``, which ``json.dumps`` would
        refuse) is written as its ``tolist()``.

        Args:
            handle: A text file open for writing.
        """
        from .._support.json_stream import dump_streamed

        # arrays streamed as they are; anything else with tolist() (a numpy scalar in the history)
        # converted as to_dict converts it
        dump_streamed(self._data(lambda value: value if isinstance(value, np.ndarray) else value.tolist()), handle)

    def _data(self, arrays: Callable[[np.ndarray], Any]) -> dict:
        """``to_dict``'s keys and values, each array passed through ``arrays``."""
        return {
            "status": str(self.status),
            "planner": self.planner,
            "settings": self.settings,
            "labels": list(self.labels),
            "metrics": self.metrics.as_dict(),
            "nodes": arrays(self.nodes),
            "parents": arrays(self.parents),
            "path": None if self.path is None else arrays(self.path),
            "goal_node": self.goal_node,
            "safety_limit": self.safety_limit,
            "history": {key: arrays(value) for key, value in self.history.items()},
        } | ({} if self.second_tree is None else {"second_tree": {"nodes": arrays(self.second_tree[0]),
                                                                  "parents": arrays(self.second_tree[1])}})
