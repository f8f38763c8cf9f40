"""One planner's milliseconds per node on this checkout's code against another checkout's, in
alternating processes (a developer's A/B tool; not run by ``run.py``, which runs ``bench_*.py``).

    python benchmarks/ab_planner.py --baseline-src OTHER_CHECKOUT/src [--planner qrrt]
                                    [--backend aer] [--pairs 4] [--worlds 6] [--nodes 100]
                                    [--replay] [--unreachable-goal] [--cpu-time] [--out FILE]

A machine whose speed drifts over minutes (seen on this project's: 1.5x) makes two benchmark runs
taken one after the other a poor comparison of two versions of the code. Here each pair is two
fresh interpreters run back to back, one importing ``qrrt_circuits`` from ``--baseline-src`` (put
first on ``PYTHONPATH``), the other from this checkout's ``src``; which one runs first alternates
from pair to pair. Each interpreter plans on ``paper_clutter`` worlds 0 .. W-1 (planner seed =
world seed, built through the registry as ``bench_planners.py`` builds them) to ``--nodes`` nodes
after one warm-up plan (and a full garbage collection, so that the one the imports' heap is due for
does not land in the timed plans), and reports its total wall time over its total nodes. Prints each pair,
the medians and their ratio (baseline / ours: above 1 means ours is faster) and the median of
the pairs' own ratios (less sensitive to a drift between pairs); writes JSON, with the baseline
checkout's git commit and whether its tree differs from it (``baseline_checkout``), and the same
for this checkout (``ours_checkout``), and the load average when it started.

``--cpu-time`` compares the interpreters' processor time per node (``time.process_time``, every
thread of the process) instead of their wall time: on a machine other programs keep busy, the wall
time follows their load, the processor time much less (each interpreter reports both,
``ms_per_node`` and ``cpu_ms_per_node``).

``--replay`` times everything but the predicate: each interpreter first plans each world with the
exact predicate, recording its answers, then plans it again (the same seed, so the same plan) with
a predicate that hands back the recorded answers, checks that the replayed plan is the recorded
one (its nodes, parents and oracle calls, every answer used), and reports the replayed plans'
microseconds per round (``us_per_round_replayed``: a round's work outside the oracle, plus one
list lookup per predicate call) instead of milliseconds per node. ``--unreachable-goal`` plans
toward a goal of radius 1e-9, so that a plan ends at ``--nodes`` or at the default round limit
(as the "3000 nodes" rows of ``bench_planners.py``).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
from _common import machine, write_json

HERE = Path(__file__).resolve().parent
OURS = HERE.parent / "src"

#: what each interpreter runs (argv: planner, backend, worlds, nodes, replay, unreachable goal);
#: prints one JSON line
CHILD = """
import gc, json, sys, time
import numpy as np
import qrrt_circuits as qc
from qrrt_circuits.experiments.planners import make_planner
planner, backend, worlds, nodes = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
replay, unreachable = sys.argv[5] == "1", sys.argv[6] == "1"
# the two checkouts may predate or follow the problem API (a planner's plan(problem, ...)): the child
# speaks whichever its checkout has
PROBLEM_API = hasattr(qc, "Problem")


def world(seed):
    return qc.paper_clutter(seed=seed) if PROBLEM_API else qc.scenarios.paper_clutter(seed=seed)


def geometry(problem):
    return problem.env if PROBLEM_API else problem


def plan(problem, seed, predicate=None, **limits):
    if PROBLEM_API:
        posed = problem if predicate is None else problem.replace(predicate=predicate)
        posed = posed.with_goal_radius(1e-9) if unreachable else posed
        return make_planner(planner, seed, backend).plan(posed, **limits)
    extra = {} if predicate is None else {"predicate": predicate}
    goal = {"goal_radius": 1e-9} if unreachable else {}
    return make_planner(planner, problem, seed, backend, **extra).plan(**limits, **goal)


problems = [world(seed) for seed in range(worlds)]
plan(problems[0], 0, max_nodes=nodes)  # compile and warm up: a whole plan, as timed below
gc.collect()  # (a full collection of the import-time heap, ~0.1 s, would otherwise land in the timed plans)


class Recorded:  # the exact predicate of a world, recording its answers (record) or handing them back
    def __init__(self, env, answers, record):
        self.exact, self.answers, self.record, self.calls = qc.ExactCheck(env), answers, record, 0
        self.dim, self.name = self.exact.dim, "recorded"

    def describe(self):
        return {"name": self.name}

    def reachable(self, parents, children):
        if self.record:
            self.answers.append(self.exact.reachable(parents, children).copy())
            return self.answers[-1]
        self.calls += 1
        return self.answers[self.calls - 1]


if not replay:
    began, cpu_began, total = time.perf_counter(), time.process_time(), 0
    for seed, problem in enumerate(problems):
        total += plan(problem, seed, max_nodes=nodes).metrics.nodes
    elapsed, cpu = time.perf_counter() - began, time.process_time() - cpu_began
    print(json.dumps({"ms_per_node": elapsed * 1e3 / max(total, 1), "cpu_ms_per_node": cpu * 1e3 / max(total, 1),
                      "nodes": total, "module": qc.__file__}))
else:
    wall = rounds = total = 0
    for seed, problem in enumerate(problems):
        answers = []
        recorded = plan(problem, seed, Recorded(geometry(problem), answers, True), max_nodes=nodes)
        replayer = Recorded(geometry(problem), answers, False)
        replayed = plan(problem, seed, replayer, max_nodes=nodes)
        same = (np.array_equal(replayed.nodes, recorded.nodes) and np.array_equal(replayed.parents, recorded.parents)
                and replayed.metrics.oracle_calls == recorded.metrics.oracle_calls)
        if not same or replayer.calls != len(answers):
            raise RuntimeError(f"world {seed}: the replayed plan is not the recorded one")
        wall += replayed.metrics.wall_time_s
        rounds += replayed.metrics.rounds
        total += replayed.metrics.nodes
    print(json.dumps({"us_per_round_replayed": wall * 1e6 / max(rounds, 1), "rounds": rounds, "nodes": total,
                      "module": qc.__file__}))
"""



def run_child(src: Path, planner: str, backend: str, worlds: int, nodes: int, replay: bool = False,
              unreachable_goal: bool = False) -> dict:
    """One interpreter importing ``qrrt_circuits`` from ``src``; its JSON line."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(src), os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep))
    done = subprocess.run([sys.executable, "-c", CHILD, planner, backend, str(worlds), str(nodes), str(int(replay)),
                           str(int(unreachable_goal))], env=env, capture_output=True, text=True, check=True)
    result = json.loads(done.stdout.strip().splitlines()[-1])
    if not Path(result["module"]).resolve().is_relative_to(src.resolve()):
        raise RuntimeError(f"the child imported {result['module']}, not the code under {src}")
    return result


def checkout_commit(source: Path) -> dict:
    """The git commit of the checkout holding ``source`` and whether its tree differs from it
    (``None`` for each when ``source`` is not in a git checkout), so a result names its baseline."""
    def git(*args: str) -> str | None:
        done = subprocess.run(["git", "-C", str(source), *args], capture_output=True, text=True)
        return done.stdout.strip() if done.returncode == 0 else None

    commit = git("rev-parse", "HEAD")
    status = git("status", "--porcelain", "--untracked-files=no") if commit else None
    return {"commit": commit, "dirty": None if status is None else bool(status)}


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline-src", required=True, metavar="SRC", help="another checkout's src directory")
    parser.add_argument("--planner", default="qrrt")
    parser.add_argument("--backend", default="aer")
    parser.add_argument("--pairs", type=int, default=4)
    parser.add_argument("--worlds", type=int, default=6)
    parser.add_argument("--nodes", type=int, default=100)
    parser.add_argument("--replay", action="store_true",
                        help="time the rounds outside the predicate (its recorded answers replayed)")
    parser.add_argument("--unreachable-goal", action="store_true",
                        help="goal radius 1e-9: a plan ends at --nodes or the default round limit")
    parser.add_argument("--cpu-time", action="store_true",
                        help="compare processor time per node (time.process_time) instead of wall time")
    parser.add_argument("--out", default=None)
    args = parser.parse_args(argv)
    baseline = Path(args.baseline_src)
    if not (baseline / "qrrt_circuits" / "__init__.py").is_file():
        parser.error(f"--baseline-src must be a checkout's src directory (holding qrrt_circuits/), got {baseline}")
    load_at_start = list(os.getloadavg()) if hasattr(os, "getloadavg") else None  # (how busy the machine was)
    for name in ("pairs", "worlds", "nodes"):
        if getattr(args, name) < 1:
            parser.error(f"--{name} must be >= 1, got {getattr(args, name)}")
    if args.replay and args.cpu_time:
        parser.error("--cpu-time times whole plans; it does not combine with --replay")
    key, unit = ("us_per_round_replayed", "us per round outside the predicate") if args.replay else \
        ("cpu_ms_per_node", "CPU ms per node") if args.cpu_time else ("ms_per_node", "ms per node")
    pairs = []
    for pair in range(args.pairs):
        order = ("baseline", "ours") if pair % 2 == 0 else ("ours", "baseline")
        row = {"first": order[0]}
        for side in order:
            row[side] = run_child(baseline if side == "baseline" else OURS, args.planner, args.backend,
                                  args.worlds, args.nodes, args.replay, args.unreachable_goal)
        pairs.append(row)
        print(f"pair {pair}: baseline {row['baseline'][key]:.3f}  ours {row['ours'][key]:.3f} {unit} "
              f"({order[0]} first)")
    medians = {side: float(np.median([row[side][key] for row in pairs])) for side in ("baseline", "ours")}
    pair_ratio = float(np.median([row["baseline"][key] / row["ours"][key] for row in pairs]))
    print(f"medians: baseline {medians['baseline']:.3f}, ours {medians['ours']:.3f} {unit}; "
          f"baseline / ours = {medians['baseline'] / medians['ours']:.2f}; median of the pairs' ratios "
          f"{pair_ratio:.2f}")
    path = write_json(f"ab_{args.planner}_{args.backend}",
                      {"machine": machine(), "load_average_at_start": load_at_start, "baseline_src": str(baseline),
                       "baseline_checkout": checkout_commit(baseline), "ours_src": str(OURS),
                       "ours_checkout": checkout_commit(OURS), "planner": args.planner,
                       "backend": args.backend, "worlds": args.worlds, "nodes": args.nodes, "replay": args.replay,
                       "unreachable_goal": args.unreachable_goal, "figure": key, "pairs": pairs,
                       f"median_{key}": medians,
                       "baseline_over_ours": medians["baseline"] / medians["ours"],
                       "median_pair_baseline_over_ours": pair_ratio}, args.out)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
