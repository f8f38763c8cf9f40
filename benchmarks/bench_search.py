"""Time per Grover search for each backend, and reachability pairs per second.

    python benchmarks/bench_search.py [--quick] [--out FILE]

Search: m = 12 marked entries (fewer for tiny N), k = 12 iterations, 8 shots (one shared database,
8 workers); Aer for n = 4..16, the exact statevector for n = 4..20. Reachability: one core, batches
of pairs on paper_clutter and annealing_field, for two pair distributions (``uniform``: a free
parent and a uniform child anywhere; ``local``: child = parent + N(0, 1.5^2) per axis, like a
database entry near its nearest tree node). Prints a table and writes JSON.
"""

from __future__ import annotations

import argparse
import os

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np
from _common import machine, median_time, write_json

import qrrt_circuits as qc
from qrrt_circuits.registry import BACKENDS


def bench_search(quick: bool) -> list[dict]:
    rows = []
    rng = np.random.default_rng(0)
    for name, registered, options, top in (("aer", "aer", {"max_parallel_threads": 1}, 16),
                                           ("statevector", "statevector", {}, 20),
                                           ("statevector-iterated", "statevector", {"closed_form": False}, 20)):
        backend = BACKENDS.create(registered, seed=1, **options)
        for n in range(4, (12 if quick else top) + 1, 2 if quick else 1):
            m = min(12, 2 ** n // 4)
            marks = np.zeros(2**n, dtype=bool)
            marks[rng.choice(2**n, m, replace=False)] = True
            repeats = 5 if quick else (10 if n >= 15 else 30)
            med, lo, hi = median_time(lambda b=backend, mk=marks: b.search(mk, 12, shots=8), repeats)
            rows.append({"backend": name, "qubits": n, "marked": m, "iterations": 12, "shots": 8,
                         "median_s": med, "min_s": lo, "max_s": hi, "repeats": repeats})
            print(f"  {name:20s} n={n:2d}  {med * 1e3:9.3f} ms  (min {lo * 1e3:.3f}, max {hi * 1e3:.3f})")
    return rows


def bench_reachability(quick: bool) -> list[dict]:
    rows = []
    count = 20000 if quick else 200000
    for scenario in ("paper_clutter", "annealing_field"):
        env = qc.scenarios.by_name(scenario, seed=0)
        oracle = qc.ReachabilityOracle(env)
        rng = np.random.default_rng(1)
        parents = env.sample_free(count, rng)
        pairs = {
            "uniform": env.sample_uniform(count, rng),
            "local": np.clip(parents + rng.normal(scale=1.5, size=parents.shape),
                             env.bounds[:, 0], env.bounds[:, 1]),
        }
        oracle.reachable(parents[:10], pairs["uniform"][:10])  # compile
        for kind, children in pairs.items():
            med, lo, hi = median_time(lambda o=oracle, c=children, p=parents: o.reachable(p, c),
                                      3 if quick else 5)
            reach = float(oracle.reachable(parents, children).mean())
            rows.append({"scenario": scenario, "pairs": kind, "count": count,
                         "pairs_per_s": count / med, "reachable_fraction": reach,
                         "median_s": med, "boxes": env.num_boxes})
            print(f"  {scenario:16s} {kind:8s} {count / med / 1e3:9.1f} k pairs/s  "
                  f"(reachable {reach:.3f})")
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    print("Grover search, time per search (k = 12, 8 shots):")
    search = bench_search(args.quick)
    print("Reachability (one core):")
    reach = bench_reachability(args.quick)
    aer12 = next((r["median_s"] for r in search if r["backend"] == "aer" and r["qubits"] == 12), None)
    sv12 = next((r["median_s"] for r in search if r["backend"] == "statevector" and r["qubits"] == 12), None)
    summary = {"aer_n12_ms": aer12 and aer12 * 1e3, "statevector_n12_ms": sv12 and sv12 * 1e3,
               "statevector_speedup_n12": aer12 / sv12 if aer12 and sv12 else None}
    sv20 = next((r["median_s"] for r in search if r["backend"] == "statevector" and r["qubits"] == 20), None)
    summary["statevector_n20_ms"] = sv20 and sv20 * 1e3
    print("summary:", {k: (round(v, 3) if isinstance(v, float) else v) for k, v in summary.items()})
    path = write_json("bench_search" + ("_quick" if args.quick else ""),
                      {"machine": machine(), "quick": args.quick, "search": search,
                       "reachability": reach, "summary": summary,
                       "note": "phase oracle built from a classical lookup of all 2^n marks; "
                               "one circuit with 8 shots stands for 8 workers"}, args.out)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
