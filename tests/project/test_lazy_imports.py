"""Qiskit, Aer and networkx are imported only when a name that needs them is used (PEP 562)."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

HEAVY = ("qiskit", "qiskit_aer", "qiskit_algorithms", "networkx", "matplotlib")


def _imported_after(code: str) -> list[str]:
    script = f"import json, sys\n{code}\nprint(json.dumps([m for m in {HEAVY!r} if m in sys.modules]))"
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_importing_the_package_and_planning_on_the_statevector_imports_none_of_them():
    assert _imported_after(
        "import qrrt_circuits as qc\n"
        "env = qc.paper_clutter(seed=0)\n"
        "assert qc.QRRT(backend=qc.StatevectorBackend(), seed=0).plan(env, max_nodes=10).metrics.nodes == 10\n"
        "assert qc.RRT(seed=0).plan(env, max_nodes=10).metrics.nodes == 10\n"
    ) == []


@pytest.mark.parametrize("name, needs", [
    ("AerBackend", "qiskit_aer"), ("SamplerBackend", "qiskit"),
    ("EstimatedOptimal", "qiskit"),
])
def test_a_lazy_name_imports_what_it_needs_on_first_use(name, needs):
    assert needs in _imported_after(f"import qrrt_circuits as qc\nqc.{name}")


def test_lazy_names_are_the_search_modules_objects_and_unknown_names_raise():
    import qrrt_circuits as qc
    import qrrt_circuits.search as search
    from qrrt_circuits.search.backends.aer import AerBackend
    from qrrt_circuits.search.backends.statevector import StatevectorBackend

    assert qc.AerBackend is search.AerBackend is AerBackend
    assert qc.StatevectorBackend is StatevectorBackend
    assert set(search.__all__) <= set(dir(search)) and set(qc.__all__) <= set(dir(qc))
    with pytest.raises(AttributeError, match="no attribute 'Nope'"):
        qc.Nope  # noqa: B018
    with pytest.raises(AttributeError, match="no attribute 'Nope'"):
        search.Nope  # noqa: B018


def test_importing_the_package_and_the_command_line_imports_nothing_heavy():
    """``qrrt``'s ``main`` installs its signal handlers before the heavy imports begin (so an
    interrupt during them is reported in one line): importing the package and the command line
    must not import them already."""
    heavy = ("numpy", "numba", "scipy", "qiskit", "qiskit_aer", "matplotlib", "importlib.metadata")
    script = (f"import json, sys\nimport qrrt_circuits, qrrt_circuits.cli\n"
              f"print(json.dumps([m for m in {heavy!r} if m in sys.modules]))")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True)
    assert json.loads(done.stdout.strip().splitlines()[-1]) == []
