"""The small parts of a quantum round that the 3 000-node work of issue 11 changed, each timed
alone (microseconds, medians of repeated calls, one thread).

    python benchmarks/bench_round_parts.py [--quick] [--out FILE]

- ``grid_build_us``: ``Tree._build_grid`` on the nodes of a q-RRT tree grown on paper_clutter
  (world 0, seed 0, toward an unreachable goal) to 3 000 nodes (``--quick``: 800), and the two
  numpy calls the build used before (``nodes.min(axis=0)``, ``nodes[order]``) beside the compiled
  ones (``_bounding_box``).
- ``as_pairs_us``: ``predicate.as_pairs`` on 256 pairs, and the check it replaced
  (``np.all(np.isfinite(...))`` on both arrays).
- ``returned_arrays_us`` / ``caller_arrays_us``: a compiled call that returns three arrays of a
  round's shapes ((256, 2), (256,), (256, 2)) against the same call writing into three arrays its
  caller makes with ``np.empty`` (what ``fused_round._candidates`` does now).
- ``take_us`` / ``fancy_index_us``: the added children of a round, 3 of 256 rows of (256, 2),
  by ``take(axis=0)`` and by ``children[added]``.
- ``draw_scanned_us`` / ``draw_listed_us``: the closed-form draw of the measured indices (a fifth
  of the entries marked) by a scan of the marks and through the lists of marked and unmarked
  entries, for 1, 2 and 8 shots at N = 2^8, 2^12 and 2^16 (``_SCANNED_SHOTS`` picks between them).

Prints a table and writes JSON.
"""

from __future__ import annotations

import argparse
import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np
from _common import machine, median_time, write_json
from numba import njit

import qrrt_circuits as qc
from qrrt_circuits.predicate import as_pairs
from qrrt_circuits.randomness import integer_seed_words
from qrrt_circuits.search.statevector import _draw_two_level_listed, _draw_two_level_scanned
from qrrt_circuits.tree import Tree, _bounding_box

PAIRS = 256


def per_call_us(func, calls: int, repeats: int) -> float:
    """Median over ``repeats`` of the microseconds per call of ``calls`` calls of ``func``."""
    def batch() -> None:
        for _ in range(calls):
            func()

    return median_time(batch, repeats)[0] * 1e6 / calls


@njit(cache=True)
def _returned(size: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    children, parents, positions = np.empty((size, 2)), np.empty(size, dtype=np.int64), np.empty((size, 2))
    children[0, 0], parents[0], positions[0, 0] = 1.0, 1, 1.0
    return children, parents, positions


@njit(cache=True)
def _written(children: np.ndarray, parents: np.ndarray, positions: np.ndarray) -> None:
    children[0, 0], parents[0], positions[0, 0] = 1.0, 1, 1.0


def grid_build(nodes: int, repeats: int) -> dict:
    env = qc.scenarios.paper_clutter(seed=0)
    result = qc.QRRT(env, backend=qc.StatevectorBackend(), seed=0).plan(max_nodes=nodes, goal_radius=1e-9)
    tree = Tree(result.nodes[0])
    tree.add_many(result.nodes[1:], result.parents[1:])
    points = tree.nodes
    order = tree._order.copy()
    return {"nodes": int(tree.size),
            "grid_build_us": per_call_us(tree._build_grid, 1, repeats),
            "numpy_min_max_us": per_call_us(lambda: (points.min(axis=0), points.max(axis=0)), 1, repeats),
            "compiled_bounding_box_us": per_call_us(lambda: _bounding_box(points), 1, repeats),
            "numpy_sorted_positions_us": per_call_us(lambda: points[order], 1, repeats)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    repeats, calls = (5, 200) if args.quick else (15, 2000)
    rng = np.random.default_rng(0)
    parents, children = rng.random((PAIRS, 2)) * 20, rng.random((PAIRS, 2)) * 20
    added = np.array([3, 77, 100])
    out = {"machine": machine(), "quick": args.quick}
    out["grid"] = grid_build(800 if args.quick else 3000, repeats)
    out["as_pairs"] = {
        "as_pairs_us": per_call_us(lambda: as_pairs(parents, children, 2), calls, repeats),
        "numpy_finite_check_us": per_call_us(
            lambda: np.all(np.isfinite(parents)) and np.all(np.isfinite(children)), calls, repeats)}
    buffers = (np.empty((PAIRS, 2)), np.empty(PAIRS, dtype=np.int64), np.empty((PAIRS, 2)))
    _written(*buffers)
    out["arrays"] = {
        "returned_arrays_us": per_call_us(lambda: _returned(PAIRS), calls, repeats),
        "caller_arrays_us": per_call_us(
            lambda: _written(np.empty((PAIRS, 2)), np.empty(PAIRS, dtype=np.int64), np.empty((PAIRS, 2))), calls,
            repeats),
        "take_us": per_call_us(lambda: children.take(added, axis=0), calls, repeats),
        "fancy_index_us": per_call_us(lambda: children[added], calls, repeats)}
    draws = []
    words = integer_seed_words(5)
    for qubits in (8, 12, 16):
        marks = rng.random(1 << qubits) < 0.2
        draw_calls = max(calls >> (qubits - 8), 20)
        for shots in (1, 2, 8):
            scanned = _draw_two_level_scanned(marks, 0.5, shots, words)
            assert np.array_equal(scanned, _draw_two_level_listed(marks, 0.5, shots, words))
            row = {"qubits": qubits, "shots": shots}
            for name, draw in (("draw_scanned_us", _draw_two_level_scanned),
                               ("draw_listed_us", _draw_two_level_listed)):
                row[name] = per_call_us(lambda d=draw, m=marks, s=shots: d(m, 0.5, s, words), draw_calls, repeats)
            draws.append(row)
    out["draws"] = draws
    grid, pairs, arrays = out["grid"], out["as_pairs"], out["arrays"]
    print(f"grid build ({grid['nodes']} nodes): {grid['grid_build_us']:.1f} us; numpy min+max "
          f"{grid['numpy_min_max_us']:.1f} us against the compiled box {grid['compiled_bounding_box_us']:.1f}; "
          f"nodes[order] {grid['numpy_sorted_positions_us']:.1f} us")
    print(f"as_pairs, {PAIRS} pairs: {pairs['as_pairs_us']:.2f} us (numpy's finite check alone: "
          f"{pairs['numpy_finite_check_us']:.2f} us)")
    print(f"three arrays returned by a compiled call {arrays['returned_arrays_us']:.2f} us, made by np.empty and "
          f"written {arrays['caller_arrays_us']:.2f} us; 3 of {PAIRS} rows by take {arrays['take_us']:.2f} us, "
          f"by children[added] {arrays['fancy_index_us']:.2f} us")
    for row in draws:
        print(f"closed-form draw, N = 2^{row['qubits']}, {row['shots']} shots: scan {row['draw_scanned_us']:.2f} us, "
              f"lists {row['draw_listed_us']:.2f} us")
    path = write_json("bench_round_parts" + ("_quick" if args.quick else ""), out, args.out)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
