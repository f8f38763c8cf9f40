"""Every public name is in the generated API reference (the built site's ``objects.inv``).

Building the site takes minutes, so this test does not build it: it reads the inventory of the
last build (``python -m sphinx -W -b html docs docs/_build/html``) and is skipped when there is
none. ``.ci/run`` builds the docs *before* it runs the test suite, so in CI the test always runs,
on a build of the same commit.

The names checked: every name of ``qrrt_circuits.__all__``; every public name of the public
submodules in it (``probability``, ``registry``); every ``qc.NAME`` of the code blocks of DESIGN §3
and §7 (the public contract), the functions its §3 lists by name, and the attributes its code reads
from the objects it builds (``problem.env``, ``env.bounds``, ``res.indices``, ``result.path``, ...).
"""

from __future__ import annotations

import re
import sys
import types
import zlib
from pathlib import Path

import pytest

import qrrt_circuits as qc

pytest.importorskip("sphinx", reason="the API reference's rule reads doc comments with Sphinx (extra docs)")

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "docs"))
from api_names import public_names  # noqa: E402  (the reference's own rule, beside docs/conf.py)

INVENTORY = ROOT / "docs" / "_build" / "html" / "objects.inv"
DESIGN = ROOT / "docs" / "DESIGN.md"

#: the variables of DESIGN's code blocks and the class of the object each one holds
DESIGN_VARIABLES = {
    "problem": "Problem",
    "env": "Environment",
    "dyn": "LinearTrackingDynamics",
    "oracle": "ExactCheck",
    "backend": "QuantumSearchBackend",
    "res": "SearchResult",
    "planner": "PQRRT",
    "result": "PlanResult",
}


def read_inventory(path: Path) -> set[str]:
    """The object names of a Sphinx inventory (version 2: four text lines, then zlib-compressed
    lines ``name domain:role priority uri display-name``)."""
    raw = path.read_bytes()
    lines = raw.split(b"\n", 4)
    assert lines[0] == b"# Sphinx inventory version 2", lines[0]
    assert b"zlib" in lines[3], lines[3]
    names = set()
    for line in zlib.decompress(lines[4]).decode().splitlines():
        match = re.match(r"(.+?)\s+(\S+:\S+)\s+-?\d+\s", line)
        if match and match.group(2).startswith("py:"):
            names.add(match.group(1))
    return names


@pytest.fixture(scope="module")
def documented() -> set[str]:
    if not INVENTORY.exists():
        pytest.skip("the docs are not built (python -m sphinx -W -b html docs docs/_build/html)")
    return read_inventory(INVENTORY)


def documented_names(path: str, obj: object) -> set[str]:
    """The names under which ``obj``, reached as ``qrrt_circuits.<path>``, may be documented."""
    names = {f"qrrt_circuits.{path}"}
    if isinstance(obj, types.ModuleType):
        return names | {obj.__name__}
    parent_path, _, last = path.rpartition(".")
    parent = resolve(parent_path) if parent_path else qc
    if isinstance(parent, types.ModuleType):  # a constant of a module reached by an alias (qc.circuits)
        names.add(f"{parent.__name__}.{last}")
    qualname = getattr(obj, "__qualname__", None)
    module = getattr(obj, "__module__", None)
    if isinstance(qualname, str) and isinstance(module, str) and module.startswith("qrrt_circuits"):
        names.add(f"{module}.{qualname}")
        head = qualname.partition(".")[0]
        if head in qc.__all__ and getattr(qc, head) is getattr(sys.modules[module], head, None):
            names.add(f"qrrt_circuits.{qualname}")  # a class re-exported at the top, and its members
    return names


def resolve(path: str) -> object:
    """The object at ``qrrt_circuits.<path>``; a dataclass field without a default resolves to
    its ``dataclasses.Field``."""
    obj: object = qc
    for part in path.split("."):
        fields = getattr(obj, "__dataclass_fields__", {})
        if not hasattr(obj, part) and isinstance(obj, type) and part in fields:
            obj = fields[part]
        else:
            obj = getattr(obj, part)
    return obj


def design_sections(*numbers: int) -> str:
    text = DESIGN.read_text()
    parts = re.split(r"^## (\d+)\.", text, flags=re.M)
    return "\n".join(parts[i + 1] for i in range(1, len(parts), 2) if int(parts[i]) in numbers)


def code_blocks(text: str) -> str:
    return "\n".join(re.findall(r"```python\n(.*?)```", text, flags=re.S))


def contract_paths() -> list[str]:
    """Dotted paths under ``qrrt_circuits`` that DESIGN's public contract names."""
    code = code_blocks(design_sections(3, 7))
    paths = set(re.findall(r"\bqc\.([A-Za-z_][\w.]*\w)", code))
    for variable, cls in DESIGN_VARIABLES.items():
        paths |= {f"{cls}.{attr}" for attr in re.findall(rf"\b{variable}\.([a-z_]\w*)", code)}
    # the lemma functions DESIGN §3 lists by name
    prose = design_sections(3)
    paths |= {f"probability.{name}" for name in re.findall(r"`(\w+)\(", prose) if hasattr(qc.probability, name)}
    return sorted(paths)


def public_paths() -> list[str]:
    """``__all__`` and the public names of the public submodules (as the reference lists them)."""
    paths = list(qc.__all__)
    for name in qc.__all__:
        module = getattr(qc, name)
        if isinstance(module, types.ModuleType):
            paths += [f"{name}.{n}" for n in public_names(module)]
    return paths


def test_design_contract_is_parsed():
    """Guard against the parser silently finding nothing (e.g. after a DESIGN reformat)."""
    paths = contract_paths()
    for expected in ("PQRRT", "paper_clutter", "Problem.build", "Problem.with_goal_radius", "probability.prob_all_same",
                     "PlanResult.path", "SearchResult.indices", "registry.PLANNERS.create"):
        assert expected in paths, (expected, paths)


@pytest.mark.parametrize("path", sorted(set(public_paths()) | set(contract_paths())))
def test_public_name_is_in_the_api_reference(documented, path):
    obj = resolve(path)  # a contract name that no longer exists fails here
    candidates = documented_names(path, obj)
    assert candidates & documented, f"qrrt_circuits.{path} is not in the API reference (looked for {candidates})"
