"""One registry of planners, backends, search policies, scenarios and predicates: every CLI choice
resolves through it, aliases mean the same object, unknown names list the choices."""

import argparse

import pytest

import qrrt_circuits as qc
from qrrt_circuits.cli import build_parser, main
from qrrt_circuits.registry import BACKENDS, PLANNERS, POLICIES, PREDICATES, SCENARIOS, Registry

EXPECTED_PLANNERS = {"rrt": qc.RRT, "prrt": qc.ParallelRRT, "qrrt": qc.QRRT, "pqrrt": qc.PQRRT,
                     "pqrrt-unshared": qc.PQRRT, "qrrt-connect": qc.QRRTConnect, "qrrt-star": qc.QRRTStar}


def _cli_action(command: str, option: str) -> argparse.Action:
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices[command]
    return next(a for a in sub._actions if option in a.option_strings)


def _cli_choices(command: str, option: str) -> tuple[str, ...]:
    return tuple(_cli_action(command, option).choices)


def test_every_cli_choice_comes_from_the_registry():
    assert _cli_choices("plan", "--planner") == PLANNERS.names()
    assert tuple(_cli_action("plan", "--backend").metavar.split("|")) == BACKENDS.names() == \
        _cli_choices("search", "--backend")
    assert tuple(_cli_action("plan", "--policy").metavar.split("|")) == POLICIES.labels()
    assert _cli_choices("plan", "--scenario") == SCENARIOS.names()
    help_text = build_parser()._subparsers._group_actions[0].choices["plan"].format_help()
    for label in POLICIES.labels() + PREDICATES.labels():
        assert label in help_text


@pytest.mark.parametrize("name", list(PLANNERS))
def test_every_planner_name_builds_its_class_and_plans(name, clutter):
    options = {"seed": 1, "workers": 3, "num_qubits": 5, "backend": qc.StatevectorBackend(1)}
    takes = PLANNERS.resolve(name).options()
    planner = PLANNERS.create(name, **{key: value for key, value in options.items() if key in takes})
    assert type(planner) is EXPECTED_PLANNERS[name]
    assert getattr(planner, "shared_database", None) == {"qrrt": True, "pqrrt": True, "pqrrt-unshared": False}.get(name)
    assert planner.plan(clutter, max_rounds=2).metrics.rounds == 2
    assert takes == {spec.name for spec in PLANNERS.resolve(name).specs} | (
        {"executor"} if EXPECTED_PLANNERS[name].takes_executor else set())


@pytest.mark.parametrize("name", list(PLANNERS))
def test_every_planner_runs_from_the_cli(name, capsys):
    """Each planner with the planner-specific options it takes (the others are refused, test_cli_errors)."""
    accepted = PLANNERS.resolve(name).options()
    argv = ["plan", "--planner", name, "--max-rounds", "2"]
    argv += ["--backend", "statevector", "--qubits", "5"] if "num_qubits" in accepted else []
    argv += ["--workers", "2"] if "workers" in accepted else []
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "max_rounds" in out
    assert ("num_qubits               5" in out) == ("num_qubits" in accepted)
    assert ("workers                  2" in out) == ("workers" in accepted)


def test_aliases_resolve_to_the_same_entry():
    for alias, name in {"RRT": "rrt", "ParallelRRT": "prrt", "QRRT": "qrrt", "PQRRT": "pqrrt",
                        "PQRRT-unshared": "pqrrt-unshared"}.items():
        assert PLANNERS.resolve(alias) is PLANNERS.resolve(name)
        assert PLANNERS.canonical(alias) == name


@pytest.mark.parametrize("name", list(BACKENDS))
def test_every_backend_name_searches(name):
    backend = BACKENDS.create(name, seed=3)
    assert isinstance(backend, qc.QuantumSearchBackend)
    marks = [False] * 15 + [True]
    assert backend.search(qc.LookupOracle(marks), 2, shots=4, seed=5).indices.shape == (4,)


def test_policies_including_parametric_ones():
    assert POLICIES.create("paper") == qc.PaperIterations()
    assert POLICIES.create("fixed:3") == qc.FixedIterations(3)
    assert isinstance(POLICIES.create("bbht"), qc.BBHT)
    assert POLICIES.labels() == ("paper", "optimal", "bbht", "adaptive", "thompson", "fixed:K", "fixed-point[:DELTA]",
                                "estimated")
    with pytest.raises(ValueError, match="policy fixed:K needs an integer K >= 0, got 'fixed:x'"):
        POLICIES.create("fixed:x")
    with pytest.raises(ValueError, match="unknown search policy 'fixed'"):
        POLICIES.create("fixed")  # the parameter is required


def test_scenarios_and_predicates(clutter):
    assert SCENARIOS.create("paper_clutter", seed=0).env.boxes.tobytes() == clutter.env.boxes.tobytes()
    assert isinstance(PREDICATES.create("exact", env=clutter.env), qc.ExactCheck)
    sampled = PREDICATES.create("time-samples:20", env=clutter.env)
    assert isinstance(sampled, qc.TimeSampledCheck) and sampled.time_samples == 20


@pytest.mark.parametrize("registry, kind", [(PLANNERS, "planner"), (BACKENDS, "backend"),
                                            (POLICIES, "search policy"), (SCENARIOS, "scenario"),
                                            (PREDICATES, "predicate")])
def test_unknown_names_list_the_choices(registry, kind):
    with pytest.raises(ValueError) as error:
        registry.create("nope")
    assert str(error.value) == f"unknown {kind} 'nope'; choose one of {', '.join(registry.labels())}"
    assert "nope" not in registry
    with pytest.raises(TypeError, match=f"{kind} must be a name"):
        registry.resolve(3)


def test_options_that_do_not_apply_are_refused():
    with pytest.raises(ValueError, match=r"option\(s\) \['backend'\] do not apply to planner 'rrt'"):
        PLANNERS.create("rrt", backend=qc.StatevectorBackend())
    with pytest.raises(ValueError, match=r"option\(s\) \['shared_database'\] do not apply to planner 'pqrrt'"):
        PLANNERS.create("pqrrt", shared_database=False)  # (the entry fixes it)
    with pytest.raises(ValueError, match=r"option\(s\) \['executor'\] do not apply to planner 'qrrt'"):
        PLANNERS.create("qrrt", executor=None)
    with pytest.raises(TypeError, match="QRRT does not take workers"):
        qc.QRRT(workers=4)


def test_a_name_is_registered_once():
    registry = Registry("thing")
    registry.register("a", dict, "first", aliases=("b",))
    with pytest.raises(ValueError, match="thing name 'b' is registered twice"):
        registry.register("b", dict, "second")
