"""A planner written outside the package, a class the library has never seen, plans a ``Problem``
through the library's one round loop, its registry (options declared once, refused by name) and its
command line (flags derived from the declarations)."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest

import qrrt_circuits as qc
from qrrt_circuits.planners.options import PlannerOptions, declare, option_specs
from qrrt_circuits.registry import Registry, register_planner


def _step(value, name):
    if isinstance(value, bool) or not isinstance(value, int | float) or not 0.0 < value <= 10.0:
        raise ValueError(f"{name} must be a number in (0, 10], got {value!r}")
    return float(value)


@dataclass(frozen=True, kw_only=True)
class StepOptions(PlannerOptions):
    """What every planner takes, and the step."""

    step: float = declare(0.5, _step, "longest step toward a sample", "--step", float)


class StepRRT(qc.Planner):
    """RRT whose child is at most ``step`` from its parent, nearest parent by the problem's metric:
    one sample, one reachability test (one oracle call) a round."""

    name = "StepRRT"
    Options: ClassVar[type[PlannerOptions]] = StepOptions

    def _round(self, state) -> None:
        context = state.worker_context
        sample = context.env.sample_uniform(1, self.rng(state.rounds))[0]
        nodes = state.tree.nodes
        parent = int(np.argmin(context.space.distance(nodes, sample)))
        gap = float(context.space.distance(nodes[parent][None], sample)[0])
        fraction = min(1.0, self.options.step / gap) if gap > 0 else 1.0
        child = context.space.interpolate(nodes[parent][None], sample[None], np.array([fraction]))[0]
        state.verification_calls += 1
        state.critical_path += 1
        state.round_entries += 1
        if context.predicate.reachable(nodes[parent][None], child[None])[0]:
            state.round_reachable += 1
            state.add_node(child, parent)


def test_it_plans_a_problem_in_the_one_loop_and_every_edge_rechecks(clutter):
    problem = clutter.replace(predicate=qc.ExactCheck(clutter.env))  # its own count of evaluations
    recheck = qc.ExactCheck(clutter.env)
    reached = calls = 0
    for seed in range(5):
        result = StepRRT(step=1.0, seed=seed).plan(problem, max_oracle_calls=4000)
        reached += result.reached
        calls += result.metrics.oracle_calls
        steps = np.linalg.norm(result.nodes[1:] - result.nodes[result.parents[1:]], axis=1)
        assert steps.max() <= 1.0 + 1e-9
        assert recheck.reachable(result.nodes[result.parents[1:]], result.nodes[1:]).all()
        assert result.metrics.oracle_calls == result.metrics.rounds == result.metrics.verification_calls
        assert result.settings["step"] == 1.0 and result.planner == "StepRRT"
        assert result.status in ("reached", "max_oracle_calls")
    assert reached >= 4
    assert problem.predicate.evaluations == calls  # one evaluation per oracle call: nothing else asked it


def test_its_options_are_declared_once_and_refused_by_name():
    assert [spec.name for spec in option_specs(StepOptions)][-1] == "step"
    with pytest.raises(ValueError, match=r"step must be a number in \(0, 10\], got 0"):
        StepRRT(step=0)
    with pytest.raises(TypeError, match="StepRRT does not take workers"):
        StepRRT(workers=2)
    with pytest.raises(TypeError, match="StepRRT does not take executor"):
        StepRRT(executor=object())
    registry = Registry("planner")
    register_planner(registry, "step-rrt", StepRRT, "RRT with a step")
    assert registry.resolve("step-rrt").options() == {"goal_bias", "max_extension", "oracle_errors", "seed", "step"}
    planner = registry.create("step-rrt", step=2.0, seed=1)
    assert isinstance(planner, StepRRT) and planner.options.step == 2.0
    with pytest.raises(ValueError, match=r"option\(s\) \['num_qubits'\] do not apply to planner 'step-rrt'"):
        registry.create("step-rrt", num_qubits=4)


def test_the_command_line_plans_it_with_its_own_flag(tmp_path):
    """Registered in ``PLANNERS`` before the command line is built: ``--step`` is derived from its
    declaration and ``--qubits`` is refused for it, naming the planners that take it."""
    module = tmp_path / "user_planner.py"
    module.write_text(textwrap.dedent(_source_of_this_planner()))
    script = ("import sys; sys.path.insert(0, sys.argv[1])\n"
              "import user_planner\n"
              "from qrrt_circuits.registry import PLANNERS, register_planner\n"
              "register_planner(PLANNERS, 'step-rrt', user_planner.StepRRT, 'RRT with a step')\n"
              "from qrrt_circuits.cli import main\n"
              "sys.exit(main(sys.argv[2:]))\n")
    base = [sys.executable, "-c", script, str(tmp_path), "plan", "--planner", "step-rrt", "--max-rounds", "20"]
    run = subprocess.run([*base, "--step", "0.25"], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert "StepRRT on paper_clutter" in run.stdout and "0.25" in run.stdout
    refused = subprocess.run([*base, "--qubits", "4"], capture_output=True, text=True, timeout=300)
    assert refused.returncode != 0 and "--qubits does not apply to --planner step-rrt" in refused.stderr
    bad = subprocess.run([*base, "--step", "11"], capture_output=True, text=True, timeout=300)
    assert bad.returncode != 0 and "--step must be a number in (0, 10], got 11.0" in bad.stderr


def _source_of_this_planner() -> str:
    """This module's planner, as the source of a module of its own (the command line's process
    imports it as a user's code)."""
    import inspect

    header = ("from __future__ import annotations\nfrom dataclasses import dataclass\nfrom typing import ClassVar\n"
              "import numpy as np\nimport qrrt_circuits as qc\n"
              "from qrrt_circuits.planners.options import PlannerOptions, declare\n\n\n")
    return header + "\n\n".join(inspect.getsource(item) for item in (_step, StepOptions, StepRRT))
