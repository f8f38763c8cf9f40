"""The vocabulary of ``records.csv``: what each measurement column holds.

A column name means one thing in every experiment (``nodes`` is a tree's node count wherever it
appears), so one table says what each holds. A record's other columns are ``trial_id``, ``seed`` and
its trial's parameters, whose values the runner knows exactly (``RecordSchema`` checks them against
the trial). A column that is neither is not a column of any experiment: a header naming one is
refused (a renamed column), and a record with one is a bug in the experiment that wrote it.

Kinds:

- ``NUMBER``: an integer or a float (``nan`` and ``inf`` included, written by rows that measure
  nothing there); never empty.
- ``TEXT``: any text, or empty (no value).
- ``JSON``: JSON text (arrays stored in one cell by ``measures.dumps``).
"""

from __future__ import annotations

import json
import re
from enum import Enum


class ColumnKind(Enum):
    """What one measurement column of ``records.csv`` holds."""

    NUMBER = "number"
    TEXT = "text"
    JSON = "json"

    def problem(self, cell: str) -> str | None:
        """Why ``cell`` (the CSV text) is not a value of this kind, or None if it is one.

        Args:
            cell: The cell as written in the file.

        Returns:
            A short reason (``"'abc' is not a number"``), or None.
        """
        if self is ColumnKind.TEXT:
            return None
        if self is ColumnKind.JSON:
            try:
                json.loads(cell)
            except ValueError:
                return f"{_shown(cell)} is not JSON text"
            return None
        try:
            float(cell)  # (an integer's text is a float's too; so are nan and inf)
        except ValueError:
            return f"{_shown(cell)} is not a number"
        return None

#: measurement columns by exact name
_NAMED: dict[str, ColumnKind] = {
    **dict.fromkeys(("cut_on", "method", "source", "status"), ColumnKind.TEXT),
    **dict.fromkeys((
        # tree growth and oracle-call accounting (DESIGN section 2)
        "nodes", "rounds", "oracle_calls", "quantum_oracle_calls", "verification_calls",
        "critical_path_calls", "critical_path_oracle_calls", "simulation_checks", "duplicates", "rejected",
        "databases", "estimation_calls", "estimated_k_total", "calls_per_node", "reachable_fraction",
        "invalid_edges", "invalid_edges_fine", "in_channel", "through_channel", "start_distance", "wall_time_s",
        "free_fraction",
        # problem families
        "reached", "classical_checks", "path_length", "path_length_simplified", "first_solution_calls",
        # coherent oracle
        "qubits", "gates", "entries", "marked", "mismatches", "ancillas_clean", "index_preserved", "rounding_compared",
        "rounding_differs", "hits", "expected", "search_s", "toffolis", "lookup_qrom_ands",
        "lookup_select_swap_ands",
        # searches and lemmas
        "iterations", "oracle_marked", "true_marked", "missed_good", "p_good", "repeats", "m",
        # noise
        "p1", "one_qubit_gates", "two_qubit_gates", "ideal", "fidelity", "white_noise", "shots",
        "successes", "success", "success_low", "success_high", "collision", "effective_false_positive",
        "collision_uniform", "collision_false_positive_model",
        # resources
        "two_qubit_depth", "depth", "physical_qubits", "oracle_ands", "oracle_t", "diffuser_ands", "t_count",
        "toffoli_equivalents",
    ), ColumnKind.NUMBER),
}

#: measurement columns by pattern (families whose names carry a setting)
_PATTERNS: tuple[tuple[re.Pattern[str], ColumnKind], ...] = (
    (re.compile(r"(nodes|calls)_at_\d+(_total)?"), ColumnKind.NUMBER),  # a growth curve cut at a call budget
    (re.compile(r"cost_at_\d+"), ColumnKind.NUMBER),  # an anytime planner's best path cost at a share of its budget
    (re.compile(r"lemma\d+_(observed|theory|stderr)"), ColumnKind.NUMBER),
    (re.compile(r"mean_parent_distance_\d+"), ColumnKind.NUMBER),
    (re.compile(r"[a-z_]+_json"), ColumnKind.JSON),
)


def column_kind(name: str) -> ColumnKind | None:
    """The kind of measurement column ``name``, or None if no experiment writes such a column.

    Args:
        name: A ``records.csv`` column name.

    Returns:
        Its ``ColumnKind``, or None for a name outside the vocabulary.
    """
    if name in _NAMED:
        return _NAMED[name]
    for pattern, kind in _PATTERNS:
        if pattern.fullmatch(name):
            return kind
    return None


def _shown(cell: str, limit: int = 40) -> str:
    """``cell`` quoted for a message, shortened to ``limit`` characters."""
    return repr(cell if len(cell) <= limit else cell[:limit] + "...")
