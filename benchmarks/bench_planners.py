"""Oracle calls per node and milliseconds per node for every planner on paper_clutter.

    python benchmarks/bench_planners.py [--quick] [--seeds 20] [--nodes 100] [--out FILE]

Each configuration plans on paper_clutter worlds seeds 0..S-1 (planner seed = world seed) until
``--nodes`` nodes or the goal. Per run: oracle calls / node, critical-path calls / node and wall
ms / node; the table gives the median and the 10th-90th percentile spread over seeds. If ``ompl``
is importable (``pip install ".[ompl]"``), OMPL's RRT runs on the same worlds with our closed-loop
motion check (a Python MotionValidator) for a time-per-node comparison. Writes JSON.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from _common import machine, write_json

import qrrt_circuits as qc

sys.path.insert(0, str(Path(__file__).resolve().parent))


#: (label, registry planner, registry backend, registry search policy); workers 8 where a planner has them
CONFIGURATIONS = (
    ("RRT", "rrt", None, None),
    ("ParallelRRT (8)", "prrt", None, None),
    ("QRRT statevector", "qrrt", "statevector", "paper"),
    ("QRRT aer", "qrrt", "aer", "paper"),
    ("PQRRT shared statevector", "pqrrt", "statevector", "paper"),
    ("PQRRT shared aer", "pqrrt", "aer", "paper"),
    ("PQRRT unshared statevector", "pqrrt-unshared", "statevector", "paper"),
    ("QRRT adaptive statevector", "qrrt", "statevector", "adaptive"),
    ("QRRT bbht statevector", "qrrt", "statevector", "bbht"),
    ("QRRT known-optimal statevector", "qrrt", "statevector", "optimal"),
)


def configurations():
    """label -> planner factory (env, seed), every planner built through the registry."""
    from qrrt_circuits.experiments.planners import make_planner

    def factory(planner, backend, policy):
        return lambda env, seed: make_planner(planner, env, seed, backend or "statevector",
                                              search_policy=policy)

    return {label: factory(planner, backend, policy) for label, planner, backend, policy in CONFIGURATIONS}


def summarize(values: list[float]) -> dict:
    arr = np.asarray(values, dtype=float)
    return {"median": float(np.median(arr)), "p10": float(np.percentile(arr, 10)),
            "p90": float(np.percentile(arr, 90)), "mean": float(arr.mean())}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--nodes", type=int, default=100)
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    seeds = 4 if args.quick else args.seeds
    nodes = 30 if args.quick else args.nodes
    worlds = [qc.scenarios.paper_clutter(seed=s) for s in range(seeds)]
    qc.RRT(worlds[0], seed=0).plan(max_rounds=5)  # compile the oracle kernel
    rows = {}
    print(f"{'planner':32s} {'calls/node':>18s} {'critical/node':>14s} {'ms/node':>18s} {'reached':>8s}")
    for name, make in configurations().items():
        runs = []
        for seed, env in enumerate(worlds):
            result = make(env, seed).plan(max_nodes=nodes)
            m = result.metrics
            count = max(m.nodes, 1)
            runs.append({"seed": seed, "nodes": m.nodes, "oracle_calls": m.oracle_calls,
                         "critical_path": m.critical_path_oracle_calls,
                         "calls_per_node": m.oracle_calls / count,
                         "critical_per_node": m.critical_path_oracle_calls / count,
                         "ms_per_node": m.wall_time_s * 1e3 / count,
                         "reached": result.status == "reached", "labels": list(result.labels)})
        pooled = sum(r["oracle_calls"] for r in runs) / max(sum(r["nodes"] for r in runs), 1)
        row = {"runs": runs,
               "calls_per_node": summarize([r["calls_per_node"] for r in runs]),
               "critical_per_node": summarize([r["critical_per_node"] for r in runs]),
               "ms_per_node": summarize([r["ms_per_node"] for r in runs]),
               "pooled_calls_per_node": pooled,
               "reached_fraction": float(np.mean([r["reached"] for r in runs]))}
        rows[name] = row
        c, k, t = row["calls_per_node"], row["critical_per_node"], row["ms_per_node"]
        print(f"{name:32s} {c['median']:6.2f} [{c['p10']:5.2f},{c['p90']:6.2f}] {k['median']:14.2f} "
              f"{t['median']:7.2f} [{t['p10']:5.2f},{t['p90']:6.2f}] {row['reached_fraction']:8.2f}")
    ompl_rows = None
    try:
        from ompl_rrt import ompl_available, run_ompl_rrt
    except ImportError:
        ompl_available = None
    if ompl_available is not None and ompl_available():
        runs = [run_ompl_rrt(env, env.start, env.goal, env.goal_radius, nodes, seed)
                for seed, env in enumerate(worlds)]
        ompl_rows = {"runs": runs, "ms_per_node": summarize([r["ms_per_node"] for r in runs])}
        t = ompl_rows["ms_per_node"]
        print(f"{'OMPL RRT (our motion check)':32s} {'':>18s} {'':>14s} "
              f"{t['median']:7.2f} [{t['p10']:5.2f},{t['p90']:6.2f}]")
    else:
        print("(ompl not importable: OMPL comparison skipped; pip install '.[ompl]')")
    path = write_json("bench_planners" + ("_quick" if args.quick else ""),
                      {"machine": machine(), "seeds": seeds, "max_nodes": nodes, "planners": rows,
                       "ompl_rrt": ompl_rows,
                       "note": "quantum planners: phase oracle built from a classical lookup of all "
                               "2^n entries (simulation_checks); shared Pq-RRT: one search with p "
                               "shots stands for p workers; 'known-optimal' uses the true m"},
                      args.out)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
