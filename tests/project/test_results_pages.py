"""Every experiment has a results page, and its numbers are the committed summary's."""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "docs" / "results"
sys.path.insert(0, str(ROOT / "docs"))
from results_tables import table, write_tables  # noqa: E402

SUMMARIES = sorted(RESULTS.glob("*/summary.json"))


def test_every_experiment_has_a_page_that_includes_its_numbers():
    pages = " ".join(path.read_text() for path in RESULTS.glob("*.md"))
    for summary in SUMMARIES:
        assert f"_generated/{summary.parent.name}.md" in pages, summary.parent.name


@pytest.mark.parametrize("summary", SUMMARIES, ids=[s.parent.name for s in SUMMARIES])
def test_the_table_shows_every_number_of_ours(summary):
    data = json.loads(summary.read_text())
    text = table(data, "x")
    first_table = text.split("| quantity", 1)[1].split("\n\n", 1)[0]  # up to the first blank line
    rows = [line for line in first_table.splitlines() if line.startswith("| ")]

    def leaves(value):
        return sum(leaves(v) for v in value.values()) if isinstance(value, dict) else 1

    assert len(rows) == leaves(data["ours"])
    assert data["provenance"]["git_commit"][:12] in text
    if "paper_design" in data:  # the paper's own estimator: one row per number, its verdict
        for path, plausible in _paths(data["paper_design"]["paper_plausible"]):
            name = re.escape(" / ".join(path))
            assert re.search(rf"\| {name} \| [^|]+ \| [^|]+ \| {'yes' if plausible else 'no'} \|", text), path


def _paths(value, path=()):
    """(path, leaf) for every leaf of nested dicts."""
    if isinstance(value, dict):
        return [leaf for key, item in value.items() for leaf in _paths(item, (*path, key))]
    return [(path, value)]


def test_the_fragments_are_written_for_both_checks(tmp_path):
    written = write_tables(RESULTS, tmp_path)
    assert {path.stem for path in written} == {s.parent.name for s in SUMMARIES}
    corridor = (tmp_path / "corridor.md").read_text()
    assert "our exact check" in corridor and "the authors' check" in corridor
    assert re.search(r"\| QRRT \| 3 \| \[0, 6\] \| 47 \| yes \|", corridor)


def test_the_committed_tables_are_the_ones_the_summaries_give(tmp_path):
    """``docs/results/_generated/`` is committed, so a repository browser shows each page's table
    (the pages link it); it must be what ``results_tables.py`` writes from the summaries now."""
    written = write_tables(RESULTS, tmp_path)
    committed = RESULTS / "_generated"
    for path in written:
        assert (committed / path.name).read_text() == path.read_text(), (
            f"docs/results/_generated/{path.name} is stale: run python docs/results_tables.py")
    assert sorted(p.name for p in committed.glob("*.md")) == sorted(p.name for p in written)


def test_every_page_links_its_tables_for_a_repository_browser():
    for page in RESULTS.glob("*.md"):
        text = page.read_text()
        for name in re.findall(r"\{include\} _generated/([\w-]+)\.md", text):
            assert f"([as a file](_generated/{name}.md), for a repository browser)" in text, (page.name, name)
