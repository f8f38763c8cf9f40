"""records.csv: one row per finished trial, appended and flushed (fsync) as trials finish.

Reading the file never changes it:

- a line counts only once it ends with a line break, so a torn last line (the writer was killed
  mid-write, or the disk filled) is not a record; a torn first line is a torn header: the file
  holds no record yet;
- with a ``RecordSchema`` (the runner always gives one), the header must name the experiment's
  columns (``RecordsError`` naming the file and the column otherwise), and each row is checked
  against its trial: ``seed`` and the trial's parameters must be the trial's own values, and each
  measurement must be of its column's kind (``columns.ColumnKind``). A row that fails, has the
  wrong number of cells or names no trial of the run is excluded, never counted, and reported
  (file, line, column, value) in one ``RecordsWarning``; its trial runs again;
- a second valid row of a trial (a file concatenated by hand) is reported and excluded: each trial
  counts once, by its first valid row.

A run (which holds its folder's lock) compacts the file before it appends (``compact_records``):
excluded rows are moved to ``records.csv.excluded`` beside it and the file is rewritten whole
without them, so each is reported once.

Before appending, ``RecordWriter`` moves a torn last line out of the way: its bytes are appended to
``records.csv.torn`` beside it, then the file is cut back to its last line break. Only bytes that
were never a record are removed, so the count of valid records never decreases.
"""

from __future__ import annotations

import csv
import io
import os
import warnings
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

from .base import Trial
from .columns import ColumnKind, column_kind

__all__ = ["RecordSchema", "RecordWriter", "RecordsError", "RecordsWarning", "check_records_header", "compact_records",
           "read_records"]

#: the columns every record starts with
_KEYS = ("trial_id", "seed")
#: the most excluded rows a warning lists one by one
_LISTED = 5


class RecordsError(ValueError):
    """A records.csv whose header cannot be used; the message names the file and the column."""


class RecordsWarning(UserWarning):
    """Rows of a records.csv were excluded (each named by file, line, column and value)."""


def cell_text(value: Any) -> str:
    """The text a value is written as in records.csv (None as an empty cell).

    Args:
        value: A JSON scalar.

    Returns:
        Its cell text.
    """
    return "" if value is None else str(value)


@dataclass(frozen=True)
class RecordSchema:
    """What each row of one run's records.csv must hold: the run's trials, by id.

    Attributes:
        trials: Every trial of the run, by id.
    """

    trials: Mapping[str, Trial]

    @classmethod
    def of(cls, trials: Iterable[Trial]) -> RecordSchema:
        """The schema of a run of ``trials``.

        Args:
            trials: The run's trials (unique ids).

        Returns:
            The schema.
        """
        return cls({trial.id: trial for trial in trials})

    def header_problem(self, header: list[str]) -> str | None:
        """Why ``header`` is not a header of this run's records, or None if it is one.

        Args:
            header: The column names of the file's first line.

        Returns:
            A reason naming the column, or None.
        """
        seen: set[str] = set()
        for name in header:
            if name in seen:
                return f"column {name!r} appears twice"
            seen.add(name)
        parameters = {name for trial in self.trials.values() for name in trial.params}
        for name in (*_KEYS, *sorted(parameters)):
            if name not in seen:
                return f"column {name!r} is missing"
        for name in header:
            if name not in parameters and name not in _KEYS and column_kind(name) is None:
                return f"column {name!r} is not a column of any experiment's records"
        return None

    def row_problem(self, row: Mapping[str, str]) -> str | None:
        """Why ``row`` (column name to cell text) is not a record of its trial, or None.

        Args:
            row: One row of a file whose header passed ``header_problem``.

        Returns:
            A reason naming the column and the value, or None.
        """
        trial = self.trials.get(row["trial_id"])
        if trial is None:
            return f"column 'trial_id': {row['trial_id']!r} is no trial of this run"
        expected = {"seed": cell_text(trial.seed), **{name: cell_text(v) for name, v in trial.params.items()}}
        for name, text in expected.items():
            if row[name] != text:
                return f"column {name!r}: {row[name]!r} is not this trial's value {text!r}"
        for name, cell in row.items():
            kind = column_kind(name)
            if name in expected or name in _KEYS or kind is None:  # (another trial's parameter)
                continue
            problem = kind.problem(cell)
            if problem is not None:
                return f"column {name!r}: {problem}"
        return None


def _convert(value: str) -> int | float | bool | str | None:
    if value == "":
        return None
    for kind in (int, float):
        try:
            return kind(value)
        except ValueError:
            pass
    if value in ("True", "False"):
        return value == "True"
    return value


def _value(name: str, cell: str) -> int | float | bool | str | None:
    """A cell read back: text columns stay text, other cells are converted (``_convert``)."""
    if column_kind(name) is ColumnKind.TEXT:
        return cell or None
    return _convert(cell)


def _lines(path: Path) -> list[str]:
    """The file's complete lines (a last line without its line break is torn: left out)."""
    text = path.read_bytes().decode("utf-8", errors="replace")
    return text.split("\n")[:-1]


def _read(path: Path, schema: RecordSchema | None) -> tuple[list[dict[str, Any]], list[str], list[str], list[str]]:
    """(records, the valid lines with the header first, the excluded lines, why each was excluded)."""
    lines = _lines(path) if path.exists() else []
    if not lines:
        return [], [], [], []
    header = next(csv.reader([lines[0]]))
    if schema is not None:
        _check_header(path, header, schema)
    excluded: list[str] = []
    why: list[str] = []
    kept = [lines[0]]
    first_line: dict[str, int] = {}
    records: list[dict[str, Any]] = []
    for number, line in enumerate(lines[1:], start=2):
        cells = next(csv.reader([line]), [])
        if len(cells) != len(header):
            excluded.append(line)
            why.append(f"line {number}: {len(cells)} cells, the header has {len(header)}")
            continue
        row = dict(zip(header, cells, strict=True))
        problem = schema.row_problem(row) if schema is not None else None
        if problem is None and "trial_id" in row and row["trial_id"] in first_line:
            problem = f"a second record of trial {row['trial_id']!r} (line {first_line[row['trial_id']]} counts)"
        if problem is not None:
            excluded.append(line)
            why.append(f"line {number}: {problem}")
            continue
        if "trial_id" in row:
            first_line[row["trial_id"]] = number
        kept.append(line)
        records.append({name: _value(name, cell) for name, cell in row.items()})
    return records, kept, excluded, why


def _listed(why: list[str]) -> str:
    return "; ".join(why[:_LISTED]) + (f"; and {len(why) - _LISTED} more" if len(why) > _LISTED else "")


def read_records(path: Path, schema: RecordSchema | None = None) -> list[dict[str, Any]]:
    """The valid records of a records.csv (see the module docstring); the file is not changed.

    Args:
        path: The ``records.csv`` file (need not exist).
        schema: The run's schema; None checks only each row's width and the trial ids' uniqueness.

    Returns:
        One dict per valid row, in file order, column name to value (numbers and booleans converted
        back, text columns kept as text, empty cells as None); ``[]`` for a missing file or one
        without a complete header.

    Raises:
        RecordsError: The header does not fit ``schema``.

    Warns:
        RecordsWarning: Once, listing the rows excluded.
    """
    records, _, _, why = _read(path, schema)
    if why:
        warnings.warn(f"{path}: {len(why)} row(s) excluded, never counted (their trials run again): {_listed(why)}",
                      RecordsWarning, stacklevel=2)
    return records


def compact_records(path: Path, schema: RecordSchema) -> list[dict[str, Any]]:
    """``read_records``, and where rows were excluded, the file rewritten without them: the
    excluded lines are appended to ``records.csv.excluded`` beside it (flushed to disk) first, then
    the header and the valid rows replace the file whole (``output_files.write_replacing``). Only
    the writer holding the folder's lock (``_support.folder_lock``) may call it.

    Args:
        path: The ``records.csv`` file (need not exist).
        schema: The run's schema.

    Returns:
        The valid records, as ``read_records`` returns them.

    Raises:
        RecordsError: The header does not fit ``schema``.

    Warns:
        RecordsWarning: Once, listing the rows moved aside (a later read finds none).
    """
    from .._support.output_files import write_replacing

    records, kept, excluded, why = _read(path, schema)
    if not excluded:
        return records
    aside = path.with_name(path.name + ".excluded")
    with aside.open("a", encoding="utf-8") as handle:
        handle.write("".join(line + "\n" for line in excluded))
        handle.flush()
        os.fsync(handle.fileno())
    text = "".join(line + "\n" for line in kept)

    def write(handle: IO[Any]) -> None:
        handle.write(text)

    write_replacing(path, write)
    warnings.warn(f"{path}: {len(why)} row(s) excluded, never counted (their trials run again), and moved to "
                  f"{aside.name}: {_listed(why)}", RecordsWarning, stacklevel=2)
    return records


def check_records_header(path: Path, schema: RecordSchema) -> None:
    """Refuse a records.csv whose (complete) header does not fit ``schema``; reads only its first line.

    Args:
        path: The ``records.csv`` file (need not exist).
        schema: The run's schema.

    Raises:
        RecordsError: The header does not fit, naming the file and the column.
    """
    if not path.exists():
        return
    with path.open("rb") as handle:
        first = handle.readline()
    if first.endswith(b"\n"):  # (a torn header is no header: the file holds no record yet)
        _check_header(path, next(csv.reader([first.decode("utf-8", errors="replace")])), schema)


def _check_header(path: Path, header: list[str], schema: RecordSchema) -> None:
    problem = schema.header_problem(header)
    if problem is not None:
        raise RecordsError(f"{path} line 1: {problem}, so its records cannot be checked; move the file away "
                           "(or use another --out) and run again")


def _set_torn_tail_aside(path: Path) -> None:
    """Append a torn last line's bytes to ``records.csv.torn`` and cut the file back to its last
    line break (nothing else is removed)."""
    with path.open("rb") as handle:
        data = handle.read()
    if not data or data.endswith(b"\n"):
        return
    keep = data.rfind(b"\n") + 1  # 0: the header itself is torn
    aside = path.with_name(path.name + ".torn")
    with aside.open("ab") as handle:
        handle.write(data[keep:] + b"\n")
        handle.flush()
        os.fsync(handle.fileno())
    os.truncate(path, keep)


class RecordWriter:
    """Appends records to records.csv, one flushed line per trial.

    Args:
        path: The ``records.csv`` file; an existing file's header fixes the columns. A torn last
            line is set aside first (see the module docstring).
        schema: The run's schema: a record that does not fit it is refused before it is written.
    """

    def __init__(self, path: Path, schema: RecordSchema | None = None) -> None:
        self.path = path
        self.schema = schema
        self.header: list[str] | None = None
        if path.exists():
            _set_torn_tail_aside(path)
            lines = _lines(path)
            if lines:
                self.header = next(csv.reader([lines[0]]))

    def write(self, record: dict[str, Any]) -> None:
        """Append ``record`` as one row and flush it to disk (fsync).

        Args:
            record: Column name to value; the first record written fixes the columns.

        Raises:
            ValueError: Its columns differ from the file's header, or it does not fit the schema
                (a bug in the experiment that made it).
            OSError: The write failed (a full disk); the message names the file and says that a
                re-run resumes.
        """
        header = self.header or list(record)
        if set(record) != set(header):
            raise ValueError(f"record columns {sorted(record)} differ from the file's {sorted(header)}")
        cells = [cell_text(record[name]) for name in header]
        if self.schema is not None:
            problem = self.schema.header_problem(header) or self.schema.row_problem(dict(zip(header, cells,
                                                                                          strict=True)))
            if problem is not None:
                raise ValueError(f"trial {record.get('trial_id')!r} made a record that does not fit the "
                                 f"records of its experiment: {problem}")
        text = io.StringIO()
        writer = csv.writer(text)
        if self.header is None:
            writer.writerow(header)
        writer.writerow(cells)
        try:
            with self.path.open("a", newline="") as handle:
                handle.write(text.getvalue())
                handle.flush()
                os.fsync(handle.fileno())
        except OSError as exc:
            raise OSError(exc.errno, f"{self.path}: {exc.strerror or exc}; the records written before are kept "
                                     "(run the same command again to resume)") from exc
        self.header = header
