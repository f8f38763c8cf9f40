"""The README is an entry point: short, its results table generated from the committed
summaries, its example runnable; and no prose narrates the project's own history."""

from __future__ import annotations

import importlib.util
import json
import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"


def _glance():
    spec = importlib.util.spec_from_file_location("glance", ROOT / "docs" / "glance.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # (its dataclasses look their module up there)
    spec.loader.exec_module(module)
    return module


def test_the_readme_reads_in_a_minute():
    assert len(README.read_text().splitlines()) <= 200


def test_the_results_table_is_the_one_the_summaries_give():
    glance = _glance()
    readme = README.read_text()
    assert glance.with_table(readme, glance.table(), glance.advantage_sentence()) == readme, "run python docs/glance.py"
    assert glance.main(["--check"]) == 0


def test_the_advantage_sentence_is_generated_and_names_the_deficit():
    glance = _glance()
    readme = README.read_text()
    sentence = glance.advantage_sentence()
    assert f"{glance.ADVANTAGE_START}\n{sentence}\n{glance.ADVANTAGE_END}" in readme
    assert "deficit at low clutter" in sentence and "below RRT in" in sentence


def test_the_default_policy_sentence_is_generated_from_both_seed_sets():
    """The README's sentence on the defaults names each planner's chosen policy and its worst
    family ratio, read from the rule's summary and from the confirmation run's."""
    glance = _glance()
    readme = README.read_text()
    sentence = glance.policy_sentence()
    assert f"{glance.POLICY_START}\n{sentence}\n{glance.POLICY_END}" in readme
    rule = json.loads((glance.RESULTS / "problems" / "summary.json").read_text())["default_policy"]
    for planner in ("QRRT", "PQRRT"):
        chosen = rule[planner]["chosen"]
        assert f"`{glance.POLICY_CLASSES[chosen]}`, worst ratio" in sentence
    assert "root seeds 3, 4, 5" in sentence


def test_every_explanation_quotes_the_summaries():
    """Every "explained by / open because" cell reads its numbers from summaries (``facts``), or is
    the paper-design verdict, which is computed."""
    glance = _glance()
    for row in glance.ROWS:
        assert row.explained == glance.DESIGN or row.facts, row.quantity


def test_the_results_table_follows_a_changed_summary(tmp_path):
    """The table is read from the files: a changed number changes it."""
    import json
    import shutil

    glance = _glance()
    results = tmp_path / "results"
    shutil.copytree(ROOT / "docs" / "results", results, ignore=shutil.ignore_patterns("*.png", "*.csv"))
    before = glance.table(results)
    path = results / "corridor" / "summary.json"
    summary = json.loads(path.read_text())
    summary["ours"]["QRRT"] = 46
    summary["interval_95"]["QRRT"] = [40, 52]
    path.write_text(json.dumps(summary))
    after = glance.table(results)
    assert before != after and "| 46 [40, 52] (runs) |" in after and "| with our check |" in after


def test_the_first_example_runs():
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), re.S)
    assert blocks, "the README has a Python example"
    exec(compile(blocks[0], "README.md", "exec"), {})  # noqa: S102 - the README's own example


def test_the_readme_links_to_files_that_exist():
    for target in re.findall(r"\]\(([^)#]+)\)", README.read_text()):
        if "://" not in target:
            assert (ROOT / target).exists(), target


#: words that narrate the project's own development rather than describe the library
NARRATIVE = re.compile(
    r"this phase|this session|earlier (run|session|pass)|an earlier|previous pass|\b0\.[12]'s\b|last figures"
    r"|fidelity issue|load average|has been removed|was removed|we fixed|used to be|slow machine", re.I)
COMMIT = re.compile(r"(?<![0-9A-Za-z_./-])(?=[0-9a-f]*[a-f])(?=[0-9a-f]*[0-9])[0-9a-f]{7,40}(?![0-9A-Za-z_])")
ISSUE = re.compile(r"\bissues?\s*#?\d+|(?<![\w&])#\d{1,5}\b", re.I)
DATE = re.compile(r"\b20\d\d-\d\d-\d\d\b")


def _prose_files() -> list[Path]:
    skipped = {"_build", "_generated", "_notebooks"}
    docs = [p for p in (ROOT / "docs").rglob("*") if p.suffix in (".md", ".py", ".rst")
            and not skipped & set(p.parts) and p.name != "_gallery.md"]
    return [README, *docs, *(ROOT / "src").rglob("*.py")]


@pytest.mark.parametrize(("name", "pattern"), [("a development narrative", NARRATIVE), ("a commit hash", COMMIT),
                                               ("an issue number", ISSUE), ("a date", DATE)])
def test_no_prose_tells_the_project_history(name, pattern):
    found = [f"{path.relative_to(ROOT)}:{number}: {match.group(0)!r}"
             for path in _prose_files()
             for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1)
             for match in pattern.finditer(line)]
    assert not found, f"{name} in the prose: " + "; ".join(found[:10])


def test_the_changelog_names_no_commit_or_issue():
    text = (ROOT / "CHANGELOG.md").read_text()
    assert not COMMIT.search(text) and not ISSUE.search(text)
