"""settings.json and summary.json are strict JSON, written whole."""

import errno
import json
import math
import os
from pathlib import Path

import numpy as np
import pytest

from qrrt_circuits._support import json_files

RESULTS = Path(__file__).resolve().parents[2] / "docs" / "results"


def _strict_load(text):
    def refuse(constant):
        raise ValueError(f"non-standard JSON constant {constant}")

    return json.loads(text, parse_constant=refuse)


def test_non_finite_numbers_are_written_as_null(tmp_path):
    value = {"a": math.nan, "b": [np.float64(np.inf), -math.inf, 1.5], "c": np.int64(3), "d": (True, np.bool_(False))}
    json_files.write_json(tmp_path / "s.json", value)
    assert _strict_load((tmp_path / "s.json").read_text()) == {"a": None, "b": [None, None, 1.5], "c": 3,
                                                               "d": [True, False]}


def test_a_failed_write_leaves_the_old_file_and_no_temporary(tmp_path, monkeypatch):
    target = tmp_path / "summary.json"
    target.write_text('{"old": 1}')

    def full(_):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(os, "fsync", full)
    with pytest.raises(OSError, match=r"could not write .*summary.json: No space left on device"):
        json_files.write_json(target, {"new": 2})
    assert target.read_text() == '{"old": 1}'
    assert sorted(path.name for path in tmp_path.iterdir()) == ["summary.json"]


@pytest.mark.parametrize("path", sorted(RESULTS.glob("*/summary.json")), ids=lambda p: p.parent.name)
def test_every_committed_summary_is_strict_json(path):
    _strict_load(path.read_text())


@pytest.mark.parametrize("predicate", ["time-samples:1", "time-samples:2000000", "time-samples:abc"])
def test_a_refused_predicate_writes_nothing(tmp_path, predicate):
    """The corrected command into the same folder must not find a settings.json of the refused one."""
    from qrrt_circuits.experiments import run_experiment

    with pytest.raises(ValueError, match="time.samples"):
        run_experiment("heatmaps", out=tmp_path, quick=True, progress=False, predicate=predicate)
    assert list(tmp_path.iterdir()) == []
