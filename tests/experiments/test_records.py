"""records.csv on resume: torn headers, rows that do not fit their trial, and folders checked first.

The file is only ever appended to; a row that does not fit its trial (a value of the wrong kind,
another trial's parameter, an unknown trial) is reported by file, line, column and value and
excluded; a header that does not fit is refused naming the file and the column.
"""

from __future__ import annotations

import json
import re
import warnings
from pathlib import Path

import pytest
from summaries import results_of

from qrrt_circuits.cli import main
from qrrt_circuits.experiments import EXPERIMENTS, run_experiment
from qrrt_circuits.experiments.base import Trial
from qrrt_circuits.experiments.columns import ColumnKind, column_kind
from qrrt_circuits.experiments.records import (
    RecordSchema,
    RecordsError,
    RecordsWarning,
    RecordWriter,
    read_records,
)

OPTIONS = {"quick": True, "trials": 1, "progress": False}


@pytest.fixture(scope="module")
def corridor(tmp_path_factory):
    """A finished ``corridor`` run (figures included): the bytes of its files."""
    out = tmp_path_factory.mktemp("corridor")
    run_experiment("corridor", out=out, **OPTIONS)
    folder = out / "corridor"
    return {path.name: path.read_bytes() for path in folder.iterdir() if path.is_file()}


def _copy(files: dict[str, bytes], out: Path, name: str = "corridor") -> Path:
    folder = out / name
    folder.mkdir(parents=True)
    for file, content in files.items():
        (folder / file).write_bytes(content)
    return folder


def _schema() -> RecordSchema:
    return RecordSchema.of([Trial("RRT-0", {"planner": "RRT", "replicate": 0}, 7),
                            Trial("QRRT-0", {"planner": "QRRT", "replicate": 0}, 7)])


HEADER = "trial_id,seed,planner,replicate,nodes,status,positions_json\r\n"
GOOD = ['RRT-0,7,RRT,0,5,done,"[[1,2]]"\r\n', 'QRRT-0,7,QRRT,0,3,done,"[]"\r\n']


# ------------------------------------------------------------------------------- the vocabulary
def test_every_committed_record_fits_its_experiment():
    """The committed results: every row of every records.csv fits its experiment's schema."""
    folders = sorted(p.parent for p in Path("docs/results").glob("*/records.csv"))
    assert len(folders) >= 10
    for folder in folders:
        settings = json.loads((folder / "settings.json").read_text())
        schema = RecordSchema.of(EXPERIMENTS[folder.name].trials(settings))
        with warnings.catch_warnings():
            warnings.simplefilter("error", RecordsWarning)
            records = read_records(folder / "records.csv", schema)
        assert len(records) == len(schema.trials), folder


@pytest.mark.parametrize(("cell", "kind", "bad"), [
    ("3", ColumnKind.NUMBER, False), ("0.25", ColumnKind.NUMBER, False), ("nan", ColumnKind.NUMBER, False),
    ("abc", ColumnKind.NUMBER, True), ("", ColumnKind.NUMBER, True), ("True", ColumnKind.NUMBER, True),
    ("[[1,2]]", ColumnKind.JSON, False), ("[[1,2", ColumnKind.JSON, True), ("", ColumnKind.TEXT, False),
])
def test_column_kinds(cell, kind, bad):
    assert (kind.problem(cell) is not None) is bad


def test_column_names_mean_one_thing():
    assert column_kind("nodes") is ColumnKind.NUMBER and column_kind("nodes_at_40") is ColumnKind.NUMBER
    assert column_kind("status") is ColumnKind.TEXT and column_kind("curve_json") is ColumnKind.JSON
    assert column_kind("nodez") is None


# ------------------------------------------------------------------------------------- reading
def test_a_row_that_does_not_fit_its_trial_is_reported_and_excluded(tmp_path):
    path = tmp_path / "records.csv"
    path.write_text(HEADER + GOOD[0] + "QRRT-0,7,QRRT,0,abc,done,[]\r\n" + "QRRT-0,7,FOO,0,3,done,[]\r\n"
                    + "X-9,7,RRT,0,1,done,[]\r\n" + "QRRT-0,8,QRRT,0,3,done,[]\r\n" + "RRT-0,7,RRT\r\n")
    before = path.read_bytes()
    with pytest.warns(RecordsWarning) as caught:
        records = read_records(path, _schema())
    assert [r["trial_id"] for r in records] == ["RRT-0"]
    message = str(caught[0].message)
    assert str(path) in message and "5 row(s) excluded" in message
    for expected in ["line 3: column 'nodes': 'abc' is not a number",
                     "line 4: column 'planner': 'FOO' is not this trial's value 'QRRT'",
                     "line 5: column 'trial_id': 'X-9' is no trial of this run",
                     "line 6: column 'seed': '8' is not this trial's value '7'",
                     "line 7: 3 cells, the header has 7"]:
        assert expected in message
    assert path.read_bytes() == before  # reading never changes the file


def test_values_read_back_by_their_column_kind(tmp_path):
    path = tmp_path / "records.csv"
    path.write_text(HEADER + 'RRT-0,7,RRT,0,5,1,"[[1,2]]"\r\n')
    (record,) = read_records(path, _schema())
    assert record == {"trial_id": "RRT-0", "seed": 7, "planner": "RRT", "replicate": 0, "nodes": 5,
                      "status": "1", "positions_json": "[[1,2]]"}


@pytest.mark.parametrize(("header", "column"), [
    ("trial_id,seed,planner,replicate,nodez,status,positions_json", "nodez"),
    ("trial_id,seed,planr,replicate,nodes,status,positions_json", "planner"),
    ("trial_id,seed,planner,replicate,nodes,nodes,positions_json", "nodes"),
])
def test_a_header_that_does_not_fit_is_refused_naming_the_file_and_column(tmp_path, header, column):
    path = tmp_path / "records.csv"
    path.write_text(header + "\r\n" + GOOD[0])
    with pytest.raises(RecordsError, match=re.escape(f"{path} line 1: column {column!r}")):
        read_records(path, _schema())


def test_a_second_record_of_a_trial_is_excluded_the_first_counts(tmp_path):
    path = tmp_path / "records.csv"
    path.write_text(HEADER + GOOD[0] + 'RRT-0,7,RRT,0,9,done,"[]"\r\n')
    with pytest.warns(RecordsWarning, match="line 3: a second record of trial 'RRT-0' \\(line 2 counts\\)"):
        (record,) = read_records(path, _schema())
    assert record["nodes"] == 5


# ------------------------------------------------------------------------------------- writing
@pytest.mark.parametrize("cut", [0, 5, len(HEADER) - 2, len(HEADER) - 1, len(HEADER) + 4])
def test_the_writer_sets_a_torn_line_aside_and_never_loses_a_record(tmp_path, cut):
    path = tmp_path / "records.csv"
    path.write_text((HEADER + GOOD[0])[:cut])
    torn = path.read_bytes()
    complete = torn[:torn.rfind(b"\n") + 1]
    writer = RecordWriter(path, _schema())
    writer.write({"trial_id": "QRRT-0", "seed": 7, "planner": "QRRT", "replicate": 0, "nodes": 3,
                  "status": "done", "positions_json": "[]"})
    text = path.read_bytes()
    assert text.startswith(complete)
    assert [r["trial_id"] for r in read_records(path, _schema())] == ["QRRT-0"]
    aside = path.with_name("records.csv.torn")
    if torn == complete:  # nothing torn: nothing set aside
        assert not aside.exists()
    else:
        assert aside.read_bytes() == torn[len(complete):] + b"\n"


def test_the_writer_refuses_a_record_that_does_not_fit(tmp_path):
    writer = RecordWriter(tmp_path / "records.csv", _schema())
    with pytest.raises(ValueError, match="column 'nodes': 'many' is not a number"):
        writer.write({"trial_id": "RRT-0", "seed": 7, "planner": "RRT", "replicate": 0, "nodes": "many",
                      "status": "done", "positions_json": "[]"})
    assert not (tmp_path / "records.csv").exists()


# ------------------------------------------------------------------------------ runs resumed
def test_a_torn_header_keeps_every_later_run_whole(corridor, tmp_path):
    """The header without its line ending (``truncate -s 151``): the run starts again from nothing,
    and a second resume still gives the uninterrupted summary."""
    header = corridor["records.csv"].split(b"\n")[0]
    for cut in (len(header) - 1, len(header)):  # without "\r\n"; without "\n"
        files = {**corridor, "records.csv": corridor["records.csv"][:cut]}
        files.pop("summary.json")
        folder = _copy(files, tmp_path / str(cut))
        for _ in range(2):
            run_experiment("corridor", out=folder.parent, **OPTIONS)
            assert results_of(folder / "summary.json") == results_of(corridor["summary.json"])
            assert (folder / "records.csv").read_bytes() == corridor["records.csv"]
        assert (folder / "records.csv.torn").read_bytes() == corridor["records.csv"][:cut] + b"\n"


@pytest.mark.parametrize("edit", ["number", "planner", "width"])
def test_a_damaged_row_runs_its_trial_again_and_the_summary_is_unchanged(corridor, tmp_path, edit):
    lines = corridor["records.csv"].split(b"\r\n")
    cells = lines[1].split(b",")
    if edit == "number":
        cells[5] = b"abc"  # nodes
    elif edit == "planner":
        cells[2] = b"FOO"
    else:
        cells = cells[:3]
    damaged = b"\r\n".join([lines[0], b",".join(cells), *lines[2:]])
    folder = _copy({**corridor, "records.csv": damaged}, tmp_path)
    with pytest.warns(RecordsWarning, match=re.escape(f"{folder / 'records.csv'}: 1 row(s) excluded") + ".*line 2"):
        summary = run_experiment("corridor", out=folder.parent, **OPTIONS)
    assert summary["complete"]
    assert results_of(folder / "summary.json") == results_of(corridor["summary.json"])
    kept = b"\r\n".join([lines[0], *lines[2:]])
    assert (folder / "records.csv").read_bytes().startswith(kept)  # the damaged row moved aside, the rest kept
    assert (folder / "records.csv.excluded").read_bytes() == b",".join(cells) + b"\r\n"
    with warnings.catch_warnings():
        warnings.simplefilter("error", RecordsWarning)  # reported once: a later run finds nothing to exclude
        run_experiment("corridor", out=folder.parent, **OPTIONS)


def test_a_renamed_column_is_refused_in_one_line(corridor, tmp_path, capsys):
    renamed = corridor["records.csv"].replace(b",nodes,", b",nodez,", 1)
    folder = _copy({**corridor, "records.csv": renamed}, tmp_path)
    with pytest.raises(SystemExit) as exit_info:
        main(["reproduce", "corridor", "--quick", "--trials", "1", "--out", str(folder.parent), "--no-progress"])
    error = capsys.readouterr().err
    assert exit_info.value.code == 2
    assert re.search(re.escape(str(folder / "records.csv")) + r" line 1: column 'nodez'", error)
    assert "Traceback" not in error and error.count("\n") == 1
    assert (folder / "records.csv").read_bytes() == renamed


# ------------------------------------------------------------------ every folder checked first
def test_reproduce_all_refuses_a_late_conflict_before_any_experiment_runs(tmp_path, capsys):
    late = sorted(EXPERIMENTS)[-1]
    folder = tmp_path / late
    folder.mkdir()
    stored = {"seed": 99, "note": "another run's settings"}
    (folder / "settings.json").write_text(json.dumps(stored))
    with pytest.raises(SystemExit) as exit_info:
        main(["reproduce", "all", "--quick", "--out", str(tmp_path), "--no-progress"])
    assert exit_info.value.code == 2
    assert "holds results for other settings" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == [late]  # nothing ran, nothing was written
    assert json.loads((folder / "settings.json").read_text()) == stored


def test_a_refused_run_leaves_old_settings_as_they_were(tmp_path):
    """Settings from before predicates existed: a run with other settings is refused without
    adding the predicate to them; the same settings are accepted (and then completed)."""
    run_experiment("corridor", out=tmp_path, **OPTIONS)
    path = tmp_path / "corridor" / "settings.json"
    old = {k: v for k, v in json.loads(path.read_text()).items() if k != "predicate"}
    path.write_text(json.dumps(old))
    with pytest.raises(ValueError, match="holds results for other settings"):
        run_experiment("corridor", out=tmp_path, **{**OPTIONS, "seed": 5})
    assert json.loads(path.read_text()) == old
    run_experiment("corridor", out=tmp_path, **OPTIONS)
    assert json.loads(path.read_text()) == {**old, "predicate": "exact"}
