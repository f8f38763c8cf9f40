"""Package metadata as the Qiskit ecosystem reads it: a capped Qiskit requirement, one licence in
pyproject.toml, LICENSE and CITATION.cff, the citation's version equal to pyproject's, the project
URLs and classifiers that tell the truth.

Everything is read from the files of the checkout (pyproject.toml, LICENSE, CITATION.cff), not
from the installed metadata, which can be stale in an editable or an old install.
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest
from packaging.requirements import Requirement
from packaging.specifiers import SpecifierSet
from packaging.utils import canonicalize_name
from packaging.version import Version

ROOT = Path(__file__).resolve().parents[2]
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
CITATION = (ROOT / "CITATION.cff").read_text(encoding="utf-8")


def _requirement(name: str) -> Requirement:
    found = [Requirement(line) for line in PROJECT["dependencies"]
             if canonicalize_name(Requirement(line).name) == canonicalize_name(name)]
    assert len(found) == 1, f"{name} is required exactly once in [project] dependencies: {found}"
    return found[0]


def _citation_field(key: str) -> str | None:
    """A top-level scalar of CITATION.cff, without its quotes (no YAML parser needed)."""
    match = re.search(rf"^{re.escape(key)}:[ \t]*(.+?)[ \t]*$", CITATION, flags=re.M)
    return None if match is None else match.group(1).strip("\"'")


def _licence_of(text: str) -> str | None:
    """The SPDX identifier of a licence text, for the licences this project could carry."""
    if text.lstrip().startswith("MIT License") and "Permission is hereby granted, free of charge" in text:
        return "MIT"
    if "Apache License" in text and "Version 2.0" in text:
        return "Apache-2.0"
    return None


@pytest.mark.parametrize("version", ["3.0", "3.0.0rc1", "3.1", "4.0", "10.0"])
def test_qiskit_requirement_excludes_the_next_major(version):
    specifier = _requirement("qiskit").specifier
    assert not specifier.contains(version, prereleases=True), (
        f"qiskit{specifier} admits {version}: cap the requirement below 3 (the ecosystem flags an uncapped major)")


def test_qiskit_requirement_has_an_upper_bound_below_3():
    bounds = [Version(spec.version) for spec in _requirement("qiskit").specifier if spec.operator in {"<", "<="}]
    assert bounds, "qiskit's requirement has no '<' bound"
    assert min(bounds) <= Version("3"), bounds


def test_license_file_matches_pyproject_and_citation():
    licence = ROOT / "LICENSE"
    assert licence.is_file(), "LICENSE is missing"
    assert isinstance(PROJECT["license"], str), "license is an SPDX expression string (PEP 639)"
    assert _licence_of(licence.read_text(encoding="utf-8")) == PROJECT["license"]
    assert "LICENSE" in PROJECT["license-files"], "the sdist and the wheel carry LICENSE"
    assert _citation_field("license") == PROJECT["license"]
    assert not [c for c in PROJECT["classifiers"] if c.startswith("License ::")], (
        "PEP 639: a license expression replaces License classifiers (setuptools rejects both)")


def test_citation_version_is_pyproject_version():
    assert _citation_field("cff-version") == "1.2.0"
    assert _citation_field("version") == PROJECT["version"], "update CITATION.cff's version with pyproject's"


@pytest.mark.parametrize("key", ["Homepage", "Documentation", "Source", "Issues", "Changelog"])
def test_project_urls(key):
    url = PROJECT.get("urls", {}).get(key)
    assert url, f"[project.urls] has no {key}"
    assert url.startswith("https://"), url


def test_development_status_fits_the_version():
    statuses = [c for c in PROJECT["classifiers"] if c.startswith("Development Status ::")]
    assert len(statuses) == 1, statuses
    level = int(statuses[0].split("::")[1].split("-")[0])
    version = Version(PROJECT["version"])
    if version.major == 0 or version.is_prerelease:
        assert level <= 4, f"{statuses[0]} for version {version}: at most '4 - Beta' before 1.0"


def test_python_classifiers_fit_requires_python():
    requires = SpecifierSet(PROJECT["requires-python"])
    minors = [c.rsplit("::", 1)[1].strip() for c in PROJECT["classifiers"]
              if re.fullmatch(r"Programming Language :: Python :: 3\.\d+", c)]
    assert minors, "no Programming Language :: Python :: 3.X classifier"
    assert all(requires.contains(f"{minor}.0") for minor in minors), (requires, minors)
    assert requires.contains(f"{min(minors, key=Version)}.0") and not requires.contains(
        f"3.{Version(min(minors, key=Version)).minor - 1}.0"), "the oldest classifier is requires-python's floor"
