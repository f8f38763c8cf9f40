"""Time per motion check and per node of the library's RRT beside OMPL's RRT on the same check, and
q-RRT's time per oracle call, on the problem families of ``qrrt reproduce problems``.

    python benchmarks/bench_problems.py [--quick] [--out FILE]

Per family, ``RUNS`` seeds of each planner plan until the goal or ``BUDGET`` motion checks:

- ``rrt``: the library's RRT with OMPL's range (0.2 of the bounds' diagonal) and goal bias 0.05, the
  algorithm of OMPL's RRT (the same tree whether rounds are tested ahead or not), with its default
  look-ahead (rounds tested ahead in batches; the tests thrown away are in the wall time and in
  ``wasted_per_check``);
- ``rrt_one_by_one``: the same with ``look_ahead=False`` (one predicate call per oracle call);
- ``ompl_rrt``: OMPL's ``geometric::RRT`` with its defaults (the same range and goal bias), the same
  predicate as its motion validator (``experiments.ompl_runs``), when the ``ompl`` extra is
  installed;
- ``qrrt``: q-RRT with ``Adaptive()``, 2^8 databases on the exact statevector;
- ``one_screen_rrt``: the floor of a round written in Python, RRT on one screen (``one_screen_rrt``):
  a sample, the nearest node from the space's own nearest-neighbour structure, a step of OMPL's
  range (the library's ``steer``: the space's ``distance`` and ``interpolate``), the problem's check
  and goal, one round per motion check, with no counters, history, look-ahead or checks of its
  input; a measuring device, not a planner of the library (its random draws are its own);
- ``*_python_check`` (with OMPL): ``rrt``, ``rrt_one_by_one`` and ``ompl_rrt`` with the predicate
  asked one pair at a time from a Python loop, each pair also paying ``PYTHON_WORK`` Python
  additions (``PairByPair``): a checker whose cost is Python's and dominates, the same on both
  sides.

A run's wall time is its search, like for like: the library's round loop (``Metrics.wall_time_s``,
what ``qrrt reproduce problems`` compares) beside OMPL's ``SimpleSetup.solve``. Its whole call is
timed too: the library's ``plan()`` (its checks of the request, memory estimate, run state and tree,
and result) beside ``ompl_run`` (the OMPL setup and planner built from the problem, ``setup()``,
``solve()`` and the path read back); OMPL's side is OMPL driven from Python (its motion checks and
termination condition are Python callbacks). Every planner's predicate is timed (its ``reachable``
wrapped by a timer), so a run's wall time splits into the time inside the check and the planner's
own time. Figures, per family and planner: ``us_per_check`` (wall time over motion checks or oracle
calls), ``check_us_per_check`` (inside the predicate), ``own_us_per_check`` (the rest: sampling,
nearest neighbours, tree, for q-RRT the database and the search), ``call_us_per_check`` (the whole
call over the checks), ``outside_search_us_per_plan`` (a call's time outside its search, per plan),
``us_per_node``; and the ratios ``rrt_over_ompl_wall`` and ``rrt_over_ompl_own`` (pooled: total time
over total checks), ``rrt_over_ompl_per_run`` (the ratio of the medians of each run's wall time per
check, with a 95 % bootstrap interval), ``*_call_per_run`` (the same of the whole calls) and
``one_screen_rrt_over_ompl_per_run``, all in one run on one machine. ``profile``: where one plan's
time goes on the maze family, per planner (``cProfile``, the functions with the most own time,
microseconds per round). Prints a table and writes JSON.
"""

from __future__ import annotations

import argparse
import functools
import importlib.util
import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from _common import machine, write_json  # noqa: E402

import qrrt_circuits as qc  # noqa: E402
from qrrt_circuits.experiments.problems import build_problem, ompl_range  # noqa: E402
from qrrt_circuits.planners.database import steer  # noqa: E402
from qrrt_circuits.problems.families import Problem  # noqa: E402
from qrrt_circuits.problems.goals import sample_goal  # noqa: E402

BUDGET = 5000
#: the library's planners of the benchmark
LIBRARY = ("rrt", "rrt_one_by_one", "qrrt")


def timed(problem: Problem) -> list[float]:
    """Wrap the problem's ``reachable`` by a timer; returns the list the seconds are added to."""
    spent = [0.0]
    inner: Callable[..., Any] = problem.predicate.reachable

    def reachable(parents: np.ndarray, children: np.ndarray) -> np.ndarray:
        began = time.perf_counter()
        try:
            return inner(parents, children)
        finally:
            spent[0] += time.perf_counter() - began

    problem.predicate.reachable = reachable  # type: ignore[method-assign]
    return spent


#: Python additions ``PairByPair`` makes per pair besides the check (a user's own Python work)
PYTHON_WORK = 2000


class PairByPair:
    """The problem's predicate asked one pair at a time from a Python loop, each pair also paying
    ``PYTHON_WORK`` Python additions: a checker whose cost is Python's and dominates the planner's,
    the same answers on both sides."""

    def __init__(self, inner: Any) -> None:
        self.inner, self.dim, self.name = inner, inner.dim, f"{inner.name}, pair by pair"

    def reachable(self, parents: np.ndarray, children: np.ndarray) -> np.ndarray:
        parents, children = np.atleast_2d(parents), np.atleast_2d(children)
        answers = np.empty(children.shape[0], dtype=bool)
        for row in range(children.shape[0]):
            total = 0
            for step in range(PYTHON_WORK):
                total += step
            answers[row] = bool(self.inner.reachable(parents[row:row + 1], children[row:row + 1])[0]) and total >= 0
        return answers

    def describe(self) -> dict:
        return self.inner.describe() | {"pair_by_pair": True}

    def __getattr__(self, name: str) -> Any:  # (is_valid, can_leave, ... of the inner check)
        return getattr(self.inner, name)


def posed(family: str, python_check: bool) -> Problem:
    """The family's world 0, its predicate asked pair by pair with ``python_check``."""
    problem = build_problem(family, 0)
    return problem.replace(predicate=PairByPair(problem.predicate)) if python_check else problem


def make(planner: str, problem: Problem, seed: int) -> qc.Planner:
    """The library's ``rrt``, ``rrt_one_by_one`` or ``qrrt`` of the benchmark."""
    if planner in ("rrt", "rrt_one_by_one"):
        return qc.RRT(goal_bias=0.05, max_extension=ompl_range(problem), look_ahead=planner == "rrt", seed=seed)
    return qc.QRRT(backend=qc.StatevectorBackend(seed=seed), search_policy=qc.Adaptive(), goal_bias=0.05, seed=seed)


def run_library(family: str, planner: str, seed: int, python_check: bool = False) -> dict[str, float]:
    """One run of the library's ``rrt``, ``rrt_one_by_one`` or ``qrrt`` on a fresh problem."""
    problem = posed(family, python_check)
    spent = timed(problem)
    plan = make(planner, problem, seed)
    began = time.perf_counter()
    result = plan.plan(problem, max_oracle_calls=BUDGET)
    call = time.perf_counter() - began
    return {"wall_s": result.metrics.wall_time_s, "call_s": call, "check_s": spent[0],
            "checks": result.metrics.oracle_calls,
            "nodes": result.metrics.nodes, "reached": float(result.reached),
            "wasted": result.metrics.wasted_checks}


def run_ompl(family: str, seed: int, python_check: bool = False) -> dict[str, float]:
    """One run of OMPL's RRT on a fresh problem (its node count is not read back: NaN)."""
    from qrrt_circuits.experiments.ompl_runs import ompl_run

    problem = posed(family, python_check)
    spent = timed(problem)
    began = time.perf_counter()
    run = ompl_run(problem, "OMPL RRT", BUDGET, seed + 1, 0.05)
    call = time.perf_counter() - began
    return {"wall_s": run.wall_time_s, "call_s": call, "check_s": spent[0], "checks": run.motion_checks,
            "nodes": float("nan"),
            "reached": float(run.reached), "wasted": 0}


def one_screen_rrt(problem: Problem, seed: int, budget: int = BUDGET,
                   goal_bias: float = 0.05) -> tuple[int, int, bool]:
    """RRT on one screen (OMPL's algorithm, the paper's Alg. 1) on the problem's own parts, until a
    node satisfies the goal or ``budget`` motion checks: returns (motion checks, nodes, reached)."""
    rng = np.random.default_rng(seed)
    space, check, goal, step = problem.space, problem.predicate, problem.goal, ompl_range(problem)
    low, span = problem.env.bounds[:, 0], problem.env.bounds[:, 1] - problem.env.bounds[:, 0]
    nodes = np.empty((budget + 1, problem.dim))
    nodes[0] = problem.start
    near = space.nearest_neighbors()
    near.add(nodes[:1])
    size = 1
    for checks in range(1, budget + 1):
        draw = rng.random(problem.dim + 1)
        sample = sample_goal(goal, 1, rng) if draw[-1] < goal_bias else (low + span * draw[:-1])[None]
        origin = nodes[near.nearest(sample)]
        child = steer(space, origin, sample, step)
        if check.reachable(origin, child)[0]:
            nodes[size] = child[0]
            size += 1
            near.add(child)
            if goal.is_satisfied(child)[0]:
                return checks, size - 1, True
    return budget, size - 1, False


def run_one_screen(family: str, seed: int) -> dict[str, float]:
    """One run of ``one_screen_rrt`` on a fresh problem."""
    problem = posed(family, False)
    spent = timed(problem)
    began = time.perf_counter()
    checks, nodes, reached = one_screen_rrt(problem, seed)
    wall = time.perf_counter() - began
    return {"wall_s": wall, "call_s": wall, "check_s": spent[0], "checks": checks, "nodes": nodes,
            "reached": float(reached), "wasted": 0}


def per_run(runs: list[dict[str, float]], key: str = "wall_s") -> np.ndarray:
    """Each run's time per motion check (its search, ``wall_s``, or its whole call, ``call_s``), in
    microseconds."""
    return np.array([1e6 * r[key] / max(r["checks"], 1) for r in runs])


def ratio_of_medians(mine: np.ndarray, peer: np.ndarray, seed: int = 0) -> dict[str, float]:
    """median(mine) / median(peer) (wall time per check, one run each seed) with a 95 % percentile
    bootstrap interval (runs resampled within each planner, 2 000 resamples)."""
    rng = np.random.default_rng(seed)
    draws = [np.median(rng.choice(mine, mine.size)) / np.median(rng.choice(peer, peer.size)) for _ in range(2000)]
    low, high = np.percentile(draws, [2.5, 97.5])
    return {"median": float(np.median(mine) / np.median(peer)), "low": float(low), "high": float(high)}


def figures(runs: list[dict[str, float]]) -> dict[str, float]:
    """Pooled figures of a planner's runs on one family."""
    wall = sum(r["wall_s"] for r in runs)
    check = sum(r["check_s"] for r in runs)
    checks = sum(r["checks"] for r in runs)
    nodes = sum(r["nodes"] for r in runs)
    call = sum(r["call_s"] for r in runs)
    return {"us_per_check": 1e6 * wall / checks, "check_us_per_check": 1e6 * check / checks,
            "own_us_per_check": 1e6 * (wall - check) / checks, "call_us_per_check": 1e6 * call / checks,
            "outside_search_us_per_plan": 1e6 * (call - wall) / len(runs),
            "us_per_node": 1e6 * wall / nodes if np.isfinite(nodes) and nodes else float("nan"),
            "checks": float(checks), "wasted_per_check": sum(r["wasted"] for r in runs) / checks,
            "success_rate": float(np.mean([r["reached"] for r in runs]))}


def round_profile(family: str, planner: str, seed: int = 0, top: int = 15) -> dict[str, Any]:
    """Where one plan's time goes: ``cProfile`` of ``run_library(family, planner, seed)``, the
    ``top`` functions by their own time, in microseconds per round (profiling slows every call, so
    the shares matter, not the totals)."""
    import cProfile
    import pstats

    profiler = cProfile.Profile()
    problem = build_problem(family, 0)
    plan = make(planner, problem, seed)
    profiler.enable()
    result = plan.plan(problem, max_oracle_calls=BUDGET)
    profiler.disable()
    rounds = max(result.metrics.rounds, 1)
    stats = pstats.Stats(profiler).stats  # type: ignore[attr-defined]
    total = sum(entry[2] for entry in stats.values())
    rows = sorted(stats.items(), key=lambda item: -item[1][2])[:top]
    return {"rounds": rounds, "total_us_per_round": 1e6 * total / rounds,
            "functions": [{"function": f"{Path(key[0]).name}:{key[1]}({key[2]})", "calls_per_round": entry[1] / rounds,
                           "own_us_per_round": 1e6 * entry[2] / rounds, "share": entry[2] / total}
                          for key, entry in rows]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    families = ("open-space", "narrow-passage-2d") if args.quick else (
        "open-space", "maze", "narrow-passage-2d", "narrow-passage-4d", "se2-gap")
    runs = 3 if args.quick else 10
    have_ompl = importlib.util.find_spec("ompl") is not None
    out: dict[str, Any] = {"machine": machine(), "budget": BUDGET, "runs": runs, "ompl": have_ompl, "families": {}}
    header = ("family", "planner", "us/check", "in check", "own", "call", "us/node", "success")
    print(f"{header[0]:20s} {header[1]:14s} " + " ".join(f"{h:>9s}" for h in header[2:]))
    for family in families:
        planners: dict[str, Callable[[int], dict[str, float]]] = {
            name: functools.partial(run_library, family, name) for name in LIBRARY}
        planners["one_screen_rrt"] = functools.partial(run_one_screen, family)
        if have_ompl:
            planners["ompl_rrt"] = functools.partial(run_ompl, family)
            for name in ("rrt", "rrt_one_by_one"):
                planners[f"{name}_python_check"] = functools.partial(run_library, family, name, python_check=True)
            planners["ompl_rrt_python_check"] = functools.partial(run_ompl, family, python_check=True)
        raw: dict[str, list[dict[str, float]]] = {name: [] for name in planners}
        for run in planners.values():
            run(10_000)  # warm-up: numba compilation, caches
        for seed in range(runs):  # interleaved: a burst of load on the machine falls on every planner
            for name, run in planners.items():
                raw[name].append(run(seed))
        rows: dict[str, Any] = {planner: figures(value) for planner, value in raw.items()}
        if have_ompl:
            rows["ratios"] = {"rrt_over_ompl_wall": rows["rrt"]["us_per_check"] / rows["ompl_rrt"]["us_per_check"],
                              "rrt_over_ompl_own": rows["rrt"]["own_us_per_check"]
                              / rows["ompl_rrt"]["own_us_per_check"],
                              "rrt_one_by_one_over_ompl_wall": rows["rrt_one_by_one"]["us_per_check"]
                              / rows["ompl_rrt"]["us_per_check"],
                              "rrt_over_ompl_per_run": ratio_of_medians(per_run(raw["rrt"]), per_run(raw["ompl_rrt"])),
                              "rrt_one_by_one_over_ompl_per_run": ratio_of_medians(
                                  per_run(raw["rrt_one_by_one"]), per_run(raw["ompl_rrt"])),
                              "python_check_rrt_over_ompl_per_run": ratio_of_medians(
                                  per_run(raw["rrt_python_check"]), per_run(raw["ompl_rrt_python_check"])),
                              "python_check_rrt_one_by_one_over_ompl_per_run": ratio_of_medians(
                                  per_run(raw["rrt_one_by_one_python_check"]), per_run(raw["ompl_rrt_python_check"])),
                              "one_screen_rrt_over_ompl_per_run": ratio_of_medians(
                                  per_run(raw["one_screen_rrt"]), per_run(raw["ompl_rrt"])),
                              "rrt_over_ompl_call_per_run": ratio_of_medians(
                                  per_run(raw["rrt"], "call_s"), per_run(raw["ompl_rrt"], "call_s")),
                              "python_check_rrt_over_ompl_call_per_run": ratio_of_medians(
                                  per_run(raw["rrt_python_check"], "call_s"),
                                  per_run(raw["ompl_rrt_python_check"], "call_s"))}
        out["families"][family] = rows
        for planner, row in rows.items():
            if planner != "ratios":
                print(f"{family:20s} {planner:14s} {row['us_per_check']:9.1f} {row['check_us_per_check']:9.1f} "
                      f"{row['own_us_per_check']:9.1f} {row['call_us_per_check']:9.1f} {row['us_per_node']:9.1f} "
                      f"{row['success_rate']:8.2f}")
        if "ratios" in rows:
            print(f"{family:20s} RRT / OMPL RRT: wall per check {rows['ratios']['rrt_over_ompl_wall']:.2f}x, "
                  f"own time per check {rows['ratios']['rrt_over_ompl_own']:.2f}x")
    out["profile"] = {planner: round_profile("maze", planner) for planner in LIBRARY}
    if not have_ompl:
        print("OMPL is not installed (pip install 'qrrt-circuits[ompl]'): the OMPL figures were skipped")
    print(f"wrote {write_json('bench_problems', out, args.out)}")


if __name__ == "__main__":
    main()
