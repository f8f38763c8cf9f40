"""Beyond the paper: what one oracle call and one plan would cost on a quantum computer.

Three parts, one trial list (``qrrt_circuits.hardware.resources`` holds the counting and the assumptions):

- ``near-term``: one Grover iteration (one oracle call) over N = 2^n entries with m = N / 16
  random marks, each phase-oracle synthesis ("diagonal", "mcz"), transpiled to [cx, rz, sx, x] on
  all-to-all, a line and heavy-hex: two-qubit gates and two-qubit depth, n = 4 ... 12.
- ``fault-tolerant``: Toffoli (And) and T counts of one call with the oracle over a classical
  lookup of the 2^n marks (QROM and select-swap QROM) plus the diffuser; Qualtran's bloqs when the
  ``ft`` extra is installed, else the published formulas.
- ``plan``: RRT and q-RRT (n = 8, the paper's schedule, exact statevector) grow 30-node trees in
  the worlds of ``oracle-efficiency`` (same world seeds). RRT's wall time gives the classical time
  of a plan and of one reachability test (measured where the trials run, other trials running
  beside it); q-RRT's quantum calls times the time of one call gives its projected time. The
  break-even time per call is where the two meet.
"""

from __future__ import annotations

import functools
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..hardware import resources as res
from ..registry import PLANNERS
from ..search.policies.schedules import PaperIterations
from .base import Experiment, Record, Settings, Summary, Trial, TrialStream, replicate_seed
from .figures import new_figure, save, with_intervals
from .intervals import MIN_BOOTSTRAP_WORLDS, bootstrap_interval, rounded_interval
from .planners import experiment_problem
from .worlds import world

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ..search.backends.statevector import StatevectorBackend

_NUMBERS = ("n", "m", "two_qubit_gates", "two_qubit_depth", "depth", "physical_qubits", "oracle_ands",
            "oracle_t", "diffuser_ands", "t_count", "toffoli_equivalents", "nodes", "oracle_calls",
            "quantum_oracle_calls", "verification_calls", "simulation_checks", "rounds", "wall_time_s",
            "world_seed", "replicate")
#: every column of a record, with its value where a part leaves it out
COLUMNS: dict[str, Any] = {**dict.fromkeys(_NUMBERS, math.nan), "synthesis": "", "connectivity": "", "lookup": "",
                           "source": "", "planner": "", "status": ""}
ASSUMPTIONS = res.ProjectionAssumptions()


def database_marks(num_qubits: int, seed: int) -> np.ndarray:
    """A database's marks for the gate counts: max(1, N / 16) random entries of N = 2^n.

    Args:
        num_qubits: Index qubits n.
        seed: Seed of the marks' positions.

    Returns:
        (2^n,) booleans.
    """
    size = 1 << num_qubits
    marks = np.zeros(size, dtype=bool)
    marks[np.random.default_rng(seed).choice(size, max(1, size >> 4), replace=False)] = True
    return marks


#: plan worlds of a full run (fewer than ``MIN_BOOTSTRAP_WORLDS``: the plan intervals are ranges over them)
PLAN_WORLDS = 10


class Resources(Experiment):
    """Gates and time per oracle call and per plan, near term and fault tolerant (beyond the paper).

    Three parts (see the module docstring): ``near-term`` (two-qubit gates and depth of one Grover
    iteration after routing), ``fault-tolerant`` (Toffoli and T counts of one call with a lookup
    oracle) and ``plan`` (RRT's measured time against q-RRT's projected time, and the break-even
    time per call), each summarized with its assumptions.
    """

    name = "resources"
    title = "Gates and time per oracle call and per plan, near term and fault tolerant (beyond the paper)"
    paper = {"cost_model": "oracle calls only; the paper gives no gate counts or times"}

    def settings(self, quick: bool, trials: int | None, seed: int) -> Settings:
        lookups = ["qrom", "select-swap"] if res.has_qualtran() else ["qrom"]
        return {"trials": trials or (1 if quick else PLAN_WORLDS), "seed": seed, "quick": quick,
                "qubits": [3, 4] if quick else list(range(4, 13)), "syntheses": ["diagonal", "mcz"],
                "connectivities": list(res.CONNECTIVITIES), "lookups": lookups,
                "ft_source": "qualtran" if res.has_qualtran() else "formula",
                "plan_qubits": 4 if quick else 8, "nodes": 3 if quick else 30,
                "toffoli_s": ASSUMPTIONS.toffoli_s, "two_qubit_gate_s": ASSUMPTIONS.two_qubit_gate_s}

    def trials(self, settings: Settings) -> list[Trial]:
        out: list[Trial] = []
        root = settings["seed"]
        for n in settings["qubits"]:
            seed = replicate_seed(root, n, TrialStream.RESOURCES_WORLDS)
            for synthesis in settings["syntheses"]:
                for connectivity in settings["connectivities"]:
                    out.append(Trial(f"near-term-n{n}-{synthesis}-{connectivity}",
                                     {"part": "near-term", "n": n, "synthesis": synthesis,
                                      "connectivity": connectivity}, seed))
            for lookup in settings["lookups"]:
                out.append(Trial(f"fault-tolerant-n{n}-{lookup}", {"part": "fault-tolerant", "n": n,
                                                                    "lookup": lookup}, 0))
        for replicate in range(settings["trials"]):  # the worlds and planner seeds of oracle-efficiency
            world_seed = replicate_seed(root, replicate, TrialStream.PAPER_WORLDS)
            seed = replicate_seed(root, replicate, TrialStream.PAPER_PLANNERS)
            for planner in ("RRT", "QRRT"):
                out.append(Trial(f"plan-{planner}-{replicate}", {"part": "plan", "planner": planner,
                                                                 "replicate": replicate, "world_seed": world_seed},
                                 seed))
        return out

    def run_trial(self, trial: Trial, settings: Settings) -> Record:
        part = trial.params["part"].replace("-", "_")
        record: Record = getattr(self, f"_run_{part}")(trial, settings)
        return {key: value for key, value in COLUMNS.items() if key not in trial.params} | record

    def _run_near_term(self, trial: Trial, settings: Settings) -> Record:
        p = trial.params
        marks = database_marks(p["n"], trial.seed)
        count = res.near_term_counts(marks, p["synthesis"], p["connectivity"])
        return {"m": count.num_marked, "two_qubit_gates": count.two_qubit_gates,
                "two_qubit_depth": count.two_qubit_depth, "depth": count.depth,
                "physical_qubits": count.physical_qubits}

    def _run_fault_tolerant(self, trial: Trial, settings: Settings) -> Record:
        count = res.fault_tolerant_counts(trial.params["n"], trial.params["lookup"],
                                          use_qualtran=settings["ft_source"] == "qualtran")
        return {"oracle_ands": count.oracle_ands, "oracle_t": count.oracle_t, "diffuser_ands": count.diffuser_ands,
                "t_count": count.t_count, "toffoli_equivalents": count.toffoli_equivalents, "source": count.source}

    def _run_plan(self, trial: Trial, settings: Settings) -> Record:
        problem = experiment_problem(settings, world("paper_clutter", trial.params["world_seed"]))
        # compile the predicate's kernels before the timed plan (a first call in a process JIT-compiles)
        problem.predicate.reachable(problem.start[None, :], problem.start[None, :])
        if trial.params["planner"] == "RRT":
            planner = PLANNERS.create("RRT", seed=trial.seed)
        else:
            planner = PLANNERS.create("QRRT", backend=plan_backend(), num_qubits=settings["plan_qubits"],
                                      search_policy=PaperIterations(), seed=trial.seed)
        result = planner.plan(problem, max_nodes=settings["nodes"])
        m = result.metrics
        return {"status": str(result.status), "nodes": m.nodes, "oracle_calls": m.oracle_calls,
                "quantum_oracle_calls": m.quantum_oracle_calls, "verification_calls": m.verification_calls,
                "simulation_checks": m.simulation_checks, "rounds": m.rounds, "wall_time_s": m.wall_time_s}

    # ------------------------------------------------------------------ summary
    def summarize(self, records: list[Record], settings: Settings) -> Summary:
        near: dict[str, dict[str, dict[str, Any]]] = {}
        for r in (r for r in records if r["part"] == "near-term"):
            near.setdefault(str(r["n"]), {})[f"{r['synthesis']}/{r['connectivity']}"] = {
                "two_qubit_gates": r["two_qubit_gates"], "two_qubit_depth": r["two_qubit_depth"]}
        fault: dict[str, dict[str, dict[str, Any]]] = {}
        for r in (r for r in records if r["part"] == "fault-tolerant"):
            fault.setdefault(str(r["n"]), {})[r["lookup"]] = {
                "ands": r["oracle_ands"] + r["diffuser_ands"], "t_count": r["t_count"],
                "toffoli_equivalents": r["toffoli_equivalents"],
                "time_per_call_s": r["toffoli_equivalents"] * settings["toffoli_s"], "source": r["source"]}
        plan = self._plan_summary(records, settings, near, fault)
        return {"ours": {"per_call_near_term": near, "per_call_fault_tolerant": fault, "per_plan": plan["table"]},
                "paper": self.paper, "plan": plan,
                "assumptions": {"toffoli_s": settings["toffoli_s"], "two_qubit_gate_s": settings["two_qubit_gate_s"],
                                "t_gate": "a quarter of a Toffoli time (4 T per And)", "cliffords": "free",
                                "near_term_time": "two-qubit depth x two_qubit_gate_s, errors ignored (lower bound)"},
                "labels": ["classical times measured on the machine that ran the trials (RRT wall time / its "
                           "reachability tests; they move with its load and speed)",
                           "q-RRT plans on the exact statevector backend (same statistics as Aer)",
                           f"plan intervals (plan.interval): {plan['interval_kind']}",
                           f"fault-tolerant counts from {settings['ft_source']}"]}

    def _plan_summary(self, records: list[Record], settings: Settings, near: dict[str, dict[str, dict[str, Any]]],
                      fault: dict[str, dict[str, dict[str, Any]]]) -> dict[str, Any]:
        rows = [r for r in records if r["part"] == "plan"]
        by_world: dict[int, dict[str, Record]] = {}
        for r in rows:
            by_world.setdefault(r["replicate"], {})[r["planner"]] = r
        worlds = sorted(by_world)
        n = settings["plan_qubits"]
        lookup = settings["lookups"][-1]  # the cheaper lookup where both are counted
        call_ft = fault[str(n)][lookup]["time_per_call_s"] if str(n) in fault else math.nan
        near_key = "diagonal/heavy-hex"
        call_nt = (near[str(n)][near_key]["two_qubit_depth"] * settings["two_qubit_gate_s"]
                   if str(n) in near else math.nan)

        def means(sample: list[int]) -> dict[str, Any]:
            rrt = [by_world[w]["RRT"] for w in sample]
            q = [by_world[w]["QRRT"] for w in sample]
            test_s = sum(r["wall_time_s"] for r in rrt) / sum(r["oracle_calls"] for r in rrt)
            return {"rrt_calls": np.mean([r["oracle_calls"] for r in rrt]),
                    "rrt_time_s": np.mean([r["wall_time_s"] for r in rrt]),
                    "test_s": test_s,
                    "quantum_calls": np.mean([r["quantum_oracle_calls"] for r in q]),
                    "verifications": np.mean([r["verification_calls"] for r in q]),
                    "table_checks": np.mean([r["simulation_checks"] for r in q])}

        def derived(sample: list[int]) -> dict[str, Any]:
            v = means(sample)
            v["qrrt_fault_tolerant_s"] = res.plan_time_s(v["quantum_calls"], v["verifications"], call_ft, v["test_s"])
            v["qrrt_fault_tolerant_with_table_s"] = v["qrrt_fault_tolerant_s"] + v["table_checks"] * v["test_s"]
            v["qrrt_near_term_lower_bound_s"] = res.plan_time_s(v["quantum_calls"], v["verifications"], call_nt,
                                                                v["test_s"])
            v["break_even_call_s"] = res.break_even_call_s(v["rrt_calls"], v["quantum_calls"], v["verifications"],
                                                           v["test_s"])
            # machine-independent: the break-even in units of one classical test (measured timings cancel)
            v["break_even_tests_per_call"] = v["break_even_call_s"] / v["test_s"]
            v["table_checks_over_rrt_calls"] = v["table_checks"] / v["rrt_calls"]
            v["break_even_toffolis"] = v["break_even_call_s"] / settings["toffoli_s"]
            v["break_even_two_qubit_layers"] = v["break_even_call_s"] / settings["two_qubit_gate_s"]
            return v

        table: dict[str, Any] = {key: float(value) for key, value in derived(worlds).items()}
        def statistic(sample: list[int], key: str) -> Any:
            return derived(sample)[key]

        if len(worlds) >= MIN_BOOTSTRAP_WORLDS:
            intervals = {key: rounded_interval(bootstrap_interval(worlds, functools.partial(statistic, key=key),
                                                                  settings["seed"]), 9) for key in table}
            kind = f"95 % percentile bootstrap over {len(worlds)} worlds"
        else:  # too few worlds for a bootstrap: the range of the single worlds' values
            singles = [derived([w]) for w in worlds]
            intervals = {key: rounded_interval((min(float(v[key]) for v in singles),
                                                max(float(v[key]) for v in singles)), 9) for key in table}
            kind = f"range over {len(worlds)} worlds (min-max of single worlds; fewer than {MIN_BOOTSTRAP_WORLDS})"
        table.update(num_qubits=n, lookup=lookup, fault_tolerant_call_s=call_ft, near_term_call_s=call_nt,
                     fault_tolerant_over_break_even=(call_ft / table["break_even_call_s"]
                                                     if table["break_even_call_s"] > 0 else math.inf))
        return {"table": table, "interval": intervals, "interval_kind": kind, "worlds": len(worlds)}

    def plot(self, records: list[Record], settings: Settings, summary: Summary, out_dir: Path) -> list[Path]:
        """Gate counts per call (near term, fault tolerant), the time per call against the plans'
        break-even (its own panel: seconds, and classical tests on a second axis), and the time
        per plan."""
        fig, axes = new_figure(2, 2, (13, 9.6))
        plan = summary["plan"]["table"]
        spans = summary["plan"]["interval"]
        ax = axes[0, 0]
        for synthesis, marker in zip(settings["syntheses"], "os", strict=False):
            for connectivity in settings["connectivities"]:
                rows = sorted((r for r in records if r["part"] == "near-term" and r["synthesis"] == synthesis
                               and r["connectivity"] == connectivity), key=lambda r: r["n"])
                ax.plot([r["n"] for r in rows], [r["two_qubit_gates"] for r in rows], marker=marker,
                        label=f"{synthesis}, {connectivity}")
        ax.set_yscale("log")
        ax.set_xlabel("index qubits n (m = N/16)")
        ax.set_ylabel("CX per oracle call (one Grover iteration)")
        ax.set_title("Near term: [cx, rz, sx, x] after routing", fontsize=10)
        ax.legend(fontsize=7.5)
        ax.grid(alpha=0.3, which="both")

        ax = axes[0, 1]
        for lookup in settings["lookups"]:
            rows = sorted((r for r in records if r["part"] == "fault-tolerant" and r["lookup"] == lookup),
                          key=lambda r: r["n"])
            ax.plot([r["n"] for r in rows], [r["toffoli_equivalents"] for r in rows], "o-",
                    label=f"lookup oracle ({lookup}) + diffuser")
        ax.set_yscale("log")
        ax.set_xlabel("index qubits n")
        ax.set_ylabel("Toffoli equivalents per oracle call")
        ax.set_title(f"Fault tolerant ({settings['ft_source']})", fontsize=10)
        ax.legend(fontsize=7.5)
        ax.grid(alpha=0.3, which="both")

        ax = axes[1, 0]
        self._plot_time_per_call(ax, records, settings, plan, spans)

        ax = axes[1, 1]
        labels = ["RRT (measured)", "q-RRT FT,\nquantum part", "q-RRT FT,\n+ lookup table",
                  "q-RRT near term\n(lower bound)"]
        keys = ["rrt_time_s", "qrrt_fault_tolerant_s", "qrrt_fault_tolerant_with_table_s",
                "qrrt_near_term_lower_bound_s"]
        values = [plan[k] for k in keys]
        errors = np.array([[plan[k] - spans[k][0], spans[k][1] - plan[k]] for k in keys]).T
        ax.bar(range(len(keys)), values, yerr=np.clip(errors, 0, None), capsize=4,
               color=["tab:gray", "tab:blue", "tab:purple", "tab:orange"])
        ax.set_xticks(range(len(keys)), labels, fontsize=8)
        ax.set_yscale("log")
        ax.set_ylabel(f"seconds per {settings['nodes']}-node plan ({summary['plan']['interval_kind'].split(' (')[0]})",
                      fontsize=8)
        ax.set_title(f"paper_clutter plans, n = {plan['num_qubits']}, paper schedule", fontsize=10)
        ax.grid(alpha=0.3, axis="y", which="both")
        return [save(fig, out_dir / "resources.png")]

    @staticmethod
    def _plot_time_per_call(ax: Axes, records: list[Record], settings: Settings, plan: dict[str, Any],
                            spans: dict[str, list[float]]) -> None:
        """Seconds per oracle call (fault tolerant at ``toffoli_s`` a Toffoli; near term at the
        two-qubit depth, a lower bound) against n, and the break-even time per call of the n-qubit
        plans with its interval (``plan.interval_kind``); a second axis counts the seconds in classical reachability
        tests of the measured time (the break-even's machine-independent unit)."""
        for lookup in settings["lookups"]:
            rows = sorted((r for r in records if r["part"] == "fault-tolerant" and r["lookup"] == lookup),
                          key=lambda r: r["n"])
            ax.plot([r["n"] for r in rows], [r["toffoli_equivalents"] * settings["toffoli_s"] for r in rows], "o-",
                    label=f"fault tolerant, {lookup} (at {settings['toffoli_s'] * 1e6:g} µs a Toffoli)")
        rows = sorted((r for r in records if r["part"] == "near-term" and r["synthesis"] == "diagonal"
                       and r["connectivity"] == "heavy-hex"), key=lambda r: r["n"])
        ax.plot([r["n"] for r in rows], [r["two_qubit_depth"] * settings["two_qubit_gate_s"] for r in rows], "s--",
                color="tab:green", label=f"near term, diagonal on heavy-hex (two-qubit depth x "
                                          f"{settings['two_qubit_gate_s'] * 1e9:g} ns; lower bound)")
        n, test_s = plan["num_qubits"], plan["test_s"]
        low, high = spans["break_even_call_s"]
        tests_low, tests_high = spans["break_even_tests_per_call"]
        with_intervals(ax, [n], [plan["break_even_call_s"]], [[low, high]], fmt="*", ms=14, color="tab:red",
                       capsize=5, zorder=4,
                       label=f"break-even of the n = {n} plans: {plan['break_even_call_s'] * 1e6:.3g} µs per call "
                             f"[{low * 1e6:.3g}, {high * 1e6:.3g}]\n= {plan['break_even_tests_per_call']:.2g} "
                             f"classical tests [{tests_low:.2g}, {tests_high:.2g}]")
        ax.set_yscale("log")
        ax.set_xlabel("index qubits n")
        ax.set_ylabel("seconds per oracle call")
        ax.set_title(f"Time per oracle call vs the break-even (n = {n} plans; q-RRT wins below it)", fontsize=10)
        second = ax.secondary_yaxis("right", functions=(lambda s: s / test_s, lambda t: t * test_s))
        second.set_ylabel(f"classical reachability tests per call ({test_s * 1e6:.2g} µs each, measured)")
        ax.legend(fontsize=7.5, loc="upper left")
        ax.grid(alpha=0.3, which="both")


def plan_backend() -> StatevectorBackend:
    """The ideal backend of the plan part (only oracle calls are taken from q-RRT's plans).

    Returns:
        A new exact statevector backend.
    """
    from ..search.backends.statevector import StatevectorBackend

    return StatevectorBackend()
