"""Property-based bad input (issue 10): over the public constructors, ``plan``, ``backend.search`` and
the scenario loader, wrong types, NaN/inf, out-of-range, huge and malformed values raise a
``ValueError`` or ``TypeError`` whose message names the argument, before any work; never another
exception type, never a hang (every plan runs under a small round budget)."""

from __future__ import annotations

import json
import math
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import qrrt_circuits as qc
from qrrt_circuits.problems.families import box_world

SETTINGS = settings(max_examples=12, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])

ENV = qc.Problem.build(qc.Environment(np.array([[0.0, 10.0], [0.0, 10.0]]), np.array([[[4.0, 4.0], [5.0, 5.0]]])),
                       [1.0, 1.0], [9.0, 9.0], 0.5)

# ------------------------------------------------------------------------------ bad values
HUGE_INTS = st.sampled_from([10**18, 2**63, 10**40, 10**400])
SOME_NOT_NUMBERS = st.one_of(st.text(max_size=4), st.binary(max_size=4), st.lists(st.integers(), max_size=2),
                        st.dictionaries(st.text(max_size=2), st.integers(), max_size=1),
                        st.complex_numbers(allow_nan=False, allow_infinity=False).filter(lambda z: z.imag != 0))
NOT_NUMBERS = st.one_of(st.none(), SOME_NOT_NUMBERS)
NON_FINITE = st.sampled_from([math.nan, math.inf, -math.inf, np.float64("nan")])


def bad_int(minimum: int, maximum: int | None = None, none_valid: bool = False):
    """Never an integer in [minimum, maximum] (nor None where None is valid): other types, floats
    (even integral ones), bools, integers out of range."""
    others = SOME_NOT_NUMBERS if none_valid else NOT_NUMBERS
    out_of_range = [st.integers(max_value=minimum - 1).map(lambda v: max(v, -10**30))]
    if maximum is not None:
        out_of_range.append(st.integers(min_value=maximum + 1, max_value=maximum + 10**6))
        out_of_range.append(HUGE_INTS.filter(lambda v: v > maximum))
    return st.one_of(others, st.booleans(), st.floats(allow_nan=True), NON_FINITE, *out_of_range)


def bad_float(minimum: float | None, maximum: float | None, open_minimum: bool = False, none_valid: bool = False):
    """Never a finite real number in the range: other types, bools, NaN/inf, values out of range."""
    out = [SOME_NOT_NUMBERS if none_valid else NOT_NUMBERS, st.booleans(), NON_FINITE]
    if minimum is not None:
        below = st.floats(max_value=minimum, allow_nan=False, allow_infinity=False)
        out.append(below if open_minimum else below.filter(lambda v: v < minimum))
    if maximum is not None:
        out.append(st.floats(min_value=maximum, allow_nan=False, allow_infinity=False).filter(lambda v: v > maximum))
    return st.one_of(*out)


def bad_choice(choices: tuple[str, ...]):
    return st.one_of(NOT_NUMBERS, st.booleans(), st.integers(), st.text(max_size=12).filter(lambda t: t not in choices))


def bad_point():
    return st.one_of(st.text(max_size=3), st.lists(st.floats(0, 9), min_size=0, max_size=1),
                     st.lists(st.floats(0, 9), min_size=3, max_size=4),
                     st.tuples(NON_FINITE, st.floats(1, 3)), st.tuples(st.floats(11, 1e300), st.floats(1, 3)),
                     st.tuples(st.text(max_size=2), st.floats(1, 3)), st.just([4.5, 4.5]))


def refused(call, *names: str) -> None:
    """``call()`` raises ValueError/TypeError naming one of ``names``; anything else fails."""
    with pytest.raises((ValueError, TypeError)) as info:
        call()
    message = str(info.value)
    assert any(name in message for name in names), f"message does not name {names}: {message!r}"


# ------------------------------------------------------------------------------ constructors
PLANNER_ARGUMENTS = [
    ("seed", bad_int(0, none_valid=True)),
    ("goal_bias", bad_float(0.0, 1.0).filter(lambda v: not isinstance(v, float) or v != 1.0) | st.just(1.0)),
    ("oracle_errors", st.one_of(st.integers(), st.text(max_size=3), st.just(0.1))),
]


@pytest.mark.parametrize("name, values", PLANNER_ARGUMENTS, ids=[a for a, _ in PLANNER_ARGUMENTS])
@pytest.mark.parametrize("planner", [qc.RRT, qc.ParallelRRT, qc.QRRT, qc.PQRRT])
@SETTINGS
@given(data=st.data())
def test_planner_arguments(planner, name, values, data):
    value = data.draw(values)
    extra = {"backend": qc.StatevectorBackend(0), "num_qubits": 4} if planner in (qc.QRRT, qc.PQRRT) else {}
    refused(lambda: planner(**extra, **{name: value}), name)


QUANTUM_ARGUMENTS = [
    ("num_qubits", bad_int(1, 28)),
    ("workers", bad_int(1, 4096)),
    ("shared_database", st.one_of(st.integers(), st.text(max_size=3), st.none(), st.floats())),
    ("backend", st.one_of(st.integers(), st.text(max_size=3), st.just(qc.RRT))),
    ("search_policy", st.one_of(st.integers(), st.text(max_size=5), st.just(qc.PaperIterations))),
    ("annealing", st.one_of(st.integers(), st.text(max_size=3), st.just(((1.0, 2.0),)))),
]


@pytest.mark.parametrize("name, values", QUANTUM_ARGUMENTS, ids=[a for a, _ in QUANTUM_ARGUMENTS])
@SETTINGS
@given(data=st.data())
def test_quantum_planner_arguments(name, values, data):
    value = data.draw(values)
    options = {"backend": qc.StatevectorBackend(0), "num_qubits": 4} | {name: value}
    refused(lambda: qc.PQRRT(**options), name)


@SETTINGS
@given(workers=bad_int(1, 4096))
def test_parallel_rrt_workers(workers):
    refused(lambda: qc.ParallelRRT(workers=workers), "workers")


CALLS = {
    "AerBackend.method": (lambda v: qc.AerBackend(method=v), bad_choice(("statevector", "automatic")), "method"),
    "AerBackend.synthesis": (lambda v: qc.AerBackend(synthesis=v), bad_choice(("auto", "diagonal", "mcz")),
                             "synthesis"),
    "AerBackend.device": (lambda v: qc.AerBackend(device=v), bad_choice(("CPU",)), "device"),
    "AerBackend.max_parallel_threads": (lambda v: qc.AerBackend(max_parallel_threads=v),
                                        bad_int(0, 4096, none_valid=True), "max_parallel_threads"),
    "AerBackend.seed": (lambda v: qc.AerBackend(seed=v), bad_int(0, none_valid=True), "seed"),
    "StatevectorBackend.seed": (lambda v: qc.StatevectorBackend(seed=v), bad_int(0, none_valid=True), "seed"),
    "StatevectorBackend.max_qubits": (lambda v: qc.StatevectorBackend(max_qubits=v),
                                      bad_int(1, 28, none_valid=True), "max_qubits"),
    "StatevectorBackend.closed_form": (lambda v: qc.StatevectorBackend(closed_form=v),
                                       st.one_of(st.integers(), st.text(max_size=3), st.none()), "closed_form"),
    "PaperIterations.early": (lambda v: qc.PaperIterations(early=v), bad_int(0, 100_000), "early"),
    "PaperIterations.late": (lambda v: qc.PaperIterations(late=v), bad_int(0, 100_000), "late"),
    "PaperIterations.switch_nodes": (lambda v: qc.PaperIterations(switch_nodes=v), bad_int(0, 1_000_000),
                                   "switch_nodes"),
    "FixedIterations.k": (lambda v: qc.FixedIterations(v), bad_int(0, 100_000), "k"),
    "BBHT.growth": (lambda v: qc.BBHT(growth=v), bad_float(1.0, 4 / 3 + 1e-12, open_minimum=True), "growth"),
    "BBHT.cap_factor": (lambda v: qc.BBHT(cap_factor=v), bad_float(0.0, 1000.0, open_minimum=True), "cap_factor"),
    "Adaptive.grid_size": (lambda v: qc.Adaptive(grid_size=v), bad_int(10, 100_000), "grid_size"),
    "Adaptive.forgetting": (lambda v: qc.Adaptive(forgetting=v), bad_float(0.0, 1.0, open_minimum=True),
                            "forgetting"),
    "Adaptive.prior": (lambda v: qc.Adaptive(prior=v), bad_choice(("uniform", "log-uniform")), "prior"),
    "Adaptive.max_iterations": (lambda v: qc.Adaptive(max_iterations=v),
                                bad_int(0, 1_000_000, none_valid=True), "max_iterations"),
    "AnnealingSchedule.bands": (lambda v: qc.AnnealingSchedule(bands=v), st.one_of(
        NOT_NUMBERS.filter(lambda v: not isinstance(v, list) or v), st.just(()),
        st.tuples(st.tuples(bad_float(0.0, None), st.floats(1, 2))),
        st.tuples(st.tuples(st.floats(0, 1), bad_float(0.0, None))),
        st.tuples(st.tuples(st.floats(3, 4), st.floats(1, 2))), st.just(((1.0, 2.0, 3.0),)), st.just((5.0,))),
        "bands"),
    "AnnealingSchedule.switch_at": (lambda v: qc.AnnealingSchedule(bands=((2.0, 3.0), (0.5, 1.0)), switch_at=v),
                                    st.one_of(st.tuples(bad_int(1)), st.just(()), st.just((3, 4)), st.none(),
                                              st.just(5), st.text(min_size=1, max_size=2)), "switch_at"),
    "AnnealingSchedule.counter": (lambda v: qc.AnnealingSchedule(bands=((1.0, 2.0),), counter=v),
                                  bad_choice(("databases", "nodes")), "counter"),
    "AnnealingSchedule.placement": (lambda v: qc.AnnealingSchedule(bands=((1.0, 2.0),), placement=v),
                                    bad_choice(("band", "clamp", "annulus", "admit")), "placement"),
    "OracleErrorModel.false_positive": (lambda v: qc.OracleErrorModel(false_positive=v), bad_float(0.0, 1.0),
                                        "false_positive"),
    "OracleErrorModel.false_negative": (lambda v: qc.OracleErrorModel(false_negative=v), bad_float(0.0, 1.0),
                                        "false_negative"),
    "OracleErrorModel.seed": (lambda v: qc.OracleErrorModel(seed=v), bad_int(0, none_valid=True), "seed"),
    "Environment.bounds": (lambda v: qc.Environment(v, np.zeros((0, 2, 2))), st.one_of(
        NOT_NUMBERS, st.booleans(), st.just([[0, 1]]), st.just([[1, 0], [0, 1]]), st.just([[0, 1e300], [0, 1]]),
        st.tuples(st.tuples(NON_FINITE, st.just(1.0)), st.just((0.0, 1.0)))), "bounds"),
    "Environment.boxes": (lambda v: qc.Environment([[0, 10], [0, 10]], v), st.one_of(
        st.none(), st.integers(), st.floats(), st.text(min_size=1, max_size=3), st.just([[1, 2]]),
        st.just([[[5, 5], [4, 4]]]), st.just([[[1, 1, 1], [2, 2, 2]]]), st.just([[[math.nan, 1], [2, 2]]])),
        "boxes"),
    "Problem.start": (lambda v: qc.Problem.build(ENV.env, v, [9.0, 9.0], 0.5), st.one_of(
        st.text(min_size=1, max_size=3), st.just([1.0]), st.just([1, 2, 3]), st.tuples(NON_FINITE, st.just(1.0))),
        "start"),
    "Problem.goal_radius": (lambda v: qc.Problem.build(ENV.env, [1.0, 1.0], [9.0, 9.0], v),
                            bad_float(0.0, None, open_minimum=True), "goal_radius"),
    "LinearTrackingDynamics.horizon": (lambda v: qc.LinearTrackingDynamics(-np.eye(2), np.eye(2), np.eye(2),
                                                                           horizon=v),
                                       bad_float(0.0, None, open_minimum=True), "horizon"),
    "LinearTrackingDynamics.A": (lambda v: qc.LinearTrackingDynamics(v, np.eye(2), np.eye(2)), st.one_of(
        st.none(), st.text(min_size=1, max_size=3), st.just([[1j, 0], [0, 1]]), st.just(np.full((2, 2), np.nan)),
        st.just(np.eye(3)), st.just([1.0, 2.0]), st.just(np.eye(2, dtype=bool)), st.just(np.eye(2) * 5)),
        "A", "B must have shape", "K does not stabilise"),
}


@pytest.mark.parametrize("key", sorted(CALLS))
@SETTINGS
@given(data=st.data())
def test_constructor_arguments(key, data):
    build, values, *names = CALLS[key]
    value = data.draw(values)
    refused(lambda: build(value), *names)


# ------------------------------------------------------------------------------ plan
PROBLEM_ARGUMENTS = [
    ("start", bad_point()),
    ("goal", bad_point()),
    ("goal_radius", bad_float(0.0, None, open_minimum=True)),
    ("resolution", bad_float(0.0, None, open_minimum=True)),
    ("predicate", st.one_of(st.integers(), st.text(max_size=3), st.just(object()))),
    ("space", st.one_of(st.integers(), st.text(max_size=3), st.just(qc.SE2Space()))),
]


@pytest.mark.parametrize("name, values", PROBLEM_ARGUMENTS, ids=[a for a, _ in PROBLEM_ARGUMENTS])
@SETTINGS
@given(data=st.data())
def test_problem_arguments_refused_when_built(name, values, data):
    value = data.draw(values)
    arguments = {"start": [1.0, 1.0], "goal": [9.0, 9.0], "goal_radius": 0.5} | {name: value}
    refused(lambda: qc.Problem.build(ENV.env, **arguments), name, "dimension mismatch")


PLAN_ARGUMENTS = [
    ("max_nodes", bad_int(1, none_valid=True)),
    ("max_oracle_calls", bad_int(1, none_valid=True)),
    ("max_rounds", bad_int(1, none_valid=True)),
    ("max_critical_path_calls", bad_int(1, none_valid=True)),
    ("stall_rounds", bad_int(1, none_valid=True)),
    ("max_time_s", bad_float(0.0, None, open_minimum=True, none_valid=True)),
]


@pytest.mark.parametrize("name, values", PLAN_ARGUMENTS, ids=[a for a, _ in PLAN_ARGUMENTS])
@pytest.mark.parametrize("make", [lambda: qc.RRT(seed=0),
                                  lambda: qc.QRRT(backend=qc.StatevectorBackend(0), num_qubits=4, seed=0)],
                         ids=["rrt", "qrrt"])
@SETTINGS
@given(data=st.data())
def test_plan_arguments_refused_before_any_work(make, name, values, data):
    planner = make()
    value = data.draw(values)
    problem = ENV.replace(predicate=qc.ExactCheck(ENV.env))
    budget = {} if name in ("max_rounds",) else {"max_rounds": 3}
    refused(lambda: planner.plan(problem, **budget, **{name: value}), name)
    assert problem.predicate.evaluations == 0


# ------------------------------------------------------------------------------ search
@pytest.mark.parametrize("backend", [qc.StatevectorBackend(0), qc.AerBackend(0)], ids=["statevector", "aer"])
@SETTINGS
@given(data=st.data())
def test_search_arguments(backend, data):
    marks = np.zeros(16, dtype=bool)
    marks[3] = True
    name, value = data.draw(st.one_of(
        st.tuples(st.just("iterations"), bad_int(0, 100_000)),
        st.tuples(st.just("shots"), bad_int(1, 10_000_000)),
        st.tuples(st.just("seed"), bad_int(0, none_valid=True)),
        st.tuples(st.just("marks"), st.one_of(st.just(np.zeros(15, bool)), st.just(np.zeros((4, 4), bool)),
                                              st.just(np.full(8, 2)), st.just(np.zeros(1, bool)),
                                              st.just(np.full(8, np.nan)), st.just(np.zeros(0))))))
    arguments = {"marks": marks, "iterations": 1, "shots": 4, "seed": 0} | {name: value}

    def search():
        given = dict(arguments)
        return backend.search(qc.LookupOracle(given.pop("marks")), **given)

    refused(search, name)


# ------------------------------------------------------------------------------ scenario files
VALID = ENV.env.to_dict() | {"start": [1.0, 1.0], "goal": [9.0, 9.0], "goal_radius": 0.5}
JSON_VALUES = st.recursive(
    st.one_of(st.none(), st.booleans(), st.integers(min_value=-10**400, max_value=10**400), st.floats(),
              st.text(max_size=4)),
    lambda children: st.one_of(st.lists(children, max_size=3), st.dictionaries(st.text(max_size=3), children,
                                                                               max_size=2)),
    max_leaves=6)


@SETTINGS
@given(field=st.sampled_from(["bounds", "boxes", "start", "goal", "goal_radius", "format", "version",
                              "metadata"]), value=JSON_VALUES)
def test_scenario_file_fields(field, value):
    data = dict(VALID, **{field: value})
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "world.json"
        path.write_text(json.dumps(data))
        try:
            problem = box_world(path)
        except (ValueError, TypeError) as exc:
            assert str(path) in str(exc) and field in str(exc), str(exc)
            return
    # accepted: then it is a valid problem that plans (under a small budget) without another error
    assert problem.dim == 2
    qc.RRT(seed=0).plan(problem, max_rounds=3)


@SETTINGS
@given(text=st.one_of(st.text(max_size=30), st.binary(max_size=30).map(lambda b: b.decode("latin-1"))))
def test_scenario_file_malformed_text(text):
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "world.json"
        path.write_bytes(text.encode("utf-8", "surrogatepass") if text else b"")
        refused(lambda: qc.Environment.load(path), str(path))
