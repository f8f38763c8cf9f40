"""The docs' Performance page is written from the run's JSON: its figures are the file's, and a
missing file or figure gives a page that says so instead of a failed build."""

import json
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "docs"))

import performance_page  # noqa: E402


def _run(commit: str, ms_per_node: float, cpu: str = "Test CPU") -> dict:
    machine = {"git_commit": commit, "git_dirty": False, "date": "DATE-OF-" + commit, "cpu": cpu, "cores": 2,
               "packages": {"qiskit": "9.9", "ompl": None}, "python": "3.x", "load_average": [0.5, 0.25, 0.125]}
    planners = {"seeds": 3, "max_nodes": 10, "big_nodes": 30, "big_seeds": 1, "note": "NOTE",
                "planners": {"RRT": {"max_nodes": 10, "runs": [{}, {}, {}], "settings": {"search_policy": None},
                                     "ms_per_node": {"median": ms_per_node, "p10": 0.1, "p90": 0.9},
                                     "ms_per_call": {"median": 0.0123}, "calls_per_node": {"median": 4.5},
                                     "oracle_share": {"median": 0.25}}},
                "ompl_rrt": {"ms_per_node": {"median": 0.5}, "ours_over_ompl": ms_per_node / 0.5},
                "round_breakdown": {"QRRT statevector": {"runs": [
                    {"us_per_round": {"predicate": 100.0, "nearest": 8.0, "rest": 40.0}},
                    {"us_per_round": {"predicate": 120.0, "nearest": 10.0, "rest": 60.0}}]}}}
    search = {"against_floor": [{"qubits": 8, "marked": 12, "iterations": 12, "shots": 8, "repeats": 5,
                                 "median_ms": {"floor": 0.5, "ours": 1.0, "qiskit_algorithms": 20.0},
                                 "ratio_to_floor": {"floor": 1.0, "ours": 2.0, "qiskit_algorithms": 40.0}}]}
    ratio = {"median": 1.25, "low": 1.0, "high": 1.5}
    call = {"median": 2.5, "low": 2.0, "high": 3.0}
    floor = {"median": 1.75, "low": 1.5, "high": 2.0}
    problems = {"runs": 4, "budget": 5000, "families": {"maze": {
        "rrt": {"us_per_check": 8.0, "own_us_per_check": 6.0}, "ompl_rrt": {"us_per_check": 6.4},
        "ratios": {"rrt_over_ompl_per_run": ratio, "rrt_over_ompl_call_per_run": call,
                   "rrt_one_by_one_over_ompl_per_run": ratio, "one_screen_rrt_over_ompl_per_run": floor}}}}
    return {"machine": machine, "quick": True, "benchmarks": {"planners": {"returncode": 0, "wall_s": 1.5},
                                                            "problems": {"returncode": 3, "wall_s": 2.0}},
            "figures": {"planners.RRT.ms_per_node.median": ms_per_node},
            "raw": {"planners": planners, "search": search, "problems": problems}}


@pytest.fixture
def root(tmp_path):
    (tmp_path / "benchmarks" / "results").mkdir(parents=True)
    (tmp_path / "benchmarks" / "compare.py").write_text((ROOT / "benchmarks" / "compare.py").read_text())
    (tmp_path / "benchmarks" / "_figures.py").write_text((ROOT / "benchmarks" / "_figures.py").read_text())
    (tmp_path / "benchmarks" / "bench_planners.py").write_text('"""Planner figures, in words."""\n')
    return tmp_path


def test_the_page_shows_the_runs_figures_provenance_and_peers(root):
    results = root / "benchmarks" / "results"
    (results / "run.json").write_text(json.dumps(_run("aaaa", 0.25)))
    (results / "baseline.json").write_text(json.dumps(_run("bbbb", 0.5, cpu="Other CPU")))
    (results / "extra.json").write_text(json.dumps({"machine": {"python": "3.y", "qiskit": "1.0"}}))
    page = performance_page.performance_page(root)
    assert page.startswith("# Performance")
    assert "`aaaa`" in page and "DATE-OF-aaaa" in page and "Test CPU, 2 cores" in page
    assert "quick run" in page and "qiskit 9.9" in page and "not installed: ompl" in page
    assert "The run holds 2 benchmarks (`planners`, `problems`" in page and "`problems` failed (exit status 3)" in page
    assert "| RRT | — | 10 | 3 | 0.25 (0.1–0.9) | 0.0123 | 4.5 | 25 % |" in page
    # RRT against OMPL on a family: the search, the whole call, one by one, the one-screen floor, —
    assert "| maze | 8 | 6 | 6.4 | 1.25 [1, 1.5] | 2.5 [2, 3] | 1.25 [1, 1.5] | 1.75 [1.5, 2] | — |" in page
    assert "ours over OMPL's: **0.5×**" in page
    assert "| QRRT statevector | 110 | 9 | — | — | — | 50 |" in page  # medians of the parts; untimed: —
    assert "| 8 | 12 | 12 | 8 | 5 | 0.5 | 1 | 2× | 20 | 40× |" in page
    assert "20× at n = 8" in page  # qiskit-algorithms over ours
    assert "`bbbb`" in page and "different machines" in page
    assert "| RRT | 0.5 | 0.25 | 0.5× |" in page  # baseline, this run, ratio
    assert "| `planners` | 1 | 0.5 |" in page  # compare.py's per-benchmark line
    assert "a reliability campaign; files: 1)" in page
    assert "not in this checkout's history" in page or "cannot be checked" in page  # tmp_path: no such commit


def test_missing_files_give_a_page_that_says_so(root):
    assert "is not found: no figures to show" in performance_page.performance_page(root)
    (root / "benchmarks" / "results" / "run.json").write_text(json.dumps({"machine": {}, "benchmarks": {}}))
    page = performance_page.performance_page(root)
    assert "holds no planner figures" in page and "no OMPL figures" in page and "no round breakdown" in page
    assert "baseline.json` is not found: no comparison" in page


def test_the_committed_run_gives_a_page():
    """The repository's own ``run.json`` (when present) is read without an error."""
    if not (ROOT / "benchmarks" / "results" / "run.json").exists():
        pytest.skip("no run.json")
    page = performance_page.performance_page(ROOT)
    assert "## The run" in page and "## Time per node and per oracle call" in page
