"""The public names resolve, no module of the package is an alias of another, and the names that
0.1.0 development builds used before their renames are gone (0.1.0 was never published, so none of
them is kept as an alias)."""

import ast
import importlib
from pathlib import Path

import pytest

import qrrt_circuits as qc
from planner_checks import posed

ROOT = Path(qc.__file__).resolve().parent

#: names of ``qc.__all__`` that are modules living below a subpackage: ``qc.scenarios`` is
#: ``qrrt_circuits.problems.scenarios``, imported under that path only (no module file aliases it)
NAMESPACE_MODULES = {"scenarios": "qrrt_circuits.problems.scenarios",
                     "termination": "qrrt_circuits.planners.termination",
                     "circuits": "qrrt_circuits.search.circuits"}


@pytest.fixture(scope="module")
def env():
    return qc.paper_clutter(seed=0)


def test_every_public_name_resolves():
    assert len(set(qc.__all__)) == len(qc.__all__)
    assert set(qc.__all__) == set(qc._WHERE)
    for name in qc.__all__:
        value = getattr(qc, name)
        assert value is not None, name
        if isinstance(value, type(qc)):
            home = NAMESPACE_MODULES.get(name, f"qrrt_circuits.{name}")
            assert value.__name__ == home and value is importlib.import_module(home), name


def test_a_module_name_of_the_namespace_is_a_module_file_or_a_listed_subpackage_module():
    """``import qrrt_circuits.X`` and ``qc.X`` agree for every top-level module file X; the modules
    of ``NAMESPACE_MODULES`` are attributes of the namespace, not module paths of their own."""
    top_level = {path.stem for path in ROOT.glob("*.py") if path.stem != "__init__"}
    for stem in top_level:
        module = importlib.import_module(f"qrrt_circuits.{stem}")
        assert module.__name__ == f"qrrt_circuits.{stem}"
        assert Path(module.__file__).resolve() == ROOT / f"{stem}.py"
        if stem in qc.__all__:
            assert getattr(qc, stem) is module
    modules = {name for name in qc.__all__ if isinstance(getattr(qc, name), type(qc))}
    assert modules - top_level == set(NAMESPACE_MODULES)
    for name in NAMESPACE_MODULES:
        with pytest.raises(ModuleNotFoundError):
            importlib.import_module(f"qrrt_circuits.{name}")


def _module_level_getattr(tree: ast.Module) -> bool:
    return any(isinstance(node, ast.FunctionDef) and node.name == "__getattr__" for node in tree.body)


def _assigns_sys_modules(tree: ast.Module) -> bool:
    return any(isinstance(target, ast.Subscript) and ast.unparse(target.value) == "sys.modules"
               for node in ast.walk(tree) if isinstance(node, ast.Assign) for target in node.targets)


def test_no_module_is_an_alias_of_another():
    """No module puts another module in ``sys.modules`` under its own name, and only the two lazy
    namespaces (the package and ``search``) answer attributes through a module ``__getattr__``."""
    lazy, aliasing = set(), set()
    for path in ROOT.rglob("*.py"):
        tree = ast.parse(path.read_text())
        name = str(path.relative_to(ROOT))
        if _module_level_getattr(tree):
            lazy.add(name)
        if _assigns_sys_modules(tree):
            aliasing.add(name)
    assert lazy == {"__init__.py", "search/__init__.py"}
    assert aliasing == set()
    search = importlib.import_module("qrrt_circuits.search")
    assert set(search.__all__) == set(search._WHERE)


@pytest.mark.parametrize("old", [
    "qrrt_circuits.authors_check", "qrrt_circuits.collision", "qrrt_circuits.database",
    "qrrt_circuits.deprecation", "qrrt_circuits.dynamics", "qrrt_circuits.environment",
    "qrrt_circuits.json_stream", "qrrt_circuits.memory", "qrrt_circuits.noise", "qrrt_circuits.oracle",
    "qrrt_circuits.oracle_errors", "qrrt_circuits.output_files", "qrrt_circuits.predicate",
    "qrrt_circuits.randomness", "qrrt_circuits.resources", "qrrt_circuits.scenarios",
    "qrrt_circuits.termination", "qrrt_circuits.time_sampled", "qrrt_circuits.tree",
    "qrrt_circuits.validation", "qrrt_circuits.worker_warmup", "qrrt_circuits.search.aer",
    "qrrt_circuits.search.estimated_policy", "qrrt_circuits.search.fixed_point_policy",
    "qrrt_circuits.search.noisy", "qrrt_circuits.search.sampler", "qrrt_circuits.search.statevector",
    "qrrt_circuits.search.schedules", "qrrt_circuits._support.deprecation", "qrrt_circuits._support.execution",
    "qrrt_circuits.search.fixed_point", "qrrt_circuits.search.policies.fixed_point",
    "qrrt_circuits.coherent.fixed_point", "qrrt_circuits.search.policies.iteration", "qrrt_circuits.search.backend",
])
def test_an_old_module_path_is_gone(old):
    with pytest.raises(ModuleNotFoundError):
        importlib.import_module(old)


@pytest.mark.parametrize("module, name", [
    ("qrrt_circuits", "SearchPolicy"), ("qrrt_circuits", "PaperSchedule"), ("qrrt_circuits", "ReachabilityOracle"),
    ("qrrt_circuits.search.policies", "SearchPolicy"), ("qrrt_circuits.search.policies", "PaperSchedule"),
    ("qrrt_circuits.search.policies.base", "SearchPolicy"),
    ("qrrt_circuits.search.policies.schedules", "PaperSchedule"),
    ("qrrt_circuits.reachability.exact", "ReachabilityOracle"),
    ("qrrt_circuits.reachability.exact", "OracleErrorModel"),
    ("qrrt_circuits.planners", "DEFAULT_MAX_ROUNDS"), ("qrrt_circuits.planners.base", "DEFAULT_MAX_ROUNDS"),
])
def test_an_old_name_is_gone(module, name):
    with pytest.raises(AttributeError):
        getattr(importlib.import_module(module), name)


def test_old_arguments_and_attributes_are_gone(env):
    predicate = qc.ExactCheck(env)
    for make in (lambda: qc.RRT(oracle=predicate), lambda: qc.ParallelRRT(oracle=predicate),
                 lambda: qc.QRRT(backend=qc.StatevectorBackend(), oracle=predicate),
                 lambda: qc.PQRRT(backend=qc.StatevectorBackend(), oracle=predicate),
                 lambda: qc.QRRT(backend=qc.StatevectorBackend(), iterations=qc.FixedIterations(2)),
                 lambda: qc.PQRRT(backend=qc.StatevectorBackend(), iterations=qc.FixedIterations(2)),
                 lambda: qc.ExactCheck(env, check="time_samples"),
                 lambda: qc.ExactCheck(env, time_samples=9)):
        with pytest.raises(TypeError, match="unexpected keyword argument"):
            make()
    planner = qc.PQRRT(backend=qc.StatevectorBackend(), predicate=predicate, seed=0)
    assert planner.predicate is predicate and not hasattr(planner, "oracle")
    assert not hasattr(planner, "iterations_policy") and not hasattr(predicate, "check")
    assert not hasattr(qc.PaperIterations().start(256), "iterations")
    assert not hasattr(qc.RRT(seed=0).plan(posed(env, goal_radius=1e-9), max_rounds=3), "budget_exhausted")
