"""Run every benchmark and write one JSON of flat figures with a description of the machine.

    python benchmarks/run.py [--quick] [--only NAME ...] [--skip NAME ...] [--out PATH]

Every ``benchmarks/bench_*.py`` is found by name (a new one is picked up without editing this
file) and run as its own process, in name order, with ``--quick`` forwarded and ``--out`` pointing
at a temporary JSON that is then read back. Each script's numbers become figures under its short
name (``bench_search.py`` -> ``search.``; see ``_figures.py`` for the keys and which way each is
better). A script that fails is recorded with its exit status and the tail of its output, and the
others still run. Writes ``benchmarks/results/run.json`` (``run_quick.json`` with ``--quick``):

    {"machine": {...}, "quick": ..., "benchmarks": {name: {"returncode", "wall_s", "command"}},
     "figures": {"search.summary.aer_n12_ms": 45.0, ...}, "raw": {name: the script's JSON}}

Compare two such files with ``python benchmarks/compare.py NEW [OLD]``, each a path or a
``REV:PATH`` read from git (``HEAD~5:benchmarks/results/run.json``); ``benchmarks/results/baseline.json``
is a pinned earlier run to compare with. A benchmark script joins in by accepting ``--quick`` and
``--out PATH`` (write its JSON there).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
sys.path.insert(0, str(HERE))

from _figures import flatten  # noqa: E402

from qrrt_circuits._support.provenance import provenance  # noqa: E402


def discover(directory: Path = HERE) -> dict[str, Path]:
    """Short name -> script, for every ``bench_*.py`` in ``directory``, sorted by name."""
    return {path.stem.removeprefix("bench_"): path for path in sorted(directory.glob("bench_*.py"))}


def machine_description() -> dict:
    """The run's provenance (``qrrt_circuits._support.provenance``) and the machine's load average."""
    return {**provenance(), "load_average": list(os.getloadavg()) if hasattr(os, "getloadavg") else None}


def run_one(script: Path, quick: bool, timeout: float | None) -> tuple[dict, dict | None]:
    """Run one benchmark script; returns (its bookkeeping, its JSON or None if it failed)."""
    with tempfile.TemporaryDirectory(prefix="qrrt-bench-run-") as scratch:
        out = Path(scratch) / "out.json"
        command = [sys.executable, str(script), "--out", str(out)] + (["--quick"] if quick else [])
        start = time.perf_counter()
        try:
            done = subprocess.run(command, cwd=HERE.parent, capture_output=True, text=True, timeout=timeout)
            returncode, output = done.returncode, done.stdout + done.stderr
        except subprocess.TimeoutExpired as exc:
            returncode = None
            output = f"timed out after {timeout} s\n" + str(exc.stdout or "")
        shown = ["python", str(script.relative_to(HERE.parent)), *command[2:]]
        entry = {"command": " ".join(shown).replace(str(out), "OUT"),
                 "returncode": returncode, "wall_s": round(time.perf_counter() - start, 2)}
        payload = None
        if returncode == 0 and out.exists():
            payload = json.loads(out.read_text())
        else:
            entry["output_tail"] = output[-2000:]
        return entry, payload


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="forwarded to every benchmark")
    parser.add_argument("--only", nargs="+", default=None, metavar="NAME", help="run only these (short names)")
    parser.add_argument("--skip", nargs="+", default=(), metavar="NAME", help="leave these out")
    parser.add_argument("--timeout", type=float, default=None, help="seconds allowed to each benchmark")
    parser.add_argument("--out", default=None, help="default: benchmarks/results/run[_quick].json")
    parser.add_argument("--list", action="store_true", help="print the benchmarks found and exit")
    args = parser.parse_args(argv)
    scripts = discover()
    unknown = sorted((set(args.only or ()) | set(args.skip)) - set(scripts))
    if unknown:
        parser.error(f"unknown benchmark(s) {unknown}; found {sorted(scripts)}")
    if args.list:
        print("\n".join(f"{name:20s} {path.relative_to(HERE.parent)}" for name, path in scripts.items()))
        return 0
    chosen = {name: path for name, path in scripts.items()
              if (args.only is None or name in args.only) and name not in args.skip}
    result = {"machine": machine_description(), "quick": args.quick, "benchmarks": {}, "figures": {}, "raw": {}}
    for name, script in chosen.items():
        print(f"== {name} ({script.name}{' --quick' if args.quick else ''})", flush=True)
        entry, payload = run_one(script, args.quick, args.timeout)
        result["benchmarks"][name] = entry
        if payload is None:
            print(f"   FAILED (exit {entry['returncode']}):\n{entry['output_tail'][-600:]}", flush=True)
            continue
        result["raw"][name] = payload
        figures = {f"{name}.{key}": value for key, value in flatten(payload).items()}
        result["figures"].update(figures)
        print(f"   {len(figures)} figures in {entry['wall_s']} s", flush=True)
    path = Path(args.out) if args.out else RESULTS / ("run_quick.json" if args.quick else "run.json")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(result, indent=1, sort_keys=False))
    failed = sorted(name for name, entry in result["benchmarks"].items() if entry["returncode"] != 0)
    print(f"wrote {path} ({len(result['figures'])} figures" + (f"; failed: {failed}" if failed else "") + ")")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
