"""The README's *Results at a glance* table, generated from the committed ``summary.json`` files.

``python docs/glance.py`` rewrites the table between the README's ``<!-- glance:start -->`` and
``<!-- glance:end -->`` markers; ``python docs/glance.py --check`` exits 1 if the committed table
differs from what the summaries give (``tests/project/test_readme.py`` runs the check), so the table cannot
drift from the results.

Each row reads one number from ``docs/results/EXPERIMENT/summary.json`` (our exact check) and, where
the experiment was also run with the authors' check, from ``docs/results/authors/EXPERIMENT/``:
``ours``, its ``interval_95`` and the paper's number from the same summary's ``paper``; each
interval is shown with its unit (what its bootstrap resamples: trees, runs or worlds). "Paper
inside?" is computed from the interval. "explained?" is a sentence whose every number and list is
read from a summary (``Row.facts``), except for the rows whose summary resamples the paper's own
estimator (``paper_design``): there it says whether the paper's number is plausible for one
replicate of the paper's design.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "docs" / "results"
README = ROOT / "README.md"
START, END = "<!-- glance:start -->", "<!-- glance:end -->"
#: the markers around the README's generated sentence on q-RRT's lead over RRT across worlds
ADVANTAGE_START, ADVANTAGE_END = "<!-- glance-advantage:start -->", "<!-- glance-advantage:end -->"
POLICY_START, POLICY_END = "<!-- glance-policy:start -->", "<!-- glance-policy:end -->"
#: the search policies' names in the rule's summaries -> their classes
POLICY_CLASSES = {"paper": "PaperIterations()", "adaptive": "Adaptive()", "bbht": "BBHT()",
                  "thompson": "ThompsonIterations()"}


@dataclass(frozen=True)
class Row:
    """One row: a quantity of one experiment, read at ``path`` in ``ours``, ``interval_95`` and
    ``paper`` (``paper_path`` where the paper's number sits elsewhere)."""

    figure: str
    quantity: str
    experiment: str
    path: tuple[str, ...]
    explained: str
    paper_path: tuple[str, ...] | None = None
    percent: bool = False
    #: the numbers ``explained`` quotes, read from the summaries: name -> (experiment, path); a
    #: list is shown as its length (its items where the name is in ``itemized``), a pair of
    #: numbers as an interval, a fraction in ``percent_facts`` as a percentage
    facts: tuple[tuple[str, str, tuple[str, ...]], ...] = ()
    #: what the interval resamples (trees, runs, worlds), shown beside it
    unit: str = "trees"
    #: facts shown as their items rather than their length
    itemized: tuple[str, ...] = ()
    #: facts shown as percentages
    percent_facts: tuple[str, ...] = ()


#: the corridor cell that held the paper's pair in world seed 0 (``corridor-sensitivity``)
CELL = "w1.0-l8.0-c120-d3.0"

#: "explained?" for a quantity whose summary resamples the paper's own estimator (``paper_design``)
DESIGN = "{design}"

ROWS = (
    Row("Fig. 9", "RRT, oracle calls per node", "oracle-efficiency", ("RRT",), DESIGN),
    Row("Fig. 9", "parallel RRT (8 workers)", "oracle-efficiency", ("ParallelRRT",), DESIGN),
    Row("Fig. 9", "q-RRT", "oracle-efficiency", ("QRRT",), DESIGN),
    Row("Fig. 9", "Pq-RRT (8 workers, shared)", "oracle-efficiency", ("PQRRT",), DESIGN),
    Row("Figs. 6-8", "q-RRT / Pq-RRT seconds per oracle call (Aer)", "wallclock",
        ("per_call_ratio_qrrt_over_pqrrt", "aer"),
        "open: ours is 8 workers sharing one search at {round}x q-RRT's cost a round; the paper's {paper}x a "
        "round is not measured", paper_path=("per_call_ratio_qrrt_over_pqrrt",),
        facts=(("round", "wallclock", ("ours", "per_critical_path_call_ratio_qrrt_over_pqrrt", "aer")),
               ("paper", "wallclock", ("paper", "per_critical_path_call_ratio_qrrt_over_pqrrt")))),
    Row("Figs. 10-12", "RRT efficiency at 40 calls, `paper_clutter`", "heatmaps", ("RRT", "40", "efficiency"),
        "explained: the paper's RRT fits only sparser worlds; of {worlds} single worlds {pass0}, {pass1} and "
        "{pass2} pass under three planner root seeds, and {again} of the passing worlds pass again under "
        "another", percent=True, unit="runs", percent_facts=("again",),
        facts=(("worlds", "heatmap-worlds", ("worlds_run",)),
               ("pass0", "heatmap-worlds", ("passing_worlds_by_root_seed", "0")),
               ("pass1", "heatmap-worlds", ("passing_worlds_by_root_seed", "1")),
               ("pass2", "heatmap-worlds", ("passing_worlds_by_root_seed", "2")),
               ("again", "heatmap-worlds", ("pass_overlap", "fraction_passing_again")))),
    Row("Figs. 10-12", "q-RRT nodes at 40 calls, single worlds with the paper's RRT", "heatmap-worlds",
        ("QRRT", "40", "nodes"),
        "open: with the 3-call round the paper's totals imply, {ours20} {span20} (worlds) against {paper20} nodes "
        "at 20 calls; one passing world's own value at 40 calls ranges over {range40}", unit="worlds",
        facts=(("ours20", "heatmap-worlds", ("ours", "QRRT", "20", "nodes")),
               ("span20", "heatmap-worlds", ("interval_95", "QRRT", "20", "nodes")),
               ("paper20", "heatmap-worlds", ("paper", "QRRT", "20", "nodes")),
               ("range40", "heatmap-worlds", ("range_over_passing_worlds", "QRRT", "40", "nodes")))),
    Row("Figs. 13-14", "q-RRT nodes in the corridor (50 trials)", "corridor", ("QRRT",),
        "open in our corridor; the 1 x 8 cell that held the paper's pair in one clutter draw holds it in {held} "
        "of {draws} new draws with 1-2 iterations, where q-RRT is {q} {qspan} (worlds) with 1 iteration; the "
        "paper's schedule misses the pair in {never} of {draws}", unit="runs",
        facts=(("held", "corridor-worlds", ("claims_over_worlds", f"paper_pair_inside_fixed_iterations/{CELL}",
                                           "holds_in")),
               ("draws", "corridor-worlds", ("design", "draws")),
               ("q", "corridor-worlds", ("ours", "QRRT", f"{CELL}-fixed:1")),
               ("qspan", "corridor-worlds", ("interval_95", "QRRT", f"{CELL}-fixed:1")),
               ("never", "corridor-worlds", ("claims_over_worlds", "paper_pair_never_with_paper_schedule",
                                            "holds_in")))),
    Row("Figs. 13-14", "RRT nodes in the corridor (50 trials)", "corridor", ("RRT",),
        "open in our corridor; {rrt} {span} (worlds) in that 1 x 8 cell over {draws} clutter draws, one draw's "
        "mean ranging over {spread}", unit="runs",
        facts=(("rrt", "corridor-worlds", ("ours", "RRT", CELL)),
               ("span", "corridor-worlds", ("interval_95", "RRT", CELL)),
               ("draws", "corridor-worlds", ("design", "draws")),
               ("spread", "corridor-worlds", ("range_over_draws", "RRT", CELL)))),
    Row("Figs. 15-17", "QDA mean parent distance, 16 nodes", "annealing", ("QDA", "16"),
        "open: outside one tree's range {single}; over {densities} world densities and {readings} readings of "
        "Alg. 4 line 7, the paper's value is plausible for one tree in {plausible}",
        paper_path=("QDA",),
        facts=(("single", "annealing", ("paper_design", "range_95", "QDA", "16")),
               ("densities", "annealing-density", ("settings", "densities")),
               ("readings", "annealing-density", ("settings", "readings")),
               ("plausible", "annealing-density", ("readings_reaching_paper", "plausible_for_one_tree")))),
    Row("Figs. 15-17", "uniform q-RRT mean parent distance, 16 nodes", "annealing", ("QRRT", "16"),
        "explained by the world's density (our assumption): our mean crosses it between {low}x and {high}x",
        paper_path=("QRRT",),
        facts=(("low", "annealing-density", ("where_paper_falls", "QRRT", "our_mean_crosses_paper_between", "0")),
               ("high", "annealing-density", ("where_paper_falls", "QRRT", "our_mean_crosses_paper_between", "1")))),
)


def _at(value: Any, path: tuple[str, ...]) -> Any:
    for key in path:
        value = value[int(key)] if isinstance(value, list) else value[key]
    return value


def _number(value: float, percent: bool) -> str:
    if percent:
        return f"{100 * value:.1f} %"
    return f"{value:.3g}" if abs(value) < 100 else f"{value:.0f}"


def _cell(summary: dict[str, Any] | None, row: Row) -> tuple[str, tuple[float, float] | None]:
    if summary is None:
        return "not run", None
    ours, interval = _at(summary["ours"], row.path), _at(summary["interval_95"], row.path)
    low, high = interval
    text = (f"{_number(ours, row.percent)} [{_number(low, row.percent)}, {_number(high, row.percent)}] "
            f"({row.unit})")
    return text, (low, high)


def _explained(row: Row, summary: dict[str, Any]) -> str:
    """The row's "explained?" text; for ``DESIGN``, whether the paper's number is plausible for one
    replicate of the paper's own estimator, with that estimator's 95 % range."""
    if row.explained != DESIGN:
        return row.explained.format(**{name: _fact(experiment, path, itemized=name in row.itemized,
                                                   percent=name in row.percent_facts)
                                       for name, experiment, path in row.facts})
    design = summary["paper_design"]
    low, high = _at(design["range_95"], row.path)
    verdict = "explained" if _at(design["paper_plausible"], row.path) else "open"
    return f"{verdict}: the paper's estimator spreads over [{_number(low, False)}, {_number(high, False)}]"


def _authors_code(row: Row, summary: dict[str, Any]) -> str:
    """The reported run of the authors' code beside ours under its design (``authors_code``), or
    "not run" where no run of their code is reported for this quantity."""
    code = summary.get("authors_code")
    if not code:
        return "not run"
    low, high = _at(code["reported_per_tree_range"], row.path)
    ours_low, ours_high = _at(code["ours_pooled_range_95"], row.path)
    return (f"{_number(_at(code['reported_pooled'], row.path), False)} (trees {_number(low, False)}-"
            f"{_number(high, False)}); ours so: [{_number(ours_low, False)}, {_number(ours_high, False)}] (trees)")


def _fact(experiment: str, path: tuple[str, ...], results: Path = RESULTS, itemized: bool = False,
          percent: bool = False) -> str:
    """A number an "explained" text quotes: ``path`` in the experiment's summary (a list as its
    length, or with ``itemized`` as its items, "none" for no items; a [low, high] pair of numbers
    as an interval; with ``percent`` a fraction as a percentage)."""
    summary = _summary(results / experiment)
    if summary is None:
        raise FileNotFoundError(f"{results / experiment / 'summary.json'} is missing")
    value = _at(summary, path)
    if itemized:
        items = value if isinstance(value, list) else [value]
        return ", ".join(f"`{item}`" for item in items) if items else "none"
    if isinstance(value, list) and len(value) == 2 and all(isinstance(v, int | float) for v in value):
        return f"[{_number(value[0], False)}, {_number(value[1], False)}]"
    if isinstance(value, list):
        return str(len(value))
    return _number(value, percent)


def _summary(folder: Path) -> dict[str, Any] | None:
    path = folder / "summary.json"
    return json.loads(path.read_text()) if path.exists() else None


def table(results: Path = RESULTS) -> str:
    """The Markdown table, from the summaries under ``results``.

    Args:
        results: The folder of the committed results (``docs/results``).

    Returns:
        The table's lines, with its header.
    """
    lines = ["| figure | quantity | paper | the authors' code, like for like | ours, 95 % interval "
             "| ours, the authors' check | paper inside ours? | explained by / open because |",
             "|---|---|---|---|---|---|---|---|"]
    for row in ROWS:
        exact = _summary(results / row.experiment)
        if exact is None:
            raise FileNotFoundError(f"{results / row.experiment / 'summary.json'} is missing: run "
                                    f"qrrt reproduce {row.experiment} --out {results}")
        paper = _at(exact["paper"], row.paper_path or row.path)
        ours, bounds = _cell(exact, row)
        authors, authors_bounds = _cell(_summary(results / "authors" / row.experiment), row)
        inside = [bounds is not None and bounds[0] <= paper <= bounds[1],
                  authors_bounds is not None and authors_bounds[0] <= paper <= authors_bounds[1]]
        verdict = {(True, True): "yes", (False, False): "no"}.get(
            (inside[0], inside[1]), "with the authors' check" if inside[1] else "with our check")
        if authors_bounds is None:
            verdict = "yes" if inside[0] else "no"
        lines.append(f"| {row.figure} | {row.quantity} | {_number(paper, row.percent)} | {_authors_code(row, exact)} "
                     f"| {ours} | {authors} | {verdict} | {_explained(row, exact)} |")
    return "\n".join(lines)


def advantage_sentence(results: Path = RESULTS) -> str:
    """The README's sentence on q-RRT's lead over RRT across single worlds, from
    ``heatmap-worlds``' ``advantage_at_10_over_worlds`` (q-RRT with 2 iterations a round).

    Args:
        results: The folder of the committed results (``docs/results``).

    Returns:
        One sentence: the worlds below RRT and the median ratio at the fewest obstacles, the
        obstacle count from which q-RRT leads in every world, and the median ratio at the most.
    """
    summary = _summary(results / "heatmap-worlds")
    if summary is None:
        raise FileNotFoundError(f"{results / 'heatmap-worlds' / 'summary.json'} is missing")
    counts = summary["settings"]["box_counts"]
    worlds = summary["settings"]["worlds"]
    advantage = {count: summary["advantage_at_10_over_worlds"][str(count)]["QRRT"] for count in counts}
    fewest, most = counts[0], counts[-1]
    leading = [count for index, count in enumerate(counts)
               if all(advantage[later]["worlds_quantum_below_rrt"] == 0 for later in counts[index:])]
    lead = (f"it is above RRT in every world from {leading[0]} boxes on" if leading
            else "no obstacle count has it above RRT in every world")
    return (f"q-RRT's efficiency at 10 calls against RRT's in the same world (`heatmap-worlds`, "
            f"{worlds} worlds per obstacle count) is a deficit at low clutter: with {fewest} boxes q-RRT "
            f"is below RRT in {advantage[fewest]['worlds_quantum_below_rrt']} of {worlds} worlds (median "
            f"ratio {_number(advantage[fewest]['ratio'][1], False)}, where 2 iterations over-rotate); "
            f"{lead}, with a median ratio of {_number(advantage[most]['ratio'][1], False)} at {most} boxes.")


def policy_sentence(results: Path = RESULTS) -> str:
    """The README's sentence on the default search policies, from the ``default_policy`` of
    ``problems`` (the rule's run) and of ``confirmation/problems`` (three more root seeds).

    Args:
        results: The folder of the committed results (``docs/results``).

    Returns:
        One sentence: each planner's chosen policy with its worst family ratio and that family,
        then what the confirmation run chose and its worst ratio.
    """
    runs = []
    for folder in (results / "problems", results / "confirmation" / "problems"):
        summary = _summary(folder)
        if summary is None:
            raise FileNotFoundError(f"{folder / 'summary.json'} is missing")
        runs.append(summary)

    def worst(rule: dict[str, Any]) -> tuple[str, str]:
        chosen = rule["chosen"]
        ratios = {family: math.inf if value is None else value
                  for family, value in rule["relative_cost"][chosen].items()}
        family = max(ratios, key=lambda name: ratios[name])
        return POLICY_CLASSES[chosen], f"{_number(ratios[family], False)} on {family}"

    first, second = (run["default_policy"] for run in runs)
    roots = [", ".join(str(root) for root in run["settings"]["root_seeds"]) for run in runs]
    parts = []
    for planner, label in (("QRRT", "q-RRT (calls)"), ("PQRRT", "Pq-RRT (critical path)")):
        policy, ratio = worst(first[planner])
        again, again_ratio = worst(second[planner])
        parts.append(f"{label}: `{policy}`, worst ratio {ratio}; on root seeds {roots[1]} the rule picks "
                     f"`{again}`, worst ratio {again_ratio}")
    return (f"By the rule on root seeds {roots[0]} (`docs/results/problems/summary.json`, "
            f"`default_policy`): " + "; ".join(parts) + ".")


def _between(text: str, start: str, end: str, rendered: str) -> str:
    before, rest = text.split(start, 1)
    _, after = rest.split(end, 1)
    return f"{before}{start}\n{rendered}\n{end}{after}"


def with_table(readme: str, rendered: str, sentence: str | None = None, policy: str | None = None) -> str:
    """``readme`` with the text between the glance markers replaced by ``rendered`` and, given
    ``sentence`` (``policy``) and where the README has the advantage (policy) markers, the text
    between those by it."""
    readme = _between(readme, START, END, rendered)
    if sentence is not None and ADVANTAGE_START in readme:
        readme = _between(readme, ADVANTAGE_START, ADVANTAGE_END, sentence)
    if policy is not None and POLICY_START in readme:
        readme = _between(readme, POLICY_START, POLICY_END, policy)
    return readme


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true",
                        help="exit 1 if README.md's table or sentence is not the generated one")
    args = parser.parse_args(argv)
    readme = README.read_text()
    updated = with_table(readme, table(), advantage_sentence(), policy_sentence())
    if args.check:
        if updated != readme:
            print("README.md's results table differs from docs/results: run python docs/glance.py", file=sys.stderr)
            return 1
        return 0
    README.write_text(updated)
    return 0


if __name__ == "__main__":
    sys.exit(main())
