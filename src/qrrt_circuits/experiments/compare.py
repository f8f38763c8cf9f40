"""The paper's numbers beside several runs of the same experiments (``qrrt compare-checks``).

An experiment's ``plot`` sees only its own run's records. Runs of the same experiments with other
reachability checks (``qrrt reproduce NAME --predicate authors --out docs/results/authors``) are
set beside one another here, from their ``summary.json`` files alone: for every experiment that
has a complete summary in every folder and compares numbers with the paper
(``Experiment.paper_comparison``), one panel with the paper's numbers and each run's, with its
95 % interval. Nothing is recomputed: the numbers drawn are those of the summaries.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

from .base import Experiment, PaperComparison, Summary
from .catalog import EXPERIMENTS
from .figures import paper_comparison_figure

#: the figure's name in the last folder, unless another path is given
FIGURE = "checks_vs_paper.png"
#: a check's name in the legend, where it differs from the predicate's
CHECK_NAMES = {"authors": "authors'", "authors-octave": "authors' (Octave)"}


def run_label(summary: Summary) -> str:
    """A run's name in the figure's legend: the check its planners used.

    Args:
        summary: A ``summary.json``.

    Returns:
        ``"ours, <predicate> check"`` (``exact`` for a summary written before predicates existed).
    """
    predicate = summary.get("settings", {}).get("predicate", "exact")
    return f"ours, {CHECK_NAMES.get(predicate, predicate)} check"


def read_summary(path: Path) -> Summary | None:
    """A complete ``summary.json``, or None where the file is missing or incomplete.

    Args:
        path: The file.

    Returns:
        The summary, or None.

    Raises:
        ValueError: If the file is not JSON.
    """
    if not path.is_file():
        return None
    try:
        summary: Summary = json.loads(path.read_text())
    except json.JSONDecodeError as exc:
        raise ValueError(f"{path} is not JSON ({exc.msg}, line {exc.lineno})") from exc
    return summary if summary.get("complete") else None


def comparisons(folders: Sequence[Path]) -> list[list[tuple[str, PaperComparison]]]:
    """Per experiment that compares with the paper and has a complete summary in every folder,
    ``(run label, comparison)`` for each folder, in ``EXPERIMENTS`` order.

    Args:
        folders: ``--out`` folders of ``qrrt reproduce`` (each holding ``NAME/summary.json``).

    Returns:
        The panels of the figure (possibly none).
    """
    panels = []
    for name, experiment in EXPERIMENTS.items():
        runs = []
        for folder in folders:
            summary = read_summary(folder / name / "summary.json")
            comparison = experiment.paper_comparison(summary) if summary is not None else None
            if summary is None or comparison is None:
                break
            runs.append((run_label(summary), comparison))
        else:
            if runs:
                panels.append(runs)
    return panels


def compare_checks(folders: Sequence[str | Path], figure: str | Path | None = None) -> Path:
    """Draw the paper's numbers beside the runs in ``folders`` (one panel per experiment).

    Args:
        folders: One or more ``--out`` folders of ``qrrt reproduce``, one per check (the first's
            run is drawn first after the paper).
        figure: Where to write the figure; None (default) for ``FIGURE`` in the last folder.

    Returns:
        The figure's path.

    Raises:
        ValueError: Without folders, or if no experiment that compares with the paper has a
            complete summary in every folder.
    """
    paths = [Path(folder) for folder in folders]
    if not paths:
        raise ValueError("compare-checks needs at least one results folder")
    for path in paths:
        if not path.is_dir():
            raise ValueError(f"{str(path)!r} is not a folder")
    panels = comparisons(paths)
    if not panels:
        names = sorted(name for name, experiment in EXPERIMENTS.items()
                       if type(experiment).paper_comparison is not Experiment.paper_comparison)
        raise ValueError(f"no experiment that compares with the paper has a complete summary.json in every one of "
                         f"{[str(p) for p in paths]} (run `qrrt reproduce NAME --out FOLDER` there first; NAME: "
                         f"{', '.join(names)})")
    return paper_comparison_figure(panels, Path(figure) if figure is not None else paths[-1] / FIGURE)
