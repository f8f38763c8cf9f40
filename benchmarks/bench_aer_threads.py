"""Aer's threads at n >= 14: one Grover search on one thread, on all cores, and on the cores the
backend chooses by default (the cores free when the search starts, ``_support.free_cores``), on a
quiet machine and beside a competing process.

    python benchmarks/bench_aer_threads.py [--quick] [--out FILE]

On a machine shared with other work, a state update spread over more threads than there are idle
cores waits on the busy ones. This times ``AerBackend.search`` (k = 12, 8 shots, 4 marked entries)
at n = 14 and 16 (``--quick``: 14) with ``max_parallel_threads`` 1, 0 (all cores) and None (the
default), in that order, alternating over the repeats, once per competitor: none, then a process
that keeps one core busy a fraction ``duty`` of every 100 ms (35 %, 70 %, 100 %; ``--quick``: none
and 100 %). Per row it records the one-minute system load, the busy cores the process's meter
measured (``BusyMeter.others``), the usable cores and the thread count the default chose. Medians
of wall time per search. Prints a table and writes JSON.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time

import numpy as np
from _common import machine, write_json

import qrrt_circuits as qc
from qrrt_circuits._support.free_cores import busy_cores, free_cores, usable_cores

SETTINGS = {"one thread": 1, "all cores": 0, "default (free cores)": None}


#: a process that keeps one core busy ``duty`` of every 100 ms (argv: duty, seconds, the benchmark's
#: pid), until the seconds are over or the benchmark is gone (killed, its ``finally`` never ran)
COMPETITOR = """
import os, sys, time
duty, end, parent = float(sys.argv[1]), time.time() + float(sys.argv[2]), int(sys.argv[3])
while time.time() < end and os.getppid() == parent:
    began = time.time()
    while time.time() - began < 0.1 * duty:
        pass
    time.sleep(max(0.0, 0.1 * (1.0 - duty)))
"""


def measure(sizes: tuple[int, ...], repeats: int, duty: float, rng: np.random.Generator) -> list[dict]:
    """The rows of one competitor (``duty`` 0: none)."""
    backends = {label: qc.AerBackend(seed=0, max_parallel_threads=threads) for label, threads in SETTINGS.items()}
    competitor = None if duty == 0 else subprocess.Popen([sys.executable, "-c", COMPETITOR, str(duty), "600",
                                                                str(os.getpid())])
    rows = []
    try:
        time.sleep(0.5)  # (the competitor's interpreter starts; the meter's interval begins)
        free_cores()
        for n in sizes:
            marks = np.zeros(1 << n, dtype=bool)
            marks[rng.choice(1 << n, 4, replace=False)] = True
            oracle = qc.LookupOracle(marks)
            times: dict[str, list[float]] = {label: [] for label in SETTINGS}
            chosen = []
            for backend in backends.values():  # warm up
                backend.search(oracle, 12, shots=8, seed=1)
            for repeat in range(repeats):
                for label, backend in backends.items():
                    if SETTINGS[label] is None:
                        chosen.append(backend.threads_for(n))
                    began = time.perf_counter()
                    backend.search(oracle, 12, shots=8, seed=repeat)
                    times[label].append(time.perf_counter() - began)
            measured = busy_cores()
            row = {"competitor": "none" if duty == 0 else f"busy{round(100 * duty)}", "num_qubits": n,
                   "competitor_duty": duty, "load_average_1min": os.getloadavg()[0],
                   "measured_busy_cores": measured, "usable_cores": usable_cores(),
                   "free_cores_now": free_cores(), "default_threads_chosen": chosen,
                   "median_ms": {label: float(np.median(values)) * 1e3 for label, values in times.items()}}
            rows.append(row)
            busy = "n/a" if measured is None else f"{measured:.2f}"
            print(f"n = {n}, competitor {duty:.0%}: load {row['load_average_1min']:.2f}, measured busy {busy} of "
                  f"{row['usable_cores']} cores, default chose {chosen}; "
                  + ", ".join(f"{label} {ms:.1f} ms" for label, ms in row["median_ms"].items()))
    finally:
        if competitor is not None:
            competitor.kill()
            competitor.wait()
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    sizes, repeats, duties = ((14,), 3, (0.0, 1.0)) if args.quick else ((14, 16), 5, (0.0, 0.35, 0.7, 1.0))
    rng = np.random.default_rng(0)
    rows = [row for duty in duties for row in measure(sizes, repeats, duty, rng)]
    path = write_json("aer_threads", {"machine": machine(), "quick": args.quick, "iterations": 12, "shots": 8,
                                      "rows": rows}, args.out)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
