"""OMPL's geometric RRT with our closed-loop reachability check, for a time-per-node comparison.

    python benchmarks/ompl_rrt.py      (needs the ``ompl`` Python bindings, OMPL >= 2.0)

``run_ompl_rrt`` grows ``ompl.geometric.RRT`` on an ``Environment`` whose motion validator is our
``ExactCheck``: ``checkMotion(s1, s2)`` is ``oracle.reachable(s1, s2)`` for the directed
closed-loop trajectory parent s1 -> child s2, and the state validity checker is ``env.is_free``. It
stops when the tree has ``max_nodes`` nodes besides the root (counted as successful motion checks:
RRT adds a node exactly when ``checkMotion`` succeeds) or a node lands within ``goal_radius`` of the
goal. The comparison with our ``qrrt_circuits.RRT`` is of wall time per tree node; the oracle is
the same, called once per pair from Python in both. Caveats:

* OMPL samples, finds nearest nodes (GNAT) and keeps its tree in C++ with its own RNG, so trees,
  acceptance rates and node counts differ from ours even on the same world; compare rates, not runs.
* Each ``checkMotion`` crosses C++ -> Python (nanobind), which costs a little extra per check.
* RRT's range is set to the workspace diagonal by default, so the sample is proposed unchanged
  (no steering step), as in our RRT. OMPL's goal bias (0.05) proposes the goal state itself, while
  ours draws from the goal ball; OMPL samples the full box (obstacles ignored), as ours does.
* RRT only calls the two-argument ``checkMotion``; the ``lastValid`` overload is not bound in the
  OMPL 2.0 Python API and is not needed.
* OMPL ignores seed 0, so OMPL's global seed is ``seed + 1``; it is reset on every call, so a
  seed gives the same tree in any process and call order (the wall time varies, of course).
"""

from __future__ import annotations

import time

import numpy as np

from qrrt_circuits import Environment, ExactCheck, LinearTrackingDynamics


def ompl_available() -> bool:
    """True if the ``ompl`` Python bindings import."""
    try:
        from ompl import base, geometric, util  # noqa: F401
    except ImportError:
        return False
    return True


def run_ompl_rrt(env: Environment, start: np.ndarray, goal: np.ndarray, goal_radius: float,
                 max_nodes: int, seed: int, range_: float | None = None,
                 dynamics: LinearTrackingDynamics | None = None, *,
                 return_edges: bool = False) -> dict:
    """Grow OMPL's RRT from ``start`` until ``max_nodes`` nodes or the goal ball is reached.

    Returns {"reached", "nodes" (excluding the root), "motion_checks", "time_s" (wall time of
    ``solve``), "ms_per_node"}; with ``return_edges`` also "edges": (nodes, 2, d) parent/child
    positions of every tree edge, read back from ``ob.PlannerData``.
    """
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    if int(max_nodes) < 1 or int(seed) < 0:
        raise ValueError(f"need max_nodes >= 1 and seed >= 0, got {max_nodes} and {seed}")
    d = env.dim
    oracle = ExactCheck(env, dynamics)
    start, goal = np.asarray(start, dtype=float), np.asarray(goal, dtype=float)
    oracle.reachable(start[None], start[None])  # load the compiled check before timing

    ou.setLogLevel(ou.LogLevel.LOG_NONE)  # setSeed complains when RNGs already exist
    ou.RNG.setSeed(int(seed) + 1)
    ou.setLogLevel(ou.LogLevel.LOG_WARN)

    from qrrt_circuits.adapters.ompl import environment_space_information

    si = environment_space_information(env)
    space = si.getStateSpace()

    class Validator(ob.MotionValidator):
        """Directed closed-loop motion s1 (parent) -> s2 (child) checked by our oracle."""

        def __init__(self, info: ob.SpaceInformation) -> None:
            super().__init__(info)
            self.calls = 0
            self.valid = 0

        def checkMotion(self, s1: ob.State, s2: ob.State) -> bool:  # noqa: N802 (OMPL's name)
            self.calls += 1
            ok = bool(oracle.reachable(np.array(s1[0:d]), np.array(s2[0:d]))[0])
            self.valid += ok
            return ok

    validator = Validator(si)
    si.setMotionValidator(validator)
    si.setup()

    def state(point: np.ndarray) -> ob.State:
        s = space.allocState()
        for axis in range(d):
            s[axis] = float(point[axis])
        return s

    pdef = ob.ProblemDefinition(si)
    pdef.addStartState(state(start))
    region = ob.GoalState(si)
    region.setState(state(goal))
    region.setThreshold(float(goal_radius))
    pdef.setGoal(region)

    planner = og.RRT(si)
    diagonal = float(np.linalg.norm(env.bounds[:, 1] - env.bounds[:, 0]))
    planner.setRange(diagonal if range_ is None else float(range_))
    planner.setGoalBias(0.05)
    planner.setProblemDefinition(pdef)
    planner.setup()
    stop = ob.PlannerTerminationCondition(lambda: validator.valid >= max_nodes)

    began = time.perf_counter()
    planner.solve(stop)
    elapsed = time.perf_counter() - began

    nodes = validator.valid
    result = {"reached": bool(pdef.hasExactSolution()), "nodes": nodes,
              "motion_checks": validator.calls, "time_s": elapsed,
              "ms_per_node": 1000.0 * elapsed / nodes if nodes else float("nan")}
    if return_edges:
        data = ob.PlannerData(si)
        planner.getPlannerData(data)
        point = [np.array(data.getVertex(v).getState()[0:d]) for v in range(data.numVertices())]
        pairs = [(point[v], point[w]) for v in range(data.numVertices()) for w in data.getEdges(v)]
        result["edges"] = np.array(pairs).reshape(-1, 2, d)
    return result


if __name__ == "__main__":
    from qrrt_circuits.problems import scenarios

    print(f"{'seed':>4} {'reached':>7} {'nodes':>5} {'checks':>6} {'ms/node':>8} {'edges ok':>8}"
          f" {'repeat':>6}")
    for s in range(5):
        world = scenarios.paper_clutter(seed=s)
        problem = (world, world.start, world.goal, world.goal_radius, 300, s)
        out = run_ompl_rrt(*problem, return_edges=True)
        edges = out.pop("edges")
        again = run_ompl_rrt(*problem)
        same = all(out[k] == again[k] for k in ("reached", "nodes", "motion_checks"))
        good = ExactCheck(world).reachable(edges[:, 0], edges[:, 1])
        ok = bool(good.all()) and len(edges) == out["nodes"]
        print(f"{s:>4} {out['reached']!s:>7} {out['nodes']:>5} {out['motion_checks']:>6} "
              f"{out['ms_per_node']:>8.3f} {ok!s:>8} {same!s:>6}")
