"""Scale-out: identical results on every executor, and faults that lose nothing."""

import os
import signal

import psutil
import pytest
from summaries import results_of

from qrrt_circuits.execution import get_executor
from qrrt_circuits.experiments import read_records, run_experiment
from qrrt_circuits.experiments.base import TIMING_SUFFIX

pytestmark = pytest.mark.xdist_group("dask")


@pytest.fixture(scope="session")
def dask_client(tmp_path_factory):
    """One LocalCluster (2 single-threaded worker processes, no dashboard) for the whole run."""
    from distributed import Client, LocalCluster

    scratch = tmp_path_factory.mktemp("dask")
    import dask

    from qrrt_circuits.execution import NO_DASHBOARD

    # the scheduler, too, keeps its scratch space (and lock files) under "temporary-directory"
    with dask.config.set({"temporary-directory": str(scratch)}), \
            LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                         dashboard_address=NO_DASHBOARD, local_directory=str(scratch)) as cluster, \
            Client(cluster) as client:
        yield client


def _records(directory, name):
    rows = read_records(directory / name / "records.csv")
    return sorted(({k: v for k, v in r.items() if not k.endswith(TIMING_SUFFIX)} for r in rows),
                  key=lambda r: r["trial_id"])


def test_serial_process_and_dask_give_identical_results(dask_client, tmp_path):
    name, trials = "heatmaps", 2
    summaries = {
        "serial": run_experiment(name, out=tmp_path / "serial", quick=True, trials=trials, progress=False),
        "process": run_experiment(name, out=tmp_path / "process", quick=True, trials=trials, progress=False,
                                  executor="process", jobs=2),
        "dask": run_experiment(name, out=tmp_path / "dask", quick=True, trials=trials, progress=False,
                               executor=dask_client.get_executor(retries=2, pure=False)),
    }
    reference = summaries["serial"]
    for kind, summary in summaries.items():
        assert summary["ours"] == reference["ours"], kind
        assert _records(tmp_path / kind, name) == _records(tmp_path / "serial", name), kind


def test_killed_dask_worker_is_rescheduled(dask_client, tmp_path):
    pids = list(dask_client.run(os.getpid).values())
    killed = []

    def kill_one_worker(_record):
        if not killed:
            os.kill(pids[0], signal.SIGKILL)
            killed.append(pids[0])

    summary = run_experiment("oracle-efficiency", out=tmp_path / "dask", quick=True, trials=3, progress=False,
                             executor=dask_client.get_executor(retries=2, pure=False), on_record=kill_one_worker)
    assert killed and summary["complete"]
    rows = read_records(tmp_path / "dask" / "oracle-efficiency" / "records.csv")
    assert len(rows) == len({r["trial_id"] for r in rows}) == 12
    serial = run_experiment("oracle-efficiency", out=tmp_path / "serial", quick=True, trials=3, progress=False)
    assert summary["ours"] == serial["ours"]
    dask_client.wait_for_workers(2, timeout=60)


def _is_pool_worker(process) -> bool:
    """A spawned worker, or one forked by the fork server (not the server itself)."""
    if any("spawn_main" in part for part in process.cmdline()):
        return True
    parent = process.parent()
    return parent is not None and any("forkserver" in part for part in parent.cmdline())


def test_killed_process_pool_worker_is_replaced(tmp_path):
    before = {p.pid for p in psutil.Process().children(recursive=True)}
    killed, restarts = [], []

    def kill_one_worker(_record):
        if killed:
            return
        for process in psutil.Process().children(recursive=True):
            try:
                is_worker = _is_pool_worker(process)
            except psutil.NoSuchProcess:
                continue
            if process.pid not in before and is_worker:
                process.kill()
                killed.append(process.pid)
                return

    from qrrt_circuits.execution import WorkerPool

    with WorkerPool("process", jobs=2) as pool:
        assert pool.executor is not None  # started before the sweep: every trial goes to a worker
        summary = run_experiment("oracle-efficiency", out=tmp_path, quick=True, trials=3, progress=False,
                                 executor=pool, on_record=kill_one_worker, on_restart=restarts.append)
    assert killed and restarts == [1] and summary["complete"]
    rows = read_records(tmp_path / "oracle-efficiency" / "records.csv")
    assert len(rows) == len({r["trial_id"] for r in rows}) == 12


def _children():
    """Child processes, except the standard library's resource tracker (it lives until exit)."""
    out = set()
    for process in psutil.Process().children(recursive=True):
        try:
            if not any("resource_tracker" in part for part in process.cmdline()):
                out.add(process.pid)
        except psutil.NoSuchProcess:
            pass
    return out


#: evaluated in a worker: it was forked from the warm fork server (the warm-up module is imported
#: by nothing else) and holds the default world already built
WARM_CHECK = ("'qrrt_circuits._support.worker_warmup' in __import__('sys').modules and __import__("
              "'qrrt_circuits.experiments.worlds', fromlist=['w'])._cached_world.cache_info().currsize >= 1")


def _is_warm(executor) -> bool:
    import multiprocessing

    if "forkserver" not in multiprocessing.get_all_start_methods():
        return True  # workers are spawned cold where there is no fork server
    return executor.submit(eval, WARM_CHECK).result()


def test_one_worker_pool_serves_several_sweeps_and_starts_only_when_needed(tmp_path):
    from qrrt_circuits.execution import WorkerPool

    serial = run_experiment("oracle-efficiency", out=tmp_path / "serial", quick=True, trials=2, progress=False)
    with WorkerPool("process", jobs=1) as pool:
        done = run_experiment("oracle-efficiency", out=tmp_path / "serial", quick=True, trials=2, progress=False,
                              executor=pool)
        assert done["ours"] == serial["ours"] and not pool.started  # nothing left to run: no workers
        worker = pool.executor.submit(os.getpid).result()
        first = run_experiment("oracle-efficiency", out=tmp_path / "pool", quick=True, trials=2, progress=False,
                               executor=pool)
        run_experiment("oracle-efficiency", out=tmp_path / "seed1", quick=True, trials=2, seed=1, progress=False,
                       executor=pool)
        assert pool.executor.submit(os.getpid).result() == worker  # the same worker throughout
    assert first["ours"] == serial["ours"]
    assert not pool.started
    with pytest.raises(RuntimeError, match="not open"):
        _ = pool.executor


def test_get_executor_cleans_up():
    import tempfile

    before = _children()
    temp = set(os.listdir(tempfile.gettempdir()))
    with get_executor("dask", jobs=1) as executor:
        assert executor.submit(pow, 2, 5).result() == 32
        assert _is_warm(executor)
    with get_executor("process", jobs=1) as executor:
        assert executor.submit(pow, 3, 2).result() == 9
        assert _is_warm(executor)
    psutil.wait_procs([psutil.Process(pid) for pid in _children() - before], timeout=20)
    assert _children() <= before
    leftovers = {name for name in set(os.listdir(tempfile.gettempdir())) - temp
                 if name.startswith(("qrrt-dask-", "dask-scratch", "dask-worker"))}
    assert not leftovers, leftovers


@pytest.mark.parametrize("kwargs, message", [
    ({"executor": "gpu"}, "executor must be one of"),
    ({"executor": "process", "jobs": 0}, "jobs must be an integer >= 1"),
    ({"executor": "process", "scheduler": "tcp://127.0.0.1:8786"}, "scheduler is only used"),
])
def test_bad_executor_arguments(kwargs, message, tmp_path):
    with pytest.raises(ValueError, match=message):
        run_experiment("lemmas", out=tmp_path, quick=True, trials=20, progress=False, **kwargs)


def test_process_pool_workers_exit_when_the_client_is_killed(tmp_path):
    """SIGKILL the client of --executor process mid-sweep: its pool workers notice their parent is
    gone and exit within seconds (0.1 left them running for minutes)."""
    import signal
    import subprocess
    import sys
    import time

    import psutil

    client = subprocess.Popen([sys.executable, "-m", "qrrt_circuits.cli", "reproduce", "heatmaps", "--quick",
                               "--executor", "process", "--jobs", "2", "--out", str(tmp_path), "--no-progress"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    workers = []
    for _ in range(600):  # wait (up to 60 s) until the pool's workers have started
        time.sleep(0.1)
        workers = [p for p in psutil.Process(client.pid).children(recursive=True)
                   if "resource_tracker" not in " ".join(p.cmdline())]
        if len(workers) >= 2:
            break
    assert len(workers) >= 2, "the pool did not start"
    client.send_signal(signal.SIGKILL)
    client.wait()
    gone, alive = psutil.wait_procs(workers, timeout=10)
    assert not alive, f"workers still running 10 s after the client died: {[p.pid for p in alive]}"


def test_client_runs_trials_while_a_new_pool_starts_and_each_trial_runs_once(tmp_path, monkeypatch):
    """A fresh local pool: this process runs trials from the back of the list until the first
    worker result arrives, a background thread starts the pool and submits from the front; every
    trial is recorded exactly once, with the records serial execution gives."""
    import functools

    from qrrt_circuits.execution import WorkerPool
    from qrrt_circuits.experiments import runner

    ran_here = []
    original = runner.execute_trial

    @functools.wraps(original)
    def counted(name, trial, settings):  # pickled by name: workers run the original
        ran_here.append(trial.id)
        return original(name, trial, settings)

    monkeypatch.setattr(runner, "execute_trial", counted)
    name, trials = "oracle-efficiency", 3
    with WorkerPool("process", jobs=1) as pool:
        assert pool.helps_while_starting and not pool.started
        summary = run_experiment(name, out=tmp_path / "pool", quick=True, trials=trials, progress=False,
                                 executor=pool)
    monkeypatch.setattr(runner, "execute_trial", original)
    serial = run_experiment(name, out=tmp_path / "serial", quick=True, trials=trials, progress=False)
    rows = read_records(tmp_path / "pool" / name / "records.csv")
    assert len(rows) == len({r["trial_id"] for r in rows}) == 12
    assert len(set(ran_here)) == len(ran_here) <= len(rows)  # each that ran here ran once
    assert summary["ours"] == serial["ours"]
    assert _records(tmp_path / "pool", name) == _records(tmp_path / "serial", name)


def test_reproducing_several_experiments_makes_each_summary_while_the_next_trials_run(tmp_path, monkeypatch):
    """run_experiments (``qrrt reproduce all``) on a process pool: every summary.json and figure is
    the serial run's, the summaries are reported in order, and an experiment's summary is made in
    the background thread, not by the thread that runs the next experiment's trials."""
    import threading

    from qrrt_circuits.execution import WorkerPool
    from qrrt_circuits.experiments import EXPERIMENTS
    from qrrt_circuits.experiments.runner import run_experiments

    names = ["corridor", "heatmaps", "oracle-efficiency"]
    options = {"quick": True, "trials": 2, "progress": False}
    made_by: dict[str, str] = {}
    for name in names:  # record which thread makes each summary
        original = type(EXPERIMENTS[name]).summarize

        def summarize(self, records, settings, original=original, name=name):
            made_by[name] = threading.current_thread().name
            return original(self, records, settings)

        monkeypatch.setattr(type(EXPERIMENTS[name]), "summarize", summarize)
    serial, pooled = [], []
    with WorkerPool("serial") as pool:
        run_experiments(names, pool, lambda name, summary: serial.append((name, summary)),
                        out=tmp_path / "serial", **options)
    assert set(made_by.values()) == {threading.current_thread().name}
    made_by.clear()
    with WorkerPool("process", jobs=2) as pool:
        run_experiments(names, pool, lambda name, summary: pooled.append((name, summary)),
                        out=tmp_path / "pool", **options)
    assert all(thread.startswith("qrrt-summary") for thread in made_by.values()), made_by
    assert [name for name, _ in pooled] == names == [name for name, _ in serial]
    for (name, ours), (_, reference) in zip(pooled, serial, strict=True):
        assert ours["complete"] and ours["ours"] == reference["ours"], name
        assert _records(tmp_path / "pool", name) == _records(tmp_path / "serial", name), name
        written = results_of(tmp_path / "pool" / name / "summary.json")
        assert written == results_of(tmp_path / "serial" / name / "summary.json"), name
        assert ours["figures"] and all((tmp_path / "pool" / name / figure).stat().st_size
                                       for figure in ours["figures"])


def test_local_workers_are_limited_per_core():
    """100 000 local workers were accepted (each a Python process with Qiskit, Aer and numba)."""
    from qrrt_circuits.execution import JOBS_PER_CORE, check_executor_args, max_local_jobs

    limit = max_local_jobs()
    assert limit == JOBS_PER_CORE * (os.cpu_count() or 1)
    assert check_executor_args("process", limit, None) == limit
    with pytest.raises(ValueError, match=rf"jobs must be an integer in \[1, {limit}\] for local workers"):
        check_executor_args("process", limit + 1, None)
    assert check_executor_args("serial", limit + 1, None) == limit + 1  # unused by the serial executor

