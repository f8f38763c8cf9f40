"""Pairs per second of the authors' check (``qc.AuthorsCheck``, refine 1 = Octave, refine 4 = MATLAB)
against our exact check (``qc.ExactCheck``) on the 8 000 reference pairs.

    python benchmarks/bench_authors_check.py [--quick] [--out FILE]

The pairs and worlds are the reference data of tests/data/authors_check (2 worlds of
paper_clutter, 525 boxes each; ``global``: a free parent and a child uniform in the workspace,
``local``: a child uniform in the disc of radius 3 around the parent), 2 000 pairs per world and
family, checked as one batch on one core. For scale: the authors' own code under Octave 7.3 checks
1.7-12.6 pairs/s (an accepted pair costs about 2 s). Prints a table and writes JSON.
"""

from __future__ import annotations

import argparse
import csv
import os
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np
from _common import machine, median_time, write_json

import qrrt_circuits as qc

DATA = Path(__file__).resolve().parent.parent / "tests" / "data" / "authors_check"
OCTAVE_PAIRS_PER_S = (1.7, 12.6)  # the reference data's README: dynamicscheck.m under Octave 7.3.0


def load(world: int):
    raw = np.loadtxt(DATA / f"boxes_world{world}.csv", delimiter=",", ndmin=2)  # xlo, xhi, ylo, yhi
    env = qc.Environment(np.array([[0.0, 20.0], [0.0, 20.0]]), np.stack([raw[:, [0, 2]], raw[:, [1, 3]]], axis=1))
    with open(DATA / "verdicts.csv", newline="") as handle:
        rows = [r for r in csv.DictReader(handle) if int(r["world"]) == world]
    pairs = {}
    for family in ("global", "local"):
        sub = [r for r in rows if r["family"] == family]
        pairs[family] = (np.array([[float(r["parent_x"]), float(r["parent_y"])] for r in sub]),
                         np.array([[float(r["child_x"]), float(r["child_y"])] for r in sub]))
    return env, pairs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    repeats = 3 if args.quick else 15
    rows = []
    print(f"{'world':>5s} {'family':8s} {'check':16s} {'pairs/s':>12s} {'accepts':>8s}")
    for world in (0, 1):
        env, pairs = load(world)
        checks = {"authors-octave": qc.AuthorsCheck(env, refine=1), "authors": qc.AuthorsCheck(env, refine=4),
                  "exact": qc.ExactCheck(env)}
        for family, (parents, children) in pairs.items():
            for name, check in checks.items():
                check.reachable(parents[:10], children[:10])  # compile / load the cache
                med, lo, hi = median_time(lambda c=check, p=parents, q=children: c.reachable(p, q), repeats)
                accepts = float(check.reachable(parents, children).mean())
                count = len(parents)
                rows.append({"world": world, "family": family, "check": name, "describe": check.describe(),
                             "pairs": count, "pairs_per_s": count / med, "median_s": med, "min_s": lo,
                             "max_s": hi, "repeats": repeats, "accept_fraction": accepts})
                print(f"{world:5d} {family:8s} {name:16s} {count / med:12,.0f} {accepts:8.4f}")
    summary = {}
    for name in ("authors-octave", "authors", "exact"):
        for family in ("global", "local"):
            rates = [r["pairs_per_s"] for r in rows if r["check"] == name and r["family"] == family]
            summary[f"{name}_{family}_pairs_per_s"] = float(np.mean(rates))
    summary["speedup_over_octave_at_least"] = min(r["pairs_per_s"] for r in rows if r["check"] != "exact") / \
        OCTAVE_PAIRS_PER_S[1]
    print("summary:", {k: round(v, 1) for k, v in summary.items()})
    path = write_json("bench_authors_check" + ("_quick" if args.quick else ""),
                      {"machine": machine(), "quick": args.quick, "rows": rows, "summary": summary,
                       "octave_reference_pairs_per_s": list(OCTAVE_PAIRS_PER_S),
                       "note": "one core, one batch of 2 000 pairs per world and family; the exact check is "
                               "ExactCheck at its default resolution 0.01"}, args.out)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
