"""The benchmark entry point and comparison tool: discovery, flat figures, regressions flagged.

Only the tools are tested here (on tiny synthetic files); no benchmark is run."""

import json
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
sys.path.insert(0, str(BENCHMARKS))

import _figures  # noqa: E402
import ab_planner  # noqa: E402
import compare  # noqa: E402
import run  # noqa: E402


def test_discovery_finds_every_bench_script_and_nothing_else():
    found = run.discover()
    assert {"search", "planners", "scaleout", "authors_check"} <= set(found)
    assert all(path.name.startswith("bench_") and path.suffix == ".py" for path in found.values())
    assert set(found) == {p.stem.removeprefix("bench_") for p in BENCHMARKS.glob("bench_*.py")}
    assert list(found) == sorted(found)


def test_run_refuses_an_unknown_benchmark_before_running_any(capsys):
    with pytest.raises(SystemExit):
        run.main(["--only", "no_such_bench"])
    assert "unknown benchmark" in capsys.readouterr().err


def test_machine_description_names_what_the_figures_depend_on():
    machine = run.machine_description()
    assert machine["cores"] >= 1 and machine["python"] and machine["date"]
    assert {"qiskit", "qiskit-aer", "numpy", "numba"} <= set(machine["packages"])


@pytest.mark.parametrize("key, way", [
    ("search.summary.aer_n12_ms", _figures.LOWER),
    ("scaleout.heatmaps.dask.s", _figures.LOWER),
    ("planners.RRT.ms_per_node.median", _figures.LOWER),
    ("search.reachability.paper_clutter.random.pairs_per_s", _figures.HIGHER),
    ("scaleout.heatmaps.dask.speedup", _figures.HIGHER),
    ("planners.RRT.calls_per_node.median", _figures.INFO),
    ("search.search.aer.qubits4.marked", _figures.INFO),
])
def test_direction_of_a_figure(key, way):
    assert _figures.direction(key) == way


def test_flatten_names_list_items_by_their_identity_and_skips_samples_and_machine():
    payload = {"machine": {"cores": 2}, "search": [{"backend": "aer", "qubits": 4, "median_s": 0.5},
                                                     {"backend": "aer", "qubits": 8, "median_s": 0.9}],
               "times_s": [1.0, 2.0], "reached": True, "note": "text"}
    assert _figures.flatten(payload) == {"search.aer.qubits4.median_s": 0.5, "search.aer.qubits8.median_s": 0.9}
    assert _figures.flatten({"figures": {"n12.ms": 45}, "other": 1}) == {"n12.ms": 45.0}


def _write(path, figures):
    path.write_text(json.dumps({"machine": {"cpu": "test"}, "quick": True, "benchmarks": {}, "figures": figures}))
    return str(path)


def test_compare_flags_a_slower_time_and_a_lower_throughput_only(tmp_path, capsys):
    old = _write(tmp_path / "old.json", {"search.n12.ms": 10.0, "search.pairs_per_s": 1000.0, "scaleout.x.s": 5.0,
                                         "planners.calls_per_node": 3.0, "gone.ms": 1.0})
    new = _write(tmp_path / "new.json", {"search.n12.ms": 13.0, "search.pairs_per_s": 700.0, "scaleout.x.s": 5.2,
                                         "planners.calls_per_node": 30.0, "added.ms": 1.0})
    assert compare.main([new, old, "--threshold", "0.2"]) == 1
    printed = capsys.readouterr().out
    regressions = printed.split("REGRESSIONS:")[1]
    assert "search.n12.ms" in regressions and "search.pairs_per_s" in regressions
    assert "scaleout.x.s" not in regressions and "calls_per_node" not in printed  # within 20 %; informational
    rows = {row["key"]: row for row in compare.compare(compare.figures_of(json.loads(Path(new).read_text())),
                                                       compare.figures_of(json.loads(Path(old).read_text())), 0.2)}
    assert rows["search.n12.ms"]["worse"] == pytest.approx(1.3)
    assert rows["search.pairs_per_s"]["worse"] == pytest.approx(1000 / 700)
    assert set(rows) == {"search.n12.ms", "search.pairs_per_s", "scaleout.x.s"}


def test_compare_of_a_faster_run_reports_no_regression(tmp_path):
    old = _write(tmp_path / "old.json", {"search.n12.ms": 10.0, "search.pairs_per_s": 1000.0})
    new = _write(tmp_path / "new.json", {"search.n12.ms": 5.0, "search.pairs_per_s": 1000.0})
    assert compare.main([new, old]) == 0


def test_compare_reads_runs_from_git_revisions_and_prints_ratios_per_benchmark(tmp_path, monkeypatch, capsys):
    """``REV:PATH`` is read through ``git show``: two commits of the same file compare without a
    checkout of either; one line per benchmark gives the geometric mean of ``worse``."""
    import shutil
    import subprocess

    if shutil.which("git") is None:
        pytest.skip("no git")
    monkeypatch.chdir(tmp_path)
    git = ["git", "-c", "user.name=t", "-c", "user.email=t@t", "-c", "commit.gpgsign=false"]
    subprocess.run(["git", "init", "-q"], check=True)
    _write(tmp_path / "run.json", {"search.n12.ms": 10.0, "search.n8.ms": 4.0, "planners.rrt.ms_per_node": 2.0})
    subprocess.run(["git", "add", "run.json"], check=True)
    subprocess.run([*git, "commit", "-q", "-m", "old"], check=True)
    _write(tmp_path / "run.json", {"search.n12.ms": 5.0, "search.n8.ms": 1.0, "planners.rrt.ms_per_node": 3.0})
    subprocess.run([*git, "commit", "-q", "-a", "-m", "new"], check=True)
    assert compare.main(["HEAD:run.json", "HEAD~1:run.json", "--threshold", "0.2"]) == 1  # planners slower
    printed = capsys.readouterr().out
    assert "old: HEAD~1:run.json" in printed and "per benchmark" in printed
    search = next(line for line in printed.splitlines() if line.strip().startswith("search "))
    assert search.split()[1:3] == ["2", "0.354"]  # sqrt(0.5 * 0.25)
    rows = compare.compare(compare.figures_of(compare.read_run("HEAD:run.json")[0]),
                           compare.figures_of(compare.read_run("HEAD~1:run.json")[0]))
    summary = compare.by_benchmark(rows)
    assert summary["planners"]["regressions"] == 1 and summary["search"]["improvements"] == 2
    assert summary["search"]["geomean_worse"] == pytest.approx((0.5 * 0.25) ** 0.5)
    with pytest.raises(SystemExit, match="git show failed"):
        compare.read_run("HEAD~9:run.json")
    with pytest.raises(SystemExit, match="no such file"):
        compare.read_run("missing.json")


@pytest.mark.parametrize(("argv", "message"), [
    (["--baseline-src", "/no/such/checkout/src"], "must be a checkout's src directory"),
    (["--baseline-src", str(BENCHMARKS.parent / "src"), "--pairs", "0"], "--pairs must be >= 1"),
    (["--baseline-src", str(BENCHMARKS.parent / "src"), "--nodes", "-3"], "--nodes must be >= 1"),
    (["--baseline-src", str(BENCHMARKS.parent / "src"), "--replay", "--cpu-time"], "does not combine with --replay"),
])
def test_ab_planner_refuses_bad_arguments_before_running_anything(argv, message, capsys, monkeypatch):
    monkeypatch.setattr(ab_planner, "run_child", lambda *args: pytest.fail("a child was started"))
    with pytest.raises(SystemExit):
        ab_planner.main(argv)
    assert message in capsys.readouterr().err


def test_ab_planner_names_the_baseline_checkouts_commit(tmp_path):
    """``checkout_commit`` gives the commit of the checkout holding a src folder (this
    repository's own, when the tests run from a git checkout) and None outside any checkout."""
    import subprocess

    source = Path(ab_planner.__file__).resolve().parent.parent / "src"
    head = subprocess.run(["git", "-C", str(source), "rev-parse", "HEAD"], capture_output=True, text=True)
    if head.returncode != 0:
        pytest.skip("the tests do not run from a git checkout")
    found = ab_planner.checkout_commit(source)
    assert found["commit"] == head.stdout.strip()
    assert isinstance(found["dirty"], bool)
    assert ab_planner.checkout_commit(tmp_path) == {"commit": None, "dirty": None}


def test_the_gpu_benchmark_without_a_gpu_says_why_and_is_recorded_as_skipped(tmp_path):
    """``bench_gpu.py`` where Aer offers no GPU: exit 0 (``run.py`` must not call it a failure),
    a JSON holding the reason, no figures."""
    import subprocess

    from qiskit_aer import AerSimulator

    if "GPU" in AerSimulator().available_devices():
        pytest.skip("this machine has Aer's GPU build: the benchmark would run")
    out = tmp_path / "gpu.json"
    done = subprocess.run([sys.executable, str(BENCHMARKS / "bench_gpu.py"), "--quick", "--out", str(out)],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "device='GPU' needs qiskit-aer-gpu" in done.stdout
    payload = json.loads(out.read_text())
    assert "needs qiskit-aer-gpu" in payload["skipped"] and _figures.flatten(payload) == {}


def test_ab_planner_replay_times_a_replayed_plan_equal_to_the_recorded_one():
    """``--replay``: the child plans with the exact predicate recording its answers, replays them
    (its tree checked equal to the recorded one, else it raises) and reports microseconds per round;
    with an unreachable goal this short plan ends at its node limit."""
    source = Path(ab_planner.__file__).resolve().parent.parent / "src"
    result = ab_planner.run_child(source, "qrrt", "statevector", 1, 25, replay=True, unreachable_goal=True)
    assert result["nodes"] == 25 and result["rounds"] >= 25
    assert result["us_per_round_replayed"] > 0
    plain = ab_planner.run_child(source, "qrrt", "statevector", 1, 25)
    assert plain["nodes"] >= 1 and plain["ms_per_node"] > 0
