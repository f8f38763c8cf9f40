"""Aer's fixed cost per run: how many ``std::random_device`` objects qiskit-aer constructs in one
``AerSimulator.run`` of a ready circuit, and what one construction costs on this machine.

    python benchmarks/bench_aer_overhead.py [--quick] [--out FILE]

A q-RRT round on Aer runs one small circuit (n = 8, k = 3, one shot; ``bench_search.py``'s
``round_search``). Of Aer's own C++ time for it, a large part is paid even at k = 0 (a circuit of
Hadamards and measurements). This script measures one cause of that fixed part:

1. ``run``: ``AerSimulator.run`` of the Grover circuit ``AerBackend`` runs (n = 8, one shot, the
   simulator options ``AerBackend`` uses, one thread), built beforehand: wall time of the run
   and its result, and Aer's own C++ time for the circuit (the result's ``time_taken``), at k = 0
   and k = 3, interleaved, medians in microseconds;
2. ``random_device_us``: one construction of a default ``std::random_device`` (the seed source
   that Aer's ``RngEngine`` and ``AER::Circuit`` constructors use whether or not
   ``seed_simulator`` is given), timed by a five-line C++ loop compiled with the machine's C++
   compiler (``c++``); null with the reason where there is none;
3. ``inits_per_run``: the number of ``std::random_device::_M_init`` calls per run, at k = 0 and
   k = 3, counted by breakpoints under ``gdb`` (this script re-runs itself with ``--child``; the
   procedure-linkage-table stubs are not counted, only the function); null with the reason where
   gdb is missing or finds no such function.

Then ``random_device_per_run_us`` = inits per run x one construction, and its share of Aer's
C++ time at k = 0. Prints a table and writes JSON (``bench_aer_overhead.json``).
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _common import machine, write_json

QUBITS = 8

_CPP_LOOP = r"""
#include <chrono>
#include <cstdio>
#include <random>
int main(int argc, char** argv) {
  const int repeats = std::atoi(argv[1]);
  unsigned sink = 0;
  const auto began = std::chrono::steady_clock::now();
  for (int i = 0; i < repeats; ++i) { std::random_device device; sink += device(); }
  const auto ended = std::chrono::steady_clock::now();
  std::printf("%.6f %u\n", std::chrono::duration<double, std::micro>(ended - began).count() / repeats, sink);
}
"""

_GDB_COUNTER = r"""
import gdb
counts = {"function": 0, "stub": 0}
class Counter(gdb.Breakpoint):
    def stop(self):
        name = gdb.selected_frame().name() or ""
        counts["stub" if "@plt" in name else "function"] += 1
        return False
gdb.execute("set pagination off")
gdb.execute("handle SIGTRAP stop nopass")
gdb.execute("run")
Counter("std::random_device::_M_init")
gdb.execute("continue")
print("RANDOM_DEVICE_INITS", counts["function"], counts["stub"])
gdb.execute("kill")
"""


def _prepared(iterations: int):
    """(simulator, circuit) of the Grover circuit ``AerBackend`` runs at n = ``QUBITS`` with a
    fifth of the entries marked, built beforehand."""
    import qrrt_circuits as qc
    from qrrt_circuits.search.circuits import aer_grover_circuit

    marks = np.random.default_rng(5).random(2**QUBITS) < 0.2
    simulator = qc.AerBackend(seed=0, max_parallel_threads=1).simulator
    return simulator, aer_grover_circuit(marks, iterations)


def _run(simulator, circuit, seed: int):
    """``AerSimulator.run`` as ``AerBackend`` calls it (one shot); the result."""
    return simulator.run(circuit, shots=1, seed_simulator=seed, memory=True, max_parallel_threads=1).result()


def run_times(repeats: int) -> dict:
    """Median wall and C++ (``time_taken``) microseconds of ``AerSimulator.run`` at k = 0 and 3,
    interleaved."""
    runs = {k: _prepared(k) for k in (0, 3)}
    wall: dict[int, list[float]] = {0: [], 3: []}
    cpp: dict[int, list[float]] = {0: [], 3: []}
    for repeat in range(repeats + 20):  # the first 20 are warm-up
        for k in ((0, 3) if repeat % 2 == 0 else (3, 0)):
            simulator, circuit = runs[k]
            began = time.perf_counter()
            result = _run(simulator, circuit, repeat)
            ended = time.perf_counter()
            if repeat >= 20:
                wall[k].append((ended - began) * 1e6)
                cpp[k].append(result.results[0].time_taken * 1e6)
    return {f"k{k}_{kind}_us": float(np.median(values[k])) for k in (0, 3)
            for kind, values in (("wall", wall), ("cpp", cpp))}


def random_device_cost(repeats: int) -> tuple[float | None, str | None]:
    """Microseconds of one ``std::random_device`` construction (and one draw), or (None, why)."""
    compiler = shutil.which("c++") or shutil.which("g++") or shutil.which("clang++")
    if compiler is None:
        return None, "no C++ compiler (c++, g++ or clang++) on PATH"
    with tempfile.TemporaryDirectory(prefix="qrrt-random-device-") as scratch:
        source, program = Path(scratch) / "loop.cpp", Path(scratch) / "loop"
        source.write_text(_CPP_LOOP)
        built = subprocess.run([compiler, "-O2", str(source), "-o", str(program)], capture_output=True, text=True)
        if built.returncode != 0:
            return None, f"{compiler} failed: {built.stderr[-300:]}"
        samples = []
        for _ in range(5):
            done = subprocess.run([str(program), str(repeats)], capture_output=True, text=True, check=True)
            samples.append(float(done.stdout.split()[0]))
    return float(np.median(samples)), None


def count_inits(iterations: int, runs: int) -> tuple[int | None, str | None]:
    """``std::random_device::_M_init`` calls in ``runs`` runs at k = ``iterations`` (under gdb,
    the child stops itself with SIGTRAP around the runs), or (None, why)."""
    gdb = shutil.which("gdb")
    if gdb is None:
        return None, "gdb is not on PATH"
    with tempfile.TemporaryDirectory(prefix="qrrt-gdb-") as scratch:
        script = Path(scratch) / "count.py"
        script.write_text(_GDB_COUNTER)
        command = [gdb, "-q", "-batch", "-x", str(script), "--args", sys.executable, str(Path(__file__).resolve()),
                   "--child", str(iterations), str(runs)]
        done = subprocess.run(command, capture_output=True, text=True, timeout=600)
    match = re.search(r"RANDOM_DEVICE_INITS (\d+) (\d+)", done.stdout)
    if match is None:
        return None, f"gdb gave no count: {(done.stdout + done.stderr)[-300:]}"
    if int(match.group(1)) == 0:
        return None, "gdb found no std::random_device::_M_init calls (no such symbol?)"
    return int(match.group(1)), None


def child(iterations: int, runs: int) -> None:
    """The process gdb runs: warm up, stop, ``runs`` runs, stop (gdb counts between)."""
    simulator, circuit = _prepared(iterations)
    for seed in range(5):
        _run(simulator, circuit, seed)
    os.kill(os.getpid(), signal.SIGTRAP)  # gdb sets its breakpoint here
    for seed in range(runs):
        _run(simulator, circuit, seed)


def main() -> None:
    if len(sys.argv) == 4 and sys.argv[1] == "--child":
        child(int(sys.argv[2]), int(sys.argv[3]))
        return
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    runs = 20 if args.quick else 200
    times = run_times(300 if args.quick else 3000)
    device_us, device_why = random_device_cost(2000 if args.quick else 20000)
    counted = {k: count_inits(k, runs) for k in (0, 3)}
    inits = {f"k{k}": (count / runs if count is not None else None) for k, (count, _) in counted.items()}
    per_run = inits["k0"] * device_us if inits["k0"] is not None and device_us is not None else None
    figures = {**{f"run_k{k}_{kind}_us": times[f"k{k}_{kind}_us"] for k in (0, 3) for kind in ("wall", "cpp")},
               "random_device_us": device_us,
               "inits_per_run_k0": inits["k0"], "inits_per_run_k3": inits["k3"],
               "random_device_per_run_us": per_run,
               "random_device_share_of_cpp_k0": per_run / times["k0_cpp_us"] if per_run is not None else None}
    why = {"random_device_us": device_why, **{f"inits_per_run_k{k}": reason for k, (_, reason) in counted.items()}}
    print(f"  AerSimulator.run, n = {QUBITS}, one shot: k = 0 {times['k0_wall_us']:.1f} us (C++ "
          f"{times['k0_cpp_us']:.1f}), k = 3 {times['k3_wall_us']:.1f} us (C++ {times['k3_cpp_us']:.1f})")
    print(f"  std::random_device: {device_us if device_us is not None else device_why} us per construction; "
          f"constructions per run: k = 0 {inits['k0'] if inits['k0'] is not None else why['inits_per_run_k0']}, "
          f"k = 3 {inits['k3'] if inits['k3'] is not None else why['inits_per_run_k3']}")
    if per_run is not None:
        print(f"  about {per_run:.1f} us per run, {100 * figures['random_device_share_of_cpp_k0']:.0f} % of the "
              "C++ time at k = 0")
    path = write_json("bench_aer_overhead_quick" if args.quick else "bench_aer_overhead",
                      {"machine": machine(), "quick": args.quick, "qubits": QUBITS, "shots": 1, "runs_counted": runs,
                       "figures": {key: value for key, value in figures.items() if value is not None},
                       "missing": {key: reason for key, reason in why.items() if reason is not None}}, args.out)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
