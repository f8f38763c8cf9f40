"""One writer per output folder: a second ``qrrt reproduce`` into a folder in use is refused at
once naming the first one's PID, and the records hold each trial once; a killed run's temporary
files are removed and a records file with duplicates is compacted by the next run."""

from __future__ import annotations

import csv
import os
import subprocess
import sys
import time
import warnings
from pathlib import Path

import pytest

from qrrt_circuits._support.folder_lock import LOCK_NAME, FolderInUse, FolderLock
from qrrt_circuits.experiments.records import RecordsWarning
from qrrt_circuits.experiments.runner import run_experiment

SRC = str(Path(__file__).resolve().parents[2] / "src")


def _reproduce(out: Path) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "qrrt_circuits.cli", "reproduce", "heatmaps", "--quick",
                             "--no-progress", "--out", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env={**os.environ, "PYTHONPATH": SRC})


def _trial_ids(path: Path) -> list[str]:
    with path.open(newline="") as handle:
        return [row["trial_id"] for row in csv.DictReader(handle)]


def test_two_runs_into_one_folder_one_is_refused_naming_the_pid_and_each_trial_is_recorded_once(tmp_path):
    first = _reproduce(tmp_path)
    lock = tmp_path / "heatmaps" / LOCK_NAME
    deadline = time.monotonic() + 120
    while not (lock.exists() and lock.read_text().strip() == str(first.pid)):
        assert first.poll() is None and time.monotonic() < deadline, first.communicate()
        time.sleep(0.05)
    second = _reproduce(tmp_path)
    _, err = second.communicate(timeout=120)
    lines = err.strip().splitlines()
    assert second.returncode == 1 and len(lines) == 1, err
    assert f"is in use by another qrrt run (PID {first.pid})" in lines[0] and "use another --out" in lines[0]
    out, err = first.communicate(timeout=300)
    assert first.returncode == 0, err
    ids = _trial_ids(tmp_path / "heatmaps" / "records.csv")
    assert ids and len(ids) == len(set(ids))
    again = _reproduce(tmp_path)  # the lock went with its holder
    assert again.wait(timeout=120) == 0


def test_the_lock_refuses_a_second_holder_and_is_dropped_on_release(tmp_path):
    with FolderLock(tmp_path):
        with pytest.raises(FolderInUse, match=rf"--out {tmp_path} is in use by another qrrt run \(PID {os.getpid()}\)"):
            FolderLock(tmp_path).acquire()
    with FolderLock(tmp_path):
        pass


def test_a_killed_runs_temporaries_are_removed_and_duplicates_compacted(tmp_path):
    options = {"quick": True, "trials": 1, "progress": False}
    run_experiment("corridor", out=tmp_path, **options)
    folder = tmp_path / "corridor"
    records = folder / "records.csv"
    text = records.read_bytes()
    header, *rows = text.split(b"\r\n")[:-1]
    records.write_bytes(text + b"\r\n".join([header, *rows]) + b"\r\n")  # a second writer's header and rows
    stale = folder / ".qrrt-abc123.tmp"
    stale.write_bytes(b"")
    with pytest.warns(RecordsWarning, match=rf"{len(rows) + 1} row\(s\) excluded.*moved to records.csv.excluded"):
        run_experiment("corridor", out=tmp_path, **options)
    assert not stale.exists()
    assert records.read_bytes() == text
    with warnings.catch_warnings():
        warnings.simplefilter("error", RecordsWarning)
        run_experiment("corridor", out=tmp_path, **options)
