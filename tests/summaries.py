"""Comparing summaries of two runs: everything but their provenance (commit, machine, date)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any


def results_of(summary: bytes | str | Path) -> dict[str, Any]:
    """A ``summary.json`` (its bytes, text or path) without its ``provenance``.

    Two runs with the same settings write the same summary apart from its provenance; the rest is
    compared here as parsed JSON,.
    """
    if isinstance(summary, Path):
        summary = summary.read_bytes()
    parsed = json.loads(summary)
    parsed.pop("provenance")
    return parsed
