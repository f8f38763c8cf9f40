"""records.csv: one row per finished trial, appended and flushed as trials finish.

A torn last line (the writer was killed mid-write) or a row of the wrong width is dropped and the
file rewritten without it, so an interrupted run loses at most the trials in flight. Records are
keyed by ``trial_id``: a second row with the same id (a file edited or concatenated by hand) is
dropped with a warning, so no trial is ever counted twice.
"""

from __future__ import annotations

import csv
import os
import warnings
from pathlib import Path
from typing import Any


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


def read_records(path: Path) -> list[dict[str, Any]]:
    """Rows of a records.csv (numbers converted). A torn last line (no newline: the writer was
    killed mid-write) or a row of the wrong width is dropped and the file rewritten without it.

    Args:
        path: The ``records.csv`` file (need not exist).

    Returns:
        One dict per kept row, column name to value (ints, floats and booleans converted back,
        empty cells as None); ``[]`` for a missing or empty file.

    Warns:
        UserWarning: For each dropped second row of a ``trial_id``.
    """
    if not path.exists():
        return []
    text = path.read_text()
    lines = text.split("\n")
    torn = bool(lines and lines[-1])  # text does not end with a newline
    lines = lines[:-1]
    rows = list(csv.reader(lines))
    if not rows:
        return []
    header, body = rows[0], rows[1:]
    good = [row for row in body if len(row) == len(header)]
    if "trial_id" in header:
        column, seen, unique = header.index("trial_id"), set(), []
        for row in good:
            if row[column] in seen:
                warnings.warn(f"{path}: a second record of trial {row[column]!r} was dropped (each trial "
                              "counts once)", stacklevel=2)
                continue
            seen.add(row[column])
            unique.append(row)
        good = unique
    if torn or len(good) != len(body):
        _rewrite(path, header, good)
    return [{key: _convert(value) for key, value in zip(header, row, strict=True)} for row in good]


def _rewrite(path: Path, header: list[str], rows: list[list[str]]) -> None:
    temporary = path.with_suffix(".tmp")
    with temporary.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(header)
        writer.writerows(rows)
    os.replace(temporary, path)


class RecordWriter:
    """Appends records to records.csv, one flushed line per trial.

    Args:
        path: The ``records.csv`` file; an existing file's header fixes the columns.
    """

    def __init__(self, path: Path) -> None:
        self.path = path
        self.header: list[str] | None = None
        if path.exists() and path.stat().st_size:
            with path.open(newline="") as handle:
                self.header = next(csv.reader(handle), None)

    def write(self, record: dict[str, Any]) -> None:
        """Append ``record`` as one row and flush it to disk (fsync).

        Args:
            record: Column name to value; the first record written fixes the columns.

        Raises:
            ValueError: If its columns differ from the file's header.
        """
        if self.header is None:
            self.header = list(record)
            with self.path.open("w", newline="") as handle:
                csv.writer(handle).writerow(self.header)
        if set(record) != set(self.header):
            raise ValueError(f"record columns {sorted(record)} differ from the file's {sorted(self.header)}")
        with self.path.open("a", newline="") as handle:
            csv.writer(handle).writerow(["" if record[key] is None else record[key] for key in self.header])
            handle.flush()
            os.fsync(handle.fileno())
