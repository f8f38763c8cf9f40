"""Every user error on the command line exits non-zero with one line on stderr and no traceback,
before any work is done (a table of the cases the reliability review found)."""

import json
import subprocess
import sys
from pathlib import Path

import pytest


def scenario_file(tmp_path, **fields):
    data = {"format": "qrrt-environment", "version": 1, "bounds": [[0, 20], [0, 20]], "boxes": [],
            "start": [1, 1], "goal": [19, 19], "goal_radius": 0.75} | fields
    path = tmp_path / "world.json"
    path.write_text(json.dumps(data))
    return str(path)


CASES = [
    (["plan", "--json", "."], "is a folder"),
    (["plan", "--json", "/proc/x"], "cannot be written"),
    (["plan", "--plot", "t.xyz"], "must end in one of"),
    (["plan", "--planner", "nope"], "unknown planner 'nope'"),
    (["plan", "--policy", "fixed:abc"], "fixed:K needs an integer"),
    (["plan", "--predicate", "time-samples:1"], "time_samples must be an integer"),
    (["plan", "--planner", "qrrt", "--backend", "statevector", "--qubits", "40"], "num_qubits = 40"),
    (["plan", "--goal-bias", "1.5"], "--goal-bias must be a finite number in [0.0, 1.0), got 1.5"),
    (["plan", "--goal-bias", "1"], "--goal-bias must be a finite number in [0.0, 1.0), got 1.0"),
    (["plan", "--max-extension", "0"], "--max-extension must be a finite number > 0.0, got 0.0"),
    (["plan", "--max-extension", "nan"], "--max-extension must be a finite number > 0.0"),
    (["plan", "--json", ""], "--json must name a file (for the standard output, /dev/stdout), got ''"),
    (["plan", "--json", "-"], "--json must name a file (for the standard output, /dev/stdout), got '-'"),
    (["plan", "--scenario-file", "."], "is a folder, not a scenario file"),
    (["plan", "--json", "same.png", "--plot", "same.png"], "--json and --plot name the same file"),
    (["search", "--shots", "1000000000"], "shots must be an integer in [1, 10000000]"),
    (["search", "--iterations", "1000000"], "iterations must be an integer in [0, 100000]"),
    (["search", "--qubits", "1000000000000"], "num_qubits = 1000000000000 is outside the range"),
    (["reproduce", "heatmaps", "--trials", "1000000000"], "trials must be an integer in [1, 100000]"),
    (["reproduce", "lemmas", "--predicate", "authors"], "does not take a predicate"),
    (["reproduce", "nope"], "EXPERIMENT must be one of"),
    (["reproduce", "lemmas", "--out", ""], "--out must name a folder"),
    (["reproduce", "lemmas", "--jobs", "4"], "--jobs needs --executor process or dask"),
    (["reproduce", "lemmas", "--executor", "process", "--jobs", "100000"], "jobs must be an integer in [1, "),
    (["plan", "--planner", "rrt", "--qubits", "30"], "--qubits does not apply to --planner rrt"),
    (["plan", "--planner", "rrt", "--backend", "statevector"], "--backend does not apply to --planner rrt"),
    (["plan", "--planner", "prrt", "--policy", "bbht"], "--policy does not apply to --planner prrt"),
    (["plan", "--planner", "qrrt", "--workers", "4"], "--workers does not apply to --planner qrrt"),
    (["plan", "--planner", "rrt", "--max-rounds", "10000000000000", "--max-nodes", "10000000000000"],
     "max_nodes = 10000000000000: this plan could need about"),
]


@pytest.mark.parametrize("argv, message", CASES)
def test_user_errors_give_one_line_and_no_traceback(argv, message, tmp_path):
    run = subprocess.run([sys.executable, "-m", "qrrt_circuits.cli", *argv], capture_output=True, text=True,
                         cwd=tmp_path, timeout=120)
    assert run.returncode != 0
    lines = [line for line in run.stderr.splitlines() if line.strip() and not line.startswith("usage:")
             and not line.startswith(" ")]
    assert "Traceback" not in run.stderr
    assert len(lines) == 1 and message in lines[0], run.stderr


@pytest.mark.parametrize("fields, message", [
    ({"boxes": None}, "'boxes' must be a list"),
    ({"goal_radius": [1, 2]}, "goal_radius must be a real number"),
    ({"bounds": [[0, 10**400], [0, 20]]}, "bounds must be numeric"),
    ({"bounds": [[-1e308, 1e308], [0, 20]]}, "bounds must lie within"),
])
def test_bad_scenario_files_name_the_field_and_the_file(fields, message, tmp_path):
    path = scenario_file(tmp_path, **fields)
    run = subprocess.run([sys.executable, "-m", "qrrt_circuits.cli", "plan", "--scenario-file", path],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 2 and "Traceback" not in run.stderr
    assert message in run.stderr and "world.json" in run.stderr


def test_non_utf8_scenario_file(tmp_path):
    path = tmp_path / "world.json"
    path.write_bytes(b"\xff\xfe\x00garbage")
    run = subprocess.run([sys.executable, "-m", "qrrt_circuits.cli", "plan", "--scenario-file", str(path)],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 2 and "not a UTF-8 text file" in run.stderr and "Traceback" not in run.stderr


def _numba_style_interrupt(args):
    """What a Ctrl-C inside a compiled function looks like from Python: a SystemError whose cause
    is the KeyboardInterrupt."""
    try:
        raise KeyboardInterrupt
    except KeyboardInterrupt as interrupt:
        raise SystemError("CPUDispatcher(<function f>) returned a result with an exception set") from interrupt


def _other_system_error(args):
    raise SystemError("not an interrupt")


@pytest.mark.parametrize("command", ["plan", "reproduce"])
def test_an_interrupt_inside_compiled_code_is_reported_like_any_interrupt(command, monkeypatch, capsys):
    from qrrt_circuits import cli

    parser = cli.build_parser()
    argv = ["plan"] if command == "plan" else ["reproduce", "lemmas"]
    args = parser.parse_args(argv)
    args.func = _numba_style_interrupt
    monkeypatch.setattr(cli.argparse.ArgumentParser, "parse_args", lambda self, argv=None: args)
    assert cli.main(argv) == 130
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"qrrt {command}: interrupted" in err
    assert ("resume" in err) == (command == "reproduce")


def test_a_system_error_without_an_interrupt_is_not_swallowed(monkeypatch):
    from qrrt_circuits import cli

    args = cli.build_parser().parse_args(["plan"])
    args.func = _other_system_error
    monkeypatch.setattr(cli.argparse.ArgumentParser, "parse_args", lambda self, argv=None: args)
    with pytest.raises(SystemError, match="not an interrupt"):
        cli.main(["plan"])


def test_planner_specific_options_take_their_defaults_where_they_apply(capsys):
    """--qubits, --workers, --backend and --policy default to 8, 8, aer and paper for the planners
    that take them (they are no longer defaults that other planners silently ignore)."""
    from qrrt_circuits.cli import main

    assert main(["plan", "--planner", "pqrrt", "--max-nodes", "3"]) == 0
    settings = dict(line.split(None, 1) for line in capsys.readouterr().out.splitlines()[1:12] if line.strip())
    assert settings["num_qubits"] == "8" and settings["workers"] == "8"
    assert settings["backend"].startswith("aer (method=statevector")
    assert settings["search_policy"].startswith("adaptive")  # Pq-RRT's default_search_policy()
    assert main(["plan", "--planner", "prrt", "--max-nodes", "3"]) == 0
    assert "workers                  8" in capsys.readouterr().out


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full (a device whose writes fail)")
def test_a_failed_json_write_says_the_plan_finished(tmp_path):
    run = subprocess.run([sys.executable, "-m", "qrrt_circuits.cli", "plan", "--planner", "rrt", "--max-nodes", "3",
                          "--json", "/dev/full"], capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert run.returncode == 1 and "Traceback" not in run.stderr
    assert "--json: writing '/dev/full' failed (No space left on device); the plan finished" in run.stderr
    assert "metrics:" in run.stdout


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full (a device whose writes fail)")
def test_a_failed_plot_write_is_named_and_the_json_is_still_written(tmp_path):
    (tmp_path / "full.png").symlink_to("/dev/full")
    run = subprocess.run([sys.executable, "-m", "qrrt_circuits.cli", "plan", "--planner", "rrt", "--max-nodes", "3",
                          "--plot", "full.png", "--json", "tree.json"], capture_output=True, text=True,
                         cwd=tmp_path, timeout=120)
    assert run.returncode == 1 and "Traceback" not in run.stderr
    assert "--plot: writing 'full.png' failed (No space left on device); the plan finished" in run.stderr
    assert json.loads((tmp_path / "tree.json").read_text())["status"] == "max_nodes"


def test_the_old_schedule_option_is_gone():
    run = subprocess.run([sys.executable, "-m", "qrrt_circuits.cli", "plan", "--planner", "qrrt", "--schedule", "bbht"],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 2 and "unrecognized arguments: --schedule bbht" in run.stderr


def test_a_symbolic_link_loop_as_output_is_refused_in_one_line(tmp_path):
    (tmp_path / "loop.json").symlink_to("loop.json")
    run = subprocess.run([sys.executable, "-m", "qrrt_circuits.cli", "plan", "--planner", "rrt", "--max-nodes", "3",
                          "--json", "loop.json"], capture_output=True, text=True, cwd=tmp_path, timeout=120)
    assert run.returncode == 2 and "Traceback" not in run.stderr
    assert "--json: 'loop.json' cannot be written" in run.stderr and "metrics:" not in run.stdout
