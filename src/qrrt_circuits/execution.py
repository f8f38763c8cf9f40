"""Executors for sweeps and parallel planners: ``get_executor(kind, jobs, scheduler)`` gives a
``concurrent.futures.Executor`` for each kind, and ``WorkerPool`` keeps one for several sweeps.

- ``serial``: none (trials run in this process, in order).
- ``process``: local processes, standard library ``ProcessPoolExecutor``.
- ``dask``: ``dask.distributed`` — a ``LocalCluster`` (``jobs`` single-threaded worker processes
  under nannies, no dashboard, no profiler: ``LOCAL_DASK_CONFIG``) or an existing cluster at
  ``scheduler`` (e.g. one started with dask-jobqueue on SLURM), used through
  ``Client.get_executor(retries=...)``: a task whose worker dies is rescheduled by the scheduler
  and, if it fails, retried.

**Warm workers.** Local workers (pool and ``LocalCluster``) are forked from one *fork server*
(the ``forkserver`` start method) that has imported ``qrrt_circuits._support.worker_warmup`` once: every
experiment, Qiskit, Aer, numba's compiled kernels, the default world and the kernels of the
problem families' plans (``experiments.problems.load_kernels``). A worker then starts
with all of that in memory instead of repeating the same imports in a fresh interpreter. The fork
server is a fresh single-threaded interpreter that never runs Aer, so nothing forked holds
threads or OpenMP state. It is started with the single-thread environment below and stopped when
the executor is shut down. Where the platform has no fork server, workers are spawned (cold).

**Interrupts.** Workers never see Ctrl-C (a Ctrl-C from a terminal goes to the whole process
group, and a worker interrupted mid-trial would print its traceback): the fork server is started
with SIGINT blocked in the starting thread (after multiprocessing's resource tracker, whose start
unblocks it) and ignores it from the first module it preloads (``_support.ignore_interrupts``),
so every worker it forks ignores it too, and a spawned pool
worker ignores it from its initializer. The command's own process gets it and shuts
the workers down as it leaves (``WorkerPool``'s ``with`` block); while a local Dask cluster shuts
down, Dask's and Tornado's loggers are silenced (its nannies and heartbeats would report the
closing connections). Scratch folders are named with the owner's PID (``qrrt-pymp-PID-*`` for
multiprocessing's, ``qrrt-dask-PID-*`` for Dask's): a run killed with SIGKILL leaves its own, and
the next pool started removes those whose process is gone (``remove_stale_scratch``).

Workers build their own backends with one thread each (``max_parallel_threads=1`` for Aer), so
``jobs`` processes use ``jobs`` cores. :class:`WorkerPool` keeps one executor for several sweeps
(``qrrt reproduce all`` starts one pool or cluster, not one per experiment) and starts a new one
when a local pool breaks. Install the Dask extra with ``pip install ".[dask]"``.
"""

from __future__ import annotations

import contextlib
import contextvars
import logging
import os
import threading
from collections.abc import Iterator
from concurrent.futures import Executor, ProcessPoolExecutor
from typing import Any

from ._support.validation import check_optional_int

__all__ = ["EXECUTORS", "WORKER_PRELOAD", "WorkerPool", "check_executor_args", "get_executor", "remove_stale_scratch"]

#: the executor kinds ``get_executor`` and ``WorkerPool`` build
EXECUTORS = ("serial", "process", "dask")

#: no Bokeh dashboard is served (bokeh is not a dependency); ``dashboard_address=None`` does not stop
#: the scheduler's small HTTP server (dask/distributed#8136), so it gets a random loopback port
NO_DASHBOARD = "127.0.0.1:0"

#: environment for worker processes: one thread per native library
SINGLE_THREAD_ENV = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
                     "NUMBA_NUM_THREADS": "1"}

#: Dask settings for a ``LocalCluster`` of a few single-threaded workers: no statistical profiler
#: sampling each running task every 10 ms, and the event-loop watchdog and system monitor ticking
#: less often (each takes CPU from the trials, which use every core)
LOCAL_DASK_CONFIG = {"distributed.worker.profile.enabled": False, "distributed.admin.tick.interval": "1s",
                     "distributed.admin.system-monitor.interval": "5s"}

#: modules the fork server imports before forking any worker (the warm-up is the import)
WORKER_PRELOAD = ("qrrt_circuits._support.worker_warmup",)
#: what a local Dask cluster's fork server imports besides: Dask, and its workers' shutdown reports
#: left out (``_support.quiet_dask_workers``)
DASK_PRELOAD = ("distributed", "qrrt_circuits._support.quiet_dask_workers")
#: imported by the fork server before anything else: SIGINT ignored (module text, "Interrupts")
INTERRUPTS_IGNORED = "qrrt_circuits._support.ignore_interrupts"

#: how often a pool worker checks that its client is alive (seconds)
PARENT_POLL_S = 0.5


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else (the pid was reused): ours is gone
        return False
    return True


def _exit_when_orphaned(client: int, parent: int) -> None:
    """Runs in a daemon thread of each pool worker: when the client dies (killed with SIGKILL, say,
    so it could not shut the pool down), the worker exits at once instead of lingering with its
    memory. ``parent`` is the worker's parent at start (the client, or the fork server, which
    outlives the client while any worker it forked is alive); a changed parent also means orphaned."""
    import time

    while os.getppid() == parent and _alive(client):
        time.sleep(PARENT_POLL_S)
    os._exit(1)


def _worker_init(client: int | None = None) -> None:
    """Pool worker start-up: SIGINT ignored (the client shuts the pool down: module text), one
    thread per native library, and a watch on ``client`` (the pid of the process that made the
    pool, passed in: a spawned worker still importing when its client dies would otherwise take its
    new parent for the real one, and a forked one's parent is the fork server)."""
    import signal
    import threading

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    os.environ.update(SINGLE_THREAD_ENV)
    parent = os.getppid()
    client = parent if client is None else client
    threading.Thread(target=_exit_when_orphaned, args=(client, parent), daemon=True,
                     name="qrrt-orphan-watch").start()


@contextlib.contextmanager
def _single_thread_environment() -> Iterator[None]:
    """``SINGLE_THREAD_ENV`` in ``os.environ`` (inherited by processes started meanwhile), restored after."""
    saved = {key: os.environ.get(key) for key in SINGLE_THREAD_ENV}
    os.environ.update(SINGLE_THREAD_ENV)
    try:
        yield
    finally:
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value


def _fork_server_available() -> bool:
    import multiprocessing

    return "forkserver" in multiprocessing.get_all_start_methods()


@contextlib.contextmanager
def _warm_fork_server(extra_preload: tuple[str, ...] = ()) -> Iterator[str]:
    """Start the fork server (preloading ``WORKER_PRELOAD``) unless one runs; yields the start method
    for workers (``"spawn"`` where there is no fork server). A server started here is stopped on exit,
    once the workers it forked are gone."""
    if not _fork_server_available():
        yield "spawn"
        return
    import multiprocessing
    from multiprocessing import forkserver, resource_tracker

    server = forkserver._forkserver  # the standard library's one per process
    started_here = server._forkserver_pid is None  # type: ignore[attr-defined]  # private, see docstring
    if started_here:
        multiprocessing.get_context("forkserver").set_forkserver_preload([INTERRUPTS_IGNORED, *extra_preload,
                                                                          *WORKER_PRELOAD])
        _own_scratch_folder()
        # the resource tracker first: starting it unblocks SIGINT in the starting thread, which
        # would leave the fork server started after it without the blocked mask
        resource_tracker.ensure_running()
        with _single_thread_environment(), _interrupts_blocked():
            forkserver.ensure_running()
    try:
        yield "forkserver"
    finally:
        if started_here:
            _stop_fork_server(server)


@contextlib.contextmanager
def _interrupts_blocked() -> Iterator[None]:
    """SIGINT blocked in this thread while the block runs (a process started meanwhile inherits the
    mask, module text); one that arrives meanwhile is delivered when the block ends."""
    import signal

    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


#: the temporary folders of this package's pools, named with the owner's PID: PREFIX-PID-random
SCRATCH_PREFIXES = ("qrrt-pymp", "qrrt-dask")


def remove_stale_scratch(folder: str | None = None) -> list[str]:
    """Remove the scratch folders (``SCRATCH_PREFIXES``) in the temporary folder whose owner
    process is gone (killed before it could remove them), owned by this user.

    Args:
        folder: Where to look (default ``tempfile.gettempdir()``).

    Returns:
        The folders removed.
    """
    import glob
    import shutil
    import tempfile

    removed = []
    for prefix in SCRATCH_PREFIXES:
        for path in glob.glob(os.path.join(folder or tempfile.gettempdir(), f"{prefix}-*-*")):
            pid = os.path.basename(path)[len(prefix) + 1:].split("-", 1)[0]
            try:
                owned = os.stat(path).st_uid == os.getuid()
            except OSError:
                continue
            if pid.isdigit() and owned and not _alive(int(pid)):
                shutil.rmtree(path, ignore_errors=True)
                removed.append(path)
    return removed


def _own_scratch_folder() -> None:
    """Give multiprocessing a temporary folder named with this PID (``qrrt-pymp-PID-*``: where the
    fork server's socket lives) unless it has one, removed at exit as its own would be."""
    import shutil
    import tempfile
    from multiprocessing import process, util

    config = process.current_process()._config  # type: ignore[attr-defined]  # util.get_temp_dir's
    if config.get("tempdir") is None:
        remove_stale_scratch()
        tempdir = tempfile.mkdtemp(prefix=f"qrrt-pymp-{os.getpid()}-")
        util.Finalize(None, shutil.rmtree, args=(tempdir,), kwargs={"ignore_errors": True}, exitpriority=-100)
        config["tempdir"] = tempdir


def _stop_fork_server(server: Any, wait_s: float = 5.0) -> None:  # a multiprocessing.forkserver.ForkServer
    """Close our end of the server's "alive" pipe (it exits when no worker holds one either) and
    reap it; kill it if it has not gone after ``wait_s`` seconds (at once for 0: a server that
    never forked a worker, perhaps still importing its preload, has nothing to finish)."""
    import signal
    import time

    pid, fd = server._forkserver_pid, server._forkserver_alive_fd
    if pid is None:
        return
    with server._lock:
        os.close(fd)
        server._forkserver_alive_fd = server._forkserver_address = server._forkserver_pid = None
    deadline = time.monotonic() + wait_s
    while True:
        done, _ = os.waitpid(pid, os.WNOHANG)
        if done:
            return
        if time.monotonic() > deadline:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            return
        time.sleep(0.02)


#: local worker processes per core at most (more only share the cores, each a Python process with
#: the library, Qiskit, Aer and numba loaded)
JOBS_PER_CORE = 4


def max_local_jobs() -> int:
    """The most local worker processes ``get_executor`` / ``WorkerPool`` start:
    ``JOBS_PER_CORE`` x ``os.cpu_count()``."""
    return JOBS_PER_CORE * (os.cpu_count() or 1)


def check_executor_args(kind: str, jobs: int | None, scheduler: str | None) -> int:
    """Validate the executor arguments of ``get_executor`` and ``WorkerPool`` before any work.

    Args:
        kind: One of ``EXECUTORS``: ``"serial"``, ``"process"`` or ``"dask"``.
        jobs: Worker processes (an integer >= 1), or None for ``os.cpu_count()``.
        scheduler: A Dask scheduler address (only with ``kind="dask"``), or None.

    Returns:
        The number of jobs: ``jobs``, or ``os.cpu_count()`` for None.

    Raises:
        ValueError: An unknown ``kind``, ``jobs`` < 1 (or above ``max_local_jobs()`` for local
            workers), a ``scheduler`` without ``kind="dask"``, or ``kind="dask"`` without the
            ``dask`` extra installed.
        TypeError: A non-integer ``jobs``.

    Example:
        >>> from qrrt_circuits.execution import check_executor_args
        >>> check_executor_args("process", 2, None)
        2
        >>> check_executor_args("mpi", None, None)
        Traceback (most recent call last):
        ...
        ValueError: executor must be one of ('serial', 'process', 'dask'), got 'mpi'
    """
    if kind not in EXECUTORS:
        raise ValueError(f"executor must be one of {EXECUTORS}, got {kind!r}")
    check_optional_int(jobs, "jobs", 1)
    if scheduler is not None and kind != "dask":
        raise ValueError("scheduler is only used with executor='dask'")
    local_limit = max_local_jobs()
    if jobs is not None and kind != "serial" and scheduler is None and jobs > local_limit:
        raise ValueError(f"jobs must be an integer in [1, {local_limit}] for local workers (each is a process of "
                         f"its own; {JOBS_PER_CORE} per core at most on this machine's {os.cpu_count() or 1}), "
                         f"got {jobs}")
    if kind == "dask":
        try:
            import distributed  # noqa: F401
        except ImportError as exc:
            raise ValueError("executor='dask' needs the dask extra: pip install \".[dask]\"") from exc
    return int(jobs) if jobs is not None else (os.cpu_count() or 1)


@contextlib.contextmanager
def _process_pool(jobs: int) -> Iterator[Executor]:
    import multiprocessing

    remove_stale_scratch()
    with _warm_fork_server() as method, \
            ProcessPoolExecutor(max_workers=jobs, mp_context=multiprocessing.get_context(method),
                                initializer=_worker_init, initargs=(os.getpid(),)) as pool:
        yield pool


@contextlib.contextmanager
def _local_dask(jobs: int, retries: int, local_directory: str | None) -> Iterator[Executor]:
    import tempfile

    import dask
    from distributed import Client, LocalCluster

    # Dask leaves lock files in its scratch directory: give it one of ours and remove it after (the
    # workers get it as local_directory, the scheduler through "temporary-directory")
    if local_directory is None:
        remove_stale_scratch()
    scratch = (None if local_directory is not None else
               tempfile.TemporaryDirectory(prefix=f"qrrt-dask-{os.getpid()}-"))
    local_directory = local_directory if scratch is None else scratch.name
    try:
        # workers forked from the fork server inherit its single-thread environment (set when it
        # started); only spawned ones need it in ours (a change of os.environ while another thread
        # runs trials would race with C code reading the environment)
        with _warm_fork_server(DASK_PRELOAD) as method, \
                dask.config.set({**LOCAL_DASK_CONFIG, "distributed.worker.multiprocessing-method": method,
                                 "temporary-directory": local_directory}), \
                (_single_thread_environment() if method == "spawn" else contextlib.nullcontext()), \
                _dask_logs_restored(), \
                LocalCluster(n_workers=jobs, threads_per_worker=1, processes=True, host="127.0.0.1",
                             dashboard_address=NO_DASHBOARD, local_directory=local_directory) as cluster, \
                Client(cluster) as client, \
                _dask_logs_silenced_on_exit():
            yield client.get_executor(retries=retries, pure=False)
    finally:
        if scratch is not None:
            scratch.cleanup()


#: the loggers a local Dask cluster's shutdown writes to (closing connections, missed heartbeats),
#: with every logger under them
DASK_LOGGERS = ("distributed", "tornado", "asyncio")


def _dask_loggers() -> list[logging.Logger]:
    """``DASK_LOGGERS`` and every logger created under them (Dask sets some of their levels)."""
    names = [name for name in list(logging.root.manager.loggerDict)
             if any(name == root or name.startswith(root + ".") for root in DASK_LOGGERS)]
    return [logging.getLogger(name) for name in {*DASK_LOGGERS, *names}]


@contextlib.contextmanager
def _dask_logs_restored() -> Iterator[None]:
    """The levels of the Dask loggers (``_dask_loggers``) as they were once the block (the
    cluster's life) ends; from the block's start, the client's reports of cancelled tasks and
    closed connections are left out (``dask_noise.SHUTDOWN_NOISE`` on ``tornado.application`` and
    ``distributed``, kept for the rest of the process: its event loop may report a task cancelled
    by an interrupt after the cluster has closed)."""
    from ._support.dask_noise import SHUTDOWN_NOISE

    for name in ("tornado.application", "distributed"):
        logging.getLogger(name).addFilter(SHUTDOWN_NOISE)  # (once: a filter already set is not added again)
    saved = {logger: logger.level for logger in _dask_loggers()}
    try:
        yield
    finally:
        for logger in _dask_loggers():
            logger.setLevel(saved.get(logger, logging.NOTSET))


@contextlib.contextmanager
def _dask_logs_silenced_on_exit() -> Iterator[None]:
    """The Dask loggers (``_dask_loggers``) silenced as the block ends, however it ends (the
    cluster then shuts down)."""
    try:
        yield
    finally:
        for logger in _dask_loggers():
            logger.setLevel(logging.CRITICAL + 1)


@contextlib.contextmanager
def _open(kind: str, jobs: int, scheduler: str | None, retries: int,
          local_directory: str | None) -> Iterator[Executor | None]:
    if kind == "serial":
        yield None
    elif kind == "process":
        with _process_pool(jobs) as pool:
            yield pool
    elif scheduler is not None:
        from distributed import Client

        with Client(scheduler) as client:
            yield client.get_executor(retries=retries, pure=False)
    else:
        with _local_dask(jobs, retries, local_directory) as executor:
            yield executor


@contextlib.contextmanager
def get_executor(kind: str = "serial", jobs: int | None = None, scheduler: str | None = None,
                 retries: int = 2, local_directory: str | None = None) -> Iterator[Executor | None]:
    """Context manager yielding an executor (``None`` for serial); everything it started is shut
    down on exit.

    ``"process"``: a ``ProcessPoolExecutor`` of ``jobs`` single-threaded workers forked from a warm
    fork server. ``"dask"``: ``Client.get_executor(retries=retries)`` of a ``LocalCluster`` of
    ``jobs`` single-threaded workers, or of the cluster at ``scheduler``.

    Args:
        kind: One of ``EXECUTORS``: ``"serial"`` (default), ``"process"`` or ``"dask"``.
        jobs: Worker processes (an integer >= 1); None means ``os.cpu_count()``. Unused by an
            existing Dask cluster.
        scheduler: Address of a running Dask scheduler (``kind="dask"`` only), or None for a local
            cluster.
        retries: Dask retries of a task whose worker failed (default 2).
        local_directory: Scratch directory of a local Dask cluster; None (default) for a temporary
            one removed on exit.

    Returns:
        A context manager that yields a ``concurrent.futures.Executor``, or None for ``"serial"``.

    Raises:
        ValueError: An unknown ``kind``, ``jobs`` < 1, a ``scheduler`` without ``kind="dask"``, or
            ``kind="dask"`` without the ``dask`` extra.
        TypeError: A non-integer ``jobs``.

    Example:
        >>> from qrrt_circuits.execution import get_executor
        >>> with get_executor("serial") as executor:
        ...     print(executor)
        None
    """
    jobs = check_executor_args(kind, jobs, scheduler)
    with _open(kind, jobs, scheduler, retries, local_directory) as executor:
        yield executor


class WorkerPool:
    """One executor of ``kind`` kept open across several sweeps (a context manager).

    ``executor`` is the live executor (``None`` for serial), started on first use, so a pool
    whose sweeps are all finished already starts no workers; ``renew()`` shuts it down and starts
    a new one (after a local pool broke because a worker died). ``run_experiment(executor=pool)``
    uses it and renews it when it breaks, so ``qrrt reproduce all`` pays the start of workers once.
    Opening a local pool (``process``, or ``dask`` without a ``scheduler``) starts the fork server at
    once, so its preload overlaps the caller's preparation; it is killed unused if no worker was
    ever needed. While a new local pool starts, ``run_experiment`` runs trials in this process
    (``helps_while_starting``).

    Args:
        kind: One of ``EXECUTORS``: ``"serial"`` (default), ``"process"`` or ``"dask"``.
        jobs: Worker processes (an integer >= 1); None means ``os.cpu_count()``.
        scheduler: Address of a running Dask scheduler (``kind="dask"`` only), or None.
        retries: Dask retries of a task whose worker failed (default 2).
        local_directory: Scratch directory of a local Dask cluster, or None for a temporary one.

    Raises:
        ValueError: An unknown ``kind``, ``jobs`` < 1, a ``scheduler`` without ``kind="dask"``, or
            ``kind="dask"`` without the ``dask`` extra.
        TypeError: A non-integer ``jobs``.

    Example:
        >>> from qrrt_circuits.execution import WorkerPool
        >>> with WorkerPool("serial", jobs=2) as pool:
        ...     print(pool.executor, pool.jobs)
        None 2
    """

    def __init__(self, kind: str = "serial", jobs: int | None = None, scheduler: str | None = None,
                 retries: int = 2, local_directory: str | None = None) -> None:
        self.kind = kind
        self.jobs = check_executor_args(kind, jobs, scheduler)
        self.scheduler = scheduler
        self.retries = retries
        self.local_directory = local_directory
        self._open = False
        self._stack: contextlib.ExitStack | None = None
        self._executor: Executor | None = None
        self._fork_server: tuple[contextlib.ExitStack, object] | None = None
        self._forked = False
        self._context = contextvars.copy_context()
        self._lock = threading.RLock()

    @property
    def executor(self) -> Executor | None:
        """The live executor (None for ``"serial"``), started on first access.

        Raises:
            RuntimeError: The pool is not open (used outside its ``with`` block).
        """
        if not self._open:
            raise RuntimeError("WorkerPool is not open: use it as a context manager")
        with self._lock:  # a start and a shut-down never overlap (the runner starts from a thread)
            if self._stack is None:
                self._start()
            return self._executor

    @property
    def helps_while_starting(self) -> bool:
        """Whether this process should run trials itself while the pool's workers start: local
        pools only (``process``, or ``dask`` without a ``scheduler``), never a remote cluster, and
        only where workers are forked from the fork server (so starting them changes nothing in
        this process's environment while it runs trials)."""
        local = self.kind == "process" or (self.kind == "dask" and self.scheduler is None)
        return local and _fork_server_available()

    @property
    def started(self) -> bool:
        """Whether workers (or a client) are running now."""
        return self._stack is not None

    def __enter__(self) -> WorkerPool:
        self._open = True
        self._prestart_fork_server()
        return self

    def __exit__(self, *exc_info: object) -> None:
        try:
            self._shut_down()
        finally:
            self._open = False
            self._stop_prestarted_fork_server()

    def _prestart_fork_server(self) -> None:
        """Local workers are forked from the fork server, whose preload (every import a trial needs)
        would otherwise begin only when the first trial is submitted. Starting it here lets it
        import while this process prepares the sweep (its own imports, the records already done),
        on another core. The pool's executors find it running and use it; it is stopped when the
        pool closes."""
        self._fork_server = None
        self._forked = False
        if self.kind == "serial" or (self.kind == "dask" and self.scheduler is not None):
            return
        if not _fork_server_available():
            return
        from multiprocessing import forkserver

        server = forkserver._forkserver
        if server._forkserver_pid is not None:  # type: ignore[attr-defined]  # one runs: not ours to stop
            return
        stack = contextlib.ExitStack()
        stack.enter_context(_warm_fork_server(DASK_PRELOAD if self.kind == "dask" else ()))
        self._fork_server = (stack, server)

    def _stop_prestarted_fork_server(self) -> None:
        if self._fork_server is None:
            return
        stack, server = self._fork_server
        self._fork_server = None
        if not self._forked:  # never used: kill it at once rather than wait for its preload
            _stop_fork_server(server, wait_s=0.0)
        stack.close()  # (stops it if it still runs)

    def _start(self) -> None:
        """Start the executor, inside the pool's own ``contextvars.Context`` (as ``_shut_down``
        stops it): the experiment runner may start a pool from a background thread while this
        process runs trials, and a Dask ``Client`` must be closed in the context it was made in."""
        self._forked = True
        self._context.run(self._enter_executor)

    def _enter_executor(self) -> None:
        stack = contextlib.ExitStack()
        with stack:
            self._executor = stack.enter_context(
                _open(self.kind, self.jobs, self.scheduler, self.retries, self.local_directory))
            self._stack = stack.pop_all()

    def renew(self) -> None:
        """Shut the executor down (a broken one too); the next use starts a fresh one."""
        self._shut_down()

    def _shut_down(self) -> None:
        with self._lock:
            stack, self._stack, self._executor = self._stack, None, None
            if stack is not None:
                self._context.run(stack.close)
