"""Compare two benchmark runs figure by figure and print the regressions (a developer tool).

    python benchmarks/compare.py NEW.json [OLD.json] [--threshold 0.15] [--all]

NEW and OLD are files written by ``benchmarks/run.py`` (or any single benchmark's JSON, whose
numbers are flattened the same way). OLD defaults to the committed run of the same kind:
``benchmarks/results/run.json`` (``run_quick.json`` when NEW is a quick run) as of ``HEAD``.
For each figure present in both with a direction (``_figures.direction``: times and memory lower
is better, throughputs and speed-ups higher), ``worse`` = new / old for lower-is-better and
old / new for higher-is-better; a figure is a regression when ``worse > 1 + threshold``, an
improvement when ``worse < 1 / (1 + threshold)``. Prints the regressions (and improvements; every
compared figure with ``--all``), figures found in only one file, and both machines when they
differ. Exit status 1 when there is a regression, else 0. Timings from different machines, or a
busy one, differ for reasons of their own: compare runs from one quiet machine.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _figures import INFO, LOWER, direction, flatten  # noqa: E402

DEFAULT_THRESHOLD = 0.15


def figures_of(payload: dict) -> dict[str, float]:
    """The flat figures of a run.json (its ``figures``) or of one benchmark's JSON."""
    if "figures" in payload and "benchmarks" in payload:
        return {key: float(value) for key, value in payload["figures"].items()}
    return flatten(payload)


def committed_run(quick: bool) -> tuple[dict, str]:
    """The committed ``run[_quick].json`` at ``HEAD``."""
    relative = f"benchmarks/results/{'run_quick' if quick else 'run'}.json"
    try:
        text = subprocess.run(["git", "show", f"HEAD:{relative}"], cwd=HERE, capture_output=True, text=True,
                              check=True).stdout
    except (OSError, subprocess.CalledProcessError) as exc:
        raise SystemExit(f"no committed {relative} to compare with; pass OLD.json") from exc
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


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("new", help="a run.json (or one benchmark's JSON)")
    parser.add_argument("old", nargs="?", default=None, help="default: the committed run of the same kind")
    parser.add_argument("--threshold", type=float, default=DEFAULT_THRESHOLD,
                        help="relative change called a regression (default 0.15 = 15%%)")
    parser.add_argument("--all", action="store_true", help="print every compared figure")
    args = parser.parse_args(argv)
    if not args.threshold > 0:
        parser.error(f"--threshold must be > 0, got {args.threshold}")
    new_payload = json.loads(Path(args.new).read_text())
    if args.old is None:
        old_payload, old_name = committed_run(bool(new_payload.get("quick")))
    else:
        old_payload, old_name = json.loads(Path(args.old).read_text()), args.old
    new, old = figures_of(new_payload), figures_of(old_payload)
    rows = compare(new, old, args.threshold)
    print(f"new: {args.new}\nold: {old_name}")
    machines = new_payload.get("machine"), old_payload.get("machine")
    if machines[0] and machines[1]:
        keys = ("cpu", "cores", "os", "python", "packages", "git_commit")
        differ = {k: (machines[1].get(k), machines[0].get(k)) for k in keys if machines[0].get(k) != machines[1].get(k)}
        for key, (before, after) in differ.items():
            print(f"  machine {key}: {before} -> {after}")
    regressions = [row for row in rows if row["verdict"] == "regression"]
    improvements = [row for row in rows if row["verdict"] == "improvement"]
    print(f"{len(rows)} figures compared (threshold {args.threshold:.0%}): {len(regressions)} regressions, "
          f"{len(improvements)} improvements")
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
