"""Kill-and-resume campaign: ``qrrt reproduce`` killed at random moments must resume to the same result.

    python benchmarks/kill_resume.py [--experiment heatmaps] [--runs 30] [--seed 0] [--quick] [--jobs 2]
                                     [--tear-every 5] [--second-kill-every 4] [--attempts 3] [--grace 10]
                                     [--strict] [--keep-all] [--work DIR] [--out FILE]

Proves (or refutes) that a long run never loses or double-counts finished work. The command under
test is ``python -m qrrt_circuits.cli reproduce EXPERIMENT --quick --seed SEED --no-progress
--executor E [--jobs J] --out FOLDER``, with this checkout's ``src`` first on ``PYTHONPATH``. The
experiment always runs with its ``--quick`` settings (it must take seconds: heatmaps takes 4-8 s on
2 cores); ``--quick`` of this script means fewer runs (6 instead of 30, every 2nd one torn, so
that each way of tearing is tried).

1. References: the command runs once uninterrupted on each executor (serial, process, dask), each
   into its own folder. The serial run's ``summary.json`` bytes, its records.csv header and its
   rows (keyed by ``trial_id``) are the reference; each executor's uninterrupted duration sets its
   kill times. The process and dask runs must give the same summary bytes and rows, else the
   campaign stops (exit 2): comparing bytes would mean nothing. A summary's bytes are compared
   without its ``provenance`` (commit, machine, date: the one part that differs between two runs
   with the same settings); for heatmaps the rest holds no timing and no executor name.
2. Runs: run i uses executor serial, process, dask in turn (``--jobs`` workers for the latter two),
   in a fresh folder. The command is started in its own process group and killed at a moment drawn
   uniformly in [2 %, 90 %] of that executor's reference duration (tear runs: [40 %, 90 %], so
   there is a file to tear), so kills land in the interpreter's start, the trials and the summary
   and figures (the references print when their first and last records were written; on a loaded
   machine a run may finish before its moment: shown as SIGNAL>seconds). The signal is drawn from
   SIGKILL, SIGINT, SIGTERM, SIGHUP and SIGINT-group: SIGKILL goes to the whole process group
   (workers die too, as in a crash), SIGINT-group too (Ctrl-C from a terminal), the others to the
   main process only (as ``kill PID``). Every
   ``--second-kill-every``-th run is killed a second time, the same way, during its first resume;
   every ``--tear-every``-th run has its records.csv truncated after the kill, in turn at a drawn
   offset inside the header line (0 included: an empty file), just before the header line's
   "\\r\\n" (the header whole, its line ending lost) and at a drawn offset anywhere in the file.
   Then the same command is rerun until it exits 0, at most ``--attempts`` times. Every draw comes
   from ``numpy.random.default_rng(--seed)``, drawn up front in the same order whatever happens,
   so a campaign is replayed by its seed (where the kills fall relative to the work done varies
   with the machine's load).
3. Checks, per run: the killed run's exit status; the valid records right after the kill (rows of
   records.csv that end with a newline and have the header's width); whether any phase's stderr
   holds "Traceback" or "leaked semaphore"; processes of a phase's group still alive ``--grace``
   seconds after its main process ended (orphans; killed then, before the next phase); whether a
   phase stopped by a signal (exit 129, 130 or 143) printed more than its one line (stdout and
   stderr together); whether a resume exited 0; whether the summary.json then is byte-identical
   to the reference (only after a resume exited 0: a run that finished before its kill already
   wrote one); and, read raw (not through the package, whose reader repairs the file), whether
   the final records.csv has the reference header, every reference trial exactly once (lost:
   missing; double-counted: extra rows of one trial), no unknown trial, no invalid line and each
   row equal to the reference row.

A run fails if no resume exits 0, its summary differs, a trial is lost or double-counted, or its
records.csv is otherwise not the reference's (unknown trials, rows differing, invalid lines).
Tracebacks, leaked semaphores and orphans are reported but fail the campaign only with
``--strict``. Prints one row per run, then "N runs: K byte-identical summaries, D double-counted,
L lost, T tracebacks" (D, L, T: runs with at least one such trial or traceback) and the failed runs
with their folders, and the flagged ones (a traceback, a leaked semaphore, orphans, a hang). The
folders of failed and flagged runs (and the references, if any run failed) are kept under the
campaign's folder (``--work``, default a fresh ``/tmp/kill_resume_*``), each phase's stdout and
stderr beside its ``out``; the other runs' folders are removed unless ``--keep-all``. Writes
``benchmarks/results/kill_resume.json`` (``kill_resume_quick.json`` with ``--quick``): every
run's row, the totals and the provenance (``run.machine_description``: commit, package versions,
machine, date). Exits 1 if any run failed, 2 if the references could not be made or disagree.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from _common import write_json
from run import machine_description

HERE = Path(__file__).resolve().parent
SRC = HERE.parent / "src"
EXECUTORS = ("serial", "process", "dask")


class GroupSignal:
    """A signal sent to the command's whole process group, as a terminal sends Ctrl-C (SIGINT to
    the foreground group: the workers and the fork server get it too)."""

    def __init__(self, signum: signal.Signals) -> None:
        self.signum = signum
        self.name = f"{signum.name}-group"


SIGNALS = (signal.SIGKILL, signal.SIGINT, signal.SIGTERM, signal.SIGHUP, GroupSignal(signal.SIGINT))
#: the kill moment, as fractions of the executor's uninterrupted duration (tear runs: the later range)
KILL_RANGE = (0.02, 0.9)
TEAR_KILL_RANGE = (0.4, 0.9)
RECORDS = "records.csv"
SUMMARY = "summary.json"


# ----------------------------------------------------------------------------- processes
def group_members(pgid: int) -> list[tuple[int, str]]:
    """(pid, name) of the live (not zombie) processes of process group ``pgid``, read from /proc."""
    members = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        name, rest = stat[stat.index("(") + 1: stat.rindex(")")], stat[stat.rindex(")") + 2:].split()
        state, pgrp = rest[0], int(rest[2])
        if pgrp == pgid and state != "Z":
            members.append((int(entry.name), name))
    return members


def _default_signals() -> None:
    """In the command's process, before it starts: the default dispositions of the signals sent.
    A campaign started in the background (``cmd &``, ``nohup``) inherits SIGINT or SIGHUP ignored,
    and a program keeps an ignored signal ignored, so its SIGINT runs would test nothing."""
    for signum in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(signum, signal.SIG_DFL)


def _kill_group(pgid: int) -> None:
    try:
        os.killpg(pgid, signal.SIGKILL)
    except ProcessLookupError:
        pass


def run_phase(command: list[str], env: dict[str, str], logs: Path, name: str, timeout: float, grace: float,
              kill_at: float | None = None, signum: signal.Signals | None = None, watch: Path | None = None) -> dict:
    """Run ``command`` in its own process group, stdout and stderr into ``logs/name.stdout|.stderr``;
    with ``kill_at``, send ``signum`` that many seconds after the start (SIGKILL to the group, any
    other to the main process) unless it has exited. Then wait for it (at most ``timeout`` seconds,
    then the group is killed: ``hung``), and for the rest of its group (at most ``grace`` seconds,
    then what is left is killed: ``orphans``). With ``watch`` (a records.csv), polls it every 50 ms:
    ``records_s`` = [seconds to its first record, seconds to its last line]."""
    logs.mkdir(parents=True, exist_ok=True)
    with open(logs / f"{name}.stdout", "wb") as out, open(logs / f"{name}.stderr", "wb") as err:
        start = time.monotonic()
        process = subprocess.Popen(command, env=env, stdout=out, stderr=err, stdin=subprocess.DEVNULL,
                                   start_new_session=True, preexec_fn=_default_signals)
    pgid = process.pid
    sent_s = None
    if kill_at is not None and signum is not None:
        try:
            process.wait(timeout=kill_at)
        except subprocess.TimeoutExpired:
            sent_s = time.monotonic() - start  # (not reaped yet, so the pid is still this process)
            if signum == signal.SIGKILL:
                _kill_group(pgid)
            elif isinstance(signum, GroupSignal):
                os.killpg(pgid, signum.signum)
            else:
                os.kill(process.pid, signum)
    hung, lines, first_s, last_s = False, 0, None, None
    while True:
        try:
            rc = process.wait(timeout=0.05 if watch else max(timeout - (time.monotonic() - start), 1.0))
            break
        except subprocess.TimeoutExpired:
            if time.monotonic() - start >= timeout:
                hung = True
                _kill_group(pgid)
                rc = process.wait()
                break
        if watch and watch.exists():  # when records.csv reached each line count
            count = watch.read_bytes().count(b"\n")
            if count > lines:
                lines, last_s = count, round(time.monotonic() - start, 2)
                if first_s is None and count >= 2:  # the header and a first record
                    first_s = last_s
    wall = time.monotonic() - start
    deadline = time.monotonic() + grace
    while group_members(pgid) and time.monotonic() < deadline:
        time.sleep(0.1)
    orphans = group_members(pgid)
    if orphans:
        _kill_group(pgid)
        stop = time.monotonic() + 10
        while group_members(pgid) and time.monotonic() < stop:
            time.sleep(0.1)
    stderr = (logs / f"{name}.stderr").read_text(errors="replace")
    stdout = (logs / f"{name}.stdout").read_text(errors="replace")
    lines_seen = [line.strip() for line in stderr.splitlines() if line.strip()]
    printed = len(lines_seen) + sum(1 for line in stdout.splitlines() if line.strip())
    leaked = [line for line in lines_seen if "leaked semaphore" in line]
    return {"rc": rc, "wall_s": round(wall, 2), "signal": signum.name if signum is not None else None,
            "kill_at_s": round(kill_at, 2) if kill_at is not None else None,
            "sent_s": round(sent_s, 2) if sent_s is not None else None, "hung": hung,
            **({"records_s": [first_s, last_s]} if watch else {}),
            "orphans": [f"{pid}:{comm}" for pid, comm in orphans],
            "traceback": "Traceback" in stderr, "leaked_semaphore": "leaked semaphore" in stderr,
            # an interrupted command prints one line (stdout and stderr together)
            "interrupted": rc in (128 + signal.SIGINT, 128 + signal.SIGTERM, 128 + signal.SIGHUP),
            "lines_printed": printed,
            # the resource tracker's warning if there is one, else the last line (an error, an exception)
            "stderr_line": leaked[0] if leaked else (lines_seen[-1][:400] if lines_seen else None)}


def results_bytes(path: Path) -> bytes:
    """A summary.json's bytes without its ``provenance`` member (the rest as written: strict JSON,
    indent 1, keys in the runner's order)."""
    summary = json.loads(path.read_bytes())
    summary.pop("provenance", None)
    return json.dumps(summary, indent=1).encode()


def reproduce_command(experiment: str, out: Path, seed: int, executor: str, jobs: int) -> list[str]:
    command = [sys.executable, "-m", "qrrt_circuits.cli", "reproduce", experiment, "--quick", "--seed", str(seed),
               "--no-progress", "--executor", executor, "--out", str(out)]
    return command + (["--jobs", str(jobs)] if executor != "serial" else [])


# ----------------------------------------------------------------------------- records.csv, read raw
def read_raw(path: Path) -> tuple[list[str] | None, list[list[str]], int]:
    """(header, valid rows, invalid lines) of a records.csv, read without repairing it: a line counts
    only if it ends with a newline; a row is valid if it has the header's width. (None, [], 0) for a
    missing file or one without a complete first line."""
    if not path.exists():
        return None, [], 0
    lines = path.read_text(errors="replace").split("\n")
    torn = 1 if lines[-1] else 0  # the last piece has no newline
    complete = lines[:-1]
    if not complete:
        return None, [], torn
    parsed = list(csv.reader(complete))
    header, body = parsed[0], parsed[1:]
    valid = [row for row in body if len(row) == len(header)]
    return header, valid, torn + len(body) - len(valid)


def check_records(path: Path, header: list[str], reference: dict[str, list[str]]) -> dict:
    """The final records.csv against the reference header and rows (keyed by trial_id)."""
    found_header, rows, invalid = read_raw(path)
    if found_header != header:
        return {"header_ok": False, "lost": len(reference), "double_counted": 0, "unknown": 0,
                "rows_differing": 0, "invalid_lines": invalid, "final_records": len(rows)}
    column = header.index("trial_id")
    counts: dict[str, int] = {}
    differing = 0
    for row in rows:
        trial = row[column]
        counts[trial] = counts.get(trial, 0) + 1
        if trial in reference and row != reference[trial]:
            differing += 1
    return {"header_ok": True, "lost": len(set(reference) - set(counts)),
            "double_counted": sum(n - 1 for n in counts.values()), "unknown": len(set(counts) - set(reference)),
            "rows_differing": differing, "invalid_lines": invalid, "final_records": len(rows)}


#: how a tear run truncates records.csv, in turn: at ``fraction`` of the first line's length (a
#: torn header; 0 is an empty file), at the end of the first line's text (the header whole but
#: without its line ending), at ``fraction`` of the whole file's length
TEAR_MODES = ("header", "header-end", "anywhere")


def tear(path: Path, mode: str, fraction: float) -> dict:
    """Truncate ``path`` at a byte offset chosen by ``mode`` (``TEAR_MODES``) and ``fraction``."""
    if not path.exists():
        return {"mode": mode, "offset": None, "size": None}
    data = path.read_bytes()
    first = data.find(b"\n")
    line = first if first >= 0 else len(data)  # the first line, without its "\n"
    if mode == "header-end":
        offset = line - 1 if line > 0 and data[line - 1: line] == b"\r" else line  # (csv writes "\r\n")
    else:
        limit = line if mode == "header" else len(data)
        offset = min(int(fraction * (limit + 1)), limit)
    with path.open("r+b") as handle:
        handle.truncate(offset)
    return {"mode": mode, "offset": offset, "size": len(data)}


# ----------------------------------------------------------------------------- the campaign
def make_references(args: argparse.Namespace, env: dict[str, str], work: Path) -> dict:
    """One uninterrupted run per executor; stops the campaign (exit 2) if one fails or disagrees."""
    references = {}
    for executor in EXECUTORS:
        folder = work / f"reference_{executor}"
        command = reproduce_command(args.experiment, folder / "out", args.seed, executor, args.jobs)
        directory = folder / "out" / args.experiment
        phase = run_phase(command, env, folder, "run", args.phase_timeout, args.grace, watch=directory / RECORDS)
        if phase["rc"] != 0 or not (directory / SUMMARY).exists():
            raise SystemExit(f"the uninterrupted {executor} run failed (exit {phase['rc']}); see {folder}")
        header, rows, invalid = read_raw(directory / RECORDS)
        references[executor] = {"folder": str(folder), "wall_s": phase["wall_s"], "phase": phase,
                                "summary": results_bytes(directory / SUMMARY), "header": header, "rows": rows,
                                "invalid": invalid}
        first, last = phase["records_s"]
        print(f"  reference {executor:8s} {phase['wall_s']:6.2f} s, {len(rows)} records (written from "
              f"{first} s to {last} s)", flush=True)
    serial = references["serial"]
    for executor, ref in references.items():
        if ref["summary"] != serial["summary"] or ref["header"] != serial["header"] or \
                sorted(ref["rows"]) != sorted(serial["rows"]) or ref["invalid"]:
            raise SystemExit(f"the uninterrupted {executor} run's summary.json or records differ from the serial "
                             f"run's: this experiment is not reproducible byte for byte; see {work}")
    return references


def draw_plan(rng: np.random.Generator, runs: int, tear_every: int, second_every: int,
              signals: tuple = SIGNALS) -> list[dict]:
    """Every run's executor, kill moments (as fractions), signals (from ``signals``) and tear, drawn
    up front."""
    plan, tears = [], 0
    for index in range(runs):
        number = index + 1
        is_tear = tear_every > 0 and number % tear_every == 0
        kill_range = TEAR_KILL_RANGE if is_tear else KILL_RANGE
        entry = {"run": number, "executor": EXECUTORS[index % len(EXECUTORS)],
                 "kill_fraction": float(rng.uniform(*kill_range)),
                 "signal": signals[int(rng.integers(len(signals)))],
                 "second_fraction": float(rng.uniform(*KILL_RANGE)),
                 "second_signal": signals[int(rng.integers(len(signals)))],
                 "tear_fraction": float(rng.uniform()),
                 "second_kill": second_every > 0 and number % second_every == 0,
                 "tear": None}
        if is_tear:
            entry["tear"] = TEAR_MODES[tears % len(TEAR_MODES)]
            tears += 1
        plan.append(entry)
    return plan


def run_one(args: argparse.Namespace, env: dict[str, str], work: Path, entry: dict, duration: float,
            reference: dict) -> dict:
    """One run: kill, maybe tear, resume (maybe killed again), check."""
    executor = entry["executor"]
    folder = work / f"run_{entry['run']:02d}_{executor}"
    command = reproduce_command(args.experiment, folder / "out", args.seed, executor, args.jobs)
    records = folder / "out" / args.experiment / RECORDS
    phases = [run_phase(command, env, folder, "killed", args.phase_timeout, args.grace,
                        kill_at=entry["kill_fraction"] * duration, signum=entry["signal"])]
    after_kill = len(read_raw(records)[1])
    torn = None
    if entry["tear"]:
        torn = tear(records, entry["tear"], entry["tear_fraction"])
    after_tear = len(read_raw(records)[1])
    resumed = False
    for attempt in range(args.attempts):
        second = entry["second_kill"] and attempt == 0
        phase = run_phase(command, env, folder, f"resume{attempt + 1}", args.phase_timeout, args.grace,
                          kill_at=entry["second_fraction"] * duration if second else None,
                          signum=entry["second_signal"] if second else None)
        phases.append(phase)
        if phase["rc"] == 0:
            resumed = True
            break
    summary = records.parent / SUMMARY
    row = {"run": entry["run"], "executor": executor, "folder": str(folder),
           "signals": [p["signal"] for p in phases if p["signal"]],
           "kill_planned_s": [p["kill_at_s"] for p in phases if p["signal"]],
           "kill_s": [p["sent_s"] for p in phases if p["signal"]],
           "killed_rc": phases[0]["rc"], "records_after_kill": after_kill, "tear": torn,
           "records_after_tear": after_tear if torn else None,
           "second_kill": entry["second_kill"], "resume_rcs": [p["rc"] for p in phases[1:]], "resumed": resumed,
           "traceback": any(p["traceback"] for p in phases),
           "beyond_one_line": any(p["interrupted"] and p["lines_printed"] > 1 for p in phases),
           "leaked_semaphore": any(p["leaked_semaphore"] for p in phases),
           "orphans": sum(len(p["orphans"]) for p in phases), "hung": any(p["hung"] for p in phases),
           # (by the resume that exited 0: a run that finished before its kill already wrote one)
           "summary_identical": resumed and summary.exists() and results_bytes(summary) == reference["summary"],
           **check_records(records, reference["header"], reference["by_id"]), "phases": phases}
    why = []
    if not resumed:
        why.append(f"no resume exited 0 in {args.attempts} attempts (exit {row['resume_rcs']})")
    if resumed and not row["summary_identical"]:
        why.append("summary.json missing" if not summary.exists() else "summary.json differs")
    if not row["header_ok"]:
        why.append("records.csv header differs or is missing")
    for key, label in (("lost", "lost"), ("double_counted", "double-counted"), ("unknown", "unknown trials"),
                       ("rows_differing", "rows differing"), ("invalid_lines", "invalid lines")):
        if row[key] and (key != "lost" or row["header_ok"]):
            why.append(f"{row[key]} {label}")
    if args.strict:
        why += [label for key, label in (("traceback", "traceback"), ("leaked_semaphore", "leaked semaphore"),
                                         ("orphans", "orphans"), ("hung", "hung")) if row[key]]
    row["failed"], row["why"] = bool(why), why
    return row


def _kills(row: dict) -> str:
    """SIGNAL@seconds of each kill sent; SIGNAL>seconds where the run had exited before that moment."""
    return "+".join(f"{name[3:]}@{sent:.1f}" if sent is not None else f"{name[3:]}>{planned:.1f}"
                    for name, planned, sent in zip(row["signals"], row["kill_planned_s"], row["kill_s"], strict=True))


def print_header() -> None:
    print(f"{'run':>3s} {'executor':8s} {'kill(s)':20s} {'rc':>4s} {'recs':>4s} {'tear':>12s} "
          f"{'resumes':12s} {'ident':5s} {'lost':>4s} {'dup':>3s} {'tb':>2s} {'sem':>3s} {'orph':>4s} result")


def print_row(row: dict) -> None:
    short = {"header": "h", "header-end": "he", "anywhere": "a"}
    tear_text = "-" if not row["tear"] else f"{short[row['tear']['mode']]}@{row['tear']['offset']}"
    print(f"{row['run']:3d} {row['executor']:8s} {_kills(row):20s} "
          f"{row['killed_rc']:4d} {row['records_after_kill']:4d} {tear_text:>12s} "
          f"{','.join(map(str, row['resume_rcs'])):12s} {'yes' if row['summary_identical'] else 'NO':5s} "
          f"{row['lost']:4d} {row['double_counted']:3d} {'y' if row['traceback'] else '-':>2s} "
          f"{'y' if row['leaked_semaphore'] else '-':>3s} {row['orphans']:4d} "
          f"{'FAIL: ' + '; '.join(row['why']) if row['failed'] else 'ok'}", flush=True)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--experiment", default="heatmaps", help="an experiment whose --quick run takes seconds")
    parser.add_argument("--runs", type=int, default=None, help="killed runs (default 30; 6 with --quick)")
    parser.add_argument("--quick", action="store_true", help="6 runs")
    parser.add_argument("--seed", type=int, default=0, help="seeds the draws, and is the experiment's --seed")
    parser.add_argument("--jobs", type=int, default=2, help="workers of the process and dask executors")
    parser.add_argument("--tear-every", type=int, default=None,
                        help="truncate records.csv in every k-th run (0: none; default 5, 2 with --quick)")
    parser.add_argument("--second-kill-every", type=int, default=4,
                        help="kill every k-th run again during its first resume (0: none)")
    parser.add_argument("--attempts", type=int, default=3, help="resumes tried before a run counts as failed")
    parser.add_argument("--grace", type=float, default=10.0,
                        help="seconds a phase's workers may outlive its main process before they are killed")
    parser.add_argument("--signals", nargs="+", default=[item.name for item in SIGNALS],
                        choices=[item.name for item in SIGNALS],
                        help="the signals drawn from (default all: SIGKILL SIGINT SIGTERM SIGHUP SIGINT-group)")
    parser.add_argument("--strict", action="store_true", help="tracebacks, leaked semaphores, orphans also fail")
    parser.add_argument("--keep-all", action="store_true", help="keep every run's folder, not only failed ones")
    parser.add_argument("--work", default=None, help="campaign folder (default: a fresh /tmp/kill_resume_*)")
    parser.add_argument("--out", default=None, help="JSON path (default benchmarks/results/kill_resume[_quick].json)")
    args = parser.parse_args()
    args.runs = args.runs if args.runs is not None else (6 if args.quick else 30)
    args.tear_every = args.tear_every if args.tear_every is not None else (2 if args.quick else 5)
    if args.runs < 1 or args.attempts < 1 or args.jobs < 1:
        parser.error("--runs, --attempts and --jobs must be >= 1")
    work = Path(args.work) if args.work else Path(tempfile.mkdtemp(prefix="kill_resume_", dir="/tmp"))
    work.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(SRC), os.environ.get("PYTHONPATH")])))
    started = time.monotonic()
    print(f"kill-and-resume campaign: {args.experiment} --quick, {args.runs} runs, seed {args.seed}, in {work}")
    args.phase_timeout = 600.0  # the references' own limit, until their durations are known
    try:
        references = make_references(args, env, work)
    except SystemExit as exc:
        print(exc, file=sys.stderr)
        return 2
    durations = {executor: ref["wall_s"] for executor, ref in references.items()}
    args.phase_timeout = max(60.0, 20 * max(durations.values()))
    serial = references["serial"]
    column = serial["header"].index("trial_id")
    reference = {"summary": serial["summary"], "header": serial["header"],
                 "by_id": {row[column]: row for row in serial["rows"]}}
    chosen = tuple(SIGNALS[[item.name for item in SIGNALS].index(name)] for name in args.signals)
    plan = draw_plan(np.random.default_rng(args.seed), args.runs, args.tear_every, args.second_kill_every, chosen)
    print_header()
    rows = []
    for entry in plan:
        row = run_one(args, env, work, entry, durations[entry["executor"]], reference)
        print_row(row)
        rows.append(row)
        row["flagged"] = [key for key in ("traceback", "leaked_semaphore", "orphans", "hung") if row[key]]
        if not row["failed"] and not row["flagged"] and not args.keep_all:
            shutil.rmtree(row["folder"], ignore_errors=True)
            row["folder"] = None
    failed = [row for row in rows if row["failed"]]
    totals = {"runs": len(rows), "byte_identical_summaries": sum(r["summary_identical"] for r in rows),
              "runs_double_counted": sum(r["double_counted"] > 0 for r in rows),
              "runs_lost": sum(r["lost"] > 0 for r in rows), "runs_traceback": sum(r["traceback"] for r in rows),
              "runs_group_sigint": sum(any(name.endswith("-group") for name in r["signals"]) for r in rows),
              "runs_beyond_one_line": sum(r["beyond_one_line"] for r in rows),
              "trials_double_counted": sum(r["double_counted"] for r in rows),
              "trials_lost": sum(r["lost"] for r in rows),
              "runs_leaked_semaphore": sum(r["leaked_semaphore"] for r in rows),
              "runs_orphans": sum(r["orphans"] > 0 for r in rows), "runs_hung": sum(r["hung"] for r in rows),
              "runs_not_resumed": sum(not r["resumed"] for r in rows), "runs_failed": len(failed),
              "wall_s": round(time.monotonic() - started, 1)}
    print(f"{totals['runs']} runs: {totals['byte_identical_summaries']} byte-identical summaries, "
          f"{totals['runs_double_counted']} double-counted, {totals['runs_lost']} lost, "
          f"{totals['runs_traceback']} tracebacks; {totals['runs_beyond_one_line']} interrupted runs printed more "
          f"than one line ({totals['runs_group_sigint']} runs had a group SIGINT)")
    print(f"  (trials: {totals['trials_lost']} lost, {totals['trials_double_counted']} double-counted; runs: "
          f"{totals['runs_leaked_semaphore']} leaked semaphores, {totals['runs_orphans']} with orphans, "
          f"{totals['runs_not_resumed']} not resumed, {totals['runs_failed']} failed; {totals['wall_s']} s)")
    for row in failed:
        print(f"  FAILED run {row['run']} ({row['executor']}, {'+'.join(row['signals'])}): "
              f"{'; '.join(row['why'])}; folder {row['folder']}")
    for row in rows:
        if row["flagged"] and not row["failed"]:
            print(f"  flagged run {row['run']} ({row['executor']}, {'+'.join(row['signals'])}): "
                  f"{', '.join(row['flagged'])}; folder {row['folder']}")
    kept_references = bool(failed) or args.keep_all
    if not kept_references:
        for ref in references.values():
            shutil.rmtree(ref["folder"], ignore_errors=True)
        if not any(work.iterdir()):
            work.rmdir()
    payload = {"machine": machine_description(), "experiment": args.experiment, "quick": args.quick,
               "seed": args.seed, "jobs": args.jobs, "tear_every": args.tear_every,
               "second_kill_every": args.second_kill_every, "attempts": args.attempts, "grace_s": args.grace,
               "signals": list(args.signals),
               "strict": args.strict, "src": str(SRC), "work": str(work),
               "compared": "summary.json bytes without its provenance",
               "references": {executor: {"wall_s": ref["wall_s"], "records": len(ref["rows"]),
                                         "folder": ref["folder"] if kept_references else None}
                              for executor, ref in references.items()},
               "totals": totals, "failed_runs": [{"run": r["run"], "folder": r["folder"], "why": r["why"]}
                                                 for r in failed],
               "flagged_runs": [{"run": r["run"], "folder": r["folder"], "flagged": r["flagged"]}
                                for r in rows if r["flagged"] and not r["failed"]],
               "rows": rows}
    path = write_json("kill_resume" + ("_quick" if args.quick else ""), payload, args.out)
    print(f"wrote {path}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
