"""Beyond the paper: what device noise does to one Grover search and to q-RRT's calls per node.

Three parts, one trial list:

- ``sweep``: the Grover circuit over N = 2^n entries with m = N / 16 random marks (k_opt = 3),
  transpiled once per (database, k) to [cx, rz, sx, x], then run under depolarizing errors p2 on cx
  and p1 = p2 / 10 on sx/x. n <= ``exact_max_qubits``: exact probabilities from Aer's density
  matrix; larger n: noise trajectories on Aer's statevector with ``shots`` shots (binomial
  interval). Recorded next to the white-noise approximation F P_ideal + (1 - F) m / N and Lemma 4's
  effective false-positive rate (``qrrt_circuits.hardware.noise``).
- ``device``: the same circuits transpiled to a fake IBM heavy-hex device (qiskit-ibm-runtime's
  fake provider, optional extra ``noise``) and sampled with its calibrated noise model.
- ``planning``: RRT and q-RRT (n = ``planning_qubits``, Adaptive and KnownOptimal) grow trees in
  the same paper_clutter worlds; q-RRT searches on ``depolarizing_backend(p2 / 10, p2)``. The
  break-even p2 is where q-RRT's mean calls per node reaches RRT's (log-linear interpolation;
  95 % interval by resampling worlds).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..hardware import noise
from ..probability import good_probability
from ..registry import PLANNERS
from ..search.backends.noisy import depolarizing_backend, fake_device_backend
from ..search.oracles import LookupOracle
from ..search.policies.adaptive import Adaptive
from ..search.policies.schedules import KnownOptimal
from .base import Experiment, Record, Settings, Summary, Trial, TrialStream, replicate_seed
from .figures import new_figure, save
from .intervals import binomial_interval, bootstrap_interval, rounded_interval
from .planners import experiment_problem
from .worlds import world

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from numpy.typing import ArrayLike
    from qiskit import QuantumCircuit

    from ..search.policies.base import IterationPolicy

#: label -> q-RRT's search policy (its class)
QRRT_CONFIGS: dict[str, Callable[[], IterationPolicy]] = {"QRRT adaptive": Adaptive, "QRRT optimal": KnownOptimal}
FRACTION_LOG2 = 4  # m = N / 16: k_opt = 3 for every n
#: every record has every column (records.csv has one header): what a part does not measure is NaN
_NUMBERS = ("n", "k", "m", "p1", "p2", "one_qubit_gates", "two_qubit_gates", "ideal", "fidelity", "white_noise",
            "shots", "successes", "success", "success_low", "success_high", "collision",
            "effective_false_positive", "collision_uniform", "collision_false_positive_model",
            "nodes", "oracle_calls", "quantum_oracle_calls", "verification_calls", "rejected", "rounds",
            "calls_per_node", "world_seed")
COLUMNS: dict[str, Any] = {**dict.fromkeys(_NUMBERS, math.nan), "method": "", "config": "", "status": ""}


def sweep_marks(num_qubits: int, seed: int) -> np.ndarray:
    """A database of N = 2^n entries with m = N / 16 marks at random positions.

    Args:
        num_qubits: Index qubits n.
        seed: Seed of the marks' positions.

    Returns:
        (2^n,) booleans with max(1, N / 16) marked.
    """
    size = 1 << num_qubits
    marks = np.zeros(size, dtype=bool)
    marks[np.random.default_rng(seed).choice(size, max(1, size >> FRACTION_LOG2), replace=False)] = True
    return marks


@functools.lru_cache(maxsize=64)
def _compiled(num_qubits: int, seed: int, iterations: int) -> QuantumCircuit:
    return noise.transpiled_grover(sweep_marks(num_qubits, seed), iterations)


#: planning worlds of a full run, the unit of its planning intervals (over very few worlds a
#: percentile bootstrap's 2.5 % and 97.5 % quantiles are the lowest and highest world's values, a
#: min-max range; over 7 it is a bootstrap interval, a little narrow for so few worlds)
PLANNING_WORLDS = 20


class Noise(Experiment):
    """Device noise (beyond the paper, which assumes a perfect quantum computer).

    Three parts (see the module docstring): ``sweep`` (one search under depolarizing noise against
    the white-noise model), ``device`` (a fake IBM device, when the ``noise`` extra is installed)
    and ``planning`` (q-RRT's oracle calls per node as the two-qubit error grows, against RRT's,
    and the break-even error rate with its 95 % interval). Every number of ``ours`` has its 95 %
    interval at the same place in ``interval_95``: exact binomial for a sweep point sampled with
    shots (the value itself for an exact density-matrix probability), a percentile bootstrap over
    worlds for the planning numbers.
    """

    name = "noise"
    title = "Device noise: one search, the fake IBM device, and q-RRT's calls per node (beyond the paper)"
    uses_predicate = True
    paper = {"noise": "none: the paper assumes a perfect quantum computer"}

    def settings(self, quick: bool, trials: int | None, seed: int) -> Settings:
        device = noise.available_fake_device() if noise.has_fake_devices() else None
        if quick:
            return {"trials": trials or 1, "seed": seed, "quick": True,
                    "sweep_qubits": [3, 4], "sweep_iterations": [1, 2], "p2": [0.0, 1e-2],
                    "p1_ratio": 0.1, "exact_max_qubits": 3, "shots": 100,
                    # no device circuits: the fake device's noise model is slow to build
                    "device": device, "device_qubits": [], "device_iterations": [1], "device_shots": 100,
                    "planning_p2": [0.0, 1e-2], "planning_qubits": 4, "nodes": 3,
                    "planning_configs": ["QRRT adaptive"]}
        return {"trials": trials or PLANNING_WORLDS, "seed": seed, "quick": False,
                "sweep_qubits": [4, 5, 6, 7, 8, 9, 10], "sweep_iterations": [1, 2, 3],
                "p2": [0.0, 1e-4, 1e-3, 3e-3, 1e-2], "p1_ratio": 0.1, "exact_max_qubits": 8, "shots": 200,
                "device": device, "device_qubits": [4, 5, 6], "device_iterations": [1, 2, 3], "device_shots": 1000,
                "planning_p2": [0.0, 1e-3, 3e-3, 1e-2], "planning_qubits": 6, "nodes": 15,
                "planning_configs": list(QRRT_CONFIGS)}

    def trials(self, settings: Settings) -> list[Trial]:
        out: list[Trial] = []
        root = settings["seed"]
        # sweep: every (n, k, p2) on the first database; n <= exact_max_qubits on `trials` databases
        for n in settings["sweep_qubits"]:
            for replicate in range(1):  # exact where feasible: one database per n is enough
                seed = replicate_seed(root, replicate * 100 + n, TrialStream.NOISE_SWEEP)
                for k in settings["sweep_iterations"]:
                    for p2 in settings["p2"]:
                        out.append(Trial(f"sweep-n{n}-k{k}-p{p2:g}-{replicate}",
                                         {"part": "sweep", "n": n, "k": k, "p2": p2, "replicate": replicate},
                                         seed))
        if settings["device"]:
            for n in settings["device_qubits"]:
                seed = replicate_seed(root, n, TrialStream.NOISE_SWEEP)  # the sweep's first database
                for k in settings["device_iterations"]:
                    out.append(Trial(f"device-n{n}-k{k}", {"part": "device", "n": n, "k": k, "replicate": 0}, seed))
        for replicate in range(settings["trials"]):
            world_seed = replicate_seed(root, replicate, TrialStream.NOISE_WORLDS)
            seed = replicate_seed(root, replicate, TrialStream.NOISE_PLANNERS)
            common = {"part": "planning", "replicate": replicate, "world_seed": world_seed}
            out.append(Trial(f"planning-RRT-{replicate}", {**common, "config": "RRT", "p2": 0.0}, seed))
            for config in settings["planning_configs"]:
                for p2 in settings["planning_p2"]:
                    out.append(Trial(f"planning-{config}-p{p2:g}-{replicate}",
                                     {**common, "config": config, "p2": p2}, seed))
        return out

    def run_trial(self, trial: Trial, settings: Settings) -> Record:
        record: Record = getattr(self, f"_run_{trial.params['part']}")(trial, settings)
        return {key: value for key, value in COLUMNS.items() if key not in trial.params} | record

    def _run_sweep(self, trial: Trial, settings: Settings) -> Record:
        n, k, p2 = trial.params["n"], trial.params["k"], trial.params["p2"]
        p1 = settings["p1_ratio"] * p2
        size = 1 << n
        marks = sweep_marks(n, trial.seed)
        m = int(marks.sum())
        compiled = _compiled(n, trial.seed, k)
        one, two = noise.noisy_gate_counts(compiled)
        model = noise.depolarizing_noise_model(p1, p2)
        fidelity = noise.white_noise_fidelity(one, two, p1, p2)
        record: Record = {"m": m, "p1": p1, "one_qubit_gates": one, "two_qubit_gates": two,
                  "ideal": good_probability(size, m, k), "fidelity": fidelity,
                  "white_noise": noise.white_noise_success(size, m, k, fidelity)}
        if n <= settings["exact_max_qubits"]:
            distribution = noise.noisy_index_distribution(compiled, model, n)
            success = float(distribution[marks].sum())
            record.update(method="density_matrix (exact)", shots=0, successes=0, success=success,
                          success_low=success, success_high=success,
                          collision=noise.wrong_answer_collision(distribution, marks))
        else:
            backend = depolarizing_backend(p1, p2, method="statevector")
            result = backend.search(LookupOracle(marks), k, shots=settings["shots"], seed=trial.seed)
            hits = int(np.count_nonzero(marks[result.indices]))
            low, high = binomial_interval(hits, settings["shots"])
            record.update(method="statevector trajectories (shots)", shots=settings["shots"], successes=hits,
                          success=hits / settings["shots"], success_low=low, success_high=high,
                          collision=math.nan)
        q = noise.effective_false_positive_rate(size, m, k, min(max(record["success"], 0.0), 1.0))
        record.update(effective_false_positive=q,
                      collision_uniform=1.0 / (size - m),
                      collision_false_positive_model=1.0 / (q * (size - m)) if q and q > 0 else math.nan)
        return record

    def _run_device(self, trial: Trial, settings: Settings) -> Record:
        n, k = trial.params["n"], trial.params["k"]
        marks = sweep_marks(n, trial.seed)
        backend = fake_device_backend(settings["device"])
        oracle = LookupOracle(marks)
        result = backend.search(oracle, k, shots=settings["device_shots"], seed=trial.seed)
        hits = int(np.count_nonzero(marks[result.indices]))
        low, high = binomial_interval(hits, settings["device_shots"])
        compiled = backend.compiled(oracle, k)
        two = sum(count for gate, count in compiled.count_ops().items() if gate in ("ecr", "cz", "cx"))
        return {"m": int(marks.sum()), "ideal": good_probability(1 << n, int(marks.sum()), k),
                "shots": settings["device_shots"], "successes": hits, "success": hits / settings["device_shots"],
                "success_low": low, "success_high": high, "two_qubit_gates": int(two),
                "method": f"{settings['device']} noise model (statevector trajectories)"}

    def _run_planning(self, trial: Trial, settings: Settings) -> Record:
        problem = experiment_problem(settings, world("paper_clutter", trial.params["world_seed"]))
        config, p2 = trial.params["config"], trial.params["p2"]
        if config == "RRT":
            planner = PLANNERS.create("RRT", seed=trial.seed)
        else:
            backend = depolarizing_backend(settings["p1_ratio"] * p2, p2, method="statevector")
            planner = PLANNERS.create("QRRT", backend=backend, num_qubits=settings["planning_qubits"],
                                      search_policy=QRRT_CONFIGS[config](), seed=trial.seed)
        result = planner.plan(problem, max_nodes=settings["nodes"])
        m = result.metrics
        return {"status": str(result.status), "nodes": m.nodes, "oracle_calls": m.oracle_calls,
                "quantum_oracle_calls": m.quantum_oracle_calls, "verification_calls": m.verification_calls,
                "rejected": m.rejected, "rounds": m.rounds, "calls_per_node": m.oracle_calls / max(m.nodes, 1)}

    # ------------------------------------------------------------------ summary
    def summarize(self, records: list[Record], settings: Settings) -> Summary:
        sweep = [r for r in records if r["part"] == "sweep"]
        k_top = max(settings["sweep_iterations"])
        success: dict[str, dict[str, float]] = {}
        success_interval: dict[str, dict[str, list[float]]] = {}
        for n in settings["sweep_qubits"]:
            success[str(n)], success_interval[str(n)] = {}, {}
            for p2 in settings["p2"]:
                rows = [r for r in sweep if r["n"] == n and r["k"] == k_top and r["p2"] == p2]
                success[str(n)][f"{p2:g}"] = _mean([r["success"] for r in rows])
                success_interval[str(n)][f"{p2:g}"] = sweep_interval(rows)
        exact = [r for r in sweep if r["shots"] == 0 and r["p2"] > 0]
        white_gap = max((abs(r["success"] - r["white_noise"]) for r in exact), default=math.nan)
        ratios = [r["collision"] / r["collision_uniform"] for r in exact if np.isfinite(r["collision"])]
        fp_ratios = [r["collision_false_positive_model"] / r["collision_uniform"] for r in exact
                     if np.isfinite(r["collision_false_positive_model"])]
        planning = self._planning_summary([r for r in records if r["part"] == "planning"], settings)
        device = [r for r in records if r["part"] == "device"]
        break_even = planning["break_even_p2"]
        cells = planning["intervals"]
        ours = {f"success_at_k{k_top}": success,
                "break_even_p2": {config: value["p2"] for config, value in break_even.items()},
                "calls_per_node": planning["calls_per_node"]}
        interval = {f"success_at_k{k_top}": success_interval,
                    "break_even_p2": {config: value["interval_95"] for config, value in break_even.items()},
                    "calls_per_node": {config: (cell["interval_95"] if config == "RRT" else
                                                {p2: x["interval_95"] for p2, x in cell.items()})
                                       for config, cell in cells.items()}}
        return {"ours": ours, "paper": self.paper, "interval_95": interval, "planning": planning,
                "white_noise_max_abs_error": white_gap,
                "wrong_answer_collision_over_uniform": {"measured_range": _range(ratios),
                                                        "false_positive_model_range": _range(fp_ratios)},
                "device": {"name": settings["device"],
                           "missing": None if settings["device"] else _missing_message(),
                           "success": {f"n{r['n']}-k{r['k']}": {"success": r["success"],
                                                                "interval_95": [r["success_low"], r["success_high"]],
                                                                "ideal": r["ideal"],
                                                                "two_qubit_gates": r["two_qubit_gates"]}
                                       for r in device}},
                "labels": [f"sweep: n <= {settings['exact_max_qubits']} exact density matrix (its interval is the "
                           f"value itself: no sampling); larger n noise trajectories with {settings['shots']} shots "
                           "(exact binomial interval)",
                           "QRRT optimal uses the true m of each database (simulation knowledge)",
                           f"p1 = {settings['p1_ratio']:g} x p2; rz is virtual and error-free",
                           f"calls_per_node and break_even_p2: 95 % percentile bootstrap over the "
                           f"{planning['worlds']} planning worlds (unit: worlds); a break-even interval's upper "
                           "end null means beyond the largest p2"]}

    def _planning_summary(self, rows: list[Record], settings: Settings) -> dict[str, Any]:
        by_world: dict[int, list[Record]] = {}
        for r in rows:
            by_world.setdefault(r["replicate"], []).append(r)
        worlds = sorted(by_world)
        levels = settings["planning_p2"]

        def stats(sample_worlds: Sequence[int], config: str) -> tuple[Any, list[Any]]:
            rrt = np.mean([_calls(by_world[w], "RRT", 0.0) for w in sample_worlds])
            quantum = [np.mean([_calls(by_world[w], config, p2) for w in sample_worlds]) for p2 in levels]
            return rrt, quantum

        def rrt_calls(sample_worlds: Sequence[int], config: str) -> Any:
            return stats(sample_worlds, config)[0]

        def quantum_calls(sample_worlds: Sequence[int], config: str, level: int) -> Any:
            return stats(sample_worlds, config)[1][level]

        def capped_crossing(sample_worlds: Sequence[int], config: str, cap: float) -> float:
            rrt, quantum = stats(sample_worlds, config)
            return min(crossing(levels, quantum, rrt), cap)

        calls: dict[str, dict[str, Any]] = {}
        break_even: dict[str, dict[str, Any]] = {}
        beyond = 1e6 * max(levels)
        rrt_all, _ = stats(worlds, settings["planning_configs"][0])
        calls["RRT"] = {"mean": rrt_all, "interval_95": rounded_interval(bootstrap_interval(
            worlds, functools.partial(rrt_calls, config=settings["planning_configs"][0]), settings["seed"]), 3)}
        for config in settings["planning_configs"]:
            _, quantum = stats(worlds, config)
            calls[config] = {f"{p2:g}": {"mean": q, "interval_95": rounded_interval(bootstrap_interval(
                worlds, functools.partial(quantum_calls, config=config, level=i), settings["seed"]), 3)}
                for i, (p2, q) in enumerate(zip(levels, quantum, strict=True))}
            value = crossing(levels, quantum, rrt_all)
            # a resample that never crosses counts as "beyond the largest level" (a finite stand-in, so
            # that the bootstrap keeps it), and is reported as inf
            interval = bootstrap_interval(
                worlds, functools.partial(capped_crossing, config=config, cap=beyond), settings["seed"])
            break_even[config] = {"p2": value, "interval_95": [_beyond(x, beyond) for x in interval],
                                  "meaning": _crossing_meaning(value, levels)}
        return {"calls_per_node": {c: (v["mean"] if c == "RRT" else {p: x["mean"] for p, x in v.items()})
                                   for c, v in calls.items()},
                "intervals": calls, "break_even_p2": break_even, "worlds": len(worlds),
                "interval_unit": f"worlds ({len(worlds)}; percentile bootstrap)"}

    def plot(self, records: list[Record], settings: Settings, summary: Summary, out_dir: Path) -> list[Path]:
        fig, axes = new_figure(2, 2, (11, 8.5))
        self._plot_sweep(axes[0, 0], records, settings)
        self._plot_device(axes[0, 1], records, settings)
        self._plot_planning(axes[1, 0], summary, settings)
        self._plot_collision(axes[1, 1], records, settings)
        return [save(fig, out_dir / "noise.png")]

    def _plot_sweep(self, ax: Axes, records: list[Record], settings: Settings) -> None:
        k = max(settings["sweep_iterations"])
        levels = [p for p in settings["p2"] if p > 0]
        for n in settings["sweep_qubits"]:
            rows = [r for r in records if r["part"] == "sweep" and r["n"] == n and r["k"] == k and r["p2"] > 0]
            y = [_mean([r["success"] for r in rows if r["p2"] == p]) for p in levels]
            line, = ax.plot(levels, y, "o-", label=f"n={n}")
            ax.plot(levels, [_mean([r["white_noise"] for r in rows if r["p2"] == p]) for p in levels], "--",
                    color=line.get_color(), lw=0.8)
        ax.axhline(1 / 2**FRACTION_LOG2, color="0.4", ls=":", label="m/N (uniform guess)")
        ax.set_xscale("log")
        ax.set_xlabel("two-qubit depolarizing error p2 (p1 = p2/10)")
        ax.set_ylabel(f"P(marked) after k={k} (m = N/16)")
        ax.set_title("One search on [cx, rz, sx, x]; dashed: white-noise F P + (1-F) m/N", fontsize=9)
        ax.legend(fontsize=7, ncol=2)
        ax.grid(alpha=0.3)

    def _plot_device(self, ax: Axes, records: list[Record], settings: Settings) -> None:
        rows = [r for r in records if r["part"] == "device"]
        if not rows:
            ax.text(0.5, 0.5, "fake device part skipped:\n" + _missing_message(), ha="center", va="center",
                    fontsize=8, wrap=True, transform=ax.transAxes)
            ax.set_axis_off()
            return
        for k in settings["device_iterations"]:
            sub = sorted((r for r in rows if r["k"] == k), key=lambda r: r["n"])
            x = [r["n"] for r in sub]
            y = np.array([r["success"] for r in sub])
            err = np.array([[r["success"] - r["success_low"], r["success_high"] - r["success"]] for r in sub]).T
            line = ax.errorbar(x, y, yerr=err, fmt="o-", capsize=3, label=f"{settings['device']}, k={k}")
            ax.plot(x, [r["ideal"] for r in sub], "x--", color=line[0].get_color(), label=f"ideal, k={k}")
        ax.axhline(1 / 2**FRACTION_LOG2, color="0.4", ls=":", label="m/N")
        ax.set_xlabel("index qubits n")
        ax.set_ylabel("P(marked) (95 % binomial interval)")
        ax.set_title("Fake IBM heavy-hex device (calibrated noise)", fontsize=9)
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3)

    def _plot_planning(self, ax: Axes, summary: Summary, settings: Settings) -> None:
        planning = summary["planning"]
        levels = settings["planning_p2"]
        x = [p if p > 0 else levels[1] / 3 for p in levels]  # p2 = 0 drawn at the left edge
        rrt = planning["intervals"]["RRT"]
        ax.axhline(rrt["mean"], color="tab:gray", label="RRT")
        ax.axhspan(*rrt["interval_95"], color="tab:gray", alpha=0.2)
        for config in settings["planning_configs"]:
            cells = planning["intervals"][config]
            y = np.array([cells[f"{p:g}"]["mean"] for p in levels])
            err = np.array([[y[i] - cells[f"{p:g}"]["interval_95"][0], cells[f"{p:g}"]["interval_95"][1] - y[i]]
                            for i, p in enumerate(levels)]).T
            crossing_at = planning["break_even_p2"][config]["p2"]
            label = f"{config} (break-even p2 {crossing_at:.2g})" if np.isfinite(crossing_at) else config
            ax.errorbar(x, y, yerr=np.clip(err, 0, None), fmt="o-", capsize=3, label=label)
        ax.set_xscale("log")
        ax.set_xlabel("p2 (leftmost point: p2 = 0)")
        ax.set_ylabel("oracle calls per node")
        ax.set_title(f"paper_clutter, {settings['nodes']} nodes, n = {settings['planning_qubits']}", fontsize=9)
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3, which="both")

    def _plot_collision(self, ax: Axes, records: list[Record], settings: Settings) -> None:
        rows = [r for r in records if r["part"] == "sweep" and r["shots"] == 0 and r["p2"] > 0
                and np.isfinite(r["collision_false_positive_model"])]
        ax.scatter([r["p2"] for r in rows], [r["collision"] / r["collision_uniform"] for r in rows], s=12,
                   label="measured (density matrix)")
        ax.scatter([r["p2"] for r in rows], [r["collision_false_positive_model"] / r["collision_uniform"]
                                             for r in rows], s=12, marker="x",
                   label="Lemma 4 oracle with the same P(G*)")
        ax.axhline(1.0, color="0.4", ls=":", label="uniform over N - m")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("p2")
        ax.set_ylabel("P(two wrong answers coincide) x (N - m)")
        ax.set_title("Where noise is not a false-positive oracle", fontsize=9)
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3, which="both")


def sweep_interval(rows: Sequence[Record]) -> list[float]:
    """The 95 % interval of a sweep point's success probability: exact binomial over its shots for
    noise trajectories, the value itself for an exact density-matrix probability (no sampling).

    Args:
        rows: The sweep records of one (n, k, p2) (one database each; several are pooled).

    Returns:
        ``[low, high]``; NaNs without rows.
    """
    if not rows:
        return [math.nan, math.nan]
    if all(r["shots"] == 0 for r in rows):  # exact probabilities
        value = _mean([r["success"] for r in rows])
        return [value, value]
    successes = sum(int(r["successes"]) for r in rows)
    shots = sum(int(r["shots"]) for r in rows)
    return rounded_interval(binomial_interval(successes, shots))


def crossing(levels: Sequence[float], values: ArrayLike, target: float) -> float:
    """The smallest level where ``values`` reaches ``target`` (log-linear interpolation between
    levels; the first level is read as a lower edge when it is 0). 0.0 if the first value is
    already at or above the target; inf if no value reaches it.

    Args:
        levels: Increasing levels (noise rates p2), the first possibly 0.
        values: The value at each level.
        target: The value to reach.

    Returns:
        The interpolated level, 0.0 or inf as above.
    """
    values = np.asarray(values, dtype=float)
    if values[0] >= target:
        return 0.0
    above = np.flatnonzero(values >= target)
    if above.size == 0:
        return math.inf
    i = int(above[0])
    low, high = levels[i - 1], levels[i]
    fraction = (target - values[i - 1]) / (values[i] - values[i - 1])
    if low <= 0:
        return float(high * fraction)  # linear between 0 and the first non-zero level
    return float(math.exp(math.log(low) + fraction * (math.log(high) - math.log(low))))


def _crossing_meaning(value: float, levels: Sequence[float]) -> str:
    if value == 0.0:
        return "q-RRT needs at least RRT's calls per node even without noise"
    if math.isinf(value):
        return f"q-RRT needs fewer calls per node than RRT at every p2 up to {max(levels):g}"
    return "q-RRT needs more calls per node than RRT above this p2"


def _calls(rows: Sequence[Record], config: str, p2: float) -> float:
    return next(r["calls_per_node"] for r in rows if r["config"] == config and r["p2"] == p2)


def _beyond(value: float, beyond: float) -> float:
    return math.inf if value >= beyond else float(value)


def _mean(values: Sequence[float]) -> float:
    return float(np.mean(values)) if len(values) else math.nan


def _range(values: Sequence[float]) -> list[float]:
    return [float(min(values)), float(max(values))] if values else [math.nan, math.nan]


def _missing_message() -> str:
    try:
        noise.available_fake_device()
    except noise.MissingExtraError as exc:
        return str(exc)
    return ""
