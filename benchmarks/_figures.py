"""Flat figures from a benchmark's JSON, and which way each figure is better.

A figure is a number under a dotted key, ``search.search.aer.qubits12.median_s`` say: the
benchmark's short name, then the path through its JSON. A benchmark may put a flat ``"figures"``
object of its own in its JSON (``{"n12.ms": 45.0}``); otherwise every number of its JSON is a
figure, except the ``machine`` description, booleans and lists of plain numbers (raw samples).
An item of a list of objects is named by its text fields and its identity numbers (``qubits``,
``seed``, ...), e.g. ``aer.qubits12``, or by its position when it has none.

Direction, read from the key's components, last first; the first that matches decides:
higher is better for throughputs and speed-ups (``*per_s*``, ``*speedup*``, ``*throughput*``);
lower is better for times and memory (``*_s``, ``*_ms``, ``*_us``, ``ms``, ``s``, ``ms_per_*``,
``*seconds*``, ``*bytes*``, ``*_mib``, ``*_mb``, ``*rss*``); any other figure (counts, settings,
calls per node) is informational: reported, never called a regression.
"""

from __future__ import annotations

import re

LOWER, INFO, HIGHER = -1, 0, 1

#: integer fields that name a list item rather than measure it
IDENTITY_FIELDS = ("qubits", "num_qubits", "n", "seed", "world", "workers", "jobs", "dimension")

_HIGHER = re.compile(r"per_s|speedup|throughput")
_LOWER = re.compile(r"(_s|_ms|_us|_ns)$|^(s|ms|us|ns|seconds)$|^(s|ms|us)_per_|seconds|bytes|_mib$|_mb$|rss")


def direction(key: str) -> int:
    """``LOWER`` (-1) if a smaller value is better, ``HIGHER`` (1) if a larger one is, else ``INFO`` (0)."""
    for part in reversed(key.lower().split(".")):
        if _HIGHER.search(part):
            return HIGHER
        if _LOWER.search(part):
            return LOWER
    return INFO


def _label(item: dict, index: int) -> str:
    parts = [str(v) for k, v in item.items() if isinstance(v, str) and k not in ("note", "labels")]
    parts += [f"{k}{v}" for k, v in item.items()
              if k in IDENTITY_FIELDS and isinstance(v, int) and not isinstance(v, bool)]
    return ".".join(part.replace(".", "_") for part in parts) or str(index)


def flatten(payload, prefix: str = "") -> dict[str, float]:
    """Every number of ``payload`` under its dotted key (see the module docstring)."""
    out: dict[str, float] = {}
    if isinstance(payload, dict):
        if isinstance(payload.get("figures"), dict) and not prefix.endswith(".figures"):
            return {f"{prefix}{k}" if not prefix else f"{prefix}.{k}": float(v)
                    for k, v in payload["figures"].items() if _is_number(v)}
        for key, value in payload.items():
            if key == "machine":
                continue
            out.update(flatten(value, f"{prefix}.{key}" if prefix else str(key)))
    elif isinstance(payload, list):
        if payload and all(isinstance(item, dict) for item in payload):
            seen: dict[str, int] = {}
            for index, item in enumerate(payload):
                label = _label(item, index)
                seen[label] = seen.get(label, 0) + 1
                if seen[label] > 1:
                    label = f"{label}.{index}"
                rest = {k: v for k, v in item.items() if k not in IDENTITY_FIELDS}  # named in the label
                out.update(flatten(rest, f"{prefix}.{label}" if prefix else label))
    elif _is_number(payload):
        out[prefix] = float(payload)
    return out


def _is_number(value) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool) and value == value
