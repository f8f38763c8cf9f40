"""The memory guard's estimate against the measured peak memory.

Each case runs in a fresh subprocess: it imports the library, warms up (numba compilation, a tiny
plan), reads its resident set (VmRSS), then runs the case and reads its peak resident set
(``resource.getrusage(RUSAGE_SELF).ru_maxrss``). The measured figure is the peak minus that
baseline: the bytes the run added, which is what ``qrrt_circuits._support.memory`` estimates.

Cases:
- ``plan``: one round of q-RRT (``QRRT``, paper_clutter, the paper's schedule: k = 5 on a new tree)
  on each backend for several n; the estimate is ``QRRT.memory_estimate()``;
- ``--database``: one database build and predicate evaluation alone, in d = 2, 4, 6, with and
  without annealing, at n = 20 (the constants ``DATABASE_*`` / ``ANNEALING_*`` come from these);
- ``--aer-iterations``: one Aer round at n = 18 for k = 1, 2, 5, 10 (the per-iteration constant);
- ``--plan-limits``: what a plan's node and round limits let it hold (``memory.plan_bytes``): a
  tree of 200 000 / 600 000 nodes grown by 4 096 parallel-RRT workers in a world whose goal is
  walled in (d = 2 and 4), and 1 000 000 RRT rounds from a start walled in a small cube (the
  round history; the tree stays small);
  the constants ``TREE_*`` and ``HISTORY_BYTES_PER_ROUND`` come from these; and the batches of
  4 096 parallel-RRT workers whose every test fails (d = 2, 6, 64: ``plan-batch``, the constants
  ``BATCH_BYTES_*`` of ``planners.classical``); and what writing a plan's JSON of 200 000 and
  1 000 000 nodes adds, and its seconds (``output``: ``PlanResult.write_json``, as ``qrrt plan
  --json`` does, against ``json.dump`` and ``json.dumps`` of ``to_dict()``);
- ``--mcz``: one ``AerBackend.search`` (8 shots) whose oracle takes the ``mcz`` form: 12 marked
  entries at n = 20, 22 (k = 1, 12) and 24 (k = 1), and 100 marked entries at n = 16 with k = 1 and
  400 (80 200 instructions); the estimate is ``AerBackend.peak_bytes(n, 8, k, marked)`` (the
  constants ``AER_MCZ_BYTES_PER_ENTRY`` and ``AER_BYTES_PER_MCZ_INSTRUCTION`` come from these).

    python benchmarks/bench_memory.py            # n = 16, 18, 20, 22 on both backends (a few minutes)
    python benchmarks/bench_memory.py --quick    # n = 16, 18, 20

Writes ``benchmarks/results/bench_memory.json``. Memory figures do not depend on a busy CPU, but
the allocator's behaviour makes them vary by a few MiB between runs.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from _common import RESULTS, machine, rows_in_subprocesses

MIB = 1 << 20


def _rss() -> int:
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) * 1024
    raise RuntimeError("no VmRSS in /proc/self/status")


def _peak() -> int:
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # KiB on Linux


def run_plan_case(backend_name: str, n: int, k: int | None) -> dict:
    import qrrt_circuits as qc

    env = qc.paper_clutter(seed=0)
    backend = qc.AerBackend(seed=0) if backend_name == "aer" else qc.StatevectorBackend(seed=0)
    policy = qc.PaperIterations() if k is None else qc.FixedIterations(k)
    qc.QRRT(backend=backend, num_qubits=4, seed=0, search_policy=policy).plan(env, max_rounds=2)  # warm up
    base = _rss()
    planner = qc.QRRT(backend=backend, num_qubits=n, seed=0, search_policy=policy)
    estimate = planner.memory_estimate(dim=2)
    planner.plan(env, max_rounds=1)
    return {"case": "plan", "backend": backend_name, "num_qubits": n,
            "iterations": policy.iterations_bound(1 << n), "measured_bytes": _peak() - base,
            "estimated_bytes": estimate.total_bytes, "estimate": estimate.describe()}


def run_database_case(n: int, d: int, annealing: bool) -> dict:
    import numpy as np

    import qrrt_circuits as qc
    from qrrt_circuits._support.memory import database_bytes
    from qrrt_circuits.planners.database import AnnealingSchedule, build_database
    from qrrt_circuits.planners.tree import Tree

    env = qc.Environment(np.array([[0.0, 10.0]] * d), np.array([[[4.0] * d, [5.0] * d]]))
    dynamics = None if d == 2 else qc.LinearTrackingDynamics(-np.eye(d), np.eye(d), np.eye(d))
    oracle = qc.ExactCheck(env, dynamics)
    rng = np.random.default_rng(0)
    tree = Tree(np.full(d, 1.0))
    for point in env.sample_free(62, rng):  # a 63-node tree
        tree.add(point, 0)
    oracle.reachable(np.ones((1, d)), np.full((1, d), 2.0))  # warm up
    base = _rss()
    db = build_database(tree, 1 << n, env, rng, np.full(d, 9.0), 0.5, 0.1,
                        AnnealingSchedule.paper() if annealing else None, 0)
    oracle.reachable(tree.nodes[db.parents], db.children)
    return {"case": "database", "num_qubits": n, "dim": d, "annealing": annealing,
            "measured_bytes": _peak() - base, "estimated_bytes": database_bytes(n, d, annealing),
            "measured_bytes_per_entry": (_peak() - base) / (1 << n)}


def _walled_world(dim: int, around: float):
    """A 20^d world with a wall (0.5 thick) around the corner cube [16, 20]^d, whose centre 18 is
    walled in: around the goal (``around`` = goal) or the start."""
    import numpy as np

    import qrrt_circuits as qc

    boxes = []
    for axis in range(dim):
        low, high = np.full(dim, 16.0), np.full(dim, 20.0)
        high[axis] = 16.5
        boxes.append([low, high])
    env = qc.Environment(np.array([[0.0, 20.0]] * dim), np.array(boxes))
    inside, outside = np.full(dim, around), np.full(dim, 2.0)
    return env, inside, outside


def run_plan_limits_case(kind: str, dim: int, limit: int) -> dict:
    import numpy as np

    import qrrt_circuits as qc
    from qrrt_circuits._support.memory import plan_bytes

    env, walled_in, outside = _walled_world(dim, 18.0)
    dynamics = None if dim == 2 else qc.LinearTrackingDynamics(-np.eye(dim), np.eye(dim), np.eye(dim))
    from qrrt_circuits.planners.termination import DEFAULT_MAX_NODES

    toward_wall = qc.Problem.build(env, outside, walled_in, 0.5, dynamics=dynamics)
    from_wall = qc.Problem.build(env, walled_in, outside, 0.5, dynamics=dynamics)
    if kind == "tree":  # 4 096 workers fill the world outside the wall; the goal is unreachable
        planner = qc.ParallelRRT(workers=4096, seed=0)
        qc.ParallelRRT(workers=8, seed=0).plan(toward_wall, max_rounds=3)
        base = _rss()
        began = time.perf_counter()
        result = planner.plan(toward_wall, max_nodes=limit)
        nodes_per_round, rounds = 4096, result.metrics.rounds
    else:  # RRT rounds from a walled-in start: nodes only inside the small walled cube, the history grows
        planner = qc.RRT(seed=0)
        planner.plan(from_wall, max_rounds=3)  # warm up
        base = _rss()
        began = time.perf_counter()
        result = planner.plan(from_wall, max_rounds=limit, stall_rounds=limit)
        nodes_per_round, rounds = 1, limit
    tree, history = plan_bytes(limit if kind == "tree" else DEFAULT_MAX_NODES, nodes_per_round, rounds, dim)
    seconds = time.perf_counter() - began
    measured = _peak() - base
    return {"case": f"plan-{kind}", "seconds": round(seconds, 2), "dim": dim, "num_qubits": 0, "limit": limit,
            "nodes": result.metrics.nodes,
            "rounds": result.metrics.rounds, "measured_bytes": measured,
            "estimated_bytes": tree + history if kind == "tree" else history,
            "measured_bytes_per_node": measured / max(result.metrics.nodes, 1),
            "measured_bytes_per_round": measured / result.metrics.rounds,
            "note": "the rounds case's estimate is the history alone (its tree stays small)"}


class _Nowhere:
    """A predicate that rejects every motion at no cost: a plan's batches are all it holds."""

    name = "nowhere"

    def __init__(self, dim: int) -> None:
        self.dim = dim

    def describe(self) -> dict:
        return {"name": self.name}

    def reachable(self, parents, children):
        import numpy as np

        return np.zeros(len(children), dtype=bool)


def run_plan_batch_case(check: str, dim: int, rounds: int) -> dict:
    """4 096 parallel-RRT workers whose tests (almost) all fail, for ``rounds`` rounds: batches of
    ``batch_round_limit`` rounds (``MAX_BATCH_BYTES``). ``check`` "nowhere": a predicate that
    rejects everything at no cost, in an empty world; "exact": the exact check, from a start walled
    in a small cube (``_walled_world``)."""
    import numpy as np

    import qrrt_circuits as qc
    from qrrt_circuits.planners import classical

    if check == "nowhere":
        env = qc.Environment(np.array([[0.0, 20.0]] * dim), np.zeros((0, 2, dim)))
        problem = qc.Problem.build(env, np.full(dim, 2.0), np.full(dim, 18.0), 0.5, predicate=_Nowhere(dim))
    else:
        env, start, goal = _walled_world(dim, 18.0)
        dynamics = None if dim == 2 else qc.LinearTrackingDynamics(-np.eye(dim), np.eye(dim), np.eye(dim))
        problem = qc.Problem.build(env, start, goal, 0.5, dynamics=dynamics)
    qc.ParallelRRT(workers=8, seed=0).plan(problem, max_rounds=3)
    base = _rss()
    began = time.perf_counter()
    result = qc.ParallelRRT(workers=4096, seed=0).plan(problem, max_rounds=rounds, stall_rounds=rounds)
    seconds = time.perf_counter() - began
    measured = _peak() - base
    candidates = classical.batch_round_limit(4096, dim) * 4096
    return {"case": f"plan-batch-{check}", "seconds": round(seconds, 2), "dim": dim, "num_qubits": 0,
            "limit": rounds, "rounds": result.metrics.rounds, "nodes": result.metrics.nodes,
            "batch_candidates": candidates, "measured_bytes": measured,
            "estimated_bytes": candidates * (classical.BATCH_BYTES_PER_CANDIDATE
                                             + classical.BATCH_BYTES_PER_COORDINATE * dim),
            "measured_bytes_per_candidate": measured / candidates}


def run_output_case(how: str, nodes: int) -> dict:
    """What writing a plan's JSON adds to the peak, and how long it takes, for a result of
    ``nodes`` nodes (4 096 parallel-RRT workers, the walled-goal world, d = 2): ``qrrt plan
    --json``'s ``PlanResult.write_json`` (``how`` = "stream": the arrays chunk by chunk through
    the C encoder) against ``json.dump(result.to_dict(), handle, indent=1)`` ("dump", the writer
    before it) and ``json.dumps`` then one write ("dumps")."""
    import json
    import tempfile

    import qrrt_circuits as qc

    env, walled_in, outside = _walled_world(2, 18.0)
    result = qc.ParallelRRT(workers=4096, seed=0).plan(qc.Problem.build(env, outside, walled_in, 0.5), max_nodes=nodes)
    with open("/proc/self/clear_refs", "w") as handle:  # the peak from here on (Linux)
        handle.write("5")
    base = _rss()
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "plan.json"
        began = time.perf_counter()
        with path.open("w") as handle:
            if how == "stream":
                result.write_json(handle)
            elif how == "dump":
                json.dump(result.to_dict(), handle, indent=1)
            else:
                handle.write(json.dumps(result.to_dict(), indent=1))
        seconds = time.perf_counter() - began
        size = path.stat().st_size
        with open("/proc/self/status") as status:
            peak = next(int(line.split()[1]) * 1024 for line in status if line.startswith("VmHWM:"))
        assert json.loads(path.read_text())["nodes"] == result.nodes.tolist()  # (after the peak is read)
    return {"case": f"output-{how}", "dim": 2, "num_qubits": 0, "nodes": result.metrics.nodes,
            "measured_bytes": peak - base, "estimated_bytes": 0, "file_bytes": size, "seconds": seconds,
            "note": "no estimate: the plan's memory check charges no output"}


def run_mcz_search_case(n: int, marked: int, k: int) -> dict:
    """One Aer search of ``marked`` random entries among 2^n (the ``mcz`` oracle), 8 shots."""
    import numpy as np

    import qrrt_circuits as qc
    from qrrt_circuits.search.aer_circuits import simulation_synthesis

    backend = qc.AerBackend(seed=0)
    marks = np.zeros(1 << n, dtype=bool)
    marks[np.random.default_rng(0).choice(1 << n, marked, replace=False)] = True
    warm = np.zeros(1 << 14, dtype=bool)
    warm[:marked] = True
    backend.search(qc.LookupOracle(warm), 1, shots=8)  # warm up (a 14-qubit run: Aer's fusion and threads)
    base = _rss()
    backend.search(qc.LookupOracle(marks), k, shots=8)
    estimate = backend.peak_bytes(n, 8, k, marked)
    return {"case": "search-mcz", "backend": "aer", "num_qubits": n, "marked": marked, "iterations": k,
            "synthesis": simulation_synthesis(marks), "measured_bytes": _peak() - base,
            "estimated_bytes": estimate,
            "measured_bytes_per_entry": (_peak() - base) / (1 << n)}


def _line(row: dict) -> str:
    ratio = row["estimated_bytes"] / max(row["measured_bytes"], 1)
    return (f"{row['case']:9s} {row.get('backend', '-'):12s} {row['num_qubits']:3d} {row.get('dim', 2):2d} "
            f"{row.get('iterations', '-')!s:>3s} {row['estimated_bytes'] / MIB:14.1f} "
            f"{row['measured_bytes'] / MIB:13.1f} {ratio:9.2f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--database", action="store_true", help="also the database cases (d = 2, 4, 6)")
    parser.add_argument("--aer-iterations", action="store_true", help="also Aer at n = 18 for k = 1..10")
    parser.add_argument("--plan-limits", action="store_true",
                        help="also a plan's tree (d = 2, 4) and round history against memory.plan_bytes")
    parser.add_argument("--only-plan-limits", action="store_true", help="only the --plan-limits cases")
    parser.add_argument("--mcz", action="store_true", help="also Aer searches with the mcz oracle")
    parser.add_argument("--only-mcz", action="store_true", help="only the --mcz cases")
    parser.add_argument("--out", default=None, help="the JSON to write (default benchmarks/results/bench_memory.json)")
    parser.add_argument("--case", nargs="+", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.case:
        kind, *rest = args.case
        if kind == "plan":
            result = run_plan_case(rest[0], int(rest[1]), None if rest[2] == "paper" else int(rest[2]))
        elif kind == "limits":
            result = run_plan_limits_case(rest[0], int(rest[1]), int(rest[2]))
        elif kind == "output":
            result = run_output_case(rest[0], int(rest[1]))
        elif kind == "batch":
            result = run_plan_batch_case(rest[0], int(rest[1]), int(rest[2]))
        elif kind == "mcz":
            result = run_mcz_search_case(int(rest[0]), int(rest[1]), int(rest[2]))
        else:
            result = run_database_case(int(rest[0]), int(rest[1]), rest[2] == "1")
        print(json.dumps(result))
        return
    sizes = (16, 18, 20) if args.quick else (16, 18, 20, 22)
    cases = [("plan", backend, str(n), "paper") for backend in ("statevector", "aer") for n in sizes]
    if args.aer_iterations:
        cases += [("plan", "aer", "18", str(k)) for k in (1, 2, 5, 10)]
    if args.database:
        cases += [("database", "20", str(d), a) for d in (2, 4, 6) for a in ("0", "1")]
    limits = [("limits", "tree", str(d), str(nodes)) for d in (2, 4) for nodes in (200_000, 600_000)]
    limits += [("limits", "rounds", "2", "1000000")]
    limits += [("batch", "nowhere", str(d), "300") for d in (2, 6, 64)] + [("batch", "exact", "6", "300")]
    limits += [("output", how, nodes) for how in ("stream", "dump", "dumps") for nodes in ("200000", "1000000")]
    mcz = [("mcz", str(n), "12", str(k)) for n in (20, 22) for k in (1, 12)] + [("mcz", "24", "12", "1")]
    mcz += [("mcz", "16", "100", str(k)) for k in (1, 400)]
    if args.only_plan_limits:
        cases = limits
    elif args.only_mcz:
        cases = mcz
    else:
        cases += (limits if args.plan_limits else []) + (mcz if args.mcz else [])
    header = (f"{'case':9s} {'backend':12s} {'n':>3s} {'d':>2s} {'k':>3s} {'estimated MiB':>14s} "
              f"{'measured MiB':>13s} {'est/meas':>9s}")
    rows = rows_in_subprocesses(__file__, cases, header, _line)
    RESULTS.mkdir(exist_ok=True)
    path = Path(args.out) if args.out else RESULTS / "bench_memory.json"
    path.write_text(json.dumps({"machine": machine(), "rows": rows,
                                "note": "peak RSS increment over a warmed-up baseline, one subprocess per case"},
                               indent=1))
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
