import json

import numpy as np
import pytest

from qrrt_circuits.cli import main
from qrrt_circuits.experiments import EXPERIMENTS, read_records, run_experiment
from qrrt_circuits.experiments.base import TIMING_SUFFIX
from qrrt_circuits.experiments.fitting import linear_fit, power_law_exponent, slope_through_origin

TINY = {"oracle-efficiency": 1, "wallclock": 1, "heatmaps": 2, "corridor": 2, "annealing": 1,
        "lemmas": 60, "scaling": 1, "oracle-check": 1}


def _is_png(path):
    return path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and path.stat().st_size > 5000


@pytest.mark.parametrize("name", sorted(EXPERIMENTS))
def test_quick_path_writes_summary_records_and_figure(name, tmp_path):
    summary = run_experiment(name, out=tmp_path, quick=True, trials=TINY[name], progress=False)
    directory = tmp_path / name
    stored = json.loads((directory / "summary.json").read_text())
    assert stored["experiment"] == name and stored["complete"]
    assert {"settings", "ours", "paper"} <= set(stored)
    assert stored["ours"] and stored["paper"]
    trials = EXPERIMENTS[name].trials(stored["settings"])
    records = read_records(directory / "records.csv")
    assert sorted(r["trial_id"] for r in records) == sorted(t.id for t in trials)
    assert summary["figures"] and all(_is_png(directory / f) for f in summary["figures"])
    if name == "oracle-efficiency":
        assert set(stored["ours"]) == {"RRT", "ParallelRRT", "QRRT", "PQRRT"}
        assert all(value > 0 for value in stored["ours"].values())


def _comparable(records):
    return sorted(({k: v for k, v in r.items() if not k.endswith(TIMING_SUFFIX)} for r in records),
                  key=lambda r: r["trial_id"])


def test_resume_ends_with_exactly_the_uninterrupted_trials(tmp_path):
    whole = run_experiment("oracle-efficiency", out=tmp_path / "a", quick=True, trials=2, progress=False)
    partial = run_experiment("oracle-efficiency", out=tmp_path / "b", quick=True, trials=2, progress=False,
                             stop_after=3)
    assert partial["complete"] is False and partial["finished_trials"] == 3
    path = tmp_path / "b" / "oracle-efficiency" / "records.csv"
    # a run killed mid-write leaves a torn last line: it must be dropped, not kept or duplicated
    with path.open("a") as handle:
        handle.write("PQRRT-1,123,PQRRT,1")
    assert len(read_records(path)) == 3
    seen = []
    resumed = run_experiment("oracle-efficiency", out=tmp_path / "b", quick=True, trials=2, progress=False,
                             on_record=seen.append)
    assert resumed["complete"] and len(seen) == 8 - 3
    a = read_records(tmp_path / "a" / "oracle-efficiency" / "records.csv")
    b = read_records(path)
    assert len(b) == len({r["trial_id"] for r in b}) == 8
    assert _comparable(a) == _comparable(b)
    assert resumed["ours"] == whole["ours"]


def test_other_settings_in_the_same_directory_are_refused(tmp_path):
    run_experiment("lemmas", out=tmp_path, quick=True, trials=20, progress=False)
    with pytest.raises(ValueError, match="holds results for other settings"):
        run_experiment("lemmas", out=tmp_path, quick=True, trials=30, progress=False)


def test_bad_arguments(tmp_path):
    with pytest.raises(ValueError, match="unknown experiment"):
        run_experiment("nope", out=tmp_path)
    with pytest.raises(ValueError, match="trials must be"):
        run_experiment("lemmas", out=tmp_path, trials=0)


def test_linear_fit_recovers_a_known_slope():
    rng = np.random.default_rng(0)
    x = rng.uniform(0, 30, 400)
    y = 7.6 * x + 3.0 + rng.normal(scale=2.0, size=x.size)
    fit = linear_fit(x, y)
    assert abs(fit.slope - 7.6) <= 5 * fit.slope_stderr
    assert fit.slope_stderr < 0.05
    assert slope_through_origin(x, 2.5 * x) == pytest.approx(2.5)
    f = np.geomspace(0.01, 0.5, 50)
    assert power_law_exponent(f, 3 * f**-0.5).slope == pytest.approx(-0.5)
    with pytest.raises(ValueError, match="two distinct"):
        linear_fit([1, 1], [2, 3])


def test_reproduce_command(tmp_path, capsys):
    assert main(["reproduce", "lemmas", "--quick", "--trials", "20", "--out", str(tmp_path),
                 "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "== lemmas" in out and "summary.json" in out
    with pytest.raises(SystemExit):
        main(["reproduce", "nope", "--out", str(tmp_path)])
