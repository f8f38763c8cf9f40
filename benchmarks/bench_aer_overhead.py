"""Aer's fixed cost per run: how many ``std::random_device`` objects qiskit-aer's controller
constructs in one run of a ready circuit, and what one construction costs on this machine.

    python benchmarks/bench_aer_overhead.py [--quick] [--out FILE]

A q-RRT round on Aer runs one small circuit (n = 8, k = 3, one shot; ``bench_search.py``'s
``round_search``). Of the controller's own C++ time for it, a large part is paid even at k = 0 (a
circuit of Hadamards and measurements). This script measures one cause of that fixed part:

1. ``controller``: the controller's call on an assembled Grover circuit (n = 8, one shot, the
   configuration ``AerBackend`` uses, one thread), wall time and Aer's own ``time_taken``, at k = 0
   and k = 3, interleaved, medians in microseconds;
2. ``random_device_us``: one construction of a default ``std::random_device`` (the seed source
   that the controller's ``RngEngine`` and ``AER::Circuit`` constructors use whether or not
   ``seed_simulator`` is given), timed by a five-line C++ loop compiled with the machine's C++
   compiler (``c++``); null with the reason where there is none;
3. ``inits_per_run``: the number of ``std::random_device::_M_init`` calls per controller run, at
   k = 0 and k = 3, counted by breakpoints under ``gdb`` (this script re-runs itself with
   ``--child``; the procedure-linkage-table stubs are not counted, only the function); null with
   the reason where gdb is missing or finds no such function.

Then ``random_device_per_run_us`` = inits per run x one construction, and its share of the
controller's C++ time at k = 0.

The same for Aer's state (``aer_state``, the path ``AerBackend`` takes below 13 qubits):
4. ``state``: ``aer_state.execute_grover`` of the same circuit at k = 0 and k = 3 (the state reset
   to |0>, the instructions applied, one sample), interleaved with the controller's calls of 1.,
   and ``state_inits_per_search_k0`` / ``_k3``, counted as in 3., and at n = 13 (k = 3), where the
   state is reallocated for each search (``state_inits_per_search_n13_k3``);
5. ``state_reset``: the two ways ``aer_state`` resets its state between searches, per n: applying a
   cached |0> list (``apply_initialize``) and clearing and reallocating it, each followed by one h
   and a flush so that the reset is carried out, less that h and flush alone; medians in
   microseconds (the threshold ``aer_state._RESET_BY_INITIALIZE_BELOW`` rests on them).
Prints a table and writes JSON (``bench_aer_overhead.json``).
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
#: the widest circuit aer_state runs, where its reset reallocates the state (``state13`` below)
WIDEST_STATE_QUBITS = 13

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


def _controller(iterations: int):
    """(simulator, assembled circuit, width) of the Grover circuit ``AerBackend`` runs at n =
    ``QUBITS`` with a fifth of the entries marked."""
    import qrrt_circuits as qc
    from qrrt_circuits.search import aer_direct

    marks = np.random.default_rng(5).random(2**QUBITS) < 0.2
    simulator = qc.AerBackend(seed=0, max_parallel_threads=1).simulator
    return simulator, aer_direct.assemble_grover(marks, iterations, "diagonal"), aer_direct._Width(QUBITS, QUBITS)


def _marks() -> np.ndarray:
    return np.random.default_rng(5).random(2**QUBITS) < 0.2


def controller_times(repeats: int) -> dict:
    """Median wall and C++ (``time_taken``) microseconds of the controller's call at k = 0 and 3,
    and wall microseconds of ``aer_state.execute_grover`` of the same circuits, interleaved."""
    from qrrt_circuits.search import aer_direct, aer_state

    runs = {k: _controller(k) for k in (0, 3)}
    marks = _marks()
    wall: dict[int, list[float]] = {0: [], 3: []}
    cpp: dict[int, list[float]] = {0: [], 3: []}
    state: dict[int, list[float]] = {0: [], 3: []}
    for repeat in range(repeats + 20):  # the first 20 are warm-up
        for k in ((0, 3) if repeat % 2 == 0 else (3, 0)):
            simulator, aer, width = runs[k]
            config = aer_direct._configuration(simulator, width, 1, repeat, 1)
            began = time.perf_counter()
            output = simulator._execute_circuits([aer], None, config)
            middle = time.perf_counter()
            aer_state.execute_grover(marks, k, "diagonal", 1, repeat)
            ended = time.perf_counter()
            if repeat >= 20:
                wall[k].append((middle - began) * 1e6)
                cpp[k].append(output["results"][0]["time_taken"] * 1e6)
                state[k].append((ended - middle) * 1e6)
    return {f"k{k}_{kind}_us": float(np.median(values[k])) for k in (0, 3)
            for kind, values in (("wall", wall), ("cpp", cpp), ("state", state))}


def _reset_samples(wrapper, n: int, repeats: int) -> dict[str, list[float]]:
    """Microseconds of (reset, h, flush) for no reset and the two resets, interleaved."""
    from qrrt_circuits.search import aer_state

    qubits = list(range(n))
    zero = [1.0 + 0.0j] + [0.0j] * ((1 << n) - 1)
    samples: dict[str, list[float]] = {"alone": [], "initialize": [], "reallocate": []}
    for repeat in range(repeats + 20):  # the first 20 are warm-up
        for name in samples:
            began = time.perf_counter()
            if name == "initialize":
                wrapper.apply_initialize(qubits, zero)
            elif name == "reallocate":
                wrapper.clear()
                aer_state.allocate(wrapper, n)
            wrapper.apply_h(0)
            wrapper.flush()
            if repeat >= 20:
                samples[name].append((time.perf_counter() - began) * 1e6)
    return samples


def state_reset_times(repeats: int) -> dict[str, dict[str, float]]:
    """Per n, median microseconds of the two resets of ``aer_state`` (see the module docstring)."""
    from qiskit_aer.backends.controller_wrappers import AerStateWrapper

    from qrrt_circuits.search import aer_state

    figures = {}
    for n in (4, 8, 10, 11, 12, 13):
        wrapper = AerStateWrapper()
        aer_state.allocate(wrapper, n)
        samples = _reset_samples(wrapper, n, repeats)
        alone = float(np.median(samples["alone"]))
        figures[f"n{n}"] = {"initialize_us": float(np.median(samples["initialize"])) - alone,
                            "reallocate_us": float(np.median(samples["reallocate"])) - alone}
        wrapper.clear()
    return figures


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


def count_inits(path: str, iterations: int, runs: int) -> tuple[int | None, str | None]:
    """``std::random_device::_M_init`` calls in ``runs`` runs at k = ``iterations`` on ``path``
    (``"controller"`` or ``"state"``; under gdb, the child stops itself with SIGTRAP around the
    runs), or (None, why)."""
    gdb = shutil.which("gdb")
    if gdb is None:
        return None, "gdb is not on PATH"
    with tempfile.TemporaryDirectory(prefix="qrrt-gdb-") as scratch:
        script = Path(scratch) / "count.py"
        script.write_text(_GDB_COUNTER)
        command = [gdb, "-q", "-batch", "-x", str(script), "--args", sys.executable, str(Path(__file__).resolve()),
                   "--child", path, str(iterations), str(runs)]
        done = subprocess.run(command, capture_output=True, text=True, timeout=600)
    match = re.search(r"RANDOM_DEVICE_INITS (\d+) (\d+)", done.stdout)
    if match is None:
        return None, f"gdb gave no count: {(done.stdout + done.stderr)[-300:]}"
    if int(match.group(1)) == 0:
        return None, "gdb found no std::random_device::_M_init calls (no such symbol?)"
    return int(match.group(1)), None


def child(path: str, iterations: int, runs: int) -> None:
    """The process gdb runs: warm up, stop, ``runs`` runs on ``path``, stop (gdb counts between)."""
    from qrrt_circuits.search import aer_direct, aer_state

    if path in ("state", "state13"):
        width = QUBITS if path == "state" else WIDEST_STATE_QUBITS
        marks = np.random.default_rng(5).random(2**width) < 0.2

        def run() -> None:
            aer_state.execute_grover(marks, iterations, "diagonal", 1, 1)
    else:
        simulator, aer, width = _controller(iterations)
        config = aer_direct._configuration(simulator, width, 1, 1, 1)

        def run() -> None:
            simulator._execute_circuits([aer], None, config)
    for _ in range(5):
        run()
    os.kill(os.getpid(), signal.SIGTRAP)  # gdb sets its breakpoint here
    for _ in range(runs):
        run()


def main() -> None:
    if len(sys.argv) == 5 and sys.argv[1] == "--child":
        child(sys.argv[2], int(sys.argv[3]), int(sys.argv[4]))
        return
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    runs = 20 if args.quick else 200
    times = controller_times(300 if args.quick else 3000)
    device_us, device_why = random_device_cost(2000 if args.quick else 20000)
    counted = {k: count_inits("controller", k, runs) for k in (0, 3)}
    inits = {f"k{k}": (count / runs if count is not None else None) for k, (count, _) in counted.items()}
    state_counted = {k: count_inits("state", k, runs) for k in (0, 3)}
    widest_counted = count_inits("state13", 3, runs)
    resets = state_reset_times(200 if args.quick else 2000)
    per_run = inits["k0"] * device_us if inits["k0"] is not None and device_us is not None else None
    figures = {**{f"controller_k{k}_{kind}_us": times[f"k{k}_{kind}_us"] for k in (0, 3) for kind in ("wall", "cpp")},
               **{f"state_k{k}_us": times[f"k{k}_state_us"] for k in (0, 3)},
               "random_device_us": device_us,
               "inits_per_run_k0": inits["k0"], "inits_per_run_k3": inits["k3"],
               "random_device_per_run_us": per_run,
               "random_device_share_of_cpp_k0": per_run / times["k0_cpp_us"] if per_run is not None else None,
               **{f"state_inits_per_search_k{k}": (count / runs if count is not None else None)
                  for k, (count, _) in state_counted.items()},
               "state_inits_per_search_n13_k3": widest_counted[0] / runs if widest_counted[0] is not None else None}
    why = {"random_device_us": device_why, **{f"inits_per_run_k{k}": reason for k, (_, reason) in counted.items()},
           **{f"state_inits_per_search_k{k}": reason for k, (_, reason) in state_counted.items()},
           "state_inits_per_search_n13_k3": widest_counted[1]}
    print(f"  controller call, n = {QUBITS}, one shot: k = 0 {times['k0_wall_us']:.1f} us (C++ "
          f"{times['k0_cpp_us']:.1f}), k = 3 {times['k3_wall_us']:.1f} us (C++ {times['k3_cpp_us']:.1f})")
    print(f"  std::random_device: {device_us if device_us is not None else device_why} us per construction; "
          f"constructions per run: k = 0 {inits['k0'] if inits['k0'] is not None else why['inits_per_run_k0']}, "
          f"k = 3 {inits['k3'] if inits['k3'] is not None else why['inits_per_run_k3']}")
    if per_run is not None:
        print(f"  about {per_run:.1f} us per run, {100 * figures['random_device_share_of_cpp_k0']:.0f} % of the "
              "C++ time at k = 0")
    state_inits = {k: (figures[f"state_inits_per_search_k{k}"] if figures[f"state_inits_per_search_k{k}"] is not None
                       else why[f"state_inits_per_search_k{k}"]) for k in (0, 3)}
    print(f"  Aer's state (aer_state.execute_grover): k = 0 {times['k0_state_us']:.1f} us, k = 3 "
          f"{times['k3_state_us']:.1f} us; std::random_device per search: k = 0 {state_inits[0]}, "
          f"k = 3 {state_inits[3]}; at n = {WIDEST_STATE_QUBITS}, k = 3: "
          f"{figures['state_inits_per_search_n13_k3'] or why['state_inits_per_search_n13_k3']}")
    print("  state reset (us), apply_initialize of a cached |0> list / clear and reallocate: "
          + "  ".join(f"{n} {row['initialize_us']:.1f} / {row['reallocate_us']:.1f}" for n, row in resets.items()))
    path = write_json("bench_aer_overhead_quick" if args.quick else "bench_aer_overhead",
                      {"machine": machine(), "quick": args.quick, "qubits": QUBITS, "shots": 1, "runs_counted": runs,
                       "figures": {key: value for key, value in figures.items() if value is not None},
                       "state_reset": resets,
                       "missing": {key: reason for key, reason in why.items() if reason is not None}}, args.out)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
