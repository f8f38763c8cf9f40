"""Runs an experiment's trials, appending records as they finish, so long runs never lose work.

``DIR/EXPERIMENT/records.csv`` gets one row per trial, written and flushed as soon as the trial
finishes. Re-running with the same ``--out`` reads the file, skips finished trials and runs the
rest; an interrupted run loses at most the trials in flight (a torn last line is set aside). The
settings are stored in ``settings.json``; resuming with different settings is refused. Each row is
checked against its trial on resume (``records.RecordSchema``): a row that fails is reported and
excluded, never counted, and its trial runs again; such rows are moved to
``records.csv.excluded`` (``records.compact_records``). One run writes a folder at a time: a run
takes the folder's lock (``_support.folder_lock``) before it reads or writes anything there, and a
second run into it is refused at once, naming the first one's PID; holding it, the run removes
temporary files (``.qrrt-*.tmp``) that a killed run left.
``summary.json`` = {"experiment", "settings", "ours", "paper", ..., "provenance"} and the figures
are rewritten from all records at the end; ``provenance`` (commit, versions, machine, date) is the
only part that differs between two runs with the same settings. Both JSON files are strict JSON
(a non-finite number is written as ``null``) and written whole (``_support.json_files.write_json``:
a temporary file renamed over the old one), and ``summary.json`` says ``"complete": true`` only once
its figures are written.
"""

from __future__ import annotations

import contextlib
import json
import threading
from collections import deque
from collections.abc import Callable
from concurrent.futures import BrokenExecutor, Executor, Future, as_completed
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from tqdm.auto import tqdm

from .._support.folder_lock import FolderLock
from .._support.json_files import dumps, write_json
from .._support.output_files import remove_stale_temporaries
from .._support.provenance import provenance
from .._support.validation import check_int, check_optional_int
from ..world.environment import Environment
from .base import Experiment, Record, Settings, Summary, Trial
from .records import RecordSchema, RecordWriter, check_records_header, compact_records, read_records

if TYPE_CHECKING:
    from ..execution import WorkerPool

__all__ = ["check_experiment_arguments", "execute_trial", "read_records", "run_experiment", "run_experiments"]

RECORDS = "records.csv"
#: the most trials per variant ``--trials`` accepts (a trial list is built in memory)
MAX_TRIALS = 100_000
SUMMARY = "summary.json"
SETTINGS = "settings.json"


def execute_trial(experiment_name: str, trial: Trial, settings: Settings) -> Record:
    """Module-level task (picklable) run by any executor: one trial -> one record.

    Args:
        experiment_name: An ``EXPERIMENTS`` name.
        trial: One of the experiment's trials.
        settings: The run's settings.

    Returns:
        ``{"trial_id", "seed", **trial.params}`` followed by the experiment's measurements.

    Raises:
        KeyError: If ``experiment_name`` is not an experiment.
    """
    from .catalog import EXPERIMENTS

    experiment = EXPERIMENTS[experiment_name]
    record = {"trial_id": trial.id, "seed": trial.seed, **trial.params}
    record.update(experiment.run_trial(trial, settings))
    return record


def _run_on(executor: Executor | Callable[[], Executor], name: str, trials: list[Trial], settings: Settings,
            record_one: Callable[[Record], None], client_helps: bool = False) -> None:
    """Run ``trials`` on ``executor`` (or on the executor ``executor()`` returns), recording each
    result as it arrives.

    With ``client_helps`` (a local pool not started yet; ``executor`` is then the callable that
    starts it), this process would sit idle while the workers start (the fork server's preload, a
    Dask cluster's start). So a background thread starts the pool and submits the trials from the
    front of the list, while this process runs trials itself from the back until the first worker
    result arrives. A trial is taken from the list under a lock, either submitted or run here, so
    each runs exactly once; its record does not depend on where it ran (trials draw only from their
    own seeds)."""
    if not client_helps:
        pool = executor() if callable(executor) else executor
        submitted = [pool.submit(execute_trial, name, trial, settings) for trial in trials]
        try:
            for future in as_completed(submitted):
                record_one(future.result())
        finally:
            for future in submitted:
                future.cancel()
        return
    queue = deque(trials)
    lock = threading.Lock()
    futures: list[Future] = []
    failures: list[BaseException] = []

    def submit_all() -> None:
        try:
            with lock:
                if not queue:  # this process already ran them all: no pool to start
                    return
            pool = executor() if callable(executor) else executor
            while True:
                with lock:
                    if not queue:
                        return
                    trial = queue.popleft()
                futures.append(pool.submit(execute_trial, name, trial, settings))
        except BaseException as exc:  # re-raised in the calling thread
            failures.append(exc)

    submitter = threading.Thread(target=submit_all, name="qrrt-submit", daemon=True)
    submitter.start()
    try:
        while not failures and not any(future.done() for future in list(futures)):
            with lock:
                if not queue:
                    break
                trial = queue.pop()
            record_one(execute_trial(name, trial, settings))
        submitter.join()
        if failures:
            raise failures[0]
        for future in as_completed(futures):
            record_one(future.result())
    finally:
        with lock:
            queue.clear()  # a submitter still running stops at its next trial
        submitter.join()  # (it may still be starting the pool: let it finish, so it can be shut down)
        for future in futures:
            future.cancel()


def _started_executor(pool: WorkerPool) -> Executor:
    """The executor of a (non-serial) ``WorkerPool``, started if it is not yet."""
    executor = pool.executor
    if executor is None:
        raise RuntimeError("a serial WorkerPool has no executor")
    return executor


def _check_arguments(name: str, trials: int | None, seed: int, executor: str | Executor | WorkerPool | None,
                     jobs: int | None, scheduler: str | None, predicate: str) -> str | None:
    """Refuse bad arguments before any work; returns the executor kind (None for an object)."""
    from ..execution import check_executor_args
    from ..registry import PREDICATES
    from .catalog import EXPERIMENTS

    if name not in EXPERIMENTS:
        raise ValueError(f"unknown experiment {name!r}; choose one of {sorted(EXPERIMENTS)} or 'all'")
    check_optional_int(trials, "trials", 1, MAX_TRIALS)
    check_int(seed, "seed", 0)
    PREDICATES.resolve(predicate)
    # its parameter (time-samples:K, ...) checked by building it once, before any file is written
    PREDICATES.create(predicate, env=Environment(np.array([[0.0, 1.0], [0.0, 1.0]]), np.zeros((0, 2, 2))))
    if not EXPERIMENTS[name].uses_predicate and PREDICATES.canonical(predicate) != "exact":
        raise ValueError(f"experiment {name!r} does not take a predicate (it plans nothing with one); "
                         "run it without --predicate")
    if isinstance(executor, str) or executor is None:
        kind = executor or "serial"
        check_executor_args(kind, jobs, scheduler)
        return kind
    return None


def check_experiment_arguments(name: str, trials: int | None = None, seed: int = 0,
                               executor: str | Executor | WorkerPool | None = None, jobs: int | None = None,
                               scheduler: str | None = None, predicate: str = "exact",
                               out: str | Path | None = None, quick: bool = False) -> None:
    """Refuse the arguments ``run_experiment`` would refuse, without writing anything (so a caller
    running several experiments can check them all, their folders included, before any runs).

    Args:
        name: An ``EXPERIMENTS`` name.
        trials: Trials per variant (1 to ``MAX_TRIALS``) or None.
        seed: The root seed (>= 0).
        executor: ``"serial"``, ``"process"``, ``"dask"``, an executor, a ``WorkerPool`` or None.
        jobs: Worker processes for a pool built by the runner.
        scheduler: A Dask scheduler's address (``executor="dask"`` only).
        predicate: A ``PREDICATES`` name (only ``"exact"`` for experiments that take none).
        out: The results folder: ``out/name`` is checked as ``run_experiment`` would check it
            (results for other settings, a corrupt ``settings.json``, records without settings, a
            records header that does not fit); None checks no folder.
        quick: The ``quick`` of the run (it is part of the settings checked against ``out``).

    Raises:
        ValueError: If an argument is out of range or names nothing known, or ``out/name`` cannot
            take this run.
        TypeError: If an argument has the wrong type.
    """
    _check_arguments(name, trials, seed, executor, jobs, scheduler, predicate)
    if out is not None:
        settings = _run_settings(name, quick, trials, seed, predicate)
        _check_directory(Path(out) / name, settings, _schema(name, settings))


def _run_settings(name: str, quick: bool, trials: int | None, seed: int, predicate: str) -> Settings:
    """The settings of a run, as ``settings.json`` stores them."""
    from ..registry import PREDICATES
    from .catalog import EXPERIMENTS

    experiment = EXPERIMENTS[name]
    settings = experiment.settings(quick, trials, int(seed))
    if experiment.uses_predicate:
        settings["predicate"] = PREDICATES.canonical(predicate)
    return cast(Settings, json.loads(dumps(settings)))


def _schema(name: str, settings: Settings) -> RecordSchema:
    """The schema of a run's records (refusing an experiment whose trial ids repeat)."""
    from .catalog import EXPERIMENTS

    all_trials = EXPERIMENTS[name].trials(settings)
    if len({trial.id for trial in all_trials}) != len(all_trials):
        raise RuntimeError(f"experiment {name} produced duplicate trial ids")
    return RecordSchema.of(all_trials)


def _stored_settings(settings_path: Path, settings: Settings) -> Settings | None:
    """The settings a folder holds (None if it holds none); settings from before predicates
    existed mean the exact check."""
    if not settings_path.exists():
        return None
    try:
        stored = json.loads(settings_path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise ValueError(f"{settings_path} is corrupt ({exc}); use another --out or delete the folder") from exc
    if not isinstance(stored, dict):
        raise ValueError(f"{settings_path} is corrupt (not a JSON object); use another --out or delete the folder")
    if "predicate" not in stored and settings.get("predicate") == "exact":
        stored = {**stored, "predicate": "exact"}  # (written back only when the run is accepted)
    return stored


def _check_directory(directory: Path, settings: Settings, schema: RecordSchema) -> None:
    """Refuse, without writing anything, a folder that cannot take a run of ``settings``."""
    settings_path, records_path = directory / SETTINGS, directory / RECORDS
    stored = _stored_settings(settings_path, settings)
    if stored is None and records_path.exists() and records_path.stat().st_size:
        raise ValueError(f"{records_path} has records but {settings_path} is missing: their settings "
                         "(seed, trials, predicate) cannot be checked; use another --out or delete the folder")
    if stored is not None and stored != settings:
        raise ValueError(f"{directory} holds results for other settings ({stored}); use another --out or "
                         "delete it")
    check_records_header(records_path, schema)


def _claim_directory(directory: Path, settings: Settings, schema: RecordSchema) -> None:
    """Create ``directory`` for ``settings``, or accept it if it holds results for the same
    settings (``_check_directory``); ``settings.json`` is written only once the folder is accepted."""
    _check_directory(directory, settings, schema)
    directory.mkdir(parents=True, exist_ok=True)
    settings_path = directory / SETTINGS
    if not settings_path.exists() or json.loads(settings_path.read_text()) != settings:
        write_json(settings_path, settings)


def _execute(kind: str | None, executor: str | Executor | WorkerPool | None, name: str, todo: list[Trial],
             settings: Settings, record_one: Callable[[Record], None], records_path: Path, schema: RecordSchema,
             jobs: int | None, scheduler: str | None, max_restarts: int,
             on_restart: Callable[[int], None] | None) -> None:
    """Run ``todo`` serially, on a given executor or ``WorkerPool``, or on a pool built here; a
    pool whose executor breaks is renewed and the unfinished trials resubmitted."""
    from ..execution import WorkerPool

    if not todo:
        return
    if kind == "serial":
        for trial in todo:
            record_one(execute_trial(name, trial, settings))
        return
    # kind is None exactly when ``executor`` is an object: an Executor or a WorkerPool
    if kind is None and not isinstance(executor, WorkerPool):
        _run_on(cast(Executor, executor), name, todo, settings, record_one)
        return
    opened: contextlib.AbstractContextManager[WorkerPool] = (
        contextlib.nullcontext(cast(WorkerPool, executor)) if kind is None else WorkerPool(kind, jobs, scheduler))
    remaining = list(todo)
    with opened as pool:
        for attempt in range(max_restarts + 1):
            try:
                if pool.kind == "serial":
                    for trial in remaining:
                        record_one(execute_trial(name, trial, settings))
                elif pool.helps_while_starting and not pool.started:
                    _run_on(partial(_started_executor, pool), name, remaining, settings, record_one,
                            client_helps=True)
                else:
                    _run_on(_started_executor(pool), name, remaining, settings, record_one)
                return
            except BrokenExecutor:
                if attempt == max_restarts:
                    raise
                if on_restart:
                    on_restart(attempt + 1)
            done_now = {r["trial_id"] for r in read_records(records_path, schema)}
            remaining = [t for t in remaining if t.id not in done_now]
            pool.renew()


def _summarize(experiment: Experiment, name: str, directory: Path, settings: Settings,
               all_trials: list[Trial], schema: RecordSchema) -> Summary:
    """summary.json and the figures from all records (or a partial summary if trials are missing)."""
    order = {trial.id: index for index, trial in enumerate(all_trials)}
    records = sorted(read_records(directory / RECORDS, schema), key=lambda r: order[r["trial_id"]])
    if len(records) < len(all_trials):
        return {"experiment": name, "settings": settings, "complete": False,
                "finished_trials": len(records), "total_trials": len(all_trials)}
    result = experiment.summarize(records, settings)
    summary = {"experiment": name, "title": experiment.title, "settings": settings,
               "ours": result.pop("ours"), "paper": result.pop("paper"), **result,
               "complete": True}
    try:
        figures = experiment.plot(records, settings, summary, directory)
        summary["figures"] = [str(path.name) for path in figures]
        summary["provenance"] = provenance()  # (the one part of a summary that differs between runs)
        write_json(directory / SUMMARY, summary)  # complete only with its figures; non-finite numbers as null
    except OSError as exc:  # (a full disk): every record is kept, so the same command finishes the job
        raise OSError(exc.errno, f"{exc.strerror or exc}; the finished trials are kept in {directory / RECORDS}: "
                                 "run the same command again to write the summary") from exc
    return summary


def run_experiment(
    name: str,
    out: str | Path = "results",
    quick: bool = False,
    trials: int | None = None,
    seed: int = 0,
    executor: str | Executor | WorkerPool | None = None,
    jobs: int | None = None,
    scheduler: str | None = None,
    progress: bool = True,
    stop_after: int | None = None,
    on_record: Callable[[Record], None] | None = None,
    max_restarts: int = 3,
    on_restart: Callable[[int], None] | None = None,
    predicate: str = "exact",
    defer_summary: Callable[[Callable[[], Summary]], None] | None = None,
) -> Summary:
    """Run (or resume) experiment ``name`` into ``out/name``; returns the summary.

    ``executor``: ``"serial"`` (default), ``"process"``, ``"dask"`` (built here with ``jobs`` and
    ``scheduler``, see ``qrrt_circuits.execution``), an open ``qrrt_circuits.execution.WorkerPool``
    (kept across several experiments, renewed if it breaks) or any ``concurrent.futures.Executor``.
    Records are written as trials finish, in whatever order. If a local process pool breaks (a
    worker died), a new pool is started (a given ``WorkerPool`` is renewed) and the unfinished trials resubmitted, up to
    ``max_restarts`` times; Dask reschedules a dead worker's tasks itself. ``stop_after`` stops
    after that many new trials (for tests of resuming). ``predicate`` (a ``PREDICATES`` name) is
    the reachability check the experiment's planners use, recorded in the settings.

    Args:
        name: An ``EXPERIMENTS`` name.
        out: The results folder; the run writes ``out/name``.
        quick: Small settings, for a quick check of the whole pipeline.
        trials: Trials per variant (default: the experiment's).
        seed: The root seed (>= 0).
        executor: Where trials run (see above).
        jobs: Worker processes for a pool built here (default: cores).
        scheduler: A Dask scheduler's address (``executor="dask"``).
        progress: Show a progress bar.
        stop_after: Stop after this many new trials (a partial summary is returned).
        on_record: Called with each record as it is written.
        max_restarts: How many times a broken pool is renewed.
        on_restart: Called with the restart's number before each renewal.
        predicate: The planners' reachability check (a ``PREDICATES`` name).
        defer_summary: Called, after the trials, with a function that makes and returns the
            summary (and writes ``summary.json`` and the figures), instead of calling it here
            (``run_experiments`` hands it to a background thread); None (default) makes it here.

    Returns:
        The summary written to ``summary.json`` (``"complete": False`` with the counts of
        finished and total trials when some are missing); with ``defer_summary``, only
        ``{"experiment": name, "deferred": True}``.

    Raises:
        ValueError: If an argument is refused, or ``out/name`` holds results for other settings.
        RuntimeError: If the experiment produced duplicate trial ids.
        FolderInUse: Another run holds ``out/name`` (an ``OSError`` naming its PID): one run writes
            a folder at a time (``_support.folder_lock``).
    """
    from .catalog import EXPERIMENTS

    kind = _check_arguments(name, trials, seed, executor, jobs, scheduler, predicate)
    experiment = EXPERIMENTS[name]
    settings = _run_settings(name, quick, trials, seed, predicate)
    schema = _schema(name, settings)
    all_trials = list(schema.trials.values())
    directory = Path(out) / name
    _check_directory(directory, settings, schema)
    directory.mkdir(parents=True, exist_ok=True)
    lock = FolderLock(directory).acquire()
    try:
        return _run_locked(experiment, name, directory, settings, schema, all_trials, kind, executor, jobs,
                           scheduler, progress, stop_after, on_record, max_restarts, on_restart, defer_summary, lock)
    except BaseException:
        lock.release()
        raise


def _run_locked(experiment: Experiment, name: str, directory: Path, settings: Settings, schema: RecordSchema,
                all_trials: list[Trial], kind: str | None, executor: str | Executor | WorkerPool | None,
                jobs: int | None, scheduler: str | None, progress: bool, stop_after: int | None,
                on_record: Callable[[Record], None] | None, max_restarts: int,
                on_restart: Callable[[int], None] | None,
                defer_summary: Callable[[Callable[[], Summary]], None] | None, lock: FolderLock) -> Summary:
    """``run_experiment`` once it holds the folder's lock, which it releases when the summary is
    made (by ``defer_summary``'s function, where given)."""
    remove_stale_temporaries(directory)
    _claim_directory(directory, settings, schema)
    records_path = directory / RECORDS
    done = {record["trial_id"] for record in compact_records(records_path, schema)}
    todo = [trial for trial in all_trials if trial.id not in done]
    if stop_after is not None:
        todo = todo[:stop_after]
    writer = RecordWriter(records_path, schema)
    bar = tqdm(total=len(all_trials), initial=len(done), desc=name, disable=not progress, unit="trial")

    def record_one(record: Record) -> None:
        writer.write(record)
        if on_record:
            on_record(record)
        bar.update()

    try:
        _execute(kind, executor, name, todo, settings, record_one, records_path, schema, jobs, scheduler,
                 max_restarts, on_restart)
    finally:
        bar.close()
    summarize = partial(_summarize, experiment, name, directory, settings, all_trials, schema)

    def summarize_and_release() -> Summary:
        try:
            return summarize()
        finally:
            lock.release()

    if defer_summary is not None:
        defer_summary(summarize_and_release)
        return {"experiment": name, "deferred": True}
    return summarize_and_release()


def run_experiments(names: list[str], pool: WorkerPool, on_summary: Callable[[str, Summary], None],
                    **options: Any) -> None:
    """``run_experiment`` for each of ``names`` on one ``WorkerPool`` (``qrrt reproduce all``),
    calling ``on_summary(name, summary)`` in order.

    With workers (a process pool or Dask), experiment i's summary and figures are made in one
    background thread of this process while experiment i + 1's trials run on the workers, which
    would otherwise wait for them; the summaries are made one at a time, in order, from the same
    records, so ``summary.json`` and the figures are those of running the experiments one after the
    other (tested). Serially, everything runs in this thread, one experiment after the other.

    Args:
        names: ``EXPERIMENTS`` names, run in this order.
        pool: The open ``WorkerPool`` every experiment's trials run on.
        on_summary: Called with each experiment's name and summary, in the order of ``names``.
        **options: ``run_experiment``'s other keywords (``out``, ``quick``, ``trials``, ``seed``,
            ``progress``, ``predicate``, ...).

    Raises:
        Whatever ``run_experiment`` or a summary raises (a failed summary after the trials of the
        experiments after it have run).
    """
    from concurrent.futures import ThreadPoolExecutor

    if pool.kind == "serial":
        for name in names:
            on_summary(name, run_experiment(name, executor=pool, **options))
        return
    pending: deque[tuple[str, Future[Summary]]] = deque()
    with ThreadPoolExecutor(max_workers=1, thread_name_prefix="qrrt-summary") as finisher:
        for name in names:
            def defer(make: Callable[[], Summary], name: str = name) -> None:
                pending.append((name, finisher.submit(make)))

            run_experiment(name, executor=pool, defer_summary=defer, **options)
            while pending and pending[0][1].done():  # report finished summaries, in order
                done_name, future = pending.popleft()
                on_summary(done_name, future.result())
        while pending:
            done_name, future = pending.popleft()
            on_summary(done_name, future.result())
