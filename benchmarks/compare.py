"""Compare two benchmark runs figure by figure: ratios per benchmark and the regressions (a developer tool).

    python benchmarks/compare.py NEW [OLD] [--threshold 0.15] [--all]
    python benchmarks/compare.py HEAD~5:benchmarks/results/run.json benchmarks/results/run.json
    python benchmarks/compare.py benchmarks/results/run.json benchmarks/results/baseline.json

NEW and OLD are files written by ``benchmarks/run.py`` (or any single benchmark's JSON, whose
numbers are flattened the same way), each given as a path or as ``REV:PATH``: a file as committed
at a git revision, read with ``git show REV:PATH`` (PATH from the repository's root, or ``./PATH``
from the current folder, as git reads it), so any two runs in the history compare without checking
either out. A path that exists on disk is read from disk. OLD defaults to the committed run of the
same kind: ``benchmarks/results/run.json`` (``run_quick.json`` when NEW is a quick run) as of
``HEAD``.

For each figure present in both with a direction (``_figures.direction``: times and memory lower
is better, throughputs and speed-ups higher), ``ratio`` = new / old and ``worse`` = new / old for
lower-is-better and old / new for higher-is-better; a figure is a regression when
``worse > 1 + threshold``, an improvement when ``worse < 1 / (1 + threshold)``. Prints both files'
provenance where it differs, then one line per benchmark (the first component of a figure's key,
``search``, ``planners``, ...): the figures compared and the geometric mean, median, lowest and
highest of ``worse`` (below 1: the new run is better), then the regressions (and improvements;
every compared figure with ``--all``) and the figures found in only one file. Exit status 1 when
there is a regression, else 0. Timings from different machines, or a busy one, differ for reasons
of their own: compare runs from one quiet machine.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _figures import INFO, LOWER, direction, flatten  # noqa: E402

DEFAULT_THRESHOLD = 0.15

_EPILOG = """examples:
  python benchmarks/compare.py benchmarks/results/run.json benchmarks/results/baseline.json
  python benchmarks/compare.py benchmarks/results/run.json HEAD~5:benchmarks/results/run.json
  python benchmarks/compare.py HEAD:benchmarks/results/run.json /tmp/my_run.json --all

REV:PATH is read with `git show REV:PATH` (PATH from the repository's root); a path that exists on
disk is read from disk. Ratios: new / old per figure; per benchmark, the geometric mean, median,
lowest and highest of `worse` (new / old for times and memory, old / new for throughputs), so that
below 1 the new run is better."""


def figures_of(payload: dict) -> dict[str, float]:
    """The flat figures of a run.json (its ``figures``) or of one benchmark's JSON."""
    if "figures" in payload and "benchmarks" in payload:
        return {key: float(value) for key, value in payload["figures"].items()}
    return flatten(payload)


def read_run(source: str) -> tuple[dict, str]:
    """The JSON at ``source``: a file on disk, else ``REV:PATH`` read through ``git show``."""
    path = Path(source)
    if path.exists():
        return json.loads(path.read_text()), source
    revision, colon, inside = source.partition(":")
    if not colon or not revision:
        raise SystemExit(f"{source}: no such file (a file at a git revision is written REV:PATH)")
    try:
        text = _git_show(f"{revision}:{inside}")
    except (OSError, subprocess.CalledProcessError) as exc:
        detail = getattr(exc, "stderr", "") or str(exc)
        raise SystemExit(f"{source}: git show failed: {detail.strip()}") from exc
    return json.loads(text), source


def _git_show(spec: str) -> str:
    """``git show SPEC`` from the current folder, else from this script's checkout."""
    try:
        return subprocess.run(["git", "show", spec], capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return subprocess.run(["git", "show", spec], cwd=HERE, capture_output=True, text=True, check=True).stdout


def committed_run(quick: bool) -> tuple[dict, str]:
    """The committed ``run[_quick].json`` at ``HEAD``."""
    relative = f"benchmarks/results/{'run_quick' if quick else 'run'}.json"
    try:
        text = subprocess.run(["git", "show", f"HEAD:{relative}"], cwd=HERE, capture_output=True, text=True,
                              check=True).stdout
    except (OSError, subprocess.CalledProcessError) as exc:
        raise SystemExit(f"no committed {relative} to compare with; pass OLD") from exc
    return json.loads(text), f"HEAD:{relative}"


def compare(new: dict[str, float], old: dict[str, float], threshold: float = DEFAULT_THRESHOLD) -> list[dict]:
    """One row per figure in both with a direction: key, old, new, ratio (new / old), worse, verdict."""
    rows = []
    for key in sorted(set(new) & set(old)):
        way = direction(key)
        if way == INFO:
            continue
        before, after = old[key], new[key]
        if before <= 0 or after <= 0:
            continue  # a ratio needs two positive numbers
        worse = after / before if way == LOWER else before / after
        verdict = "regression" if worse > 1 + threshold else "improvement" if worse < 1 / (1 + threshold) else "same"
        rows.append({"key": key, "old": before, "new": after, "ratio": after / before, "worse": worse,
                     "lower_is_better": way == LOWER, "verdict": verdict})
    return rows


def _print_rows(title: str, rows: list[dict]) -> None:
    if not rows:
        return
    print(f"{title}:")
    width = max(len(row["key"]) for row in rows)
    for row in rows:
        better = "lower" if row["lower_is_better"] else "higher"
        print(f"  {row['key']:{width}s}  {row['old']:12.6g} -> {row['new']:12.6g}  "
              f"x{row['ratio']:.3f} ({better} is better; {row['worse']:.2f}x worse)")


def by_benchmark(rows: list[dict]) -> dict[str, dict]:
    """Per benchmark (a key's first component): figures compared, regressions, improvements, and the
    geometric mean, median, lowest and highest of ``worse`` (new over old, oriented so that below 1
    means the new run is better)."""
    groups: dict[str, list[dict]] = {}
    for row in rows:
        groups.setdefault(row["key"].split(".", 1)[0], []).append(row)
    summary = {}
    for name, group in sorted(groups.items()):
        worse = [row["worse"] for row in group]
        summary[name] = {"figures": len(group),
                         "regressions": sum(row["verdict"] == "regression" for row in group),
                         "improvements": sum(row["verdict"] == "improvement" for row in group),
                         "geomean_worse": math.exp(statistics.fmean(math.log(w) for w in worse)),
                         "median_worse": statistics.median(worse), "min_worse": min(worse), "max_worse": max(worse)}
    return summary


def _print_benchmarks(summary: dict[str, dict]) -> None:
    if not summary:
        return
    width = max(len(name) for name in summary)
    print("per benchmark (worse = new / old for times and memory, old / new for throughputs; < 1: new is better):")
    print(f"  {'benchmark':{width}s}  {'figures':>7s}  {'geomean':>8s}  {'median':>8s}  {'min':>8s}  {'max':>8s}  "
          f"regressions  improvements")
    for name, row in summary.items():
        print(f"  {name:{width}s}  {row['figures']:7d}  {row['geomean_worse']:8.3f}  {row['median_worse']:8.3f}  "
              f"{row['min_worse']:8.3f}  {row['max_worse']:8.3f}  {row['regressions']:11d}  {row['improvements']:12d}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0], epilog=_EPILOG,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("new", help="a run.json (or one benchmark's JSON): a path, or REV:PATH for the file as "
                                    "committed at git revision REV (e.g. HEAD~5:benchmarks/results/run.json)")
    parser.add_argument("old", nargs="?", default=None,
                        help="the same forms as NEW; default: the committed run of the same kind at HEAD")
    parser.add_argument("--threshold", type=float, default=DEFAULT_THRESHOLD,
                        help="relative change called a regression (default 0.15 = 15%%)")
    parser.add_argument("--all", action="store_true", help="print every compared figure")
    args = parser.parse_args(argv)
    if not args.threshold > 0:
        parser.error(f"--threshold must be > 0, got {args.threshold}")
    new_payload, new_name = read_run(args.new)
    if args.old is None:
        old_payload, old_name = committed_run(bool(new_payload.get("quick")))
    else:
        old_payload, old_name = read_run(args.old)
    new, old = figures_of(new_payload), figures_of(old_payload)
    rows = compare(new, old, args.threshold)
    print(f"new: {new_name}\nold: {old_name}")
    machines = new_payload.get("machine"), old_payload.get("machine")
    if machines[0] and machines[1]:
        keys = ("cpu", "cores", "os", "python", "packages", "git_commit", "date")
        differ = {k: (machines[1].get(k), machines[0].get(k)) for k in keys if machines[0].get(k) != machines[1].get(k)}
        for key, (before, after) in differ.items():
            print(f"  machine {key}: {before} -> {after}")
    regressions = [row for row in rows if row["verdict"] == "regression"]
    improvements = [row for row in rows if row["verdict"] == "improvement"]
    print(f"{len(rows)} figures compared (threshold {args.threshold:.0%}): {len(regressions)} regressions, "
          f"{len(improvements)} improvements")
    _print_benchmarks(by_benchmark(rows))
    _print_rows("REGRESSIONS", sorted(regressions, key=lambda row: -row["worse"]))
    _print_rows("improvements", sorted(improvements, key=lambda row: row["worse"]))
    if args.all:
        _print_rows("all", rows)
    only_new, only_old = sorted(set(new) - set(old)), sorted(set(old) - set(new))
    if only_new or only_old:
        print(f"only in new: {len(only_new)} figures; only in old: {len(only_old)}")
    return 1 if regressions else 0


if __name__ == "__main__":
    sys.exit(main())
