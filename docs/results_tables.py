"""Each results page's table of numbers, generated from the committed ``summary.json`` at build time.

``write_tables(results, target)`` writes ``target/EXPERIMENT.md`` for every
``results/EXPERIMENT/summary.json`` (and ``results/authors/EXPERIMENT/summary.json``): every number
of the summary's ``ours`` with the paper's number at the same place in ``paper``, its 95 %
interval from ``interval_95`` and whether the paper's number lies outside it
(``differs_from_paper``); where the summary resamples the paper's own estimator (``paper_design``),
its range and verdict; where it holds the reported run of the authors' code (``authors_code``), that
run beside ours under its design; every other block ``KEY`` of the summary that has its intervals in
``KEY_interval_95``, number by number; then the run's settings and provenance. The pages' prose discusses these
numbers; the tables are never typed by hand.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any


def _leaves(value: Any, path: tuple[str, ...] = ()) -> list[tuple[tuple[str, ...], Any]]:
    """(path, value) for every number, string or boolean in nested dicts (lists stay whole)."""
    if isinstance(value, dict):
        return [leaf for key, item in value.items() for leaf in _leaves(item, (*path, str(key)))]
    return [(path, value)]


def _at(value: Any, path: tuple[str, ...]) -> Any:
    for key in path:
        if not isinstance(value, dict) or key not in value:
            return None
        value = value[key]
    return value


def _at_or_above(value: Any, path: tuple[str, ...]) -> Any:
    """The value at ``path``, else at its first key where the paper gives one number (or one
    verdict) for what we report per setting (``QDA`` for ``QDA / 16``)."""
    found = _at(value, path)
    if found is None and len(path) > 1:
        found = _at(value, path[:1])
        found = found if not isinstance(found, dict) else None
    return found


def _shown(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, list) and len(value) == 2 and all(isinstance(v, (int, float)) or v is None for v in value):
        return "[" + ", ".join("" if v is None else f"{v:.4g}" for v in value) + "]"
    text = json.dumps(value) if not isinstance(value, str) else value
    return text.replace("|", "\\|")


def table(summary: dict[str, Any], label: str) -> str:
    """The Markdown of one summary: its numbers beside the paper's, its settings and provenance."""
    rows = ["| quantity | ours | 95 % interval | paper | paper outside our interval |", "|---|---|---|---|---|"]
    for path, value in _leaves(summary.get("ours", {})):
        paper = _at_or_above(summary.get("paper", {}), path)
        interval = _at(summary.get("interval_95") or {}, path)
        differs = _at_or_above(summary.get("differs_from_paper") or {}, path)
        rows.append(f"| {' / '.join(path)} | {_shown(value)} | {_shown(interval)} | {_shown(paper)} | "
                    f"{_shown(differs)} |")
    design = summary.get("paper_design")
    if design:  # the paper's own estimator, resampled from our trials
        trees = f"{design['trees']} tree{'' if design['trees'] == 1 else 's'}"
        rows += ["", f"The paper's estimator ({trees}, {design['resamples']} replicates; "
                 f"{design['meaning']}):", "", "| quantity | paper | its 95 % range | paper plausible |",
                 "|---|---|---|---|"]
        for path, low_high in _leaves(design["range_95"]):
            rows.append(f"| {' / '.join(path)} | {_shown(_at_or_above(summary.get('paper', {}), path))} | "
                        f"{_shown(low_high)} | {_shown(_at(design['paper_plausible'], path))} |")
    code = summary.get("authors_code")
    if code:  # the reported Octave run of the authors' code, beside ours under its design
        rows += ["", f"The authors' code under Octave, as reported, against ours under its design ({code['meaning']}; "
                 f"the reported per-tree range covers the median tree with probability "
                 f"{code['reported_range_covers_median_tree']:.3f}):", "",
                 "| quantity | reported pooled | ours pooled, 95 % range | plausible | reported per-tree range "
                 "| ours median tree, 95 % range | overlap |", "|---|---|---|---|---|---|---|"]
        for path, pooled in _leaves(code["reported_pooled"]):
            rows.append(f"| {' / '.join(path)} | {_shown(pooled)} | "
                        f"{_shown(_at(code['ours_pooled_range_95'], path))} | "
                        f"{_shown(_at(code['reported_pooled_plausible'], path))} | "
                        f"{_shown(_at(code['reported_per_tree_range'], path))} | "
                        f"{_shown(_at(code['ours_median_tree_range_95'], path))} | "
                        f"{_shown(_at(code['median_tree_ranges_overlap'], path))} |")
    for key, values in summary.items():  # every other block of numbers that carries its intervals
        spans = summary.get(f"{key}_interval_95")
        if key == "ours" or not isinstance(values, dict) or not isinstance(spans, dict):
            continue
        rows += ["", f"`{key}`:", "", "| quantity | value | 95 % interval |", "|---|---|---|"]
        for path, value in _leaves(values):
            rows.append(f"| {' / '.join(path)} | {_shown(value)} | {_shown(_at(spans, path))} |")
    provenance = summary.get("provenance") or {}
    packages = provenance.get("packages") or {}
    made = (f"Summarized at commit `{(provenance.get('git_commit') or 'unknown')[:12]}` on "
            f"{provenance.get('cpu', 'an unknown machine')} ({provenance.get('cores', '?')} cores), Python "
            f"{provenance.get('python', '?')}, qiskit {packages.get('qiskit', '?')}, qiskit-aer "
            f"{packages.get('qiskit-aer', '?')}, {provenance.get('date', 'date unknown')}."
            if provenance else "This summary records no provenance.")
    settings = ", ".join(f"`{key}`: `{json.dumps(value)}`" for key, value in summary.get("settings", {}).items())
    complete = "" if summary.get("complete") else "\n\n**Incomplete:** this summary lacks some trials.\n"
    return (f"### {label}\n\n" + "\n".join(rows) + f"{complete}\n\nSettings: {settings}.\n\n{made}\n")


def write_tables(results: Path, target: Path) -> list[Path]:
    """Write one page fragment per experiment (both checks in one file) under ``target``.

    Args:
        results: ``docs/results``.
        target: The folder of the generated fragments.

    Returns:
        The fragments written (or left as they were).
    """
    target.mkdir(parents=True, exist_ok=True)
    written = []
    for summary_path in sorted(results.glob("*/summary.json")):
        name = summary_path.parent.name
        parts = [table(json.loads(summary_path.read_text()), f"`{name}`, our exact check")]
        authors = results / "authors" / name / "summary.json"
        if authors.exists():
            parts.append(table(json.loads(authors.read_text()), f"`{name}`, the authors' check"))
        path = target / f"{name}.md"
        text = "\n".join(parts)
        if not path.exists() or path.read_text() != text:
            path.write_text(text)
        written.append(path)
    return written


if __name__ == "__main__":  # python docs/results_tables.py: the committed tables, written afresh
    here = Path(__file__).resolve().parent
    for fragment in write_tables(here / "results", here / "results" / "_generated"):
        print(f"wrote {fragment.relative_to(here.parent)}")
