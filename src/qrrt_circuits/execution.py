"""Executors for sweeps: one way to get a ``concurrent.futures.Executor`` for each kind.

- ``serial``: none (trials run in this process, in order).
- ``process``: local processes, standard library ``ProcessPoolExecutor`` with the *spawn* start
  method (no forked simulator or numba state); task functions are module-level.
- ``dask``: ``dask.distributed`` — a ``LocalCluster`` (``jobs`` single-threaded worker processes,
  no dashboard) or an existing cluster at ``scheduler`` (e.g. one started with dask-jobqueue on
  SLURM), used through ``Client.get_executor(retries=...)``: a task whose worker dies is rescheduled
  by the scheduler and, if it fails, retried.

Workers build their own backends with one thread each (``max_parallel_threads=1`` for Aer), so
``jobs`` processes use ``jobs`` cores. Install the Dask extra with ``pip install ".[dask]"``.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Iterator
from concurrent.futures import Executor, ProcessPoolExecutor

from .validation import check_optional_int

EXECUTORS = ("serial", "process", "dask")

#: no Bokeh dashboard is served (bokeh is not a dependency); ``dashboard_address=None`` does not stop
#: the scheduler's small HTTP server (dask/distributed#8136), so it gets a random loopback port
NO_DASHBOARD = "127.0.0.1:0"

#: environment for worker processes: one thread per native library
SINGLE_THREAD_ENV = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
                     "NUMBA_NUM_THREADS": "1"}


#: how often a pool worker checks that its parent is alive (seconds)
PARENT_POLL_S = 0.5


def _exit_when_orphaned(parent: int) -> None:
    """Runs in a daemon thread of each pool worker: when the parent dies (killed with SIGKILL, say,
    so it could not shut the pool down), the worker is re-parented and exits at once instead of
    lingering with its memory."""
    import time

    while os.getppid() == parent:
        time.sleep(PARENT_POLL_S)
    os._exit(1)


def _worker_init(parent: int | None = None) -> None:
    """Pool worker start-up: one thread per native library, and a watch on ``parent`` (the pid of
    the process that made the pool, passed in, since a worker still importing when its parent
    dies would otherwise take its new parent for the real one)."""
    import threading

    os.environ.update(SINGLE_THREAD_ENV)
    parent = os.getppid() if parent is None else parent
    threading.Thread(target=_exit_when_orphaned, args=(parent,), daemon=True, name="qrrt-orphan-watch").start()


def check_executor_args(kind: str, jobs: int | None, scheduler: str | None) -> int:
    if kind not in EXECUTORS:
        raise ValueError(f"executor must be one of {EXECUTORS}, got {kind!r}")
    check_optional_int(jobs, "jobs", 1)
    if scheduler is not None and kind != "dask":
        raise ValueError("scheduler is only used with executor='dask'")
    if kind == "dask":
        try:
            import distributed  # noqa: F401
        except ImportError as exc:
            raise ValueError("executor='dask' needs the dask extra: pip install \".[dask]\"") from exc
    return int(jobs) if jobs is not None else (os.cpu_count() or 1)


@contextlib.contextmanager
def get_executor(kind: str = "serial", jobs: int | None = None, scheduler: str | None = None,
                 retries: int = 2, local_directory: str | None = None) -> Iterator[Executor | None]:
    """Context manager yielding an executor (``None`` for serial); everything it started is shut
    down on exit."""
    jobs = check_executor_args(kind, jobs, scheduler)
    if kind == "serial":
        yield None
        return
    if kind == "process":
        import multiprocessing

        with ProcessPoolExecutor(max_workers=jobs, mp_context=multiprocessing.get_context("spawn"),
                                 initializer=_worker_init, initargs=(os.getpid(),)) as pool:
            yield pool
        return
    from distributed import Client, LocalCluster

    if scheduler is not None:
        with Client(scheduler) as client:
            yield client.get_executor(retries=retries, pure=False)
        return
    import tempfile

    saved = {key: os.environ.get(key) for key in SINGLE_THREAD_ENV}
    os.environ.update(SINGLE_THREAD_ENV)  # inherited by the worker processes
    # Dask leaves lock files in its scratch directory: give it one of ours and remove it after
    scratch = None if local_directory is not None else tempfile.TemporaryDirectory(prefix="qrrt-dask-")
    local_directory = local_directory if scratch is None else scratch.name
    try:
        with LocalCluster(n_workers=jobs, threads_per_worker=1, processes=True, host="127.0.0.1",
                          dashboard_address=NO_DASHBOARD, local_directory=local_directory) as cluster, \
                Client(cluster) as client:
            yield client.get_executor(retries=retries, pure=False)
    finally:
        if scratch is not None:
            scratch.cleanup()
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value
