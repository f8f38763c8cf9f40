"""``qrrt`` stopped by a signal: Ctrl-C (SIGINT) at any moment, from the heavy imports on, and
SIGTERM / SIGHUP, which stop a command the way Ctrl-C does. Each prints one line and no traceback,
exits with 128 + the signal's number, shuts its worker pool down (no semaphore leaks), and leaves
a ``qrrt reproduce`` that the same command resumes.

Every test here runs the real command in a process of its own and sends it a real signal."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import psutil
import pytest

from qrrt_circuits import cli

if not hasattr(signal, "SIGHUP"):
    pytest.skip("these tests send POSIX signals", allow_module_level=True)

QRRT = [sys.executable, "-m", "qrrt_circuits.cli"]


def _environment() -> dict[str, str]:
    """The command's environment: this one, with bytecode caches written and read as an installed
    package's are (PYTHONDONTWRITEBYTECODE would recompile every module on every start)."""
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def _default_signals() -> None:
    """In the child: the default dispositions of the signals sent here. A test run started in the
    background (``cmd &``) or under ``nohup`` inherits SIGINT or SIGHUP ignored, and a program
    keeps an ignored signal ignored, as a background job should."""
    for signum in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(signum, signal.SIG_DFL)


def _start(argv, tmp_path, env=None, preexec_fn=_default_signals, **options):
    return subprocess.Popen([*QRRT, *argv], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            cwd=tmp_path, env=env or _environment(), preexec_fn=preexec_fn, **options)


def _wait_for(condition, process, what, timeout_s=60.0):
    deadline = time.monotonic() + timeout_s
    while not condition():
        if process.poll() is not None:
            raise AssertionError(f"qrrt exited ({process.returncode}) before {what}: {process.communicate()[1]}")
        if time.monotonic() > deadline:
            process.kill()
            raise AssertionError(f"no {what} after {timeout_s} s")
        time.sleep(0.005)


def _catches_sigterm(pid: int) -> bool:
    """Whether process ``pid`` has a handler for SIGTERM (Linux: SigCgt in /proc/PID/status)."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except FileNotFoundError:
        return False
    caught = next(line.split()[1] for line in status.splitlines() if line.startswith("SigCgt:"))
    return bool(int(caught, 16) >> (signal.SIGTERM - 1) & 1)


def _wait_until_running(process):
    """Wait until the command's own code runs: ``main`` installs its SIGTERM handler before
    anything else (before the package's heavy imports). Before that, the interpreter is starting
    (tens of milliseconds), which no program can take over. Without /proc, 0.1 s."""
    if not Path("/proc/self/status").is_file():
        time.sleep(0.1)
        return
    _wait_for(lambda: _catches_sigterm(process.pid), process, "SIGTERM handler")


def _stop(process, signum, after_s=0.0):
    """Send ``signum`` ``after_s`` seconds from now; the exit status, stdout and stderr."""
    time.sleep(after_s)
    process.send_signal(signum)
    out, err = process.communicate(timeout=120)  # (to EOF: the resource tracker's warnings included)
    return process.returncode, out, err


def _error_lines(err):
    return [line for line in err.splitlines() if line.strip()]


def _reproduce(experiment, out, *options):
    return ["reproduce", experiment, "--quick", "--no-progress", "--out", str(out), *options]


def _records(out, experiment="heatmaps") -> int:
    try:
        return max(0, len((out / experiment / "records.csv").read_text().splitlines()) - 1)
    except FileNotFoundError:
        return 0


def _names(processes) -> list[str]:
    """The names of ``processes`` (psutil), those gone meanwhile as "gone"."""
    names = []
    for process in processes:
        try:
            names.append(" ".join(process.cmdline()[:3]) or process.name())
        except psutil.Error:
            names.append("gone")
    return names


def _terminated_line(signum, out):
    return (f"qrrt reproduce: terminated ({signal.Signals(signum).name}); finished trials are kept in "
            f"{out / 'heatmaps' / 'records.csv'}; run the same command again to resume")


@pytest.fixture(scope="module")
def compiled(tmp_path_factory):
    """The package's bytecode written once, so that the command starts as an installed one does."""
    subprocess.run([*QRRT, "--version"], check=True, capture_output=True, env=_environment(),
                   cwd=tmp_path_factory.mktemp("version"), timeout=120)


@pytest.mark.parametrize("after_s", [0.0, 0.05, 0.1, 0.2, 0.35, 0.5, 0.75, 1.0, 1.5])
def test_ctrl_c_at_any_moment_is_one_line_and_130(after_s, compiled, tmp_path):
    """Counted from the moment the command's code runs, it first imports numpy, numba, scipy and
    Qiskit, then reads its arguments, then runs trials (3000 of them: it is still running at
    1.5 s): an interrupt anywhere in that is reported the same way."""
    process = _start(_reproduce("heatmaps", tmp_path / "results", "--trials", "1000"), tmp_path)
    _wait_until_running(process)
    status, _, err = _stop(process, signal.SIGINT, after_s)
    assert "Traceback" not in err, err
    assert status == 130, (status, err)
    assert len(_error_lines(err)) == 1, err
    assert err.startswith("qrrt reproduce: interrupted; finished trials are kept in"), err
    assert "run the same command again to resume" in err


@pytest.mark.parametrize("signum, status", [(signal.SIGTERM, 143), (signal.SIGHUP, 129)])
def test_sigterm_and_sighup_stop_a_serial_run_that_the_same_command_resumes(signum, status, tmp_path):
    """(The resumed run is checked after SIGTERM; SIGHUP leaves the same records.)"""
    out = tmp_path / "results"
    argv = _reproduce("heatmaps", out)
    process = _start(argv, tmp_path)
    _wait_for(lambda: _records(out) >= 5, process, "5 finished trials")  # (of 150)
    code, _, err = _stop(process, signum)
    assert code == status, (code, err)
    assert _error_lines(err) == [_terminated_line(signum, out)]
    assert 5 <= _records(out) < 150
    if signum != signal.SIGTERM:
        return
    again = subprocess.run([*QRRT, *argv], capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert again.returncode == 0, again.stderr
    assert f"wrote {out.resolve() / 'heatmaps'}/" in again.stdout
    assert '"complete": true' in (out / "heatmaps" / "summary.json").read_text()


def _pool_workers(pid: int) -> int:
    """Processes forked by ``pid``'s children (the pool's workers, forked by the fork server)."""
    try:
        return sum(len(child.children()) for child in psutil.Process(pid).children())
    except psutil.NoSuchProcess:
        return 0


def test_sigterm_shuts_the_worker_pool_down_and_the_run_resumes(tmp_path):
    """With ``--executor process`` the pool and its fork server are shut down on the way out:
    nothing is left running, and no semaphore is left for the resource tracker to report."""
    out = tmp_path / "results"
    argv = _reproduce("heatmaps", out, "--executor", "process", "--jobs", "2", "--trials", "100")
    process = _start(argv, tmp_path)
    _wait_for(lambda: _pool_workers(process.pid) >= 2, process, "2 pool workers")
    helpers = psutil.Process(process.pid).children(recursive=True)
    code, _, err = _stop(process, signal.SIGTERM)
    assert code == 143, (code, err)
    assert "Traceback" not in err and "leaked" not in err, err
    assert _error_lines(err) == [_terminated_line(signal.SIGTERM, out)]
    gone, alive = psutil.wait_procs(helpers, timeout=10)
    assert not alive, f"left running: {alive}"
    assert _records(out) < 300
    again = subprocess.run([*QRRT, *argv], capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert again.returncode == 0, again.stderr
    assert "Traceback" not in again.stderr and "leaked" not in again.stderr, again.stderr
    assert '"complete": true' in (out / "heatmaps" / "summary.json").read_text()


def test_an_ignored_sighup_stays_ignored(tmp_path):
    """Under ``nohup`` (SIGHUP ignored) the command does not stop when its terminal closes."""
    process = _start(["plan", "--planner", "rrt", "--max-nodes", "3"], tmp_path,
                     preexec_fn=lambda: (_default_signals(), signal.signal(signal.SIGHUP, signal.SIG_IGN)))
    code, stdout, err = _stop(process, signal.SIGHUP, 0.3)
    assert code == 0, err
    assert "RRT on paper_clutter" in stdout


def test_main_restores_the_signal_handlers_it_installed(capsys):
    before = {signum: signal.getsignal(signum) for signum in cli.STOP_SIGNALS}
    assert cli.main(["plan", "--planner", "rrt", "--max-nodes", "3"]) == 0
    with pytest.raises(SystemExit):
        cli.main(["plan", "--goal-bias", "2"])
    assert {signum: signal.getsignal(signum) for signum in cli.STOP_SIGNALS} == before
    capsys.readouterr()


def test_the_exit_statuses_are_documented_where_the_command_line_is():
    page = Path(__file__).resolve().parents[2] / "docs" / "explanations" / "planners.md"
    readme = " ".join(page.read_text().split())
    for status in cli.EXIT_STATUSES:
        if status:
            assert f"exit {status}" in readme, status


@pytest.mark.parametrize("executor", ["process", "dask"])
def test_ctrl_c_to_the_process_group_is_one_line_and_the_workers_are_shut_down(executor, tmp_path):
    """Ctrl-C from a terminal reaches the whole process group, workers and fork server included:
    they ignore it, the command prints its one line, exits 130 and shuts them down, and the run
    resumes. Sent once the first records are written (the workers mid-trial) and on a second run as
    soon as the command has a child process (the fork server, importing its preload)."""
    if executor == "dask":
        pytest.importorskip("distributed")
    out = tmp_path / "results"
    argv = _reproduce("heatmaps", out, "--executor", executor, "--jobs", "2", "--trials", "100")

    def pool_started() -> bool:  # the fork server exists, importing its preload
        return bool(psutil.Process(process.pid).children())

    moments = {"records written": lambda: _records(out) >= 2, "a child process": pool_started}
    for moment, ready in moments.items():
        process = _start(argv, tmp_path, start_new_session=True)
        _wait_for(ready, process, "the moment to interrupt", timeout_s=120)
        helpers = psutil.Process(process.pid).children(recursive=True)
        seen = (moment, _names(helpers), _records(out))  # (what a failure reports: when it was sent)
        os.killpg(process.pid, signal.SIGINT)
        out_text, err = process.communicate(timeout=120)
        assert process.returncode == 130, (*seen, _records(out), process.returncode, out_text[-300:], err)
        assert _error_lines(out_text + err) == [
            f"qrrt reproduce: interrupted; finished trials are kept in {out / 'heatmaps' / 'records.csv'}; run the "
            "same command again to resume"], err
        gone, alive = psutil.wait_procs(helpers, timeout=10)
        assert not alive, f"left running: {alive}"


def test_stale_scratch_folders_of_dead_runs_are_removed_on_the_next_start(tmp_path):
    """A run killed with SIGKILL leaves its qrrt-pymp-PID-* / qrrt-dask-PID-* folders; the next
    pool removes those whose PID is gone, and keeps a live process's."""
    from qrrt_circuits.execution import remove_stale_scratch

    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    stale = [tmp_path / f"qrrt-pymp-{dead.pid}-abc", tmp_path / f"qrrt-dask-{dead.pid}-def"]
    live = tmp_path / f"qrrt-dask-{os.getpid()}-ghi"
    for folder in (*stale, live):
        folder.mkdir()
        (folder / "lock").write_text("")
    assert sorted(remove_stale_scratch(str(tmp_path))) == sorted(map(str, stale))
    assert live.exists() and not any(folder.exists() for folder in stale)


@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="reads the signal mask from /proc")
def test_the_fork_server_starts_with_sigint_blocked():
    """Starting multiprocessing's resource tracker unblocks SIGINT in the starting thread; the fork
    server is started after it, inside the blocked window, so a Ctrl-C while it is still starting
    (before its first preload ignores the signal) waits instead of interrupting its imports."""
    from multiprocessing import forkserver

    from qrrt_circuits import execution

    if not execution._fork_server_available():
        pytest.skip("no fork server on this platform")
    if forkserver._forkserver._forkserver_pid is not None:
        pytest.skip("a fork server already runs in this process")
    with execution._warm_fork_server():
        pid = forkserver._forkserver._forkserver_pid
        blocked = next(line for line in Path(f"/proc/{pid}/status").read_text().splitlines()
                       if line.startswith("SigBlk:"))
    assert int(blocked.split()[1], 16) & (1 << (signal.SIGINT - 1)), blocked
