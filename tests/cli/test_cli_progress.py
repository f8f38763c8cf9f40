"""The progress display of ``qrrt plan``: numba's compile time measured from its own events, and the
bar following a plan's counters through ``Planner.plan``'s ``on_round`` observer."""

from __future__ import annotations

import numba
import pytest

import qrrt_circuits as qc
from qrrt_circuits.cli.progress import CompileClock, PlanDisplay
from qrrt_circuits.planners.termination import Progress


def test_the_compile_clock_counts_a_fresh_compilation_and_not_a_second_call():
    @numba.njit
    def triple(x):  # a new function: its first call compiles
        return 3 * x

    clock = CompileClock()
    seen = []
    clock.on_change = seen.append
    with clock.running():
        assert triple(2) == 6
    compiled = clock.seconds
    assert compiled > 0 and seen[0] is True and seen[-1] is False
    with clock.running():
        assert triple(3) == 9  # compiled already: no event
    assert clock.seconds == compiled


def test_on_round_sees_every_round_and_the_final_counts():
    seen: list[Progress] = []
    result = qc.QRRT(num_qubits=5, backend=qc.StatevectorBackend(seed=0), seed=0).plan(
        qc.paper_clutter(seed=0), max_nodes=12, on_round=seen.append)
    assert len(seen) == result.metrics.rounds
    assert [p.rounds for p in seen] == list(range(1, result.metrics.rounds + 1))
    assert seen[-1].nodes == result.metrics.nodes and seen[-1].oracle_calls == result.metrics.oracle_calls
    assert all(a.oracle_calls <= b.oracle_calls and a.nodes <= b.nodes for a, b in zip(seen, seen[1:], strict=False))


def test_on_round_does_not_change_the_plan():
    problem = qc.paper_clutter(seed=0)
    quiet = qc.RRT(seed=4).plan(problem, max_nodes=30)
    watched = qc.RRT(seed=4).plan(problem, max_nodes=30, on_round=lambda progress: None)
    assert (quiet.nodes == watched.nodes).all() and quiet.metrics.oracle_calls == watched.metrics.oracle_calls


@pytest.mark.parametrize("enabled", [True, False])
def test_the_display_follows_a_plan(enabled, capsys):
    display = PlanDisplay(CompileClock(), enabled=enabled)
    display.stage("RRT", total=None)
    display.on_round(Progress(oracle_calls=9, critical_path_oracle_calls=9, nodes=4, rounds=9,
                              rounds_without_new_node=0, elapsed_s=0.1))
    if enabled:
        assert display.bar.n == 4 and "oracle calls=9" in display.bar.postfix
    else:
        assert display.bar is None
    display.close()
    assert display.bar is None
