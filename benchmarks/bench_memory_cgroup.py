"""The memory guard inside a memory-limited control group (a container's situation).

Makes a cgroup (v2, or v1's memory controller) with a 600 MiB limit, which needs root and a
writable cgroup file system, and runs in it, in fresh processes: a q-RRT construction and one
round at n = 22, 23 and 24 with the guard as it is (the room of the group,
``available_memory.cgroup_available_bytes``), and n = 24 with the group ignored (the guard before it read the
group: the machine's ``MemAvailable`` only). Records for each: refused (the message), ran, or
killed (exit status, the group's failure count).

    python benchmarks/bench_memory_cgroup.py

Writes ``benchmarks/results/bench_memory_cgroup.json``. Where no group can be made (not root) it
says why and writes only to an ``--out`` it is given (``missing``), never over the committed
results. On Ctrl-C or SIGTERM the child is killed and the group removed. The group limits memory
only, not swap: on a machine with swap the unguarded run may swap instead of being killed.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import time
import uuid
from pathlib import Path

from _common import RESULTS, machine

LIMIT = 600 << 20

CHILD = """
import sys
from qrrt_circuits._support import available_memory as probe
import qrrt_circuits as qc
from qrrt_circuits._support import memory
n, guarded = int(sys.argv[1]), sys.argv[2] == "guarded"
if not guarded:
    probe.cgroup_available_bytes = lambda: None
env = qc.paper_clutter(seed=0)
planner = qc.QRRT(backend=qc.StatevectorBackend(0, max_qubits=24), num_qubits=n, seed=0)
try:
    planner.plan(env, max_rounds=1)
except ValueError as error:
    print("refused:", error)
else:
    print("ran")
"""


def make_group() -> tuple[Path, str] | str:
    """A new group with the limit: (its folder, the file that takes a process id), or why not."""
    name = f"qrrt-bench-{uuid.uuid4().hex[:8]}"
    reason = "no cgroup memory controller mounted at /sys/fs/cgroup"
    for root, limit_file in ((Path("/sys/fs/cgroup/memory"), "memory.limit_in_bytes"),
                             (Path("/sys/fs/cgroup"), "memory.max")):
        if not (root / limit_file).exists() and not (root / "cgroup.controllers").exists():
            continue
        folder = root / name
        try:
            folder.mkdir()
            (folder / limit_file).write_text(str(LIMIT))
            return folder, "cgroup.procs"
        except OSError as exc:
            if folder.exists():
                folder.rmdir()
            reason = f"cannot make a group under {root}: {exc}"
    return reason


def run_in(folder: Path, procs: str, n: int, mode: str) -> dict:
    """One child in the group; it is killed and waited for on any interruption, so the group can be
    removed."""
    command = f'echo $$ > {folder / procs} && exec "$0" -c "$1" {n} {mode}'
    child = subprocess.Popen(["sh", "-c", command, sys.executable, CHILD], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, cwd=Path(__file__).resolve().parent.parent)
    try:
        stdout, stderr = child.communicate(timeout=600)
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
    out = stdout.strip().splitlines()
    outcome = "killed" if child.returncode in (-9, 137) else (out[-1].split(":")[0] if out else "no output")
    return {"num_qubits": n, "guard": mode, "returncode": child.returncode, "outcome": outcome,
            "message": out[-1] if out else stderr.strip()[-300:]}


def remove_group(folder: Path) -> None:
    """rmdir the group (retried while its last process exits); say so if it stays."""
    for _ in range(50):
        try:
            os.rmdir(folder)
            return
        except FileNotFoundError:
            return
        except OSError:
            time.sleep(0.1)
    print(f"could not remove the cgroup {folder}; remove it with: rmdir {folder}", file=sys.stderr)


def _terminate(signum, frame):  # SIGTERM as Ctrl-C: the finally blocks clean up
    raise KeyboardInterrupt


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="accepted for benchmarks/run.py (the same cases)")
    parser.add_argument("--out", default=None, help="the JSON to write (default: results/bench_memory_cgroup.json)")
    args = parser.parse_args()
    path = Path(args.out) if args.out else RESULTS / "bench_memory_cgroup.json"
    made = make_group()
    if isinstance(made, str):
        print(f"skipped: {made}")
        if args.out:  # (benchmarks/run.py's file; the committed results are not overwritten)
            path.write_text(json.dumps({"machine": machine(), "missing": made}, indent=1))
        return
    folder, procs = made
    signal.signal(signal.SIGTERM, _terminate)
    try:
        rows = [run_in(folder, procs, n, "guarded") for n in (22, 23, 24)] + [run_in(folder, procs, 24, "unguarded")]
        failures = (folder / "memory.failcnt") if (folder / "memory.failcnt").exists() else folder / "memory.events"
        events = failures.read_text().strip()
    finally:
        remove_group(folder)
    for row in rows:
        print(f"n = {row['num_qubits']} {row['guard']:9s} {row['outcome']:8s} rc {row['returncode']}  "
              f"{row['message'][:110]}")
    RESULTS.mkdir(exist_ok=True)
    from qrrt_circuits._support.available_memory import (
        _machine_available_bytes,  # the machine's figure, outside any group
    )

    path.write_text(json.dumps({"machine": machine(), "machine_available_bytes": _machine_available_bytes(),
                                "limit_bytes": LIMIT, "rows": rows,
                                "group_failures": events}, indent=1))
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
