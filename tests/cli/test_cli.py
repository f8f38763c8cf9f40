import re

import pytest
from tolerances import binomial_counts

from qrrt_circuits.cli import main


@pytest.mark.parametrize("backend", ["aer", "statevector"])
def test_search_command(capsys, backend):
    assert main(["search", "--qubits", "6", "--marked", "3", "--shots", "500",
                 "--backend", backend, "--seed", "1"]) == 0
    out = capsys.readouterr().out
    rate = float(re.search(r"success rate\s+([0-9.]+)", out).group(1))
    theory = float(re.search(r"sin\^2\(\(2k\+1\)th\)\s+([0-9.]+)", out).group(1))
    low, high = binomial_counts(500, theory)
    # both numbers are printed to 4 decimals: each may be off by 5e-5
    assert low / 500 - 1e-4 <= rate <= high / 500 + 1e-4
    assert "classical lookup" in out


def test_search_table_columns_line_up_for_wide_indices(capsys):
    """Indices of 6 digits (n = 18) and of 1 digit share one layout: every row of the table has its
    fields at the header's columns."""
    assert main(["search", "--qubits", "18", "--marked", "3", "--iterations", "0", "--shots", "40",
                 "--backend", "statevector", "--top", "40"]) == 0
    lines = capsys.readouterr().out.splitlines()
    header = next(i for i, line in enumerate(lines) if "bitstring" in line)
    rows = [line for line in lines[header + 1:] if line.startswith("  ")]
    assert len(rows) >= 30
    count_end = lines[header].index("count") + len("count")
    for row in rows:
        index, bits, count, marked = row.split()
        assert len(bits) == 18 and int(bits, 2) == int(index) and marked in ("yes", "no")
        assert row.index(count, lines[header].index("bitstring") + 18) + len(count) == count_end
        assert row.index(index) + len(index) == lines[header].index("index") + len("index")


def test_search_command_rejects_bad_input(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["search", "--qubits", "4", "--marked", "17"])
    assert exc.value.code == 2
    assert "--marked must be in [0, 2**qubits = 16]" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["search", "--shots", "0"])


def test_plan_command_writes_json_and_plot(tmp_path, capsys):
    import json

    out_json, out_png = tmp_path / "r.json", tmp_path / "t.png"
    assert main(["plan", "--planner", "qrrt", "--backend", "statevector", "--policy", "adaptive",
                 "--max-nodes", "15", "--seed", "2", "--json", str(out_json), "--plot", str(out_png)]) == 0
    out = capsys.readouterr().out
    assert "oracle_calls" in out and "classical lookup" in out
    data = json.loads(out_json.read_text())
    assert data["planner"] == "QRRT" and data["metrics"]["nodes"] == len(data["nodes"]) - 1
    assert data["metrics"]["oracle_calls"] == data["metrics"]["quantum_oracle_calls"] + \
        data["metrics"]["verification_calls"]
    assert out_png.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("argv, message", [
    (["plan", "--policy", "fixed:abc"], "fixed:K needs an integer"),
    (["plan", "--policy", "magic"],
     "unknown search policy 'magic'; choose one of paper, optimal, bbht, adaptive, thompson, fixed:K, "
     "fixed-point[:DELTA], estimated"),
    (["plan", "--planner", "qrrt", "--backend", "statevector", "--qubits", "40"], "num_qubits = 40 is outside"),
])
def test_plan_command_rejects_bad_input(argv, message, capsys):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    assert message in capsys.readouterr().err


def test_plan_says_in_words_whether_its_budget_or_a_safety_limit_ended_it(tmp_path, capsys):
    import json

    ring = [[[4, 4], [6, 4.99]], [[4, 5.01], [6, 6]], [[4, 4.99], [4.99, 5.01]], [[5.01, 4.99], [6, 5.01]]]
    world = tmp_path / "walled.json"
    world.write_text(json.dumps({"format": "qrrt-environment", "version": 1, "bounds": [[0, 10], [0, 10]],
                                 "boxes": ring, "start": [5, 5], "goal": [9, 9], "goal_radius": 0.5}))
    common = ["plan", "--planner", "rrt", "--scenario-file", str(world), "--no-compare"]
    assert main([*common, "--max-oracle-calls", "6000"]) == 0
    out = capsys.readouterr().out
    assert "max_oracle_calls: ended by a limit you set: 6000 oracle calls were spent" in out
    assert main([*common, "--max-nodes", "5", "--stall-rounds", "300"]) == 0
    assert "stalled: ended by a limit you set: 300 rounds in a row added no node" in capsys.readouterr().out
    assert main([*common, "--max-nodes", "5"]) == 0
    assert "stalled: ended by a safety limit, not one you set: 5000 rounds" in capsys.readouterr().out
