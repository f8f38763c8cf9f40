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


def _verdict(output: str) -> re.Match:
    match = re.search(r"^verdict: (\S+) needed fewer oracle calls per node than (\S+): (\S+) ([0-9.]+) \[([0-9.]+), "
                      r"([0-9.]+)\], (\S+) ([0-9.]+) \[([0-9.]+), ([0-9.]+)\] \(95 % bootstrap intervals over each "
                      r"plan's rounds\); the difference is (larger than|within) its spread", output, re.M)
    assert match, output
    return match


@pytest.mark.parametrize("planner", ["qrrt", "pqrrt"])
def test_the_last_line_is_a_verdict_that_the_table_confirms(capsys, planner):
    """The verdict names the plan with fewer oracle calls per node (the table's row), each value
    inside its own interval, and calls the difference larger than its spread exactly when the
    intervals are apart."""
    main(["plan", "--planner", planner, "--backend", "statevector", "--max-nodes", "60", "--seed", "1"])
    output = capsys.readouterr().out
    assert output.rstrip().splitlines()[-1].startswith("verdict: ")
    verdict = _verdict(output)
    fewer, more, first, value, low, high, second, other, other_low, other_high, spread = verdict.groups()
    quantum, classical = _row(output, "oracle calls per node")
    assert (first, second) == tuple(re.search(r"^  \s+(\S+)\s+(\S+)$", output, re.M).groups())
    assert (value, other) == (quantum, classical)
    assert float(low) <= float(value) <= float(high) and float(other_low) <= float(other) <= float(other_high)
    assert fewer == (first if float(value) < float(other) else second) and {fewer, more} == {first, second}
    apart = float(high) < float(other_low) or float(other_high) < float(low)
    assert (spread == "larger than") is apart


def test_the_note_names_the_reason_of_the_policy_that_ran(capsys):
    """A failed-verification note gives the reason of the policy that ran, not another's."""
    main(["plan", "--planner", "qrrt", "--backend", "statevector", "--policy", "fixed:8", "--max-nodes", "60",
          "--seed", "0"])
    output = capsys.readouterr().out
    assert qc.FixedIterations(8).miss_reason() in output
    assert "BBHT" not in output and "paper's fixed counts" not in output


def test_most_calls_classical_is_said_plainly(capsys):
    """Where verifications outnumber quantum calls (0 iterations: uniform draws) the output says so."""
    main(["plan", "--planner", "qrrt", "--backend", "statevector", "--policy", "fixed:0", "--max-nodes", "30",
          "--seed", "0"])
    output = capsys.readouterr().out
    verified = int(re.search(r"^  verification_calls\s+(\d+)$", output, re.M).group(1))
    assert re.search(r"^  quantum_oracle_calls\s+0$", output, re.M)
    assert f"note: most oracle calls were classical verifications ({verified} of {verified}; 0 quantum)" in output


def test_the_default_view_leaves_out_internals_and_none(capsys):
    main(["plan", "--planner", "qrrt", "--backend", "statevector", "--max-nodes", "10", "--no-compare"])
    output = capsys.readouterr().out
    settings = output.split("settings (--json writes every setting):")[1].split("metrics:")[0]
    assert "radius=0.75" in settings and "kind=ball" in settings
    for hidden in ("false_rejection_bound", "centre", "None", "dynamics"):
        assert hidden not in settings


def test_no_progress_bar_when_the_output_is_not_a_terminal(capsys):
    """Under capsys neither stream is a terminal: the bar stays quiet (stderr empty)."""
    main(["plan", "--planner", "rrt", "--max-nodes", "10"])
    captured = capsys.readouterr()
    assert captured.err == "" and "nodes" in captured.out
