"""``qrrt`` with numba's on-disk cache of compiled functions corrupt: one line naming the cache and
what to do, exit status 1, no traceback.

numba (0.68) does not recompile a function whose cache entry it cannot read: unpickling the index
(``*.nbi``) or the data (``*.nbc``) raises whatever the garbage makes pickle raise
(``UnpicklingError``, ``EOFError``, ``OverflowError``, ...), at the first call of the function.
The caches here are real ones, filled by building the default world (the first thing every
command that plans does, and the kernels it compiles are few) and then overwritten."""

import multiprocessing
import os
import shutil
import subprocess
import sys
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import pytest

import qrrt_circuits
from qrrt_circuits import cli

pytestmark = pytest.mark.xdist_group("numba-cache")  # one filled cache for the module

PLAN = ["plan", "--planner", "rrt", "--max-nodes", "3"]
FILL = ["-c", "import qrrt_circuits as qc; qc.paper_clutter(seed=0)"]


def _python(argv, cwd, **env):
    environment = {key: value for key, value in os.environ.items() if key not in ("NUMBA_CACHE_DIR", "PYTHONPATH")}
    environment.update(env)
    return subprocess.run([sys.executable, *argv], capture_output=True, text=True, cwd=cwd, env=environment,
                          timeout=300)


def _qrrt(argv, cwd, **env):
    return _python(["-m", "qrrt_circuits.cli", *argv], cwd, **env)


def _corrupt(folder: Path, suffixes=(".nbi", ".nbc")) -> int:
    files = [path for path in folder.rglob("*") if path.suffix in suffixes]
    for number, path in enumerate(files):
        path.write_bytes(bytes((37 * number + 11 * i) % 256 for i in range(64)))
    return len(files)


@pytest.fixture(scope="module")
def filled_cache(tmp_path_factory):
    """A NUMBA_CACHE_DIR holding the default world's compiled kernels."""
    folder = tmp_path_factory.mktemp("numba-cache")
    run = _python(FILL, folder, NUMBA_CACHE_DIR=str(folder), PYTHONPATH=_source())
    assert run.returncode == 0, run.stderr
    assert any(folder.rglob("*.nbi")) and any(folder.rglob("*.nbc"))
    return folder


def _source() -> str:
    return str(Path(qrrt_circuits.__file__).resolve().parent.parent)


def _one_line(run) -> str:
    """The one line on stderr of a run that failed with status 1 because of numba's cache."""
    assert run.returncode == 1, run.stderr
    assert "Traceback" not in run.stderr, run.stderr
    lines = [line for line in run.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, run.stderr
    assert "error: numba's compiled-function cache in " in lines[0] and "and run again" in lines[0]
    return lines[0]


def _named_cache(line: str) -> str:
    return line.split("cache in ", 1)[1].split(" is unreadable or corrupt (", 1)[0]


@pytest.mark.parametrize("corrupt", [(".nbi", ".nbc"), (".nbc",)], ids=["index-and-data", "data"])
def test_a_corrupt_numba_cache_dir_is_one_line_naming_it(corrupt, filled_cache, tmp_path):
    cache = tmp_path / "cache"
    shutil.copytree(filled_cache, cache)
    assert _corrupt(cache, corrupt)
    line = _one_line(_qrrt(PLAN, tmp_path, NUMBA_CACHE_DIR=str(cache), PYTHONPATH=_source()))
    assert _named_cache(line) == str(cache)
    assert line.startswith("qrrt plan: error:") and "delete that folder (or unset NUMBA_CACHE_DIR)" in line


def test_a_corrupt_cache_is_one_line_with_a_worker_pool(filled_cache, tmp_path):
    """The fork server's warm-up meets the corrupt cache too: it prints nothing, and the command
    reports the cache once."""
    cache = tmp_path / "cache"
    shutil.copytree(filled_cache, cache)
    assert _corrupt(cache)
    run = _qrrt(["reproduce", "heatmaps", "--quick", "--no-progress", "--out", str(tmp_path / "out"),
                 "--executor", "process", "--jobs", "2"], tmp_path, NUMBA_CACHE_DIR=str(cache), PYTHONPATH=_source())
    line = _one_line(run)
    assert _named_cache(line) == str(cache) and line.startswith("qrrt reproduce: error:")


def test_a_corrupt_cache_beside_the_modules_is_named_by_its_folder(tmp_path):
    """Without NUMBA_CACHE_DIR numba caches in ``__pycache__`` beside each module: the line names
    the folder of the file it could not read (the package is copied, so the tree is not touched)."""
    package = tmp_path / "src" / "qrrt_circuits"
    shutil.copytree(Path(qrrt_circuits.__file__).resolve().parent, package,
                    ignore=shutil.ignore_patterns("__pycache__"))
    assert _python(FILL, tmp_path, PYTHONPATH=str(package.parent)).returncode == 0
    assert _corrupt(package, (".nbi",))
    line = _one_line(_qrrt(PLAN, tmp_path, PYTHONPATH=str(package.parent)))
    folder = _named_cache(line)
    assert Path(folder).name == "__pycache__" and Path(folder).is_relative_to(package), line
    assert any(Path(folder).glob("*.nbi")) and "delete its *.nbi and *.nbc files" in line


def _use_cache(folder: str) -> None:
    os.environ["NUMBA_CACHE_DIR"] = folder  # (the worker imports numba after this)


def _build_world() -> str:
    return qrrt_circuits.paper_clutter(seed=0).name


def test_a_worker_process_meeting_a_corrupt_cache_is_recognised(filled_cache, tmp_path):
    """A trial that fails in a pool worker reaches the client with the worker's traceback as text
    (``concurrent.futures``): that is enough to recognise the cache."""
    cache = tmp_path / "cache"
    shutil.copytree(filled_cache, cache)
    assert _corrupt(cache)
    with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn"), initializer=_use_cache,
                             initargs=(str(cache),)) as pool:
        with pytest.raises(Exception) as raised:  # noqa: B017 (whatever the garbage makes pickle raise)
            pool.submit(_build_world).result(timeout=300)
    found = cli._numba_cache_failure(raised.value)
    assert found is not None and found[0] is raised.value
    assert cli._numba_cache_failure(ValueError("not from numba")) is None
