"""The site's Performance page, written from ``benchmarks/results/run.json`` when the docs are built.

``write_performance_page(root, target)`` reads the run that ``benchmarks/run.py`` wrote and the
pinned ``benchmarks/results/baseline.json``, and writes a Markdown page: the run's provenance (the
machine, the package versions, the commit), whether the measured commit is behind the code (asked
of git), each planner's time per node and per oracle call, the ratios against the peers measured
in the same run (OMPL's RRT, Aer's own floor, qiskit-algorithms' ``Grover``) and against the
baseline, and the other results kept under ``benchmarks/results/`` with their provenance.

Every number on the page is read from those files (or counted by git); the page's prose names no
figure of its own. A missing or unreadable file gives a page that says so rather than a failed
build.
"""

from __future__ import annotations

import ast
import json
import math
import statistics
import subprocess
import sys
from pathlib import Path
from typing import Any

RESULTS = Path("benchmarks") / "results"
RUN = RESULTS / "run.json"
BASELINE = RESULTS / "baseline.json"

#: what a change to these paths can alter in the figures (the code measured, the measuring scripts)
MEASURED_PATHS = ("src", "benchmarks/bench_*.py", "benchmarks/_common.py", "benchmarks/_figures.py",
                  "benchmarks/ompl_rrt.py", "benchmarks/run.py")

#: packages shown in the provenance table, in this order
SHOWN_PACKAGES = ("qrrt-circuits", "qiskit", "qiskit-aer", "qiskit-algorithms", "numpy", "numba", "scipy",
                  "ompl", "dask")

#: contenders of ``bench_search.py``'s table against Aer's floor, in the page's column order
CONTENDERS = {
    "ours": "`AerBackend.search`",
    "run_prebuilt": "`AerSimulator.run` of the circuit built beforehand",
    "sampler_v2": "the same circuit through qiskit-aer's `SamplerV2`",
    "gate_by_gate": "the circuit gate by gate",
    "qiskit_algorithms": "qiskit-algorithms' `Grover` with `SamplerV2`",
}

PLANNER_SUMMARY = ("ms_per_node", "ms_per_call", "calls_per_node", "oracle_share")


# ------------------------------------------------------------------------------------------ helpers
def _number(value: Any) -> str:
    """Three significant digits (whole numbers from 1 000 on), a dash for no value."""
    if not isinstance(value, int | float) or isinstance(value, bool) or not math.isfinite(value):
        return "—"
    if abs(value) >= 1000:
        return f"{value:,.0f}".replace(",", " ")
    if value != 0 and abs(value) < 0.001:
        return f"{value:.2e}"
    return f"{value:.3g}"


def _percent(value: Any) -> str:
    return _number(100 * value) + " %" if isinstance(value, int | float) and not isinstance(value, bool) else "—"


def _ratio(value: Any) -> str:
    text = _number(value)
    return text if text == "—" else f"{text}×"


def _table(header: list[str], rows: list[list[str]], align: str | None = None) -> list[str]:
    """A Markdown table; ``align``: one letter per column, ``l`` or ``r`` (default: first l, rest r)."""
    align = align or "l" + "r" * (len(header) - 1)
    rule = ["---:" if a == "r" else ":---" for a in align]
    lines = ["| " + " | ".join(header) + " |", "| " + " | ".join(rule) + " |"]
    lines += ["| " + " | ".join(cell.replace("|", "\\|") for cell in row) + " |" for row in rows]
    return lines + [""]


def _load(path: Path) -> tuple[dict | None, str | None]:
    """(payload, None), or (None, why not)."""
    try:
        return json.loads(path.read_text()), None
    except FileNotFoundError:
        return None, "not found"
    except (OSError, ValueError) as exc:
        return None, f"unreadable ({type(exc).__name__})"


def _git(root: Path, *args: str) -> str | None:
    try:
        return subprocess.run(["git", *args], cwd=root, capture_output=True, text=True, check=True,
                              timeout=30).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None


def _median(summary: Any) -> Any:
    return summary.get("median") if isinstance(summary, dict) else None


def _spread(summary: Any) -> str:
    """``median (p10–p90)`` of a ``{"median", "p10", "p90"}`` summary."""
    if not isinstance(summary, dict):
        return "—"
    text = _number(summary.get("median"))
    if "p10" in summary and "p90" in summary:
        text += f" ({_number(summary['p10'])}–{_number(summary['p90'])})"
    return text


def _script_summary(root: Path, name: str) -> str:
    """The first paragraph of ``benchmarks/bench_<name>.py``'s docstring, in Markdown."""
    try:
        doc = ast.get_docstring(ast.parse((root / "benchmarks" / f"bench_{name}.py").read_text()))
    except (OSError, SyntaxError):
        return ""
    paragraph = " ".join((doc or "").strip().split("\n\n")[0].split())
    return paragraph.replace("``", "`")


def _compare_module(root: Path) -> Any:
    """``benchmarks/compare.py``, imported (it holds the comparison the command line prints)."""
    benchmarks = str(root / "benchmarks")
    if benchmarks not in sys.path:
        sys.path.insert(0, benchmarks)
    import compare  # noqa: PLC0415

    return compare


# ------------------------------------------------------------------------------------------ sections
def _provenance_rows(run: dict) -> list[list[str]]:
    machine = run.get("machine") or {}
    commit = machine.get("git_commit")
    dirty = machine.get("git_dirty")
    commit_text = f"`{commit}`" if commit else "not recorded"
    if dirty is not None and commit:
        commit_text += " (uncommitted changes to tracked files)" if dirty else " (no uncommitted changes)"
    rows = [["commit", commit_text],
            ["date (UTC)", str(machine.get("date", "not recorded"))],
            ["kind", "quick run (`--quick`: fewer sizes and repeats)" if run.get("quick") else "full run"]]
    cpu = machine.get("cpu") or machine.get("processor") or machine.get("machine") or "not recorded"
    cores = machine.get("cores")
    usable = machine.get("cores_usable")
    if cores is not None:
        cpu += f", {cores} cores" + (f" ({usable} usable)" if usable not in (None, cores) else "")
    if machine.get("memory_gib") is not None:
        cpu += f", {_number(machine['memory_gib'])} GiB of memory"
    rows.append(["machine", cpu])
    if machine.get("os"):
        rows.append(["operating system", str(machine["os"])])
    if machine.get("python"):
        rows.append(["Python", str(machine["python"])])
    packages = machine.get("packages") or {}
    shown = [f"{name} {packages[name]}" for name in SHOWN_PACKAGES if packages.get(name)]
    missing = [name for name in SHOWN_PACKAGES if name in packages and not packages.get(name)]
    if shown:
        rows.append(["packages", ", ".join(shown) + (f" (not installed: {', '.join(missing)})" if missing else "")])
    load = machine.get("load_average")
    if isinstance(load, list) and len(load) == 3:
        rows.append(["machine load at the start (1, 5, 15 min averages)", ", ".join(_number(x) for x in load)])
    return rows


def _staleness(root: Path, run: dict) -> list[str]:
    """Whether commits after the measured one change the measured code, asked of git."""
    machine = run.get("machine") or {}
    commit = machine.get("git_commit")
    lines: list[str] = []
    if machine.get("git_dirty"):
        lines += [":::{warning}", "The run was made from a working tree with uncommitted changes to tracked "
                  "files: the code measured is not exactly that of its commit.", ":::", ""]
    if not commit:
        return lines + ["The run records no commit: whether the code has changed since cannot be checked.", ""]
    if _git(root, "cat-file", "-e", f"{commit}^{{commit}}") is None:
        return lines + [f"The measured commit `{commit}` is not in this checkout's history: whether the code "
                        "has changed since cannot be checked.", ""]
    count = _git(root, "rev-list", "--count", f"{commit}..HEAD", "--", *MEASURED_PATHS)
    if count is None:
        return lines + ["Whether the code has changed since the measured commit cannot be checked here.", ""]
    paths = "`src/` or the benchmark scripts"
    if int(count) == 0:
        return lines + [f"No commit after the measured one (`{commit}`) changes {paths}: the figures describe "
                        "the current code.", ""]
    plural = "commits" if int(count) > 1 else "commit"
    return lines + [":::{warning}",
                    f"The figures are stale: {count} {plural} after the measured one (`{commit}`) change {paths}. "
                    "They describe the code at the measured commit; `python benchmarks/run.py` measures the "
                    "current code.", ":::", ""]


def _benchmarks_table(root: Path, run: dict) -> list[str]:
    """One sentence: the benchmarks the run holds, and any that failed or were skipped (their
    commands and wall times are in the run's JSON)."""
    raw = run.get("raw") or {}
    names, notes = [], []
    for name, entry in (run.get("benchmarks") or {}).items():
        names.append(f"`{name}`")
        payload = raw.get(name)
        if isinstance(payload, dict) and payload.get("skipped"):
            notes.append(f"`{name}` skipped ({str(payload['skipped']).split(';')[0]})")
        elif entry.get("returncode") != 0:
            notes.append(f"`{name}` failed (exit status {entry.get('returncode')})")
    if not names:
        return ["The run holds no benchmark.", ""]
    outcome = "; ".join(notes) if notes else "every one ran"
    return [f"The run holds {len(names)} benchmarks ({', '.join(names)}; each script's docstring says what it "
            f"measures): {outcome}. Their commands and wall times are in the run's JSON.", ""]


def _families_section(run: dict) -> list[str]:
    problems = (run.get("raw") or {}).get("problems") or {}
    figures = problems.get("families")
    lines = ["### OMPL's RRT on the problem families", ""]
    if not isinstance(figures, dict) or not figures:
        return lines + ["This run holds no problem-family figures (`bench_problems.py`).", ""]
    lines += [f"Each family of `qrrt reproduce problems` (its world 0), {problems.get('runs', '—')} seeds per planner, "
              f"interleaved seed by seed, each plan until the goal or {_number(problems.get('budget'))} motion checks. "
              "`RRT` has OMPL's range and goal bias and tests rounds ahead (its wall time includes the tests "
              "thrown away); `RRT, one by one` asks the predicate once per oracle call; OMPL's `RRT` uses the same "
              "predicate as its motion validator. A run's wall time is its search, like for like: the library's "
              "round loop (what `qrrt reproduce problems` compares) beside OMPL's `solve()`; its whole call adds "
              "what each side does around it (the library's `plan()`: its checks of the request, memory "
              "estimate, run state and tree, and result; OMPL's setup and planner built from the problem, "
              "`setup()` and the path read back). OMPL's side is OMPL driven from Python: its motion checks and "
              "termination condition are Python callbacks. "
              "Wall time per motion check in microseconds (pooled over the seeds), and the ratio of the medians "
              "of each seed's time per check, ours over OMPL's, with its 95 % bootstrap interval over the seeds.",
              ""]
    rows = []
    for family, row in figures.items():
        ratios = row.get("ratios") or {}
        per_run = ratios.get("rrt_over_ompl_per_run") or {}
        one_by_one = ratios.get("rrt_one_by_one_over_ompl_per_run") or {}

        def interval(ratio: dict) -> str:
            return (f"{_number(ratio.get('median'))} [{_number(ratio.get('low'))}, {_number(ratio.get('high'))}]"
                    if ratio else "—")

        rows.append([family, _number((row.get("rrt") or {}).get("us_per_check")),
                     _number((row.get("rrt") or {}).get("own_us_per_check")),
                     _number((row.get("ompl_rrt") or {}).get("us_per_check")), interval(per_run),
                     interval(ratios.get("rrt_over_ompl_call_per_run") or {}),
                     interval(one_by_one), interval(ratios.get("one_screen_rrt_over_ompl_per_run") or {}),
                     interval(ratios.get("python_check_rrt_over_ompl_per_run") or {})])
    lines += _table(["family", "RRT µs / check", "its own µs", "OMPL µs / check", "RRT / OMPL",
                     "RRT / OMPL, whole call", "one by one / OMPL", "one screen / OMPL",
                     "RRT / OMPL, Python check"], rows, "lrrrrrrrr")
    lines += ["`one screen` is the floor of a round written in Python: RRT on one screen (`one_screen_rrt` in "
              "the benchmark) on the same parts (the space's nearest-neighbour structure, `distance` and "
              "`interpolate`, the problem's check and goal), one round per motion check, with no counters, "
              "history, termination conditions or look-ahead. The last column asks the same predicate one pair "
              "at a time from a Python loop that also does fixed Python work per pair, on both sides: a check "
              "whose cost dominates the planner's.", ""]
    return lines


def _streams_section(run: dict) -> list[str]:
    streams = (run.get("raw") or {}).get("streams") or {}
    dims = streams.get("dims")
    lines = ["### Random draws: a keyed generator per use, or the plan's sequential stream", ""]
    if not isinstance(dims, dict) or not dims:
        return lines + ["This run holds no stream figures (`bench_streams.py`).", ""]
    lines += [f"The d + 1 doubles of one classical extension sample, for {streams.get('keys', '—')} candidates: "
              "from a generator built per key (round, worker, stream) through numpy's `SeedSequence`, as each "
              "quantum round builds its generators; and from the plan's one sequential stream, as the classical "
              "planners draw their candidates, all in one call (a batch of rounds tested ahead) or one call "
              "each (a round drawn on its own). Microseconds per candidate; RRT's time per motion check on the "
              "maze family in the same run is the yardstick.", ""]
    rows = [[dim, _number((row.get("keyed") or {}).get("us_per_key")),
             _number((row.get("sequential") or {}).get("us_per_key")),
             _number((row.get("sequential_one_call_each") or {}).get("us_per_key")),
             _ratio(row.get("keyed_over_sequential"))] for dim, row in dims.items()]
    lines += _table(["d", "keyed generator", "sequential, one call", "sequential, a call each",
                     "keyed / sequential"], rows, "lrrrr")
    lines += [f"RRT on the maze: {_number((streams.get('rrt_maze') or {}).get('us_per_check'))} µs per motion "
              "check.", ""]
    return lines


def _profile_section(run: dict) -> list[str]:
    problems = (run.get("raw") or {}).get("problems") or {}
    profile = problems.get("profile")
    lines = ["### Where one round's time goes", ""]
    if not isinstance(profile, dict) or not profile:
        return lines + ["This run holds no round profile (`bench_problems.py`).", ""]
    lines += ["One plan of each of the library's planners on the maze family under `cProfile`: the functions "
              "with the most own time, in microseconds per round (profiling slows every call, so the shares "
              "matter, not the totals).", ""]
    rows = []
    for planner, entry in profile.items():
        functions = entry.get("functions") or []
        top = ", ".join(f"`{item.get('function')}` {_number(item.get('own_us_per_round'))}" for item in functions[:6])
        rows.append([f"`{planner}`", _number(entry.get("rounds")), _number(entry.get("total_us_per_round")), top])
    lines += _table(["planner", "rounds", "µs per round", "largest own times (µs per round)"], rows, "lrrl")
    return lines


#: the parts of a quantum round in ``bench_planners.py``'s breakdown, in the page's column order
ROUND_PARTS = {"predicate": "predicate (2^n entries)", "nearest": "nearest nodes", "candidate_draws": "samples",
               "search": "backend search", "keyed_generators": "keyed generators", "rest": "rest"}


def _round_parts_section(run: dict) -> list[str]:
    planners = (run.get("raw") or {}).get("planners") or {}
    breakdown = planners.get("round_breakdown")
    lines = ["### A quantum round, part by part", ""]
    if not isinstance(breakdown, dict) or not breakdown:
        return lines + ["This run holds no round breakdown (`bench_planners.py`).", ""]
    lines += ["Microseconds per round in each part of the round, medians over the worlds (`bench_planners.py`, "
              "`round_breakdown`): the predicate on every database entry (the simulation's checks behind the "
              "phase oracle), the nearest-node query and the samples of the database, the backend's search "
              "(the generator it builds from its seed included), the round's keyed generators (the database's "
              "and the one its search seed comes from) and the rest of the round (the policy, the verification, "
              "the bookkeeping and the planner's loop). A missing part is one this run did not time.", ""]
    rows = []
    for name, entry in breakdown.items():
        runs = [item.get("us_per_round") or {} for item in (entry.get("runs") or [])]
        medians = [statistics.median(r[part] for r in runs) if runs and all(part in r for r in runs) else None
                   for part in ROUND_PARTS]
        rows.append([name, *(_number(value) for value in medians)])
    lines += _table(["planner", *ROUND_PARTS.values()], rows, "l" + "r" * len(ROUND_PARTS))
    return lines


def _planners_section(run: dict) -> list[str]:
    planners = (run.get("raw") or {}).get("planners")
    if not isinstance(planners, dict) or not isinstance(planners.get("planners"), dict):
        return ["This run holds no planner figures (`bench_planners.py`).", ""]
    lines = [f"Each planner grows a tree on the benchmark's worlds ({planners.get('seeds', '—')} seeds, up to "
             f"{planners.get('max_nodes', '—')} nodes; the rows at {planners.get('big_nodes', '—')} nodes: "
             f"{planners.get('big_seeds', '—')} seeds, the goal made unreachable so that the tree reaches its size). "
             "Medians over the worlds, with the 10th and 90th percentiles in brackets. An oracle call is one "
             "application of the reachability predicate as the algorithm sees it (DESIGN §2): one classical test, "
             "one Grover iteration of one preparation, or one classical verification of a measured candidate; "
             "the oracle share is the fraction of the plan's wall time spent inside the predicate. The search "
             "policy is the registry's name (`paper`: the paper's iteration schedule, not the planners' defaults: "
             "`thompson` for q-RRT, `adaptive` for Pq-RRT).", ""]
    rows = []
    for name, row in planners["planners"].items():
        settings = row.get("settings") or {}
        rows.append([name, f"`{settings.get('search_policy')}`" if settings.get("search_policy") else "—",
                     _number(row.get("max_nodes")), str(len(row.get("runs") or [])),
                     _spread(row.get("ms_per_node")), _spread(row.get("ms_per_call")),
                     _number(_median(row.get("calls_per_node"))), _percent(_median(row.get("oracle_share")))])
    lines += _table(["planner", "policy", "nodes", "worlds", "ms / node", "ms / call", "calls / node",
                     "in oracle"], rows, "llrrrrrr")
    if planners.get("note"):
        lines += [f"Settings, as the benchmark records them: {planners['note']}.", ""]
    return lines


def _ompl_section(run: dict) -> list[str]:
    planners = (run.get("raw") or {}).get("planners") or {}
    ompl = planners.get("ompl_rrt")
    lines = ["### OMPL's RRT", ""]
    packages = ((run.get("machine") or {}).get("packages") or {})
    if not isinstance(ompl, dict) or "ms_per_node" not in ompl:
        return lines + ["OMPL's Python bindings were not importable in this run (`pip install \".[ompl]\"`): it "
                        "holds no OMPL figures.", ""]
    ours = ((planners.get("planners") or {}).get("RRT") or {}).get("ms_per_node")
    version = f" {packages['ompl']}" if packages.get("ompl") else ""
    lines += [f"OMPL{version}'s geometric RRT (`benchmarks/ompl_rrt.py`) on the same worlds and with the same "
              "motion validator (this library's exact reachability check), beside this library's `RRT`. OMPL "
              "samples, finds nearest nodes and keeps its tree in C++ with its own random numbers, so its trees "
              "differ from ours: compare the rates, not the runs.", ""]
    rows = [["`qrrt_circuits.RRT`", _spread(ours)], ["OMPL's `RRT`", _spread(ompl["ms_per_node"])]]
    lines += _table(["planner", "ms per node"], rows)
    lines += [f"Ratio of the medians, ours over OMPL's: **{_ratio(ompl.get('ours_over_ompl'))}** (below 1: ours "
              "takes less time per node).", ""]
    return lines


def _floor_section(run: dict) -> list[str]:
    search = (run.get("raw") or {}).get("search") or {}
    rows_in = search.get("against_floor")
    lines = ["### Aer's floor and qiskit-algorithms' Grover", ""]
    if not isinstance(rows_in, list) or not rows_in:
        return lines + ["This run holds no search figures against Aer's floor (`bench_search.py`).", ""]
    present = [name for name in CONTENDERS if any(name in (row.get("median_ms") or {}) for row in rows_in)]
    lines += ["One Grover search on n qubits (m marked entries, k iterations, the shots below), timed in each "
              "repeat in a shuffled order, on one thread. "
              "Aer's floor is a one-qubit circuit (a Hadamard and a measurement) through `AerSimulator.run` with "
              "the same shots and options: what any search through Aer's documented API costs at least. Each "
              "contender's median time, then its ratio to the floor measured in the same run:", ""]
    lines += [f"* {CONTENDERS[name]} (`{name}`)" for name in present] + [""]
    header = ["n", "m", "k", "shots", "repeats", "floor (ms)"]
    for name in present:
        header += [f"`{name}` (ms)", "× floor"]
    rows = []
    for row in rows_in:
        times, ratios = row.get("median_ms") or {}, row.get("ratio_to_floor") or {}
        cells = [str(row.get(key, "—")) for key in ("qubits", "marked", "iterations", "shots", "repeats")]
        cells.append(_number(times.get("floor")))
        for name in present:
            cells += [_number(times.get(name)), _ratio(ratios.get(name))]
        rows.append(cells)
    lines += _table(header, rows, "r" * len(header))
    both = [row for row in rows_in if "qiskit_algorithms" in (row.get("median_ms") or {})
            and (row.get("median_ms") or {}).get("ours")]
    if both:
        pairs = ", ".join(f"{_ratio(row['median_ms']['qiskit_algorithms'] / row['median_ms']['ours'])} at n = "
                          f"{row.get('qubits')}" for row in both)
        lines += [f"qiskit-algorithms' `Grover` over `AerBackend.search`, ratio of the medians: {pairs} (above 1: "
                  "`AerBackend.search` takes less time).", ""]
    if search.get("note"):
        lines += [f"Settings, as the benchmark records them: {search['note']}.", ""]
    return lines


def _interleaved_section(run: dict) -> list[str]:
    interleaved = ((run.get("raw") or {}).get("planners") or {}).get("interleaved")
    if not isinstance(interleaved, dict) or not interleaved:
        return []
    lines = ["### Aer against the exact statevector", "",
             "The same planner on the two backends, world by world in alternation (so that the machine's drift "
             "during the run enters both alike): the ratio of the medians of ms per node.", ""]
    rows = [[name, _number(row.get("numerator_ms_per_node")), _number(row.get("denominator_ms_per_node")),
             _ratio(row.get("ratio_of_medians"))] for name, row in interleaved.items() if isinstance(row, dict)]
    return lines + _table(["ratio", "numerator (ms per node)", "denominator (ms per node)", "ratio of medians"],
                          rows)


def _baseline_section(root: Path, run: dict, baseline: dict | None, why: str | None) -> list[str]:
    lines = ["## Against the baseline", ""]
    if baseline is None:
        return lines + [f"`{BASELINE.as_posix()}` is {why}: no comparison.", ""]
    base_machine, run_machine = baseline.get("machine") or {}, run.get("machine") or {}
    lines += [f"`{BASELINE.as_posix()}` is a pinned run of `benchmarks/run.py` kept to compare with; its "
              "provenance, as recorded in it:", ""]
    lines += _table(["", ""], _provenance_rows(baseline), "ll")
    if (base_machine.get("cpu"), base_machine.get("cores")) != (run_machine.get("cpu"), run_machine.get("cores")):
        lines += [":::{note}", "The two runs were measured on different machines (see the CPUs above): their "
                  "timings differ for reasons of the machines as well as of the code.", ":::", ""]
    if bool(baseline.get("quick")) != bool(run.get("quick")):
        lines += [":::{note}", "One run is a quick run and the other a full one: their sizes and repeats differ.",
                  ":::", ""]
    lines += ["Ratios are this run over the baseline (below 1 for a time: this run takes less).", ""]
    planners_new = ((run.get("raw") or {}).get("planners") or {}).get("planners") or {}
    planners_old = ((baseline.get("raw") or {}).get("planners") or {}).get("planners") or {}
    rows = []
    for name in planners_new:
        if name in planners_old:
            new = _median(planners_new[name].get("ms_per_node"))
            old = _median(planners_old[name].get("ms_per_node"))
            rows.append([name, _number(old), _number(new), _ratio(new / old if new and old else None)])
    if rows:
        lines += ["Median ms per node:", ""] + _table(["planner", "baseline", "this run", "ratio"], rows)
    floor_new = {row.get("qubits"): row for row in ((run.get("raw") or {}).get("search") or {}).get(
        "against_floor") or []}
    floor_old = {row.get("qubits"): row for row in ((baseline.get("raw") or {}).get("search") or {}).get(
        "against_floor") or []}
    rows = []
    for n, row in floor_new.items():
        old_row = floor_old.get(n)
        if old_row is None:
            continue
        new, old = (row.get("ratio_to_floor") or {}).get("ours"), (old_row.get("ratio_to_floor") or {}).get("ours")
        new_ms, old_ms = (row.get("median_ms") or {}).get("ours"), (old_row.get("median_ms") or {}).get("ours")
        rows.append([str(n), _number(old_ms), _number(new_ms), _ratio(old), _ratio(new)])
    if rows:
        lines += ["`AerBackend.search` against Aer's floor, each run's own floor:", ""]
        lines += _table(["n", "baseline (ms)", "this run (ms)", "baseline × floor", "this run × floor"], rows)
    ompl_new = (((run.get("raw") or {}).get("planners") or {}).get("ompl_rrt") or {}).get("ours_over_ompl")
    ompl_old = (((baseline.get("raw") or {}).get("planners") or {}).get("ompl_rrt") or {}).get("ours_over_ompl")
    if ompl_new is not None and ompl_old is not None:
        lines += [f"`RRT` over OMPL's RRT, ratio of the medians: {_ratio(ompl_old)} in the baseline, "
                  f"{_ratio(ompl_new)} in this run.", ""]
    try:
        compare = _compare_module(root)
        rows_all = compare.compare(compare.figures_of(run), compare.figures_of(baseline))
        summary = compare.by_benchmark(rows_all)
    except Exception as exc:  # noqa: BLE001 -- the page says what failed rather than failing the build
        return lines + [f"The figure-by-figure comparison could not be made here ({type(exc).__name__}).", ""]
    if summary:
        lines += ["Every figure with a direction that both runs hold, per benchmark, as "
                  "`python benchmarks/compare.py benchmarks/results/run.json benchmarks/results/baseline.json` "
                  "prints it: `worse` is this run over the baseline for times and memory and the baseline over "
                  "this run for throughputs (below 1: this run is better); a regression or an improvement is a "
                  f"change beyond {_percent(compare.DEFAULT_THRESHOLD)}.", ""]
        rows = [[f"`{name}`", str(row["figures"]), _number(row["geomean_worse"]), _number(row["median_worse"]),
                 _number(row["min_worse"]), _number(row["max_worse"]), str(row["regressions"]),
                 str(row["improvements"])] for name, row in summary.items()]
        lines += _table(["benchmark", "figures", "geometric mean", "median", "lowest", "highest", "regressions",
                         "improvements"], rows)
    return lines


def _script_of(root: Path, stem: str) -> str:
    """The script under ``benchmarks/`` that writes a results file named ``stem``: the longest script
    name that begins it (``bench_gpu_dense`` -> ``bench_gpu.py``), ``ab_planner.py`` for ``ab_*``."""
    if stem.startswith("ab_"):
        return "benchmarks/ab_planner.py"
    scripts = sorted((p.stem for p in (root / "benchmarks").glob("*.py")), key=len, reverse=True)
    for script in scripts:
        if stem == script or stem.startswith(script + "_"):
            return f"benchmarks/{script}.py"
    return "—"


def _recorded(payload: dict) -> str:
    """What a results file records of its provenance: commit, date, machine, versions."""
    machine = payload.get("machine") if isinstance(payload.get("machine"), dict) else {}
    parts = []
    if machine.get("git_commit"):
        parts.append(f"commit `{machine['git_commit'][:12]}`" + (" (uncommitted changes)" if machine.get("git_dirty")
                                                                  else ""))
    for side in ("ours_checkout", "baseline_checkout"):  # ab_planner.py: the two checkouts compared
        checkout = payload.get(side)
        if isinstance(checkout, dict) and checkout.get("commit"):
            parts.append(f"{side.split('_')[0]} `{checkout['commit'][:12]}`"
                         + (" (uncommitted changes)" if checkout.get("dirty") else ""))
    if machine.get("date"):
        parts.append(str(machine["date"]))
    if machine.get("cpu"):
        parts.append(str(machine["cpu"]))
    gpus = machine.get("gpus")
    if isinstance(gpus, list) and gpus:
        parts.append("; ".join(str(gpu).split(",")[0] for gpu in gpus))
    packages = machine.get("packages") if isinstance(machine.get("packages"), dict) else {}
    versions = [f"Python {machine['python']}"] if machine.get("python") else []
    for name in ("qiskit", "qiskit-aer"):
        version = packages.get(name) or machine.get(name.replace("-", "_"))  # older files: flat in machine
        if isinstance(version, str):
            versions.append(f"{name} {version}")
    if versions:
        parts.append(", ".join(versions))
    missing = [what for what, present in (("commit", any("`" in part for part in parts)),
                                          ("date", bool(machine.get("date")))) if not present]
    if missing:
        parts.append(f"no {' or '.join(missing)}")
    return " · ".join(parts) if parts else "none"


def _other_results(root: Path) -> list[str]:
    files = sorted(path.name for path in (root / RESULTS).iterdir()
                   if path.name not in (RUN.name, BASELINE.name) and not path.name.startswith("."))
    return ["## Other results kept", "",
            f"`{RESULTS.as_posix()}/` also keeps the results of measurements `benchmarks/run.py` does not make "
            f"(other modes of a script, the GPU, comparisons of two checkouts, a reliability campaign; files: "
            f"{len(files)}); each names the script that wrote it and carries its provenance inside.", ""]


# ------------------------------------------------------------------------------------------ the page
def performance_page(root: Path) -> str:
    """The page's Markdown, from the files under ``root / benchmarks/results``."""
    lines = ["# Performance", "",
             f"This page is written from `{RUN.as_posix()}` each time the site is built: every figure on it is "
             f"read from that file (and, for the comparison, from `{BASELINE.as_posix()}`). "
             "`python benchmarks/run.py` runs every `benchmarks/bench_*.py` script, each in its own process, and "
             "writes that file: the figures and the provenance of the run (the code's commit, the package "
             "versions, the machine). Timings depend on the machine and on its load: compare runs from one quiet "
             "machine, with `python benchmarks/compare.py NEW OLD` (either file may be `REV:PATH`, a file as "
             "committed at a git revision).", ""]
    run, why = _load(root / RUN)
    if run is None:
        return "\n".join(lines + [f"`{RUN.as_posix()}` is {why}: no figures to show.", ""])
    lines += ["## The run", ""]
    lines += _table(["", ""], _provenance_rows(run), "ll")
    lines += _staleness(root, run)
    lines += ["## What is measured", ""]
    lines += _benchmarks_table(root, run)
    lines += ["## Time per node and per oracle call", ""]
    lines += _planners_section(run)
    lines += _round_parts_section(run)
    lines += ["## Against peers measured in the same run", ""]
    lines += _ompl_section(run)
    lines += _families_section(run)
    lines += _streams_section(run)
    lines += _profile_section(run)
    lines += _floor_section(run)
    lines += _interleaved_section(run)
    baseline, why = _load(root / BASELINE)
    lines += _baseline_section(root, run, baseline, why)
    lines += _other_results(root)
    return "\n".join(lines).rstrip() + "\n"


def write_performance_page(root: Path, target: Path) -> None:
    """Write the page to ``target`` (only when its text changes)."""
    text = performance_page(root)
    target.parent.mkdir(parents=True, exist_ok=True)
    if not target.exists() or target.read_text() != text:
        target.write_text(text)
