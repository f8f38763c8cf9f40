"""What one keyed random stream costs: the first d + 1 doubles of the generator of a key (round,
worker, stream), as the classical planners draw one candidate per key.

    python benchmarks/bench_streams.py [--quick] [--out FILE]

Two ways to the same doubles (asserted equal before timing), per key, for ``KEYS`` consecutive
rounds of one worker:

- ``documented``: numpy's documented constructors, one per key:
  ``Generator(PCG64(SeedSequence(entropy, spawn_key=key))).random(d + 1)``;
- ``compiled``: ``randomness.uniform_draws`` (the library's compiled seed words and PCG64 doubles,
  all keys in one call), as ``keyed_samples`` draws them;
- ``compiled_one_key``: the same for a single key (one call per key).

Also the library's RRT time per motion check in the maze family (``bench_problems``' setting,
``SEEDS`` plans), the yardstick the per-key cost is read against. Writes
``benchmarks/results/bench_streams.json``: microseconds per key (``us_per_key``), medians of ``REPEATS`` timings.
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
from qrrt_circuits._support.randomness import RandomStreams, Stream, round_keys, uniform_draws  # noqa: E402
from qrrt_circuits.experiments.problems import build_problem, ompl_range  # noqa: E402

KEYS = 256
REPEATS = 15
SEEDS = 20


def documented_draws(streams: RandomStreams, keys: np.ndarray, count: int) -> np.ndarray:
    """The first ``count`` doubles of each key's generator, built with numpy's documented API."""
    return np.array([np.random.Generator(np.random.PCG64(np.random.SeedSequence(
        streams.entropy, spawn_key=tuple(int(part) for part in key)))).random(count) for key in keys])


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


def per_key_costs(streams: RandomStreams, keys: np.ndarray, count: int, repeats: int) -> dict:
    """Microseconds per key of ``count`` doubles, each way (asserted equal first)."""
    if not np.array_equal(documented_draws(streams, keys, count), uniform_draws(streams, keys, count)):
        raise AssertionError("the compiled draws differ from numpy's")
    one_by_one = [keys[row:row + 1] for row in range(keys.shape[0])]
    documented = median_time(functools.partial(documented_draws, streams, keys, count), repeats)[0]
    compiled = median_time(functools.partial(uniform_draws, streams, keys, count), repeats)[0]
    one = median_time(lambda: [uniform_draws(streams, key, count) for key in one_by_one], repeats)[0]
    return {"documented": {"us_per_key": 1e6 * documented / keys.shape[0]},
            "compiled": {"us_per_key": 1e6 * compiled / keys.shape[0]},
            "compiled_one_key": {"us_per_key": 1e6 * one / keys.shape[0]},
            "documented_over_compiled": documented / compiled}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    repeats, seeds = (3, 4) if args.quick else (REPEATS, SEEDS)
    streams = RandomStreams.from_seed(2024)
    out: dict = {"machine": machine(), "keys": KEYS, "repeats": repeats, "dims": {}}
    keys = round_keys(1000, KEYS, 1, int(Stream.CANDIDATES))
    for dim in (2, 6):
        out["dims"][str(dim)] = row = per_key_costs(streams, keys, dim + 1, repeats)
        print(f"d = {dim}: documented {row['documented']['us_per_key']:.2f} µs/key, compiled "
              f"{row['compiled']['us_per_key']:.3f} µs/key "
              f"(one key a call {row['compiled_one_key']['us_per_key']:.2f})")
    out["rrt_maze"] = {"us_per_check": rrt_us_per_check(seeds)}
    print(f"RRT on the maze: {out['rrt_maze']['us_per_check']:.2f} µs per motion check")
    print(f"wrote {write_json('bench_streams', out, args.out)}")


if __name__ == "__main__":
    main()
