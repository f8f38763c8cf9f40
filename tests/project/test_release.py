"""Release metadata: one version (pyproject's), ``qrrt --version``, the changelog and the citation."""

from __future__ import annotations

import re
import subprocess
import sys
import tomllib
from importlib import metadata
from pathlib import Path

import pytest

import qrrt_circuits as qc
from qrrt_circuits.cli import main

ROOT = Path(__file__).resolve().parents[2]
PYPROJECT_VERSION = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]


def test_version_comes_from_the_package_metadata():
    assert qc.__version__ == metadata.version("qrrt-circuits")
    assert qc.__version__ == PYPROJECT_VERSION, "installed metadata is stale: reinstall the package"


def test_qrrt_version_prints_it(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["--version"])
    assert exit_info.value.code == 0
    assert capsys.readouterr().out.strip() == f"qrrt {qc.__version__}"


def test_qrrt_version_on_the_command_line():
    out = subprocess.run([sys.executable, "-m", "qrrt_circuits.cli", "--version"], capture_output=True,
                         text=True, check=False)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == f"qrrt {qc.__version__}"


def test_changelog_follows_keep_a_changelog():
    text = (ROOT / "CHANGELOG.md").read_text()
    releases = re.findall(r"^## \[([^\]]+)\]", text, flags=re.M)
    assert releases[0] == "Unreleased", releases
    assert "0.1.0" in releases
    dated = re.findall(r"^## \[(\d+\.\d+\.\d+)\] - (\d{4}-\d{2}-\d{2})$", text, flags=re.M)
    assert {version for version, _ in dated} == set(releases[1:]), "every release has a date"
    sections = set(re.findall(r"^### (\w+)$", text, flags=re.M))
    assert sections <= {"Added", "Changed", "Deprecated", "Removed", "Fixed", "Security"}, sections


def test_citation_cites_the_software_and_the_paper():
    yaml = pytest.importorskip("yaml")
    citation = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert citation["cff-version"] == "1.2.0" and citation["type"] == "software"
    assert str(citation["version"]) == PYPROJECT_VERSION, "CITATION.cff repeats pyproject's version"
    paper = citation["preferred-citation"]
    assert paper["title"] == "Parallel Quantum Rapidly-Exploring Random Trees"
    assert [a["family-names"] for a in paper["authors"]] == ["Lathrop", "Boardman", "Martínez"]
    assert paper["journal"] == "IEEE Access" and paper["year"] == 2024
    assert "2310.15303" in paper["url"]
