"""Speed-up of ``qrrt reproduce EXPERIMENT --quick`` on 2 jobs over serial.

    python benchmarks/bench_scaleout.py [--experiment heatmaps|all|NAME] [--repeats 3] [--jobs 2] [--full] [--quick]
                                        [--baseline-src OTHER_CHECKOUT/src]

Runs the real command line (a fresh ``--out`` each time, so nothing is resumed), end to end
including interpreter start, cluster start and worker imports, and reports median wall seconds
and the ratio serial / parallel measured in the same run, and the CPU seconds of the whole process
tree (client, fork server, workers): on a machine shared with other work the wall-clock ratio
moves with the load, the CPU seconds much less. ``--quick`` runs each command once. Writes JSON
with flat ``figures`` for ``benchmarks/run.py``.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _common import machine, write_json


def _children_cpu_s() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def time_command(args: list[str], source: str | None = None) -> tuple[float, float]:
    """(wall seconds, CPU seconds of the command and every process it waited for); ``source``: a
    ``src`` folder put first on ``PYTHONPATH`` (another checkout's code)."""
    env = dict(os.environ, PYTHONPATH=source) if source else None
    cpu = _children_cpu_s()
    start = time.perf_counter()
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    return time.perf_counter() - start, _children_cpu_s() - cpu


PHASES_SCRIPT = """
import json, pathlib, sys, tempfile, time
clock = time.process_time
start = clock()
from qrrt_circuits.experiments import EXPERIMENTS
from qrrt_circuits.experiments.runner import execute_trial
imported = clock()
names = sorted(EXPERIMENTS) if sys.argv[1] == "all" else [sys.argv[1]]
phases = {"import_s": imported - start, "trials_s": 0.0, "summarize_s": 0.0, "plot_s": 0.0}
for name in names:
    experiment = EXPERIMENTS[name]
    settings = json.loads(json.dumps({**experiment.settings(sys.argv[2] == "quick", None, 0), "predicate": "exact"}))
    began = clock()
    records = [execute_trial(name, trial, settings) for trial in experiment.trials(settings)]
    ran = clock()
    result = experiment.summarize(records, settings)
    summarized = clock()
    experiment.plot(records, settings, result, pathlib.Path(tempfile.mkdtemp()))
    plotted = clock()
    phases["trials_s"] += ran - began
    phases["summarize_s"] += summarized - ran
    phases["plot_s"] += plotted - summarized
    phases["last_tail_s"] = plotted - ran
print(json.dumps(phases))
"""


def serial_phases(experiment: str, full: bool, jobs: int) -> dict:
    """CPU seconds of each phase of a serial run in a fresh interpreter (imports, trials, summary,
    figures), and the speed-up ``jobs`` workers could give at best if only the trials were shared
    and nothing else cost anything (Amdahl): the import, summary and figures stay serial; and the
    bound when the summaries and figures overlap the next experiment's trials (``reproduce all``)."""
    done = subprocess.run([sys.executable, "-c", PHASES_SCRIPT, experiment, "full" if full else "quick"],
                          check=True, capture_output=True, text=True)
    phases = json.loads(done.stdout.strip().splitlines()[-1])
    last_tail = phases.pop("last_tail_s")
    serial = sum(phases.values())
    tails = phases["summarize_s"] + phases["plot_s"]
    best = phases["import_s"] + phases["trials_s"] / jobs + tails
    phases["serial_tail_share"] = tails / serial
    phases["best_speedup"] = serial / best
    # ``reproduce all`` makes each summary and figure while the next experiment's trials run
    # (runner.run_experiments): at best only the import and the last experiment's summary and
    # figures stay serial, and everything else shares the ``jobs`` cores
    phases["last_tail_s"] = last_tail
    pipelined = phases["import_s"] + (phases["trials_s"] + tails - last_tail) / jobs + last_tail
    phases["best_speedup_pipelined"] = serial / pipelined
    return phases


def warm_throughput(experiment: str, jobs: int, repeats: int) -> dict:
    """Seconds for the experiment's last 50 quick trials (heatmaps: the Pq-RRT ones) on workers that
    have already run 4 trials (imports, world, simulators warm); serial runs them in this process."""
    from concurrent.futures import as_completed

    from qrrt_circuits.execution import get_executor
    from qrrt_circuits.experiments import EXPERIMENTS
    from qrrt_circuits.experiments.runner import execute_trial

    exp = EXPERIMENTS[experiment]
    settings = exp.settings(True, None, 0)
    trials = exp.trials(settings)
    warm, timed = trials[:4], trials[-50:]
    out = {}
    for kind in ("serial", "process", "dask"):
        times = []
        with get_executor(kind, jobs if kind != "serial" else None) as pool:
            for _ in range(repeats):
                if pool is None:
                    for trial in warm:
                        execute_trial(experiment, trial, settings)
                    start = time.perf_counter()
                    for trial in timed:
                        execute_trial(experiment, trial, settings)
                else:
                    for future in [pool.submit(execute_trial, experiment, t, settings) for t in warm]:
                        future.result()
                    start = time.perf_counter()
                    for future in as_completed([pool.submit(execute_trial, experiment, t, settings) for t in timed]):
                        future.result()
                times.append(time.perf_counter() - start)
        out[kind] = {"median_s": float(np.median(times)), "times_s": times}
        print(f"  warm {kind:8s} median {np.median(times):6.2f} s")
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--experiment", default="heatmaps")
    parser.add_argument("--repeats", type=int, default=None, help="runs of each command (default 3; 1 with --quick)")
    parser.add_argument("--quick", action="store_true", help="each command once")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--full", action="store_true", help="the full settings instead of --quick")
    parser.add_argument("--warm", action="store_true",
                        help="time the last 50 quick trials on already-warm workers instead of whole commands")
    parser.add_argument("--baseline-src", default=None, metavar="SRC",
                        help="also time process and Dask with the package from this src folder (e.g. a "
                             "`git worktree` of an older commit), interleaved with ours")
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    args.repeats = args.repeats or (1 if args.quick else 3)
    if args.warm:
        rows = warm_throughput(args.experiment, args.jobs, args.repeats)
        speedup = {kind: rows["serial"]["median_s"] / rows[kind]["median_s"] for kind in ("process", "dask")}
        print("speed-up over serial (warm):", {k: round(v, 2) for k, v in speedup.items()})
        path = write_json(f"bench_scaleout_{args.experiment}_warm",
                          {"machine": machine(), "experiment": args.experiment, "jobs": args.jobs, "warm": True,
                           "repeats": args.repeats, "runs": rows, "speedup": speedup}, args.out)
        print(f"wrote {path}")
        return
    qrrt = str(Path(sys.executable).with_name("qrrt"))
    variants = {"serial": ("serial", None), "process": ("process", None), "dask": ("dask", None)}
    if args.baseline_src:  # the same commands on another checkout's code, interleaved with ours
        variants.update({"baseline_process": ("process", args.baseline_src),
                         "baseline_dask": ("dask", args.baseline_src)})
    samples = {name: ([], []) for name in variants}
    for _ in range(args.repeats):  # interleaved, so a change of load hits every variant alike
        for name, (kind, source) in variants.items():
            out = tempfile.mkdtemp(prefix="qrrt-bench-")
            try:
                command = [qrrt, "reproduce", args.experiment, "--out", out, "--no-progress", "--executor", kind]
                if not args.full:
                    command.append("--quick")
                if kind != "serial":
                    command += ["--jobs", str(args.jobs)]
                wall, cpu = time_command(command, source)
                samples[name][0].append(wall)
                samples[name][1].append(cpu)
            finally:
                shutil.rmtree(out, ignore_errors=True)
    rows = {}
    for name, (times, cpus) in samples.items():
        rows[name] = {"median_s": float(np.median(times)), "times_s": times,
                      "cpu_median_s": float(np.median(cpus)), "cpu_s": cpus}
        print(f"  {name:17s} median {np.median(times):6.2f} s  {[round(t, 2) for t in times]}  "
              f"CPU {np.median(cpus):6.2f} s")
    speedup = {name: rows["serial"]["median_s"] / rows[name]["median_s"] for name in rows if name != "serial"}
    print("speed-up over serial:", {k: round(v, 2) for k, v in speedup.items()})
    phases = serial_phases(args.experiment, args.full, args.jobs)
    print("serial phases (CPU s):", {k: round(v, 2) for k, v in phases.items()})
    sweep = f"{args.experiment}{'_full' if args.full else ''}"
    figures = {f"{sweep}.{name}.s": row["median_s"] for name, row in rows.items()}
    figures.update({f"{sweep}.{name}.cpu_s": row["cpu_median_s"] for name, row in rows.items()})
    figures.update({f"{sweep}.{kind}.speedup": value for kind, value in speedup.items()})
    figures.update({f"{sweep}.serial_phase.{key}": value for key, value in phases.items()})
    path = write_json(f"bench_scaleout_{sweep}",
                      {"machine": machine(), "experiment": args.experiment, "jobs": args.jobs, "full": args.full,
                       "repeats": args.repeats, "load_average": list(os.getloadavg()), "runs": rows,
                       "speedup": speedup, "serial_phases_cpu_s": phases, "figures": figures}, args.out)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
