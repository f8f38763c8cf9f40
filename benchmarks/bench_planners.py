"""Oracle calls per node, milliseconds per node and the oracle's share of the time for every
planner on paper_clutter.

    python benchmarks/bench_planners.py [--quick] [--seeds 20] [--nodes 100] [--big-nodes 3000]
                                        [--big-seeds 3] [--out FILE]

Each configuration plans on paper_clutter worlds seeds 0..S-1 (planner seed = world seed) until
``--nodes`` nodes or the goal. Per run: oracle calls / node, critical-path calls / node, wall
ms / node, the oracle share (wall time inside the predicate's ``reachable`` calls / the plan's wall
time; the predicate is the exact ``ExactCheck`` wrapped in a timer) and the non-oracle
microseconds per round; the table gives the median and the 10th-90th percentile spread over seeds.
The "3000 nodes" rows grow q-RRT trees to ``--big-nodes`` nodes on the first ``--big-seeds`` worlds
with the goal made unreachable (goal radius 1e-9), so the per-round cost can be compared at 100
and 3000 nodes. If ``ompl`` is importable (``pip install ".[ompl]"``), OMPL's RRT runs on the same
worlds with our closed-loop motion check (a Python MotionValidator) right after our RRT, and the
ratio of their median ms per node is printed. The round breakdown times the parts of a quantum
round. The ratio of q-RRT on Aer over the statevector planner is also measured interleaved: per
world the two planners one right after the other (``interleaved``, the two in alternating order),
so that a drift of the machine's speed between sections does not enter the ratio. Writes JSON.
"""

from __future__ import annotations

import argparse
import sys
import time
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
    ("QRRT statevector 3000 nodes", "qrrt", "statevector", "paper"),
    ("QRRT aer", "qrrt", "aer", "paper"),
    ("PQRRT shared statevector", "pqrrt", "statevector", "paper"),
    ("PQRRT shared aer", "pqrrt", "aer", "paper"),
    ("PQRRT unshared statevector", "pqrrt-unshared", "statevector", "paper"),
    ("QRRT adaptive statevector", "qrrt", "statevector", "adaptive"),
    ("QRRT bbht statevector", "qrrt", "statevector", "bbht"),
    ("QRRT known-optimal statevector", "qrrt", "statevector", "optimal"),
)



#: the configurations grown to --big-nodes nodes with an unreachable goal
BIG = ("QRRT statevector 3000 nodes",)


class TimedPredicate:
    """A predicate that times its delegate's ``reachable`` calls (the oracle share)."""

    def __init__(self, delegate) -> None:
        self.delegate = delegate
        self.seconds = 0.0
        self.pairs = 0

    @property
    def dim(self) -> int:
        return self.delegate.dim

    @property
    def name(self) -> str:
        return self.delegate.name

    def describe(self) -> dict:
        return self.delegate.describe()

    def reachable(self, parents, children):
        began = time.perf_counter()
        out = self.delegate.reachable(parents, children)
        self.seconds += time.perf_counter() - began
        self.pairs += len(out)
        return out


class PartTimer:
    """Times the main parts of a quantum planner's round by wrapping, for the duration of a
    ``with`` block, the functions that do them: the nearest-node query of the candidates
    (``GridNearest.nearest``), the candidate draws (``Environment.sample_uniform``), the backend's
    searches as a plan runs them (``QuantumSearchBackend.run`` and ``run_sequence``, each with the
    generator it builds from its seed) and the keyed generators of the round (``RandomStreams.
    generator``: the database's, and the one its search seed is drawn from). The predicate is
    timed by ``TimedPredicate``; the rest of the round (the policy, verification, bookkeeping, the
    planner's loop) is the plan's wall time minus these."""

    def __init__(self) -> None:
        self.seconds = {"nearest": 0.0, "candidate_draws": 0.0, "search": 0.0, "keyed_generators": 0.0}
        self._patched: list[tuple[object, str, object]] = []

    def _wrap(self, owner, attribute: str, part: str) -> None:
        original = getattr(owner, attribute)
        seconds = self.seconds

        def timed(*args, **kwargs):
            began = time.perf_counter()
            try:
                return original(*args, **kwargs)
            finally:
                seconds[part] += time.perf_counter() - began

        self._patched.append((owner, attribute, original))
        setattr(owner, attribute, timed)

    def __enter__(self) -> PartTimer:
        from qrrt_circuits._support.randomness import RandomStreams
        from qrrt_circuits.search.backends.base import QuantumSearchBackend
        from qrrt_circuits.world.environment import Environment
        from qrrt_circuits.world.nearest import GridNearest

        self._wrap(GridNearest, "nearest", "nearest")
        self._wrap(Environment, "sample_uniform", "candidate_draws")
        self._wrap(QuantumSearchBackend, "run", "search")
        self._wrap(QuantumSearchBackend, "run_sequence", "search")
        self._wrap(RandomStreams, "generator", "keyed_generators")
        return self

    def __exit__(self, *exc_info) -> None:
        for owner, attribute, original in reversed(self._patched):
            setattr(owner, attribute, original)
        self._patched.clear()


def _timed(problem, big: bool):
    """The problem with a timed exact check (and, for the big trees, an unreachable goal)."""
    predicate = TimedPredicate(qc.ExactCheck(problem.env))
    posed = problem.replace(predicate=predicate)
    return (posed.with_goal_radius(1e-9) if big else posed), predicate


def breakdown(make, env, seed: int, nodes: int, big: bool) -> dict:
    """Microseconds per round in the predicate, the nearest-node queries, the candidate draws, the
    backend search, the keyed generators and the rest, for one plan (the wrappers add about a
    microsecond per call)."""
    problem, predicate = _timed(env, big)
    planner = make(seed)
    with PartTimer() as parts:
        result = planner.plan(problem, max_nodes=nodes)
    rounds = max(result.metrics.rounds, 1)
    wall = result.metrics.wall_time_s
    per_round = {"predicate": predicate.seconds, **parts.seconds}
    per_round["rest"] = wall - sum(per_round.values())
    entries = float(np.sum(result.history["entries"]))
    return {"seed": seed, "nodes": result.metrics.nodes, "rounds": result.metrics.rounds,
            "reachable_fraction": float(np.sum(result.history["reachable"])) / entries if entries else float("nan"),
            "predicate_us_per_pair": predicate.seconds * 1e6 / max(predicate.pairs, 1),
            "us_per_round": {k: v * 1e6 / rounds for k, v in per_round.items()},
            "share": {k: v / wall for k, v in per_round.items()}}


#: configurations whose round is broken down into parts (label, configuration, big, planner options)
BREAKDOWN = tuple((label, label, big, {})
                  for label, big in (("QRRT statevector", False), ("QRRT statevector 3000 nodes", True),
                                     ("PQRRT shared statevector", False)))


def configurations(**options):
    """label -> planner factory (seed), every planner built through the registry (``options`` go
    to the quantum planners)."""
    from qrrt_circuits.experiments.planners import make_planner

    def factory(planner, backend, policy, extra):
        return lambda seed: make_planner(planner, seed, backend or "statevector", search_policy=policy, **extra)

    return {label: factory(planner, backend, policy, options if backend else {})
            for label, planner, backend, policy in CONFIGURATIONS}


def summarize(values: list[float]) -> dict:
    arr = np.asarray(values, dtype=float)
    return {"median": float(np.median(arr)), "p10": float(np.percentile(arr, 10)),
            "p90": float(np.percentile(arr, 90)), "mean": float(arr.mean())}


def run_one(make, env, seed: int, nodes: int, big: bool) -> dict:
    problem, predicate = _timed(env, big)
    result = make(seed).plan(problem, max_nodes=nodes)
    m = result.metrics
    count = max(m.nodes, 1)
    other_s = max(m.wall_time_s - predicate.seconds, 0.0)
    return {"seed": seed, "nodes": m.nodes, "rounds": m.rounds, "oracle_calls": m.oracle_calls,
            "critical_path": m.critical_path_oracle_calls, "wasted_checks": m.wasted_checks,
            "predicate_pairs": predicate.pairs,
            "calls_per_node": m.oracle_calls / count,
            "critical_per_node": m.critical_path_oracle_calls / count,
            "ms_per_node": m.wall_time_s * 1e3 / count,
            "ms_per_call": m.wall_time_s * 1e3 / max(m.oracle_calls, 1),
            "oracle_share": predicate.seconds / m.wall_time_s if m.wall_time_s > 0 else float("nan"),
            "other_us_per_round": other_s * 1e6 / max(m.rounds, 1),
            "reached": result.status == "reached", "labels": list(result.labels)}


#: the ratio targets of the performance work (README, *Benchmarks*: q-RRT on Aer over the
#: statevector planner), each measured world by world with the two planners run one right after
#: the other (numerator, denominator): a machine whose speed drifts over minutes (seen: the same
#: planner 1.5x slower from one section of a run to the next) moves both sides alike
INTERLEAVED = (("QRRT aer", "QRRT statevector"),)


def interleaved_ratios(worlds: list[qc.Environment], nodes: int) -> dict:
    """For each pair of ``INTERLEAVED``: per world both planners to ``nodes`` nodes, the numerator
    first on even worlds and second on odd ones (so neither always runs first); the median ms per
    node of each and the ratio of the medians."""
    factories = configurations()
    out = {}
    for numerator, denominator in INTERLEAVED:
        times: dict[str, list[float]] = {numerator: [], denominator: []}
        for seed, env in enumerate(worlds):
            for name in ((numerator, denominator) if seed % 2 == 0 else (denominator, numerator)):
                times[name].append(run_one(factories[name], env, seed, nodes, False)["ms_per_node"])
        medians = {name: float(np.median(values)) for name, values in times.items()}
        out[f"{numerator} / {denominator}"] = {
            "numerator_ms_per_node": medians[numerator], "denominator_ms_per_node": medians[denominator],
            "ratio_of_medians": medians[numerator] / medians[denominator]}
    return out


def predicate_construction(env, repeats: int = 20) -> dict:
    """Milliseconds to build the exact predicate (every trial of an experiment builds one): its
    chord grid computed (the process-wide cache emptied first) and taken from the cache."""
    from qrrt_circuits.reachability import exact as oracle

    def median_ms(clear: bool) -> float:
        times = []
        for _ in range(repeats):
            if clear:
                oracle._CHORD_GRIDS.clear()
            start = time.perf_counter()
            qc.ExactCheck(env.env)
            times.append((time.perf_counter() - start) * 1e3)
        return float(np.median(times))

    return {"grid_computed_ms": median_ms(True), "grid_cached_ms": median_ms(False)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--nodes", type=int, default=100)
    parser.add_argument("--big-nodes", type=int, default=3000)
    parser.add_argument("--big-seeds", type=int, default=3)
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    seeds = 4 if args.quick else args.seeds
    nodes = 30 if args.quick else args.nodes
    big_nodes = 300 if args.quick else args.big_nodes
    big_seeds = 1 if args.quick else args.big_seeds
    worlds = [qc.paper_clutter(seed=s) for s in range(seeds)]
    qc.RRT(seed=0).plan(worlds[0], max_rounds=5)  # compile the oracle kernel
    qc.QRRT(backend=qc.StatevectorBackend(), seed=0).plan(worlds[0], max_rounds=5)  # and the tree's
    try:
        from ompl_rrt import ompl_available, run_ompl_rrt
    except ImportError:
        ompl_available = None
    with_ompl = ompl_available is not None and ompl_available()
    rows = {}
    ompl_rows = None
    print(f"{'planner':40s} {'calls/node':>18s} {'critical/node':>14s} {'ms/node':>18s} {'oracle':>7s} "
          f"{'other us/rnd':>12s} {'reached':>8s}")
    settings = {label: {"planner": planner, "backend": backend, "search_policy": policy}
                for label, planner, backend, policy in CONFIGURATIONS}
    for name, make in configurations().items():
        big = name in BIG
        runs = [run_one(make, env, seed, big_nodes if big else nodes, big)
                for seed, env in enumerate(worlds[:big_seeds] if big else worlds)]
        pooled = sum(r["oracle_calls"] for r in runs) / max(sum(r["nodes"] for r in runs), 1)
        row = {"runs": runs, "max_nodes": big_nodes if big else nodes, "settings": settings[name],
               "goal": "unreachable (goal radius 1e-9)" if big else "the world's",
               "calls_per_node": summarize([r["calls_per_node"] for r in runs]),
               "critical_per_node": summarize([r["critical_per_node"] for r in runs]),
               "ms_per_node": summarize([r["ms_per_node"] for r in runs]),
               "ms_per_call": summarize([r["ms_per_call"] for r in runs]),
               "oracle_share": summarize([r["oracle_share"] for r in runs]),
               "other_us_per_round": summarize([r["other_us_per_round"] for r in runs]),
               "pooled_calls_per_node": pooled,
               "reached_fraction": float(np.mean([r["reached"] for r in runs]))}
        rows[name] = row
        c, k, t = row["calls_per_node"], row["critical_per_node"], row["ms_per_node"]
        print(f"{name:40s} {c['median']:6.2f} [{c['p10']:5.2f},{c['p90']:6.2f}] {k['median']:14.2f} "
              f"{t['median']:7.3f} [{t['p10']:5.2f},{t['p90']:6.2f}] {row['oracle_share']['median']:7.2f} "
              f"{row['other_us_per_round']['median']:12.1f} {row['reached_fraction']:8.2f}")
        if name == "RRT" and with_ompl:  # side by side, right after ours
            ompl_runs = [run_ompl_rrt(env.env, env.start, env.goal.centre, env.goal.radius, nodes, seed)
                         for seed, env in enumerate(worlds)]
            ompl_rows = {"runs": ompl_runs, "ms_per_node": summarize([r["ms_per_node"] for r in ompl_runs])}
            t = ompl_rows["ms_per_node"]
            ompl_rows["ours_over_ompl"] = row["ms_per_node"]["median"] / t["median"]
            print(f"{'OMPL RRT (our motion check)':40s} {'':>18s} {'':>14s} "
                  f"{t['median']:7.3f} [{t['p10']:5.2f},{t['p90']:6.2f}]   (RRT / OMPL ms per node: "
                  f"{ompl_rows['ours_over_ompl']:.2f})")
    if not with_ompl:
        print("(ompl not importable: OMPL comparison skipped; pip install '.[ompl]')")
    parts = {}
    print(f"\n{'round breakdown, us per round':44s} " + " ".join(f"{k:>15s}" for k in
          ("predicate", "nearest", "candidate_draws", "search", "keyed_generators", "rest")))
    for name, configuration, big, options in BREAKDOWN:
        make = configurations(**options)[configuration]
        runs = [breakdown(make, env, seed, big_nodes if big else nodes, big)
                for seed, env in enumerate(worlds[:big_seeds] if big else worlds)]
        medians = {k: float(np.median([r["us_per_round"][k] for r in runs])) for k in runs[0]["us_per_round"]}
        shares = {k: float(np.median([r["share"][k] for r in runs])) for k in runs[0]["share"]}
        parts[name] = {"runs": runs, "us_per_round": medians, "share": shares,
                       "reachable_fraction": float(np.median([r["reachable_fraction"] for r in runs])),
                       "predicate_us_per_pair": float(np.median([r["predicate_us_per_pair"] for r in runs]))}
        print(f"{name:44s} " + " ".join(f"{medians[k]:8.1f} ({shares[k]:3.0%})" for k in medians)
              + f"   reachable {parts[name]['reachable_fraction']:.2f}, "
              f"predicate {parts[name]['predicate_us_per_pair']:.2f} us/pair")
    ratios = interleaved_ratios(worlds, nodes)
    print()
    for name, row in ratios.items():
        print(f"interleaved seed by seed, {name}: {row['numerator_ms_per_node']:.3f} / "
              f"{row['denominator_ms_per_node']:.3f} ms per node = {row['ratio_of_medians']:.2f}")
    construction = predicate_construction(worlds[0])
    print(f"\nexact predicate built: {construction['grid_computed_ms']:.2f} ms computing its chord grid, "
          f"{construction['grid_cached_ms']:.2f} ms with the grid cached")
    path = write_json("bench_planners" + ("_quick" if args.quick else ""),
                      {"machine": machine(), "seeds": seeds, "max_nodes": nodes, "big_nodes": big_nodes,
                       "big_seeds": big_seeds, "planners": rows, "ompl_rrt": ompl_rows,
                       "round_breakdown": parts, "interleaved": ratios, "predicate_construction": construction,
                       "note": "quantum planners: phase oracle built from a classical lookup of all "
                               "2^n entries (simulation_checks); shared Pq-RRT: one search with p "
                               "shots stands for p workers; 'known-optimal' uses the true m; "
                               "oracle_share: wall time inside predicate.reachable / plan wall time; "
                               "RRT and ParallelRRT test rounds in batches (wasted_checks: tests of "
                               "rounds that never ran, not oracle calls); round_breakdown: medians "
                               "over seeds of the time per round in each part (PartTimer)"},
                      args.out)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
