"""`qrrt plan` prints a quantum plan beside its classical peer's, names the critical path, and says
when most measurements failed verification."""

from __future__ import annotations

import re

import pytest

import qrrt_circuits as qc
from qrrt_circuits.cli import main


def _row(output: str, label: str) -> list[str]:
    match = re.search(rf"^  {re.escape(label)}\s+(\S+)\s+(\S+)$", output, re.M)
    assert match, (label, output)
    return [match.group(1), match.group(2)]


def test_pq_rrt_is_printed_beside_parallel_rrt_planned_alike(capsys):
    main(["plan", "--planner", "pqrrt", "--backend", "statevector", "--max-nodes", "40", "--seed", "3"])
    output = capsys.readouterr().out
    assert "beside ParallelRRT (the same world, seed, predicate and limits" in output
    env = qc.paper_clutter(seed=0)
    peer = qc.ParallelRRT(workers=8, seed=3).plan(env, max_nodes=40).metrics
    assert _row(output, "oracle calls")[1] == str(peer.oracle_calls)
    assert _row(output, "critical-path calls")[1] == str(peer.critical_path_oracle_calls)
    assert _row(output, "nodes")[1] == str(peer.nodes)
    assert "critical-path calls: per round, the most calls any one worker made" in output


@pytest.mark.parametrize(("policy", "noted"), [("fixed:8", True), ("optimal", False)])
def test_the_note_says_when_most_measurements_fail(capsys, policy, noted):
    main(["plan", "--planner", "qrrt", "--backend", "statevector", "--policy", policy, "--max-nodes", "60",
          "--seed", "0"])
    output = capsys.readouterr().out
    rejected = int(re.search(r"^  rejected\s+(\d+)$", output, re.M).group(1))
    verified = int(re.search(r"^  verification_calls\s+(\d+)$", output, re.M).group(1))
    assert (rejected / verified > 0.5) is noted
    assert ("failed verification" in output) is noted


def test_no_comparison_for_a_classical_planner_or_on_request(capsys):
    main(["plan", "--planner", "rrt", "--max-nodes", "20"])
    assert "beside" not in capsys.readouterr().out
    main(["plan", "--planner", "qrrt", "--backend", "statevector", "--max-nodes", "20", "--no-compare"])
    assert "beside" not in capsys.readouterr().out
