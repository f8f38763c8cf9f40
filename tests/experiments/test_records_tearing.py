"""A finished run's files torn at every byte offset, then resumed.

Each of ``records.csv``, ``settings.json`` and ``summary.json`` of a small finished run is cut at
every byte offset (its first line included) and the run resumed: the resumed ``summary.json`` is
byte-identical to the uninterrupted run's, or the run refuses naming the torn file; the valid
records never decrease, and the file is only ever appended to (what it held up to its last line
break is still its first bytes).

The run is the real ``corridor`` experiment (real plans on Aer) with its figures left out, so
that the ~1 400 resumes stay fast; ``tests/experiments/test_records.py`` tears a run with figures at its line
boundaries.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import pytest
from summaries import results_of

from qrrt_circuits.experiments import EXPERIMENTS, run_experiment
from qrrt_circuits.experiments.corridor import Corridor
from qrrt_circuits.experiments.records import RecordSchema, read_records


class CorridorWithoutFigures(Corridor):
    """The corridor experiment, its trials and summary unchanged, drawing no figure."""

    name = "corridor-without-figures"

    def plot(self, records, settings, summary, out_dir):
        return []


NAME = CorridorWithoutFigures.name
OPTIONS = {"quick": True, "trials": 1, "progress": False}


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """A finished run: its folder and the bytes of its three files."""
    EXPERIMENTS[NAME] = CorridorWithoutFigures()
    out = tmp_path_factory.mktemp("finished")
    try:
        run_experiment(NAME, out=out, **OPTIONS)
        folder = out / NAME
        yield {name: (folder / name).read_bytes() for name in ("records.csv", "settings.json", "summary.json")}
    finally:
        del EXPERIMENTS[NAME]


@pytest.fixture
def registered(monkeypatch):
    monkeypatch.setitem(EXPERIMENTS, NAME, CorridorWithoutFigures())


def _schema(settings_bytes: bytes) -> RecordSchema:
    import json

    return RecordSchema.of(EXPERIMENTS[NAME].trials(json.loads(settings_bytes)))


def _valid(path: Path, schema: RecordSchema) -> int:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return len(read_records(path, schema))


@pytest.mark.parametrize("torn", ["records.csv", "settings.json", "summary.json"])
def test_a_file_torn_at_every_offset_resumes_to_the_same_summary_or_is_refused(torn, finished, registered,
                                                                                tmp_path):
    schema = _schema(finished["settings.json"])
    whole = finished[torn]
    refused = resumed = 0
    for offset in range(len(whole)):
        folder = tmp_path / str(offset) / NAME
        folder.mkdir(parents=True)
        for name, content in finished.items():
            (folder / name).write_bytes(content[:offset] if name == torn else content)
        records = folder / "records.csv"
        valid_before = _valid(records, schema)
        kept = records.read_bytes()
        kept = kept[:kept.rfind(b"\n") + 1]  # what the file held up to its last line break
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                run_experiment(NAME, out=folder.parent, **OPTIONS)
        except ValueError as exc:
            assert torn != "records.csv", f"offset {offset}: a torn records.csv was refused: {exc}"
            assert re.search(re.escape(str(folder / torn)), str(exc)), f"offset {offset}: {exc}"
            assert records.read_bytes() == finished["records.csv"]  # a refusal writes nothing
            refused += 1
            continue
        resumed += 1
        assert results_of(folder / "summary.json") == results_of(finished["summary.json"]), f"offset {offset}"
        assert records.read_bytes().startswith(kept), f"offset {offset}: records.csv was rewritten"
        assert _valid(records, schema) >= valid_before, f"offset {offset}"
        assert _valid(records, schema) == len(schema.trials), f"offset {offset}"
    if torn == "settings.json":  # only the whole file, or the file without its last line break, is JSON
        assert resumed <= 1 and refused == len(whole) - resumed
    else:
        assert resumed == len(whole)
