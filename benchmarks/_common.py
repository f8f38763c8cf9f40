"""Shared helpers for the benchmark scripts: timing and JSON output."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from qrrt_circuits._support.provenance import provenance

RESULTS = Path(__file__).resolve().parent / "results"


def median_time(func, repeats: int, warmup: int = 1) -> tuple[float, float, float]:
    """(median, min, max) wall time in seconds of ``func()`` over ``repeats`` runs."""
    for _ in range(warmup):
        func()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        func()
        times.append(time.perf_counter() - start)
    return float(np.median(times)), float(np.min(times)), float(np.max(times))


def machine() -> dict:
    """The run's provenance: commit, package versions, machine and date."""
    return provenance()


def write_json(name: str, payload: dict, out: str | None = None) -> Path:
    path = Path(out) if out else RESULTS / f"{name}.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(payload, indent=1))
    return path


def rows_in_subprocesses(script: str, cases: Sequence[Sequence[object]], header: str,
                         line: Callable[[dict], str]) -> list[dict]:
    """Each case run as ``python script --case *case`` in a fresh process (one OpenMP thread), whose
    last line of output is its row as JSON; ``header``, then ``line(row)`` for each row as it comes.

    Returns:
        The rows, in the order of ``cases``.
    """
    env = dict(os.environ, OMP_NUM_THREADS="1")
    print(header)
    rows = []
    for case in cases:
        done = subprocess.run([sys.executable, script, "--case", *map(str, case)], capture_output=True, text=True,
                              check=True, env=env)
        rows.append(json.loads(done.stdout.strip().splitlines()[-1]))
        print(line(rows[-1]), flush=True)
    return rows
