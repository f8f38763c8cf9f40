"""Beyond the paper: every planner of the library on standard problem families, beside OMPL's RRT
and RRTConnect on the same motion check, at equal budgets in motion checks.

**Problems** (``world.problems``, built by the library): ``open-space`` (one box in [0, 10]^2),
``maze`` (a perfect maze of 4 x 4 rooms, a new maze per replicate: its seed is the replicate
index), ``narrow-passage-{2,4,6}d`` (a wall with a square hole whose share of the wall's
cross-section is 1 % in every dimension: side 10 x 0.01^(1 / (d - 1)), so 0.1 in 2-D, 2.15 in 4-D,
3.98 in 6-D; with a fixed side the share falls as (side / 10)^(d - 1), and at side 0.5 no planner
solved 6-D within the budget) and ``se2-gap`` (a rectangle in SE(2) through a gap). Straight
segments under the exact checks (``ExactCheck``, ``GridCheck``, ``RigidBodyCheck``).

**Planners**: RRT; RRT with OMPL's range (``max_extension`` = 0.2 of the bounds' diagonal, no
look-ahead: the algorithm of OMPL's RRT); manager-worker parallel RRT (8 workers); q-RRT under the
paper's schedule, ``Adaptive`` and ``BBHT``; Pq-RRT (8 workers, shared database) under the paper's
schedule and ``Adaptive``; and, when the ``ompl`` extra is installed, OMPL's RRT and RRTConnect
(``experiments.ompl_runs``). All with goal bias 0.05 (OMPL's default; RRTConnect has none),
2^8-entry databases on the exact statevector.

**Budget**: each run ends when it reaches the goal or has made ``budget`` oracle calls: DESIGN §2
counting for the library's planners (a Grover iteration is one call, a classical test one), motion
checks for OMPL's (each one evaluation of the same predicate). A run that ends at the budget failed.

**Measures**, per family and planner, with 95 % percentile-bootstrap intervals over replicates
(Clopper-Pearson for success rates): success rate; oracle calls per solution (all calls of all runs,
failed ones included, over the number of solved runs: the expected cost of one solution when a
failed run is restarted, the budget-censored estimator of a Las Vegas algorithm's cost); the same
for critical-path calls (p parallel devices), for classical checks actually made (every predicate
evaluation: the simulation's 2^n per database, look-ahead checks thrown away, verifications) and
for wall time; path length of the solved runs, raw and after the greedy shortcut
(``planners.paths.shortcut``, the same post-processing for every planner). Ratios to OMPL's RRT and
RRTConnect (and to the library's RRT): calls, critical-path calls (one device per worker against
OMPL's one thread) and wall time, resampling the replicates of both planners together.

**The default search policy** is chosen from this experiment by a rule fixed before the run: for
each candidate (``paper``, ``adaptive``, ``bbht``) the q-RRT calls per solution divided by the
smallest of the three in each family, and the candidate whose geometric mean of that ratio over the
families is lowest is the default (a family no candidate solved is left out).
"""

from __future__ import annotations

import importlib.util
import math
from collections.abc import Callable, Sequence
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from ..planners.paths import path_length, shortcut
from ..registry import POLICIES
from ..world.problems import Problem, maze, narrow_passage, open_space, se2_gap
from .base import Experiment, Record, Settings, Summary, Trial, TrialStream, replicate_seed
from .figures import dodge, new_figure, save, with_intervals
from .intervals import binomial_interval, bootstrap_interval, rounded_interval
from .planners import BACKEND_LABEL, make_planner

FAMILIES = ("open-space", "maze", "narrow-passage-2d", "narrow-passage-4d", "narrow-passage-6d", "se2-gap")
QUICK_FAMILIES = ("open-space", "maze", "narrow-passage-2d", "se2-gap")
#: label -> (registry planner, search policy name or None, the extra options for a problem)
LIBRARY_CONFIGS: dict[str, tuple[str, str | None, Callable[[Problem], dict[str, Any]]]] = {
    "RRT": ("rrt", None, lambda problem: {}),
    "RRT range": ("rrt", None, lambda problem: {"look_ahead": False, "max_extension": ompl_range(problem)}),
    "ParallelRRT": ("prrt", None, lambda problem: {}),
    "QRRT paper": ("qrrt", "paper", lambda problem: {}),
    "QRRT adaptive": ("qrrt", "adaptive", lambda problem: {}),
    "QRRT bbht": ("qrrt", "bbht", lambda problem: {}),
    "PQRRT paper": ("pqrrt", "paper", lambda problem: {}),
    "PQRRT adaptive": ("pqrrt", "adaptive", lambda problem: {}),
}
OMPL_CONFIGS = ("OMPL RRT", "OMPL RRTConnect")
POLICY_CANDIDATES = ("paper", "adaptive", "bbht")
GOAL_BIAS = 0.05
#: the narrow passage's hole: its share of the wall's cross-section, in every dimension
HOLE_SHARE = 0.01
#: OMPL's default range: this fraction of the space's largest extent (the bounds' diagonal)
RANGE_FRACTION = 0.2
#: the summary's ``ours`` (with the success rate) ...
HEADLINE = ("calls_per_solution", "wall_time_per_solution_s")
#: ... and its ``details``
DETAILS = ("critical_path_per_solution", "classical_checks_per_solution", "path_length", "path_length_simplified")


def build_problem(family: str, replicate: int) -> Problem:
    """The problem of ``family`` for one replicate (a new maze per replicate, the others fixed).

    Args:
        family: One of ``FAMILIES``.
        replicate: The replicate index.

    Returns:
        A fresh problem (its predicate's ``evaluations`` at 0).
    """
    if family == "maze":
        return maze(4, replicate)
    if family.startswith("narrow-passage-"):
        dim = int(family.removeprefix("narrow-passage-").removesuffix("d"))
        return narrow_passage(dim, 10.0 * HOLE_SHARE ** (1.0 / (dim - 1)))
    return {"open-space": open_space, "se2-gap": se2_gap}[family]()


def ompl_range(problem: Problem) -> float:
    """OMPL's default RRT range for the problem's bounds: 0.2 of their diagonal."""
    extent = np.diff(problem.env.bounds, axis=1)[:, 0]
    return float(RANGE_FRACTION * np.linalg.norm(extent))


def has_ompl() -> bool:
    """Whether the OMPL Python bindings can be imported."""
    return importlib.util.find_spec("ompl") is not None


def _ompl_version() -> str | None:
    if not has_ompl():
        return None
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("ompl")
    except PackageNotFoundError:
        return "unknown"


class Problems(Experiment):
    """Every planner on standard problem families beside OMPL's (module docstring)."""

    name = "problems"
    title = "Problem families beyond the paper: every planner beside OMPL's RRT and RRTConnect"
    uses_predicate = False
    paper = {"note": "the paper plans in its own box worlds only; no problem family of this experiment is in it"}

    def settings(self, quick: bool, trials: int | None, seed: int) -> Settings:
        configs = [*LIBRARY_CONFIGS, *(OMPL_CONFIGS if has_ompl() else ())]
        return {"trials": trials or (2 if quick else 20), "families": list(QUICK_FAMILIES if quick else FAMILIES),
                "budget": 1500 if quick else 10000, "configs": configs, "ompl": _ompl_version(),
                "workers": 8, "num_qubits": 8, "backend": "statevector", "goal_bias": GOAL_BIAS,
                "range_fraction": RANGE_FRACTION,
                "policies": {name: POLICIES.create(name).describe() for name in POLICY_CANDIDATES},
                "seed": seed, "quick": quick}

    def trials(self, settings: Settings) -> list[Trial]:
        trials = []
        for replicate in range(settings["trials"]):
            seed = replicate_seed(settings["seed"], replicate, TrialStream.PROBLEMS_PLANNERS)
            for family in settings["families"]:
                for config in settings["configs"]:
                    trials.append(Trial(f"{family} {config}-{replicate}",
                                        {"family": family, "config": config, "replicate": replicate}, seed))
        return trials

    def run_trial(self, trial: Trial, settings: Settings) -> Record:
        problem = build_problem(trial.params["family"], trial.params["replicate"])
        config = trial.params["config"]
        if config in OMPL_CONFIGS:
            return self._ompl_trial(problem, config, trial.seed, settings)
        kind, policy, options = LIBRARY_CONFIGS[config]
        planner = make_planner(kind, problem.env, trial.seed, settings["backend"], settings["workers"],
                               settings["num_qubits"], search_policy=policy, goal_bias=settings["goal_bias"],
                               **problem.planner_options(), **options(problem))
        result = planner.plan(goal=problem.goal, max_oracle_calls=settings["budget"])
        m = result.metrics
        record = {"status": str(result.status), "reached": int(result.reached), "oracle_calls": m.oracle_calls,
                  "critical_path_calls": m.critical_path_oracle_calls, "simulation_checks": m.simulation_checks,
                  "classical_checks": _evaluations(problem), "nodes": m.nodes,
                  "wall_time_s": m.wall_time_s}
        return record | self._paths(problem, result.path)

    @staticmethod
    def _ompl_trial(problem: Problem, config: str, seed: int, settings: Settings) -> Record:
        from .ompl_runs import ompl_run

        run = ompl_run(problem, config, settings["budget"], seed % (2**31 - 1) + 1, settings["goal_bias"])
        record = {"status": "reached" if run.reached else "max_oracle_calls", "reached": int(run.reached),
                  "oracle_calls": run.motion_checks, "critical_path_calls": run.motion_checks,
                  "simulation_checks": 0, "classical_checks": _evaluations(problem),
                  "nodes": math.nan, "wall_time_s": run.wall_time_s}
        return record | Problems._paths(problem, run.path)

    @staticmethod
    def _paths(problem: Problem, path: np.ndarray | None) -> Record:
        if path is None:
            return {"path_length": math.nan, "path_length_simplified": math.nan}
        return {"path_length": path_length(path, problem.space),
                "path_length_simplified": path_length(shortcut(path, problem.predicate), problem.space)}

    def summarize(self, records: list[Record], settings: Settings) -> Summary:
        seed = settings["seed"]
        ours: dict[str, dict[str, dict[str, float]]] = {}
        intervals: dict[str, dict[str, dict[str, list[float]]]] = {}
        details: dict[str, dict[str, dict[str, float]]] = {}
        detail_intervals: dict[str, dict[str, dict[str, list[float]]]] = {}
        ratios: dict[str, dict[str, dict[str, float]]] = {}
        ratio_intervals: dict[str, dict[str, dict[str, list[float]]]] = {}
        references = [ref for ref in ("OMPL RRT", "OMPL RRTConnect", "RRT") if ref in settings["configs"]]
        for family in settings["families"]:
            rows = {config: [r for r in records if r["family"] == family and r["config"] == config]
                    for config in settings["configs"]}
            ours[family], intervals[family], ratios[family], ratio_intervals[family] = {}, {}, {}, {}
            details[family], detail_intervals[family] = {}, {}
            for config, runs in rows.items():
                solved = sum(int(r["reached"]) for r in runs)
                values = {"success_rate": round(solved / len(runs), 4) if runs else math.nan}
                spans = {"success_rate": rounded_interval(binomial_interval(solved, len(runs)), 4)}
                for quantity in (*HEADLINE, *DETAILS):
                    values[quantity] = _rounded(_statistic(runs, quantity))
                    spans[quantity] = rounded_interval(bootstrap_interval(runs, partial(_statistic, quantity=quantity),
                                                                          seed), 4)
                ours[family][config] = {key: values[key] for key in ("success_rate", *HEADLINE)}
                intervals[family][config] = {key: spans[key] for key in ("success_rate", *HEADLINE)}
                details[family][config] = {key: values[key] for key in DETAILS}
                detail_intervals[family][config] = {key: spans[key] for key in DETAILS}
                for reference in references:
                    if reference == config:
                        continue
                    for quantity, short in (("calls_per_solution", "calls"),
                                            ("critical_path_per_solution", "critical_path"),
                                            ("wall_time_per_solution_s", "wall_time")):
                        key = f"{short}_vs_{reference.replace(' ', '_')}"
                        value, span = _paired_ratio(runs, rows[reference], quantity, seed)
                        ratios[family].setdefault(config, {})[key] = value
                        ratio_intervals[family].setdefault(config, {})[key] = span
        choice = choose_default_policy(ours)
        return {"ours": ours, "paper": self.paper, "interval_95": intervals, "details": details,
                "details_interval_95": detail_intervals, "ratios": ratios,
                "ratios_interval_95": ratio_intervals, "default_policy": choice,
                "note": "per family and planner: success rate within the budget; calls, critical-path calls, "
                        "classical checks and wall time per solution (all runs' totals over the solved runs: the "
                        "expected cost of one solution with restarts after failures); mean path length of the "
                        "solved runs, raw and after the greedy shortcut; intervals: percentile bootstrap over "
                        "replicates (Clopper-Pearson for success rates); ratios resample the replicates of both "
                        "planners together",
                "labels": ["phase oracle from a classical lookup of all 2^8 database entries (simulation_checks: "
                           "2^8 predicate evaluations per database, inside classical_checks)",
                           "Pq-RRT: one search with 8 shots for 8 workers on the shared database",
                           f"backend: {BACKEND_LABEL['statevector']}",
                           "OMPL plans se2-gap in a real-vector space (the angle a real coordinate); the same "
                           "check moves along the shorter arc",
                           "wall times are of one process on a shared machine; OMPL's include its Python motion "
                           "validator (one Python call per motion check)"]}

    def plot(self, records: list[Record], settings: Settings, summary: Summary, out_dir: Path) -> list[Path]:
        """Per family: calls per solution and wall time per solution of every planner (log scale,
        95 % intervals), and its success rate."""
        families, configs = settings["families"], settings["configs"]
        fig, axes = new_figure(3, 1, (max(9.0, 1.9 * len(families)), 12))
        x = np.arange(len(families), dtype=float)
        offsets = dodge(len(configs), 0.8)
        colors = _colors(configs)
        panels = (("calls_per_solution", "oracle calls (motion checks) per solution", True),
                  ("wall_time_per_solution_s", "wall time per solution (s)", True),
                  ("success_rate", f"success rate within {settings['budget']} calls", False))
        for ax, (quantity, label, log) in zip(axes[:, 0], panels, strict=True):
            for offset, config in zip(offsets, configs, strict=True):
                values = [summary["ours"][f][config][quantity] for f in families]
                spans = [summary["interval_95"][f][config][quantity] for f in families]
                with_intervals(ax, x + offset, values, spans, fmt="o", ms=4, color=colors[config], label=config)
            if log:
                ax.set_yscale("log")
            ax.set_xticks(x, families)
            ax.set_ylabel(label)
            ax.grid(alpha=0.3, axis="y", which="both")
            for boundary in x[:-1] + 0.5:
                ax.axvline(boundary, color="0.85", lw=0.8)
        axes[0, 0].legend(ncol=5, fontsize=7.5, loc="upper center", bbox_to_anchor=(0.5, 1.32), frameon=False)
        axes[0, 0].set_title(f"{settings['trials']} replicates per family, budget {settings['budget']} calls",
                             fontsize=10, pad=48)
        fig.tight_layout()
        return [save(fig, out_dir / "problems.png")]


def _colors(configs: Sequence[str]) -> dict[str, Any]:
    import matplotlib

    cmap = matplotlib.colormaps["tab10"]
    return {config: cmap(i % 10) for i, config in enumerate(configs)}


def _rounded(value: float) -> float:
    return round(value, 4) if math.isfinite(value) else value


def _statistic(runs: Sequence[Record], quantity: str) -> float:
    """One quantity of ``HEADLINE`` or ``DETAILS`` over runs (module docstring); inf for a cost per solution
    without a solved run, NaN for a path length without one."""
    solved = [r for r in runs if int(r["reached"])]
    if quantity.startswith("path_length"):
        return float(np.mean([float(r[quantity]) for r in solved])) if solved else math.nan
    column = {"calls_per_solution": "oracle_calls", "critical_path_per_solution": "critical_path_calls",
              "classical_checks_per_solution": "classical_checks", "wall_time_per_solution_s": "wall_time_s"}[quantity]
    total = float(sum(float(r[column]) for r in runs))
    return total / len(solved) if solved else math.inf


def _paired_ratio(runs: Sequence[Record], reference: Sequence[Record], quantity: str,
                  seed: int) -> tuple[float, list[float]]:
    """The ratio of ``quantity`` of ``runs`` to that of ``reference`` and its interval, resampling
    replicates (a replicate's run of each planner together)."""
    by_replicate = {int(r["replicate"]): r for r in runs}
    other = {int(r["replicate"]): r for r in reference}
    replicates = sorted(set(by_replicate) & set(other))

    def ratio(sample: list[int]) -> float:
        top = _statistic([by_replicate[i] for i in sample], quantity)
        bottom = _statistic([other[i] for i in sample], quantity)
        if not (math.isfinite(top) and math.isfinite(bottom)) or bottom == 0:
            raise ValueError("undefined in this resample")
        return top / bottom

    try:
        value = round(ratio(replicates), 4)
    except ValueError:
        value = math.nan
    return value, rounded_interval(bootstrap_interval(replicates, ratio, seed), 4)


def choose_default_policy(ours: dict[str, dict[str, dict[str, float]]]) -> dict[str, Any]:
    """The default search policy by the rule of the module docstring.

    Args:
        ours: The summary's ``ours`` (family -> planner -> quantities).

    Returns:
        ``{"rule", "relative_cost": {policy: {family: ratio}}, "score": {policy: geometric mean},
        "chosen": policy}``.
    """
    relative: dict[str, dict[str, float]] = {policy: {} for policy in POLICY_CANDIDATES}
    for family, planners in ours.items():
        costs = {policy: planners[f"QRRT {policy}"]["calls_per_solution"] for policy in POLICY_CANDIDATES
                 if f"QRRT {policy}" in planners}
        best = min(costs.values(), default=math.inf)
        if not math.isfinite(best):
            continue
        for policy, cost in costs.items():
            relative[policy][family] = round(cost / best, 4) if math.isfinite(cost) else math.inf
    score = {policy: round(float(np.exp(np.mean(np.log(list(values.values()))))), 4) if values else math.nan
             for policy, values in relative.items()}
    finite = {policy: value for policy, value in score.items() if math.isfinite(value)}
    return {"rule": "geometric mean over families of q-RRT calls per solution relative to the best candidate "
                    "in the family; lowest wins",
            "relative_cost": relative, "score": score,
            "chosen": min(finite, key=lambda p: finite[p]) if finite else None}


def _evaluations(problem: Problem) -> int:
    """The predicate evaluations made so far through the problem's check (every family's check,
    ``ExactCheck``, ``GridCheck`` and ``RigidBodyCheck``, counts them in ``evaluations``)."""
    return int(problem.predicate.evaluations)  # type: ignore[attr-defined]
