"""Beyond the paper: the reachability check as a reversible circuit (``qrrt_circuits.coherent``),
verified and costed against the lookup oracle and against classical RRT.

Trials of three kinds, every instance from ``coherent.costs.scaling_instance`` (the paper's clutter
world with B boxes on [0, 20]^2, 2^m tree nodes uniform over its free space, (n - m) / 2 cell bits
per axis, b-bit coordinates, the paper's dynamics at K time samples with f = b fraction bits), one
world per replicate (its seed):

- ``verify``: ``verify_oracle`` on every one of the 2^n index states (m = 2, b = 12, K = 8, B = 20):
  mismatches with the fixed-point reference, ancillas clean, index preserved; and the rounding
  comparison with the floating-point ``TimeSampledCheck`` at the same K
  (``compare_with_time_sampled``): the share of entries whose answer the rounding changes.
- ``grover``: Grover search with the coherent oracle on Aer's ``matrix_product_state`` method
  (index register in the middle of the chain), k = ``optimal_iterations(2^n, m)`` for the
  reference's m, ``GROVER_SHOTS`` shots: the marked share against sin^2((2k+1) theta).
- ``cost``: qubits, ANDs (Toffolis with measurement-based uncomputation) and CCX of one oracle call
  for n = 10 .. 30 and B = 10, 100, 1000 (m = 6, b = 16, K = 16), counted in closed form by the
  circuit's own constructors, beside the lookup oracle over the same 2^n marks (unary-iteration
  QROM and select-swap, load and unload: ``coherent.lookup_costs``); and at n = 20, B = 100 the
  same against the coordinate bits b (K = 16) and the time samples K (b = 16).

- ``plan``: q-RRT (n = 7, ``BBHT()``, budget ``PLAN_BUDGET`` oracle calls) in a corridor world with a
  box in its middle (start (2, 10), goal ball (18, 10) of radius 2.5), its database the paper's
  (``NearestParents``), the lattice searched by lookup, or the lattice searched by the coherent
  circuit on Aer (``LatticeCandidates(3, bits=6)``, K = 4), every edge verified by the exact check:
  the planning figures of the two databases side by side.

The summary gives the verification counts, the Grover hit rate against theory with its binomial
interval, the costs and, per (n, B), the **break-even test time**: with the coherent oracle one
q-RRT oracle call costs (oracle ANDs + the diffuser's n - 2) x 10 us (the resource study's
``ProjectionAssumptions``), and it pays against RRT only if it costs less than the classical tests
it saves; the resource study measures those savings as ``break_even_tests_per_call`` (its
``plan`` table, read into the settings from ``docs/results/resources/summary.json`` when present:
measured at n = 8 in the paper's world, an assumption elsewhere), so the break-even is a classical
test slower than call time / tests saved per call; and the plan time that follows on the resource
study's plans (its q-RRT's mean quantum calls x call time + verifications x test time, beside its
RRT's calls x test time).
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .base import Experiment, Record, Settings, Summary, Trial, TrialStream, replicate_seed
from .figures import new_figure, save
from .intervals import binomial_interval, bootstrap_interval, rounded_interval

if TYPE_CHECKING:
    from ..search.backends.base import QuantumSearchBackend

VERIFY_BITS = (8, 12, 16)
GROVER_BITS = (5, 9, 13)
COST_BITS = (10, 14, 18, 22, 26, 30)
COST_BOXES = (10, 100, 1000)
#: the precision sweeps at n = 20, B = 100: coordinate bits b (K = 16) and time samples K (b = 16)
SWEEP_BITS = (8, 12, 16, 20, 24)
SWEEP_SAMPLES = (4, 8, 16, 32, 64)
GROVER_SHOTS = 256
PLAN_BUDGET = 400
PLAN_CONFIGS = ("paper database", "lattice, lookup", "lattice, coherent")
#: the resource study's summary, whose measured savings per quantum call the break-even reads
RESOURCES_SUMMARY = Path("docs") / "results" / "resources" / "summary.json"
TOFFOLI_S = 1e-5
#: every trial's measurement columns (a kind leaves the others NaN)
COLUMNS = ("reached", "oracle_calls", "nodes", "qubits", "gates", "entries", "marked", "mismatches",
           "ancillas_clean", "index_preserved", "rounding_compared", "rounding_differs", "iterations", "shots",
           "hits", "expected", "search_s", "oracle_ands", "toffolis", "diffuser_ands", "lookup_qrom_ands",
           "lookup_select_swap_ands")


#: the corridor of the searches and plans: [0, 20]^2 less y <= 7 and y >= 13
BOUNDS = np.array([[0.0, 20.0], [0.0, 20.0]])
CORRIDOR_WALLS = np.array([[[0.0, 0.0], [20.0, 7.0]], [[0.0, 13.0], [20.0, 20.0]]])
#: the box in the corridor's middle that the plans go round
MIDDLE_BOX = np.array([[[9.0, 9.0], [11.0, 11.0]]])


def _grover_instance(index_bits: int, seed: int) -> tuple[Any, Any, Any]:
    """A corridor world: [0, 20]^2 less y <= 7 and y >= 13, two tree nodes in the corridor,
    a = (n - 1) / 2 cell bits per axis, b = max(6, a + 1), the paper's dynamics at K = 4."""
    from ..coherent import FixedPointFormat, LatticeDatabase, SampledMotion
    from ..reachability.dynamics import LinearTrackingDynamics
    from ..world.environment import Environment

    env = Environment(BOUNDS, CORRIDOR_WALLS)
    rng = np.random.default_rng(seed)
    nodes = np.column_stack([rng.uniform(1.0, 19.0, 2), rng.uniform(8.0, 12.0, 2)])
    cell_bits = (index_bits - 1) // 2
    bits = max(6, cell_bits + 1)
    database = LatticeDatabase(FixedPointFormat.covering(env, bits), cell_bits, nodes)
    return env, database, SampledMotion.from_dynamics(LinearTrackingDynamics.paper(), 4, bits)


class CoherentOracleExperiment(Experiment):
    """The coherent reachability oracle: verified, searched on Aer, costed (module docstring)."""

    name = "coherent-oracle"
    title = "The reachability check as a reversible circuit: verified, searched on Aer, costed (beyond the paper)"
    uses_predicate = False
    paper = {"note": "the paper's oracle is a black box; no circuit for it is given or costed"}

    def settings(self, quick: bool, trials: int | None, seed: int) -> Settings:
        return {"trials": trials or (1 if quick else 3), "verify_bits": list(VERIFY_BITS[:1] if quick else VERIFY_BITS),
                "grover_bits": list(GROVER_BITS[:1] if quick else GROVER_BITS),
                "cost_bits": list(COST_BITS[:2] if quick else COST_BITS), "cost_boxes": list(COST_BOXES),
                "sweep_bits": list(SWEEP_BITS[:2] if quick else SWEEP_BITS),
                "sweep_samples": list(SWEEP_SAMPLES[:2] if quick else SWEEP_SAMPLES),
                "plan_configs": list(PLAN_CONFIGS), "plan_replicates": 2 if quick else 20,
                "plan_budget": PLAN_BUDGET,
                "grover_shots": GROVER_SHOTS, "toffoli_s": TOFFOLI_S, **_resource_savings(),
                "seed": seed, "quick": quick}

    def trials(self, settings: Settings) -> list[Trial]:
        trials = []
        for replicate in range(settings["trials"]):
            seed = replicate_seed(settings["seed"], replicate, TrialStream.COHERENT_ORACLE) % (2**31)
            for n in settings["verify_bits"]:
                trials.append(Trial(f"verify-{n}-{replicate}", {"kind": "verify", "config": "", "index_bits": n,
                                                                 "boxes": 20, "replicate": replicate}, seed))
            for n in settings["grover_bits"]:
                trials.append(Trial(f"grover-{n}-{replicate}", {"kind": "grover", "config": "", "index_bits": n,
                                                                 "boxes": 2, "replicate": replicate}, seed))
        for replicate in range(settings["plan_replicates"]):
            seed = replicate_seed(settings["seed"], replicate, TrialStream.COHERENT_ORACLE_PLANS)
            for config in settings["plan_configs"]:
                trials.append(Trial(f"plan-{config}-{replicate}", {"kind": "plan", "config": config, "index_bits": 7,
                                                                    "boxes": 3, "replicate": replicate}, seed))
        for n in settings["cost_bits"]:  # counts do not depend on the replicate's draw: one world
            for boxes in settings["cost_boxes"]:
                trials.append(Trial(f"cost-{n}-{boxes}", {"kind": "cost", "config": "", "index_bits": n,
                                                          "boxes": boxes,
                                                          "replicate": 0}, 0))
        for b in settings["sweep_bits"]:
            trials.append(Trial(f"cost-b{b}", {"kind": "cost", "config": f"b={b}", "index_bits": 20, "boxes": 100,
                                               "replicate": 0}, 0))
        for k in settings["sweep_samples"]:
            trials.append(Trial(f"cost-K{k}", {"kind": "cost", "config": f"K={k}", "index_bits": 20, "boxes": 100,
                                               "replicate": 0}, 0))
        return trials

    def run_trial(self, trial: Trial, settings: Settings) -> Record:
        kind = trial.params["kind"]
        if kind == "verify":
            record = _verify(trial.params["index_bits"], trial.params["boxes"], trial.seed)
        elif kind == "plan":
            record = _plan(trial.params["config"], trial.seed, settings["plan_budget"])
        elif kind == "grover":
            record = _grover(trial.params["index_bits"], trial.seed, settings["grover_shots"])
        else:
            sweep = dict(part.split("=") for part in trial.params["config"].split(",") if part)
            record = _cost(trial.params["index_bits"], trial.params["boxes"], trial.seed, int(sweep.get("b", 16)),
                           int(sweep.get("K", 16)))
        return dict.fromkeys(COLUMNS, math.nan) | record  # one header for the three kinds

    def summarize(self, records: list[Record], settings: Settings) -> Summary:
        verify = [r for r in records if r["kind"] == "verify"]
        grover = [r for r in records if r["kind"] == "grover"]
        costs = [r for r in records if r["kind"] == "cost"]
        ours: dict[str, Any] = {"verification": {}, "grover": {}}
        intervals: dict[str, Any] = {"verification": {}, "grover": {}}
        for n in settings["verify_bits"]:
            rows = [r for r in verify if r["index_bits"] == n]
            entries = sum(r["entries"] for r in rows)
            differ = sum(r["rounding_differs"] for r in rows)
            compared = sum(r["rounding_compared"] for r in rows)
            ours["verification"][str(n)] = {"mismatches": sum(r["mismatches"] for r in rows),
                                            "entries": entries,
                                            "rounding_differs_fraction": round(differ / compared, 5)}
            low, high = binomial_interval(differ, compared)
            intervals["verification"][str(n)] = {"mismatches": [0, 0], "entries": [entries, entries],
                                                 "rounding_differs_fraction": rounded_interval((low, high), 5)}
        for n in settings["grover_bits"]:
            rows = [r for r in grover if r["index_bits"] == n]
            hits, shots = sum(r["hits"] for r in rows), sum(r["shots"] for r in rows)
            expected = float(np.mean([r["expected"] for r in rows]))
            ours["grover"][str(n)] = {"hit_rate": round(hits / shots, 4), "expected": round(expected, 4)}
            intervals["grover"][str(n)] = {"hit_rate": rounded_interval(binomial_interval(hits, shots), 4),
                                           "expected": [round(expected, 4)] * 2}
        plans = [r for r in records if r["kind"] == "plan"]
        ours["planning"], intervals["planning"] = {}, {}
        for config in settings["plan_configs"]:
            rows = [r for r in plans if r["config"] == config]
            solved = sum(int(r["reached"]) for r in rows)
            calls = [int(r["oracle_calls"]) for r in rows]
            ours["planning"][config] = {"success_rate": round(solved / len(rows), 4),
                                        "calls_per_solution": round(sum(calls) / solved, 2) if solved else math.inf}
            intervals["planning"][config] = {
                "success_rate": rounded_interval(binomial_interval(solved, len(rows)), 4),
                "calls_per_solution": rounded_interval(bootstrap_interval(
                    rows, _calls_per_solution, settings["seed"]), 2)}
        tests_per_call, test_s = settings["tests_saved_per_call"], settings["classical_test_s"]
        cost_table: dict[str, Any] = {}
        sweeps: dict[str, dict[str, Any]] = {"bits": {}, "time_samples": {}}
        for r in costs:
            if r["config"]:
                name, value = r["config"].split("=")
                sweeps["bits" if name == "b" else "time_samples"][value] = {
                    "qubits": r["qubits"], "oracle_ands": r["oracle_ands"]}
                continue
            call_s = (r["oracle_ands"] + r["diffuser_ands"]) * settings["toffoli_s"]
            entry = {"qubits": r["qubits"], "oracle_ands": r["oracle_ands"], "toffolis": r["toffolis"],
                     "lookup_qrom_ands": r["lookup_qrom_ands"], "lookup_select_swap_ands": r["lookup_select_swap_ands"],
                     "coherent_over_qrom": round(r["oracle_ands"] / r["lookup_qrom_ands"], 6),
                     "call_s": call_s}
            if tests_per_call is not None:
                entry["break_even_test_s"] = call_s / tests_per_call
                entry["measured_test_s"] = test_s
                entry["qrrt_plan_s"] = (settings["qrrt_quantum_calls"] * call_s
                                        + settings["qrrt_verifications"] * test_s)
                entry["rrt_plan_s"] = settings["rrt_calls"] * test_s
            cost_table.setdefault(str(r["index_bits"]), {})[str(r["boxes"])] = entry
        largest = max((r["index_bits"] for r in verify if r["mismatches"] == 0 and r["ancillas_clean"]
                       and r["index_preserved"]), default=None)
        return {"ours": ours, "paper": self.paper, "interval_95": intervals, "costs": cost_table,
                "cost_sweeps_n20_b100": sweeps,
                "largest_verified_index_bits": largest,
                "largest_verified_qubits": max((r["qubits"] for r in verify if r["index_bits"] == largest),
                                               default=None),
                "grover_qubits": {str(r["index_bits"]): r["qubits"] for r in grover},
                "grover_seconds_per_search": {str(n): round(float(np.mean([r["search_s"] for r in grover
                                                                            if r["index_bits"] == n])), 3)
                                              for n in settings["grover_bits"]},
                "break_even_reads": {"tests_saved_per_call": tests_per_call, "classical_test_s": test_s,
                                     "source": str(RESOURCES_SUMMARY) if tests_per_call is not None else None,
                                     "meaning": "measured by the resource study for q-RRT at n = 8 in the paper's "
                                                "world; at other n and worlds it is an assumption"},
                "note": "verification: every index state of every instance (mismatches with the fixed-point "
                        "reference; the rounding comparison with TimeSampledCheck is over valid entries, exact "
                        "binomial interval); grover: hits over all shots of all replicates, exact binomial "
                        "interval, beside sin^2((2k+1) theta); costs: closed-form counts from the circuit's "
                        "constructors, call time = (oracle ANDs + n - 2) x toffoli_s, break-even test time = "
                        "call time / the resource study's classical tests saved per quantum call",
                "labels": ["coherent oracle: the marks are computed by the circuit, no classical lookup (the "
                           "reference's marks only check it)",
                           "Grover on Aer's matrix_product_state method, one circuit per search with its shots"]}

    def plot(self, records: list[Record], settings: Settings, summary: Summary, out_dir: Path) -> list[Path]:
        """Left: ANDs of one oracle call against n, coherent (one line per B) and lookup (QROM,
        select-swap). Right: the break-even classical test time against n, per B."""
        fig, axes = new_figure(1, 2, (13, 5))
        ax, right = axes[0, 0], axes[0, 1]
        bits = [int(n) for n in summary["costs"]]
        for boxes in settings["cost_boxes"]:
            ax.plot(bits, [summary["costs"][str(n)][str(boxes)]["oracle_ands"] for n in bits], "o-",
                    label=f"coherent, B = {boxes}")
            if "break_even_test_s" in summary["costs"][str(bits[0])][str(boxes)]:
                right.plot(bits, [summary["costs"][str(n)][str(boxes)]["break_even_test_s"] for n in bits], "o-",
                           label=f"B = {boxes}")
        first = str(settings["cost_boxes"][0])
        ax.plot(bits, [summary["costs"][str(n)][first]["lookup_qrom_ands"] for n in bits], "k--", label="lookup, QROM")
        swap = [summary["costs"][str(n)][first]["lookup_select_swap_ands"] for n in bits]
        if all(value is not None for value in swap):
            ax.plot(bits, swap, "k:", label="lookup, select-swap")
        ax.set_yscale("log")
        ax.set_xlabel("index qubits n")
        ax.set_ylabel("Toffolis (ANDs) per oracle call")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3, which="both")
        ax.set_title("one oracle call (compute and uncompute)", fontsize=10)
        test_s = summary["break_even_reads"]["classical_test_s"]
        if test_s is not None:
            right.axhline(test_s, color="k", ls="--", label="measured classical test")
        right.set_yscale("log")
        right.set_xlabel("index qubits n")
        right.set_ylabel("classical test time (s) above which q-RRT pays")
        right.legend(fontsize=8)
        right.grid(alpha=0.3, which="both")
        right.set_title(f"break-even at {settings['toffoli_s'] * 1e6:g} us per Toffoli", fontsize=10)
        fig.tight_layout()
        return [save(fig, out_dir / "coherent_oracle.png")]


def _resource_savings() -> dict[str, float | None]:
    """The classical tests saved per quantum call, the seconds of one classical test and the mean
    calls of q-RRT's and RRT's plans, from the resource study's summary (run from the repository's
    root), or None where it is not there."""
    try:
        table = json.loads(RESOURCES_SUMMARY.read_text())["plan"]["table"]
        return {"tests_saved_per_call": float(table["break_even_tests_per_call"]),
                "classical_test_s": float(table["test_s"]), "qrrt_quantum_calls": float(table["quantum_calls"]),
                "qrrt_verifications": float(table["verifications"]), "rrt_calls": float(table["rrt_calls"])}
    except (OSError, KeyError, ValueError):
        return dict.fromkeys(("tests_saved_per_call", "classical_test_s", "qrrt_quantum_calls", "qrrt_verifications",
                              "rrt_calls"))


def _calls_per_solution(rows: list[Record]) -> float:
    solved = sum(int(r["reached"]) for r in rows)
    return sum(float(r["oracle_calls"]) for r in rows) / solved if solved else math.inf


def _plan(config: str, seed: int, budget: int) -> Record:
    from ..planners.candidates import LatticeCandidates, NearestParents
    from ..planners.quantum import QRRT
    from ..problems.problem import Problem
    from ..search.backends.statevector import StatevectorBackend
    from ..world.environment import Environment

    world = Environment(BOUNDS, np.concatenate([CORRIDOR_WALLS, MIDDLE_BOX]))
    problem = Problem.build(world, [2.0, 10.0], [18.0, 10.0], 2.5)
    database = {"paper database": NearestParents(), "lattice, lookup": LatticeCandidates(3, bits=6),
                "lattice, coherent": LatticeCandidates(3, bits=6, coherent=True)}[config]
    if database.describe().get("coherent"):  # a circuit oracle, simulated gate by gate
        from ..search.backends.aer import AerBackend

        backend: QuantumSearchBackend = AerBackend(seed=seed, method="matrix_product_state")
    else:  # a lookup, in closed form
        backend = StatevectorBackend(seed=seed)
    planner = QRRT(backend=backend, num_qubits=7, database=database, seed=seed)
    result = planner.plan(problem, max_oracle_calls=budget)
    edges = problem.predicate.reachable(result.nodes[result.parents[1:]], result.nodes[1:])
    if not bool(np.all(edges)):
        raise RuntimeError(f"{config}: a tree edge the exact check rejects")
    return {"reached": int(result.reached), "oracle_calls": result.metrics.oracle_calls, "nodes": result.metrics.nodes}


def _verify(index_bits: int, boxes: int, seed: int) -> Record:
    from ..coherent import compare_with_time_sampled, verify_oracle
    from ..coherent.costs import scaling_instance

    env, database, motion = scaling_instance(index_bits, boxes, parent_bits=2, bits=12, time_samples=8, seed=seed)
    result = verify_oracle(env, database, motion)
    rounding = compare_with_time_sampled(env, database, motion)
    return {"qubits": result.qubits, "gates": result.gates, "entries": 1 << index_bits, "marked": result.marked,
            "mismatches": result.mismatches, "ancillas_clean": int(result.ancillas_clean),
            "index_preserved": int(result.index_preserved), "rounding_compared": rounding.entries,
            "rounding_differs": rounding.differ}


def _grover(index_bits: int, seed: int, shots: int) -> Record:
    from qiskit import transpile
    from qiskit_aer import AerSimulator

    from ..coherent import build_coherent_oracle, coherent_grover_circuit, reachable_reference
    from ..probability import optimal_iterations

    env, database, motion = _grover_instance(index_bits, seed)
    oracle = build_coherent_oracle(env, database, motion)
    marks = reachable_reference(env, database, motion)
    marked = int(marks.sum())
    iterations = optimal_iterations(1 << index_bits, marked)
    circuit = transpile(coherent_grover_circuit(oracle.circuit, index_bits, iterations, index_in_middle=True),
                        basis_gates=["x", "z", "h", "cx", "ccx", "u", "p", "measure"], optimization_level=0)
    began = time.perf_counter()
    counts = AerSimulator(method="matrix_product_state").run(circuit, shots=shots,
                                                             seed_simulator=seed).result().get_counts()
    elapsed = time.perf_counter() - began
    hits = sum(count for bits, count in counts.items() if marks[int(bits, 2)])
    theta = math.asin(math.sqrt(marked / (1 << index_bits))) if marked else 0.0
    return {"qubits": oracle.circuit.num_qubits, "marked": marked, "iterations": iterations, "shots": shots,
            "hits": hits, "expected": math.sin((2 * iterations + 1) * theta) ** 2, "search_s": elapsed}


def _cost(index_bits: int, boxes: int, seed: int, bits: int = 16, time_samples: int = 16) -> Record:
    from ..coherent import lookup_costs, oracle_costs
    from ..coherent.costs import scaling_instance

    env, database, motion = scaling_instance(index_bits, boxes, bits=bits, time_samples=time_samples, seed=seed)
    cost = oracle_costs(env, database, motion)
    lookup = lookup_costs(index_bits)
    return {"qubits": cost.qubits, "oracle_ands": cost.ands, "toffolis": cost.toffolis,
            "diffuser_ands": max(index_bits - 2, 0), "lookup_qrom_ands": lookup.qrom_ands,
            "lookup_select_swap_ands": math.nan if lookup.select_swap_ands is None else lookup.select_swap_ands}
