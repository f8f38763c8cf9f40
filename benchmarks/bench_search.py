"""One Grover search on each backend, against Aer's own floor, through documented APIs only.

    python benchmarks/bench_search.py [--quick] [--repeats 30] [--out FILE]

Per width n (4, 8, 12, 16), interleaved repeat by repeat so that a drift of a shared machine's
speed enters every column alike:

- ``floor``: a 1-qubit circuit with one measurement, 8 shots, through ``AerSimulator.run`` with the
  options ``AerBackend`` uses (the least any Aer search can cost);
- ``aer``: ``AerBackend.search(marks, 12, 8, seed)``: the circuit built once and run through
  ``AerSimulator.run``;
- ``statevector``: ``StatevectorBackend.search`` of the same request (the closed form).

Marks: m = 1 entry of N = 2^n. Prints and writes the medians (seconds), the ratio ``aer / floor``
per n, and the time per oracle call (k x shots = 96 calls a search). Writes JSON.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from _common import machine, write_json
from qiskit import QuantumCircuit

import qrrt_circuits as qc

WIDTHS = (4, 8, 12, 16)
ITERATIONS, SHOTS = 12, 8


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer repeats")
    parser.add_argument("--repeats", type=int, default=30)
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    repeats = 5 if args.quick else args.repeats
    aer, statevector = qc.AerBackend(seed=0), qc.StatevectorBackend(seed=0)
    floor = QuantumCircuit(1, 1)
    floor.h(0)
    floor.measure(0, 0)
    simulator = aer.simulator

    def run_floor() -> None:
        simulator.run(floor, shots=SHOTS, seed_simulator=1, memory=True, max_parallel_threads=1).result()

    rows = {}
    for n in WIDTHS:
        marks = np.zeros(1 << n, dtype=bool)
        marks[(1 << n) // 3] = True
        runs = {"floor": run_floor,
                "aer": lambda marks=marks: aer.search(marks, ITERATIONS, SHOTS, seed=7),
                "statevector": lambda marks=marks: statevector.search(marks, ITERATIONS, SHOTS, seed=7)}
        for run in runs.values():  # warm up
            run()
        times: dict[str, list[float]] = {name: [] for name in runs}
        for _ in range(repeats):
            for name, run in runs.items():
                began = time.perf_counter()
                run()
                times[name].append(time.perf_counter() - began)
        medians = {name: float(np.median(values)) for name, values in times.items()}
        rows[f"qubits{n}"] = {**{f"{name}_median_s": value for name, value in medians.items()},
                              "aer_over_floor": medians["aer"] / medians["floor"],
                              "aer_us_per_oracle_call": medians["aer"] * 1e6 / (ITERATIONS * SHOTS)}
        print(f"n = {n:2d}: floor {medians['floor'] * 1e3:8.3f} ms, aer {medians['aer'] * 1e3:8.3f} ms "
              f"({medians['aer'] / medians['floor']:6.2f}x floor), statevector {medians['statevector'] * 1e3:7.3f} ms")
    write_json("bench_search", {"machine": machine(), "quick": args.quick, "repeats": repeats,
                                "iterations": ITERATIONS, "shots": SHOTS, "search": rows}, args.out)


if __name__ == "__main__":
    main()
