"""Every deprecated name still works, warns with a DeprecationWarning naming its replacement and
the removal version, and points the warning at the caller's line."""

import importlib
import sys
import warnings

import numpy as np
import pytest

import qrrt_circuits as qc
from qrrt_circuits._support.deprecation import DEPRECATED, REMOVED_IN


@pytest.fixture(scope="module")
def env():
    return qc.scenarios.paper_clutter(seed=0)


def _one_warning(action, replacement):
    """Run ``action`` and return its value; exactly one DeprecationWarning, naming ``replacement``
    and the removal version, attributed to this file."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        value = action()
    deprecations = [w for w in caught if issubclass(w.category, DeprecationWarning)]
    assert len(deprecations) == 1, [str(w.message) for w in deprecations]
    message = str(deprecations[0].message)
    assert replacement in message and f"removed in {REMOVED_IN}" in message
    assert deprecations[0].filename == __file__
    return value


def test_oracle_keyword_and_attribute(env):
    predicate = qc.ExactCheck(env)
    for make in (lambda: qc.RRT(env, oracle=predicate, seed=0),
                 lambda: qc.ParallelRRT(env, workers=2, oracle=predicate, seed=0),
                 lambda: qc.QRRT(env, backend=qc.StatevectorBackend(), oracle=predicate, seed=0),
                 lambda: qc.PQRRT(env, backend=qc.StatevectorBackend(), oracle=predicate, seed=0)):
        planner = _one_warning(make, "predicate=")
        assert planner.predicate is predicate
        assert _one_warning(lambda planner=planner: planner.oracle, "Planner.predicate") is predicate


def test_iterations_keyword_and_attribute_give_the_same_plan(env):
    policy = qc.FixedIterations(2)
    old = _one_warning(lambda: qc.QRRT(env, backend=qc.StatevectorBackend(), iterations=policy, seed=3),
                       "search_policy=")
    new = qc.QRRT(env, backend=qc.StatevectorBackend(), search_policy=policy, seed=3)
    assert _one_warning(lambda: old.iterations_policy, "PQRRT.search_policy") is policy
    assert np.array_equal(old.plan(max_nodes=5).nodes, new.plan(max_nodes=5).nodes)


def test_policy_state_iterations():
    state = qc.PaperIterations().start(256)
    assert _one_warning(lambda: state.iterations(20), "choose_iterations") == state.choose_iterations(20) == 3


def test_search_policy_names():
    assert _one_warning(lambda: qc.SearchPolicy, "IterationPolicy") is qc.IterationPolicy
    from qrrt_circuits.search import policies

    assert _one_warning(lambda: policies.SearchPolicy, "IterationPolicy") is qc.IterationPolicy


def test_schedules_module():
    sys.modules.pop("qrrt_circuits.search.schedules", None)
    module = _one_warning(lambda: importlib.import_module("qrrt_circuits.search.schedules"),
                          "qrrt_circuits.search.policies")
    assert module.PaperIterations is qc.PaperIterations


def test_default_max_rounds_of_the_planners_module():
    from qrrt_circuits.planners import base

    assert _one_warning(lambda: base.DEFAULT_MAX_ROUNDS, "termination.DEFAULT_MAX_ROUNDS") == \
        qc.termination.DEFAULT_MAX_ROUNDS


def test_time_samples_check_and_budget_exhausted(env):
    check = _one_warning(lambda: qc.ExactCheck(env, check="time_samples", time_samples=9), "TimeSampledCheck")
    assert isinstance(check, qc.TimeSampledCheck) and check.time_samples == 9
    result = qc.RRT(env, seed=0).plan(max_rounds=3, goal_radius=1e-9)
    assert _one_warning(lambda: result.budget_exhausted, "not PlanResult.reached") is True


def test_every_deprecated_name_is_tested():
    """The table the docs show lists exactly the names this file exercises."""
    assert len(DEPRECATED) == 12


@pytest.mark.parametrize("old, new", [
    ("qrrt_circuits.environment", "qrrt_circuits.world.environment"),
    ("qrrt_circuits.oracle", "qrrt_circuits.reachability.exact"),
    ("qrrt_circuits.termination", "qrrt_circuits.planners.termination"),
    ("qrrt_circuits.memory", "qrrt_circuits._support.memory"),
    ("qrrt_circuits.search.aer", "qrrt_circuits.search.backends.aer"),
    ("qrrt_circuits.search.fixed_point_policy", "qrrt_circuits.search.policies.fixed_point"),
])
def test_an_old_module_path_imports_the_new_module_and_warns(old, new):
    sys.modules.pop(old, None)
    module = _one_warning(lambda: importlib.import_module(old), new)
    assert module is importlib.import_module(new)


def test_renamed_classes():
    from qrrt_circuits.reachability import exact
    from qrrt_circuits.search import policies

    assert _one_warning(lambda: qc.ReachabilityOracle, "ExactCheck") is qc.ExactCheck
    assert _one_warning(lambda: exact.ReachabilityOracle, "ExactCheck") is qc.ExactCheck
    assert _one_warning(lambda: qc.PaperSchedule, "PaperIterations") is qc.PaperIterations
    assert _one_warning(lambda: policies.PaperSchedule, "PaperIterations") is qc.PaperIterations
