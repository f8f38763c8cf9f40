"""Nearest-node queries: ``GridNearest.nearest`` (a compiled grid) against the compiled brute force.

    python benchmarks/bench_nearest.py [--quick] [--out FILE]

One quantum round of the planners pairs 2^n = 256 candidates with their nearest tree nodes. This
times ``GridNearest.nearest`` (a brute force below ``nearest.BRUTE_FORCE_BELOW`` nodes, the grid from
there), ``GridNearest.grid_nearest`` (the grid at every size) and its brute force alone (``nearest._brute_block``
over every node: one pass over the nodes for all queries, the reference that placed the switch) for
256 uniform queries on trees of 100 to 3 000 nodes (``--quick``: up to 400): uniform in the 20 x 20
workspace, and the tree q-RRT grows on paper_clutter (which clusters around the start, so many
queries lie far from every node). Medians of repeated calls
on the same 256 queries, and (``*_fresh_us``) on a new set of 256 queries each call, as a planner's
rounds ask (on one repeated set the processor's branch predictors learn the searches' branches);
one thread. Prints a table and writes JSON.
"""

from __future__ import annotations

import argparse
import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np
from _common import machine, median_time, write_json

import qrrt_circuits as qc
from qrrt_circuits.world.nearest import GridNearest, _brute_block

QUERIES = 256
SIZES = (100, 200, 300, 400, 500, 1000, 3000)


def brute_force(points: np.ndarray, nodes: np.ndarray, size: int, out: np.ndarray) -> None:
    """out[i] = the lowest index among the nodes nearest to points[i] (the tree's brute force over
    every node)."""
    _brute_block(points, nodes, 0, size, np.empty(points.shape[0]), out)


def on_new_queries(kernel, query_sets):
    """A function that calls ``kernel`` on the next of ``query_sets`` each time."""
    sets = iter(query_sets)
    return lambda: kernel(next(sets))


def uniform_tree(size: int, rng: np.random.Generator) -> GridNearest:
    """The structure of a tree of ``size`` nodes uniform in the 20 x 20 workspace, added one by one."""
    tree = GridNearest(2)
    while tree.size < size:
        tree.add(rng.random((1, 2)) * 20.0)
    return tree


def planner_tree(size: int) -> GridNearest:
    """The structure of the tree q-RRT (statevector, n = 8) grows on paper_clutter world 0 toward an
    unreachable goal, to ``size`` nodes: the trees the planners query (clustered around the start)."""
    problem = qc.paper_clutter(seed=0).with_goal_radius(1e-9)
    result = qc.QRRT(backend=qc.StatevectorBackend(), seed=0).plan(problem, max_nodes=size - 1)
    tree = GridNearest(2)
    for node in result.nodes:
        tree.add(node[None])
    return tree


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    repeats = 50 if args.quick else 300
    rng = np.random.default_rng(0)
    rows = []
    for layout in ("uniform", "planner"):
        for size in (SIZES[:4] if args.quick else SIZES):
            tree = uniform_tree(size, rng) if layout == "uniform" else planner_tree(size)
            queries = rng.random((QUERIES, 2)) * 20.0
            out = np.empty(QUERIES, dtype=np.int64)

            def brute(t=tree, q=queries, o=out):
                brute_force(q, t.points, t.size, o)

            fresh = [rng.random((QUERIES, 2)) * 20.0 for _ in range(repeats + 1)]  # one per call, warm-up too
            times = {"nearest_us": median_time(lambda t=tree, q=queries: t.nearest(q), repeats)[0] * 1e6,
                     "grid_us": median_time(lambda t=tree, q=queries: t.grid_nearest(q), repeats)[0] * 1e6,
                     "brute_force_us": median_time(brute, repeats)[0] * 1e6,
                     "nearest_fresh_us": median_time(on_new_queries(tree.nearest, fresh), repeats)[0] * 1e6,
                     "grid_fresh_us": median_time(on_new_queries(tree.grid_nearest, fresh), repeats)[0] * 1e6,
                     "brute_force_fresh_us": median_time(on_new_queries(
                         lambda q, t=tree, o=out: brute_force(q, t.points, t.size, o), fresh), repeats)[0] * 1e6}
            brute()
            assert np.array_equal(out, tree.nearest(queries)), "the kernels disagree"
            assert np.array_equal(out, tree.grid_nearest(queries)), "the kernels disagree"
            rows.append({"layout": layout, "nodes": size, "queries": QUERIES, **times})
            print(f"  {layout:8s} {size:5d} nodes: GridNearest.nearest {times['nearest_us']:7.1f} us (the grid "
                  f"{times['grid_us']:7.1f} us), brute force {times['brute_force_us']:8.1f} us; new queries each "
                  f"call: {times['nearest_fresh_us']:7.1f} / {times['grid_fresh_us']:7.1f} / "
                  f"{times['brute_force_fresh_us']:8.1f} us ({QUERIES} queries)")
    keys = ("nearest_us", "grid_us", "brute_force_us", "nearest_fresh_us", "grid_fresh_us", "brute_force_fresh_us")
    summary = {f"{row['layout']}_n{row['nodes']}_{key}": row[key] for row in rows for key in keys}
    path = write_json("bench_nearest_quick" if args.quick else "bench_nearest",
                      {"machine": machine(), "quick": args.quick, "rows": rows, "summary": summary}, args.out)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
