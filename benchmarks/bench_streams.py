"""What a plan's random draws cost: a keyed generator per (round, worker, stream), against the
sequential stream the classical planners draw their candidates from.

    python benchmarks/bench_streams.py [--quick] [--out FILE]

Per candidate, the d + 1 doubles of one classical extension sample (``KEYS`` candidates of
consecutive rounds of one worker):

- ``keyed``: a generator per key (round, worker, stream), built by ``RandomStreams.generator``
  (numpy's ``SeedSequence(entropy, spawn_key=key)``), then ``random(d + 1)``: what each quantum
  round pays per generator it builds;
- ``sequential``: the plan's sequential ``Stream.EXTENSION_SAMPLES`` generator
  (``RandomStreams.sequence``), all candidates in one ``random((K, d + 1))`` call, as a batch of
  rounds tested ahead draws them;
- ``sequential_one_call_each``: the same, one call per candidate (a round drawn on its own).

Also the library's RRT time per motion check in the maze family (``bench_problems``' setting,
``SEEDS`` plans), the yardstick the per-candidate cost is read against. Writes
``benchmarks/results/bench_streams.json``: microseconds per candidate (``us_per_key``), medians of
``REPEATS`` timings.
"""

from __future__ import annotations

import argparse
import functools
import os
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from _common import machine, median_time, write_json  # noqa: E402

import qrrt_circuits as qc  # noqa: E402
from qrrt_circuits._support.randomness import RandomStreams, Stream  # noqa: E402
from qrrt_circuits.experiments.problems import build_problem, ompl_range  # noqa: E402

KEYS = 256
REPEATS = 15
SEEDS = 20


def keyed_draws(streams: RandomStreams, rounds: range, count: int) -> np.ndarray:
    """The first ``count`` doubles of each round's keyed generator (worker 0, candidates' stream)."""
    return np.array([streams.generator(round_index, 0, Stream.CANDIDATES).random(count) for round_index in rounds])


def rrt_us_per_check(seeds: int) -> float:
    """The library's RRT on the maze family: wall time per motion check (µs) over ``seeds`` plans."""
    problem = build_problem("maze", 0)
    elapsed = checks = 0.0
    for seed in range(seeds + 1):
        planner = qc.RRT(goal_bias=0.05, max_extension=ompl_range(problem), seed=seed)
        began = time.perf_counter()
        result = planner.plan(problem, max_oracle_calls=5000)
        if seed:  # the first plan warms the compiled code
            elapsed += time.perf_counter() - began
            checks += result.metrics.oracle_calls
    return 1e6 * elapsed / checks


def per_key_costs(streams: RandomStreams, rounds: range, count: int, repeats: int) -> dict:
    """Microseconds per candidate of ``count`` doubles, each way."""
    keys = len(rounds)

    def sequential() -> np.ndarray:
        return streams.sequence(Stream.EXTENSION_SAMPLES).random((keys, count))

    def sequential_one_call_each() -> list[np.ndarray]:
        generator = streams.sequence(Stream.EXTENSION_SAMPLES)
        return [generator.random((1, count)) for _ in range(keys)]

    if not np.array_equal(sequential(), np.concatenate(sequential_one_call_each())):
        raise AssertionError("the sequential stream's batch differs from its draws one by one")
    keyed = median_time(functools.partial(keyed_draws, streams, rounds, count), repeats)[0]
    batch = median_time(sequential, repeats)[0]
    each = median_time(sequential_one_call_each, repeats)[0]
    return {"keyed": {"us_per_key": 1e6 * keyed / keys},
            "sequential": {"us_per_key": 1e6 * batch / keys},
            "sequential_one_call_each": {"us_per_key": 1e6 * each / keys},
            "keyed_over_sequential": keyed / batch}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    repeats, seeds = (3, 4) if args.quick else (REPEATS, SEEDS)
    streams = RandomStreams.from_seed(2024)
    out: dict = {"machine": machine(), "keys": KEYS, "repeats": repeats, "dims": {}}
    rounds = range(1000, 1000 + KEYS)
    for dim in (2, 6):
        out["dims"][str(dim)] = row = per_key_costs(streams, rounds, dim + 1, repeats)
        print(f"d = {dim}: keyed {row['keyed']['us_per_key']:.2f} µs/candidate, sequential "
              f"{row['sequential']['us_per_key']:.3f} µs/candidate "
              f"(one call each {row['sequential_one_call_each']['us_per_key']:.2f})")
    out["rrt_maze"] = {"us_per_check": rrt_us_per_check(seeds)}
    print(f"RRT on the maze: {out['rrt_maze']['us_per_check']:.2f} µs per motion check")
    print(f"wrote {write_json('bench_streams', out, args.out)}")


if __name__ == "__main__":
    main()
