"""``AerBackend(device="GPU")`` (Aer's GPU build) against the CPU, n = 16-28.

    python benchmarks/bench_gpu.py [--quick] [--dense] [--qubits 8,12,16,...] [--cpu-budget 150] [--out FILE]
    python benchmarks/bench_gpu.py --cpu-only      # a dry run where Aer offers no GPU

Needs qiskit-aer-gpu and an NVIDIA GPU (``benchmarks/gpu/on_device.sh`` installs the wheel on a
machine without a package index). Without a GPU it measures nothing: it says why, writes a JSON
holding only that reason (``skipped``) and exits 0, so ``benchmarks/run.py`` records it as skipped
rather than failed; ``--cpu-only`` measures the CPU alone (its distribution check included,
about 20 s on 2 cores). ``--quick``: n = 12, 16, 20, 24 (unless ``--qubits`` is given) and a
30-second CPU budget.

For each n: 12 marked entries (the ``mcz`` oracle from n = 13 on: ``simulation_synthesis``), k = 12
iterations, 8 shots (the searches of ``bench_search.py``'s floor table), ``AerBackend(seed=1,
device=...)`` with ``max_parallel_threads=0`` (all cores; circuits under 14 qubits run on one thread;
both devices run every width through ``AerSimulator.run``).
Each repeat searches with the same seed on both devices and records whether they measured the same
indices. Medians and minimums of the repeats; ``speedup`` = the CPU's median over the GPU's. The
GPU's first search (CUDA's context, Aer's kernels) is timed apart (``gpu_first_search_s``) and not
counted. The CPU is measured while the time its next size is predicted to take (the last median
times 4 per 2 more qubits, times its repeats) fits what is left of ``--cpu-budget`` seconds; the
sizes it skips say so. A check of the sampled distribution on each device: n = 16, m = 2^n / 256
(k = 12 is then optimal, sin^2(25 theta) = 0.99995; the mcz oracle), 256 shots: the fraction of
marked indices and its binomial standard deviation; and a probe of the diagonal oracle on the GPU
(k = 1, 8 shots, n = 10-20), where Aer's GPU build ran out of memory from n = 18 on an H200 (a failed
run is recorded with Aer's error and the benchmark goes on). ``--dense``: a q-RRT round's search
instead (a fifth of the entries marked, k = 3, 1 shot), where the CPU takes the diagonal oracle and
the GPU, above ``GPU_DIAGONAL_CHOSEN_UP_TO_QUBITS``, the mcz form (``AerBackend.synthesis_for``).
``--blocking``: only a probe of Aer's cache blocking for that dense search (``blocking_probe``).

Writes the JSON after every size (a run cut short keeps what it measured), with the machine (CPU
count, ``nvidia-smi``'s GPU name, memory and driver, Aer's devices and version).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import time
from pathlib import Path

import numpy as np
from _common import RESULTS, machine

import qrrt_circuits as qc

ITERATIONS = 12
SHOTS = 8
MARKED = 12
DEFAULT_QUBITS = (8, 12, 16, 18, 20, 22, 24, 26, 28)
QUICK_QUBITS = (12, 16, 20, 24)
#: 12 marked entries need 2^n >= 12; 34 qubits are 256 GiB of state
MIN_QUBITS, MAX_QUBITS = 4, 34


def _qubit_list(text: str) -> list[int]:
    """``--qubits``: comma-separated integers in [MIN_QUBITS, MAX_QUBITS]."""
    try:
        sizes = [int(part) for part in text.split(",")]
    except ValueError:
        sizes = []
    if not sizes or any(not MIN_QUBITS <= n <= MAX_QUBITS for n in sizes):
        raise argparse.ArgumentTypeError(f"must be comma-separated integers in [{MIN_QUBITS}, {MAX_QUBITS}], "
                                         f"got {text!r}")
    return sizes


def _budget(text: str) -> float:
    """``--cpu-budget``: a finite number of seconds >= 0."""
    try:
        seconds = float(text)
    except ValueError:
        seconds = math.nan
    if not (math.isfinite(seconds) and seconds >= 0):
        raise argparse.ArgumentTypeError(f"must be a finite number of seconds >= 0, got {text!r}")
    return seconds
DIAGONAL_PROBE_QUBITS = (10, 12, 14, 16, 18, 20)


def _attempt(measure) -> dict:
    """``measure()``, or the error Aer raised (a failed run is recorded, the benchmark goes on)."""
    try:
        return measure()
    except (RuntimeError, ValueError) as error:  # Aer's failure, or the memory guard's refusal
        return {"error": str(error)[:300]}


def _gpu_description() -> dict:
    """``nvidia-smi``'s name, memory and driver of each GPU (empty where there is none)."""
    try:
        out = subprocess.run(["nvidia-smi", "--query-gpu=name,memory.total,driver_version",
                              "--format=csv,noheader"], capture_output=True, text=True, timeout=30, check=True)
    except (OSError, subprocess.SubprocessError):
        return {"gpus": []}
    return {"gpus": [line.strip() for line in out.stdout.splitlines() if line.strip()]}


def _marks(n: int, marked: int, rng: np.random.Generator) -> np.ndarray:
    marks = np.zeros(1 << n, dtype=bool)
    marks[rng.choice(1 << n, marked, replace=False)] = True
    return marks


def _timed(backend: qc.AerBackend, marks: np.ndarray, seed: int, shots: int = SHOTS,
           iterations: int = ITERATIONS) -> tuple[float, np.ndarray]:
    start = time.perf_counter()
    result = backend.search(qc.LookupOracle(marks), iterations, shots=shots, seed=seed)
    return time.perf_counter() - start, result.indices


def _summary(times: list[float]) -> dict:
    return {"median_s": float(np.median(times)), "min_s": float(np.min(times)), "repeats": len(times)}


BLOCKING_QUBITS = (12, 14)


def blocking_probe(sizes: list[int], gpu: qc.AerBackend | None, path: Path, payload: dict) -> None:
    """A q-RRT round's search (a fifth of the entries marked, k = 3, 1 shot) with the diagonal
    oracle: on the CPU as ``AerBackend`` runs it, and on the GPU with Aer's cache blocking
    (``blocking_enable``, ``blocking_qubits`` b), where Aer applies a wide diagonal chunk by chunk
    on b qubits (``Chunk::block_diagonal_matrix``), so its matrix buffer might be sized for b, not
    n. Median ms of 3 seeded searches each (after one unmeasured), and whether the GPU's indices
    equal the CPU's; a failed run is recorded with Aer's error. Rows go to
    ``payload["blocking_probe"]``, written to ``path`` after each size."""
    rows = payload["blocking_probe"] = []
    diagonal_cpu = qc.AerBackend(seed=1, device="CPU", synthesis="diagonal")
    for n in sizes:
        marks = _marks(n, (1 << n) // 5, np.random.default_rng(n))
        row: dict = {"qubits": n, "marked": int(marks.sum()), "iterations": 3, "shots": 1}
        runs: dict[str, list] = {}
        backends = {"cpu_diagonal": diagonal_cpu}
        for bits in BLOCKING_QUBITS if gpu is not None and n > min(BLOCKING_QUBITS) else ():
            blocked = qc.AerBackend(seed=1, device="GPU", synthesis="diagonal")
            blocked.simulator.set_options(blocking_enable=True, blocking_qubits=bits)
            backends[f"gpu_diagonal_blocking{bits}"] = blocked
        for name, backend in backends.items():
            try:
                _timed(backend, marks, 99, 1, 3)
                runs[name] = [_timed(backend, marks, seed, 1, 3) for seed in (100, 101, 102)]
                row[f"{name}_ms"] = float(np.median([t for t, _ in runs[name]])) * 1e3
            except (RuntimeError, ValueError) as error:
                row[f"{name}_error"] = str(error)[:300]
        for name in runs:
            if name != "cpu_diagonal" and "cpu_diagonal" in runs:
                row[f"{name}_same_indices"] = all(np.array_equal(c, g) for (_, c), (_, g)
                                                  in zip(runs["cpu_diagonal"], runs[name], strict=True))
        rows.append(row)
        path.write_text(json.dumps(payload, indent=1))
        print(f"blocking probe n = {n}: {row}", flush=True)


def distribution_check(device: str, n: int = 16, shots: int = 256) -> dict:
    """The fraction of marked indices among ``shots`` of k = 12 with m = 2^n / 256 (sin^2(25
    theta) = 0.99995), the ``mcz`` oracle (2 m instructions per iteration), its binomial standard
    deviation, and whether it lies within 5 of them (or one shot) of the expected fraction."""
    backend = qc.AerBackend(seed=1, device=device, synthesis="mcz")
    marks = _marks(n, (1 << n) // 256, np.random.default_rng(5))
    seconds, indices = _timed(backend, marks, 11, shots=shots)
    theta = math.asin(math.sqrt(1 / 256))
    expected = math.sin((2 * ITERATIONS + 1) * theta) ** 2
    observed = float(marks[indices].mean())
    sigma = math.sqrt(expected * (1 - expected) / shots)
    return {"qubits": n, "marked": int(marks.sum()), "shots": shots, "synthesis": "mcz",
            "expected": expected, "observed": observed, "sigma": sigma,
            "within_5_sigma_or_1_miss": abs(observed - expected) <= max(5 * sigma, 1 / shots), "seconds": seconds}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--qubits", type=_qubit_list, default=None,
                        help=f"comma-separated n, each in [{MIN_QUBITS}, {MAX_QUBITS}] "
                             f"(default {','.join(map(str, DEFAULT_QUBITS))})")
    parser.add_argument("--cpu-budget", type=_budget, default=150.0,
                        help="seconds of CPU searches at most, >= 0 (default %(default)s)")
    parser.add_argument("--cpu-only", action="store_true",
                        help="measure the CPU alone, its distribution check included (no GPU needed)")
    parser.add_argument("--quick", action="store_true",
                        help="n = 12, 16, 20, 24 (unless --qubits is given) and a CPU budget of at most 30 s")
    parser.add_argument("--blocking", action="store_true",
                        help="only the cache-blocking probe: the dense diagonal oracle on the GPU with Aer's "
                             "blocking_enable (blocking_qubits 12 and 14) against the CPU's diagonal")
    parser.add_argument("--dense", action="store_true",
                        help="a q-RRT round's search instead: a fifth of the entries marked, k = 3, 1 shot "
                             "(no distribution check or diagonal probe)")
    parser.add_argument("--out", default=None, help="JSON to write (default benchmarks/results/bench_gpu.json)")
    args = parser.parse_args()
    sizes = args.qubits or (QUICK_QUBITS if args.quick else DEFAULT_QUBITS)
    if args.quick:
        args.cpu_budget = min(args.cpu_budget, 30.0)
    from qiskit_aer import AerSimulator

    devices = list(AerSimulator().available_devices())
    kind = "_blocking" if args.blocking else "_dense" if args.dense else ""
    path = Path(args.out) if args.out else RESULTS / f"bench_gpu{kind}.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    if "GPU" not in devices and not args.cpu_only:
        reason = (f"this qiskit-aer offers the devices {devices}; device='GPU' needs qiskit-aer-gpu and an "
                  "NVIDIA GPU (benchmarks/gpu/on_device.sh); --cpu-only measures the CPU alone")
        path.write_text(json.dumps({"machine": machine(), "skipped": reason}, indent=1))
        print(f"skipped: {reason}")
        return
    iterations, shots = (3, 1) if args.dense else (ITERATIONS, SHOTS)

    def marked_for(n: int) -> int:
        return (1 << n) // 5 if args.dense else MARKED

    payload: dict = {
        "machine": {**machine(), "cpu_count": os.cpu_count(), **_gpu_description(), "aer_devices": devices},
        "settings": {"marked": "2^n / 5" if args.dense else MARKED, "iterations": iterations, "shots": shots,
                     "max_parallel_threads": 0, "cpu_budget_s": args.cpu_budget, "cpu_only": args.cpu_only},
        "rows": [], "checks": [], "diagonal_probe": [],
    }
    cpu = qc.AerBackend(seed=1, device="CPU")
    gpu = None if args.cpu_only else qc.AerBackend(seed=1, device="GPU")
    if gpu is not None:
        start = time.perf_counter()
        gpu.search(qc.LookupOracle(_marks(8, MARKED, np.random.default_rng(9))), ITERATIONS, shots=SHOTS, seed=0)
        payload["gpu_first_search_s"] = time.perf_counter() - start
        print(f"GPU first search (CUDA context, kernels): {payload['gpu_first_search_s']:.2f} s", flush=True)
    cpu.search(qc.LookupOracle(_marks(8, MARKED, np.random.default_rng(9))), ITERATIONS, shots=SHOTS, seed=0)  # warm-up
    for name, backend in (("GPU", gpu), ("CPU", cpu)):
        if backend is not None and not args.dense and not args.blocking:
            payload["checks"].append({"device": name, **_attempt(lambda d=name: distribution_check(d))})
            print(f"distribution check on {name}: {payload['checks'][-1]}", flush=True)
    if gpu is not None and not args.dense and not args.blocking:  # where the GPU runs the diagonal (k = 1, 8 shots)
        for n in DIAGONAL_PROBE_QUBITS:
            probe = qc.AerBackend(seed=1, device="GPU", synthesis="diagonal")
            marks = _marks(n, MARKED, np.random.default_rng(n))
            outcome = _attempt(lambda b=probe, m=marks: {"seconds": _timed(b, m, 7, iterations=1)[0]})
            payload["diagonal_probe"].append({"qubits": n, **outcome})
            print(f"diagonal oracle on the GPU, n = {n}: {outcome}", flush=True)
    path.write_text(json.dumps(payload, indent=1))
    if args.blocking:
        blocking_probe(sizes, gpu, path, payload)
        print(f"wrote {path}")
        return
    cpu_left = args.cpu_budget
    last_cpu: tuple[int, float] | None = None
    rng = np.random.default_rng(0)
    print(f"{'n':>3s} {'GPU form':8s} {'GPU median ms':>14s} {'CPU median ms':>14s} {'CPU/GPU':>8s} {'same':>5s}",
          flush=True)
    for n in sizes:
        marks = _marks(n, marked_for(n), rng)
        row: dict = {"qubits": n, "marked": marked_for(n), "cpu_synthesis": cpu.oracle_form(n, marked_for(n))}
        if gpu is not None:
            row["gpu_synthesis"] = gpu.oracle_form(n, marked_for(n))
        seeds = list(range(100, 105 if n <= 24 and not args.dense else 103))
        gpu_runs: list = []
        if gpu is not None:
            try:
                _timed(gpu, marks, 99, shots, iterations)  # this width's first run (allocation)
                gpu_runs = [_timed(gpu, marks, seed, shots, iterations) for seed in seeds]
                row["gpu"] = _summary([t for t, _ in gpu_runs])
            except (RuntimeError, ValueError) as error:  # Aer's failure, or the memory guard's refusal
                row["gpu_error"] = str(error)[:300]
        cpu_repeats = 3 if n <= 22 else 1
        cpu_runs: list = []
        predicted = None if last_cpu is None else last_cpu[1] * 4.0 ** ((n - last_cpu[0]) / 2) * cpu_repeats
        if predicted is not None and predicted > cpu_left:
            row["cpu"] = {"skipped": f"predicted {predicted:.0f} s > the {cpu_left:.0f} s left of --cpu-budget"}
        else:
            try:
                cpu_runs = [_timed(cpu, marks, seed, shots, iterations) for seed in seeds[:cpu_repeats]]
            except (RuntimeError, ValueError) as error:
                row["cpu"] = {"error": str(error)[:300]}
        if cpu_runs:
            cpu_left -= sum(t for t, _ in cpu_runs)
            row["cpu"] = _summary([t for t, _ in cpu_runs])
            last_cpu = (n, row["cpu"]["median_s"])
            if gpu_runs:
                pairs = zip(cpu_runs, gpu_runs, strict=False)  # the CPU may have fewer repeats
                row["same_indices"] = all(np.array_equal(c, g) for (_, c), (_, g) in pairs)
                row["speedup"] = row["cpu"]["median_s"] / row["gpu"]["median_s"]
        payload["rows"].append(row)
        path.write_text(json.dumps(payload, indent=1))
        gpu_ms = f"{row['gpu']['median_s'] * 1e3:14.2f}" if "gpu" in row else f"{'-':>14s}"
        cpu_ms = (f"{row['cpu']['median_s'] * 1e3:14.2f}" if "median_s" in row["cpu"]
                  else f"{'error' if 'error' in row['cpu'] else 'skipped':>14s}")
        ratio = f"{row['speedup']:8.2f}" if "speedup" in row else f"{'-':>8s}"
        same = str(row.get("same_indices", "-"))
        print(f"{n:3d} {row.get('gpu_synthesis', '-'):8s} {gpu_ms} {cpu_ms} {ratio} {same:>5s}", flush=True)
    path.write_text(json.dumps(payload, indent=1))
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
