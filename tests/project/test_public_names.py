"""The public names resolve, no module of the package is an alias of another, and the names that
0.1.0 development builds used before their renames are gone (0.1.0 was never published, so none of
them is kept as an alias)."""

import ast
import importlib
from pathlib import Path

import pytest
from planner_checks import posed

import qrrt_circuits as qc

ROOT = Path(qc.__file__).resolve().parent

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
            assert value.__name__ == f"qrrt_circuits.{name}" and value is importlib.import_module(value.__name__)


@pytest.mark.parametrize("name", sorted({path.stem for path in ROOT.glob("*.py") if path.stem != "__init__"}
                                        | {path.parent.name for path in ROOT.glob("*/__init__.py")}
                                        | {"scenarios", "termination", "circuits", "nope"}))
def test_import_and_attribute_agree_for_every_name(name):
    """``import qrrt_circuits.X`` and ``qc.X`` give the same module for every module file and
    subpackage X, and both fail for a name that is neither."""
    try:
        module = importlib.import_module(f"qrrt_circuits.{name}")
    except ModuleNotFoundError:
        with pytest.raises(AttributeError):
            getattr(qc, name)
        return
    assert getattr(qc, name) is module


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
    predicate = qc.ExactCheck(env.env)
    for make in (lambda: qc.RRT(oracle=predicate), lambda: qc.ParallelRRT(oracle=predicate),
                 lambda: qc.QRRT(backend=qc.StatevectorBackend(), oracle=predicate),
                 lambda: qc.PQRRT(backend=qc.StatevectorBackend(), oracle=predicate),
                 lambda: qc.QRRT(backend=qc.StatevectorBackend(), iterations=qc.FixedIterations(2)),
                 lambda: qc.PQRRT(backend=qc.StatevectorBackend(), iterations=qc.FixedIterations(2)),
                 lambda: qc.RRT(env.env), lambda: qc.QRRT(predicate=predicate)):
        with pytest.raises(TypeError, match="does not take|options must be"):
            make()
    for make in (lambda: qc.ExactCheck(env.env, check="time_samples"),
                 lambda: qc.ExactCheck(env.env, time_samples=9)):
        with pytest.raises(TypeError, match="unexpected keyword argument"):
            make()
    planner = qc.PQRRT(backend=qc.StatevectorBackend(), seed=0)
    assert not hasattr(planner, "oracle") and not hasattr(planner, "predicate") and not hasattr(planner, "env")
    assert not hasattr(planner, "iterations_policy") and not hasattr(predicate, "check")
    assert not hasattr(qc.PaperIterations().start(256), "iterations")
    assert not hasattr(qc.RRT(seed=0).plan(posed(env, goal_radius=1e-9), max_rounds=3), "budget_exhausted")
    assert not hasattr(env.env, "start") and not hasattr(env.env, "goal_radius")
    with pytest.raises(TypeError):
        qc.RRT(seed=0).plan(env, None, None, 100)  # the budgets are keyword-only
