"""``qrrt --help`` and its commands' help: every option explained, each default said once, the
experiments listed, no reST markup; a problem file's missing file named by its key; a closed pipe
ends the command quietly."""

from __future__ import annotations

import json
import re
import subprocess
import sys

import pytest

from qrrt_circuits.cli import EXIT_STATUSES, build_parser
from qrrt_circuits.experiments import EXPERIMENTS
from qrrt_circuits.problems.families import FAMILIES

COMMANDS = ["search", "plan", "reproduce", "compare-checks"]


def _help(*words: str) -> str:
    parser = build_parser()
    if not words:
        return parser.format_help()
    sub = next(action for action in parser._actions if action.dest == "command")
    return sub.choices[words[0]].format_help()


def _options(text: str) -> dict[str, str]:
    """Each option's help, joined over its lines (the option's first word as the key)."""
    blocks: dict[str, str] = {}
    key = None
    for line in text.split("options:")[1].split("\n\n")[0].splitlines():
        match = re.match(r"^  (-\S+)", line)
        if match:
            key = match.group(1).rstrip(",")
            blocks[key] = line[len(match.group(0)):]
        elif key is not None:
            blocks[key] += " " + line.strip()
    return {key: " ".join(value.split()) for key, value in blocks.items()}


@pytest.mark.parametrize("command", COMMANDS)
def test_every_option_has_help_and_says_its_default_once(command):
    for option, text in _options(_help(command)).items():
        words = text.split(maxsplit=1)
        explained = words[1] if words and words[0].isupper() else text  # after a metavar
        assert explained.strip(), (command, option)
        assert len(re.findall(r"\(default", text)) <= 1, (command, option, text)


def test_the_top_help_has_no_markup():
    assert "``" not in _help() and "`" not in _help().split("positional")[0]


def test_reproduce_help_lists_every_experiment():
    text = _help("reproduce")
    for name, experiment in EXPERIMENTS.items():
        assert re.search(rf"^  {re.escape(name)}\s+{re.escape(experiment.title)}$", text, re.M), name


def test_problem_help_names_every_family():
    text = " ".join(_options(_help("plan"))["--problem"].split())
    for family in [*FAMILIES, "boxes"]:
        assert family in text


@pytest.mark.parametrize(("family", "key"), [("boxes", "scenario"), ("image", "image")])
def test_a_missing_file_inside_a_problem_file_names_its_key(tmp_path, family, key):
    fields = {"scenario": "absent.json"} if family == "boxes" else {
        "image": "absent.png", "pixel_size": 0.1, "start": [1, 1], "goal": [2, 2], "goal_radius": 0.5}
    problem = tmp_path / "problem.json"
    problem.write_text(json.dumps({"format": "qrrt-problem", "version": 1, "family": family, **fields}))
    run = subprocess.run([sys.executable, "-m", "qrrt_circuits.cli", "plan", "--problem", str(problem)],
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 2 and "Traceback" not in run.stderr and "Errno" not in run.stderr
    assert f'problem.json: "{key}":' in run.stderr and "no such file" in run.stderr and "absent" in run.stderr


def test_a_closed_pipe_ends_the_command_quietly():
    """More output than a pipe holds, read one line: exit 141 (128 + SIGPIPE) and nothing on stderr."""
    script = ("import subprocess, sys; p = subprocess.Popen([sys.executable, '-m', 'qrrt_circuits.cli', 'search', "
              "'--qubits', '14', '--iterations', '0', '--shots', '20000', '--top', '20000', '--backend', "
              "'statevector'], stdout=subprocess.PIPE, stderr=subprocess.PIPE); p.stdout.readline(); "
              "p.stdout.close(); err = p.stderr.read(); print(p.wait(), repr(err.decode()))")
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    status, err = run.stdout.split(maxsplit=1)
    assert int(status) == 141 and 141 in EXIT_STATUSES and err.strip() == "''", run.stdout
