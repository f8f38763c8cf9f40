"""Runs an experiment's trials, appending records as they finish, so long runs never lose work.

``DIR/EXPERIMENT/records.csv`` gets one row per trial, written and flushed as soon as the trial
finishes. Re-running with the same ``--out`` reads the file, skips finished trials and runs the
rest; an interrupted run loses at most the trials in flight (a torn last line is dropped). The
settings are stored in ``settings.json``; resuming with different settings is refused.
``summary.json`` = {"experiment", "settings", "ours", "paper", ...} and the figures are rewritten
from all records at the end.
"""

from __future__ import annotations

import csv
import json
import os
from collections.abc import Callable
from concurrent.futures import BrokenExecutor, Executor, as_completed
from pathlib import Path

from tqdm.auto import tqdm

from .base import Trial

RECORDS = "records.csv"
SUMMARY = "summary.json"
SETTINGS = "settings.json"


def execute_trial(experiment_name: str, trial: Trial, settings: dict) -> dict:
    """Module-level task (picklable) run by any executor: one trial -> one record."""
    from . import EXPERIMENTS

    experiment = EXPERIMENTS[experiment_name]
    record = {"trial_id": trial.id, "seed": trial.seed, **trial.params}
    record.update(experiment.run_trial(trial, settings))
    return record


def _convert(value: str):
    if value == "":
        return None
    for kind in (int, float):
        try:
            return kind(value)
        except ValueError:
            pass
    if value in ("True", "False"):
        return value == "True"
    return value


def read_records(path: Path) -> list[dict]:
    """Rows of a records.csv (numbers converted). A torn last line (no newline: the writer was
    killed mid-write) or a row of the wrong width is dropped and the file rewritten without it."""
    if not path.exists():
        return []
    text = path.read_text()
    lines = text.split("\n")
    torn = bool(lines and lines[-1])  # text does not end with a newline
    lines = lines[:-1]
    rows = list(csv.reader(lines))
    if not rows:
        return []
    header, body = rows[0], rows[1:]
    good = [row for row in body if len(row) == len(header)]
    if torn or len(good) != len(body):
        _rewrite(path, header, good)
    return [{key: _convert(value) for key, value in zip(header, row, strict=True)} for row in good]


def _rewrite(path: Path, header: list[str], rows: list[list[str]]) -> None:
    temporary = path.with_suffix(".tmp")
    with temporary.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(header)
        writer.writerows(rows)
    os.replace(temporary, path)


class RecordWriter:
    """Appends records to records.csv, one flushed line per trial."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.header: list[str] | None = None
        if path.exists() and path.stat().st_size:
            with path.open(newline="") as handle:
                self.header = next(csv.reader(handle), None)

    def write(self, record: dict) -> None:
        if self.header is None:
            self.header = list(record)
            with self.path.open("w", newline="") as handle:
                csv.writer(handle).writerow(self.header)
        if set(record) != set(self.header):
            raise ValueError(f"record columns {sorted(record)} differ from the file's {sorted(self.header)}")
        with self.path.open("a", newline="") as handle:
            csv.writer(handle).writerow(["" if record[key] is None else record[key] for key in self.header])
            handle.flush()
            os.fsync(handle.fileno())


def _run_on(executor: Executor, name: str, trials: list[Trial], settings: dict, record_one) -> None:
    futures = [executor.submit(execute_trial, name, trial, settings) for trial in trials]
    try:
        for future in as_completed(futures):
            record_one(future.result())
    finally:
        for future in futures:
            future.cancel()


def run_experiment(
    name: str,
    out: str | Path = "results",
    quick: bool = False,
    trials: int | None = None,
    seed: int = 0,
    executor: str | Executor | None = None,
    jobs: int | None = None,
    scheduler: str | None = None,
    progress: bool = True,
    stop_after: int | None = None,
    on_record: Callable[[dict], None] | None = None,
    max_restarts: int = 3,
    on_restart: Callable[[int], None] | None = None,
) -> dict:
    """Run (or resume) experiment ``name`` into ``out/name``; returns the summary.

    ``executor``: ``"serial"`` (default), ``"process"``, ``"dask"`` (built here with ``jobs`` and
    ``scheduler``, see ``qrrt_circuits.execution``) or any ``concurrent.futures.Executor``.
    Records are written as trials finish, in whatever order. If a local process pool breaks (a
    worker died), a new pool is started and the unfinished trials resubmitted, up to
    ``max_restarts`` times; Dask reschedules a dead worker's tasks itself. ``stop_after`` stops
    after that many new trials (for tests of resuming).
    """
    from ..execution import check_executor_args, get_executor
    from . import EXPERIMENTS

    if name not in EXPERIMENTS:
        raise ValueError(f"unknown experiment {name!r}; choose one of {sorted(EXPERIMENTS)} or 'all'")
    if trials is not None and (int(trials) != trials or trials < 1):
        raise ValueError(f"trials must be an integer >= 1, got {trials}")
    if int(seed) != seed or seed < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed}")
    if isinstance(executor, str) or executor is None:
        kind = executor or "serial"
        check_executor_args(kind, jobs, scheduler)
    else:
        kind = None
    experiment = EXPERIMENTS[name]
    settings = experiment.settings(quick, trials, int(seed))
    settings = json.loads(json.dumps(settings))  # plain JSON types, as stored
    directory = Path(out) / name
    directory.mkdir(parents=True, exist_ok=True)
    settings_path = directory / SETTINGS
    if settings_path.exists():
        stored = json.loads(settings_path.read_text())
        if stored != settings:
            raise ValueError(
                f"{directory} holds results for other settings ({stored}); use another --out or "
                "delete it")
    else:
        settings_path.write_text(json.dumps(settings, indent=1))
    all_trials = experiment.trials(settings)
    ids = [trial.id for trial in all_trials]
    if len(set(ids)) != len(ids):
        raise RuntimeError(f"experiment {name} produced duplicate trial ids")
    records_path = directory / RECORDS
    done = {record["trial_id"] for record in read_records(records_path)}
    todo = [trial for trial in all_trials if trial.id not in done]
    if stop_after is not None:
        todo = todo[:stop_after]
    writer = RecordWriter(records_path)
    bar = tqdm(total=len(all_trials), initial=len(done), desc=name, disable=not progress, unit="trial")
    def record_one(record: dict) -> None:
        writer.write(record)
        if on_record:
            on_record(record)
        bar.update()

    try:
        if kind == "serial":
            for trial in todo:
                record_one(execute_trial(name, trial, settings))
        elif kind is None:
            _run_on(executor, name, todo, settings, record_one)
        else:
            remaining = list(todo)
            for attempt in range(max_restarts + 1):
                with get_executor(kind, jobs, scheduler) as pool:
                    try:
                        _run_on(pool, name, remaining, settings, record_one)
                        break
                    except BrokenExecutor:
                        if attempt == max_restarts:
                            raise
                        if on_restart:
                            on_restart(attempt + 1)
                done_now = {r["trial_id"] for r in read_records(records_path)}
                remaining = [t for t in remaining if t.id not in done_now]
    finally:
        bar.close()
    records = read_records(records_path)
    order = {trial_id: index for index, trial_id in enumerate(ids)}
    records = sorted((r for r in records if r["trial_id"] in order), key=lambda r: order[r["trial_id"]])
    if len(records) < len(all_trials):
        summary = {"experiment": name, "settings": settings, "complete": False,
                   "finished_trials": len(records), "total_trials": len(all_trials)}
        return summary
    result = experiment.summarize(records, settings)
    summary = {"experiment": name, "title": experiment.title, "settings": settings,
               "ours": result.pop("ours"), "paper": result.pop("paper"), **result,
               "complete": True}
    (directory / SUMMARY).write_text(json.dumps(summary, indent=1, default=float))
    figures = experiment.plot(records, settings, summary, directory)
    summary["figures"] = [str(path.name) for path in figures]
    (directory / SUMMARY).write_text(json.dumps(summary, indent=1, default=float))
    return summary
