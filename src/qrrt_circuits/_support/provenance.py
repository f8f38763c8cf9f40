"""Where a result came from: the code's commit, the package versions, the machine and the date.

Every results file (``summary.json``, a benchmark's JSON) carries ``provenance()`` inside, so that
a number can be traced to what produced it without the file's name or the prose saying so. Two
runs with the same seed give the same results and differ only in their provenance. A summary's
provenance is that of the run that wrote it: a resumed run summarizes records that runs before it,
with the same settings (``settings.json``), may have written.
"""

from __future__ import annotations

import datetime
import os
import platform
import subprocess
from importlib import metadata
from pathlib import Path
from typing import Any

#: packages whose versions describe a run (None where one is not installed)
PACKAGES = ("qrrt-circuits", "qiskit", "qiskit-aer", "qiskit-algorithms", "numpy", "numba", "scipy", "matplotlib",
            "dask", "distributed", "ompl")

#: the package's source folder: its git commit is the code's
_SOURCE = Path(__file__).resolve().parents[1]


def provenance() -> dict[str, Any]:
    """The commit, package versions, machine and date of a run.

    Returns:
        ``{"git_commit", "git_dirty", "packages", "python", "os", "cpu", "cores", "cores_usable",
        "memory_gib", "date"}``: the commit of the package's source (None outside a git checkout)
        and whether tracked files differ from it, the versions of ``PACKAGES``, the machine, and
        the date in UTC (ISO 8601, seconds).
    """
    versions: dict[str, str | None] = {}
    for package in PACKAGES:
        try:
            versions[package] = metadata.version(package)
        except metadata.PackageNotFoundError:
            versions[package] = None
    status = _git("status", "--porcelain", "--untracked-files=no")
    return {
        "git_commit": _git("rev-parse", "HEAD"),
        "git_dirty": bool(status) if status is not None else None,
        "packages": versions,
        "python": platform.python_version(),
        "os": platform.platform(),
        "cpu": _cpu_model(),
        "cores": os.cpu_count(),
        "cores_usable": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count(),
        "memory_gib": _memory_gib(),
        "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
    }


def _git(*args: str) -> str | None:
    try:
        return subprocess.run(["git", *args], cwd=_SOURCE, capture_output=True, text=True, check=True,
                              timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None


def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _memory_gib() -> float | None:
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemTotal:"):
                return round(int(line.split()[1]) / 2**20, 2)
    except OSError:
        pass
    return None
