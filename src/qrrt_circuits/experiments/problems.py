"""Beyond the paper: every planner of the library on standard problem families, beside OMPL's RRT
and RRTConnect on the same motion check, at equal budgets in motion checks.

**Problems** (``world.problems``, built by the library): ``open-space`` (one box in [0, 10]^2),
``maze`` (a perfect maze of 4 x 4 rooms, a new maze per replicate: its seed is the replicate
index), ``narrow-passage-{2,4,6}d`` (a wall with a square hole whose share of the wall's
cross-section is 1 % in every dimension: side 10 x 0.01^(1 / (d - 1)), so 0.1 in 2-D, 2.15 in 4-D,
3.98 in 6-D; with a fixed side the share falls as (side / 10)^(d - 1), and at side 0.5 no planner
solved 6-D within the budget), ``winding-band-{2,4,6}d`` (a staircase band with two turns in the
(x_0, x_1) plane, every other axis free, a new band per replicate: a long narrow passage the tree
travels along, where a database of 2^8 entries holds on average one or two reachable entries and
often none; width 0.08 in 2-D and 0.15 in 4-D and 6-D, the narrowest of 0.05, 0.08, 0.1, 0.15 at
which a pilot of 4 or 5 runs (world seeds 0-4) saw q-RRT under the paper's schedule or ``Adaptive``
solve at least half within the budget) and ``se2-gap`` (a rectangle in SE(2) through a gap).
Straight segments under the exact checks (``ExactCheck``, ``GridCheck``, ``RigidBodyCheck``).

**Worlds and seeds.** The maze and the band draw a new world per replicate (its seed is the
replicate index); the other families have one world. Every replicate is run under each of the
``root_seeds`` (default three: ``--seed`` and the next two): the same worlds, new planner draws.
The unit of an interval is the world: a two-level bootstrap (``intervals.two_level_bootstrap_
interval``) resamples the worlds of a family, then the runs (root seed x replicate) inside each;
in a family with one world every run is its own group, so the interval is over runs in that world.

**Planners**: RRT; RRT with OMPL's range (``max_extension`` = 0.2 of the bounds' diagonal, no
look-ahead: the algorithm of OMPL's RRT); manager-worker parallel RRT (8 workers); q-RRT under the
paper's schedule, ``Adaptive``, ``BBHT`` and ``ThompsonIterations``; Pq-RRT (8 workers, shared
database) under the same four; and, when the ``ompl`` extra is installed, OMPL's RRT and RRTConnect
(``experiments.ompl_runs``). All with goal bias 0.05 (OMPL's default; RRTConnect has none),
2^8-entry databases on the exact statevector.

**Budget**: each run ends when it reaches the goal or has made ``budget`` oracle calls: DESIGN §2
counting for the library's planners (a Grover iteration is one call, a classical test one), motion
checks for OMPL's (each one evaluation of the same predicate). A run that ends at the budget failed.

**Measures**, per family and planner, with 95 % two-level bootstrap intervals over worlds and runs
(Clopper-Pearson over runs for success rates): success rate; oracle calls per solution (all calls of all runs,
failed ones included, over the number of solved runs: the expected cost of one solution when a
failed run is restarted, the budget-censored estimator of a Las Vegas algorithm's cost); the same
for critical-path calls (p parallel devices), for classical checks actually made (every predicate
evaluation: the simulation's 2^n per database, look-ahead checks thrown away, verifications) and
for wall time; path length of the solved runs, raw and after the greedy shortcut
(``planners.paths.shortcut``, the same post-processing for every planner). Ratios to OMPL's RRT and
RRTConnect (and to the library's RRT): calls, critical-path calls (one device per worker against
OMPL's one thread) and wall time, resampling the runs of both planners together (a run is one root
seed and replicate, every planner's record of it).

**The default search policy** is chosen from this experiment by a rule fixed before the run, for
q-RRT on its calls per solution and for Pq-RRT on its critical-path calls per solution (its total
calls reported beside): in each family, each candidate's cost per solution (all runs of all root
seeds) over the smallest candidate's, its *family ratio* (a family no candidate solved is left out;
a candidate that solved none there has ratio inf). The default is the candidate whose *worst*
family ratio is smallest; candidates whose worst ratios lie within 5 % of the smallest are tied,
and the tie goes to the lower geometric mean of the family ratios, then to the earlier candidate
in ``POLICY_CANDIDATES``. The goal is a worst ratio of at most 1.5. The rule is also applied to
each root seed's runs alone (``chosen_by_root_seed``) and to two-level bootstrap resamples
(``chosen_share_in_resamples``); each family ratio has its interval over worlds and runs.
"""

from __future__ import annotations

import importlib.util
import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..planners.paths import path_length, shortcut
from ..registry import POLICIES
from ..world.problems import Problem, maze, narrow_passage, open_space, se2_gap, winding_band
from .base import Experiment, Record, Settings, Summary, Trial, TrialStream, replicate_seed
from .figures import dodge, new_figure, save, with_intervals
from .intervals import RESAMPLES, binomial_interval, percentile_interval, rounded_interval, two_level_bootstrap_counts
from .planners import BACKEND_LABEL, make_planner

FAMILIES = ("open-space", "maze", "narrow-passage-2d", "narrow-passage-4d", "narrow-passage-6d", "se2-gap",
            "winding-band-2d", "winding-band-4d", "winding-band-6d")
QUICK_FAMILIES = ("open-space", "maze", "se2-gap", "winding-band-2d")
#: families that draw a new world per replicate (its seed is the replicate index)
WORLD_FAMILIES = ("maze", "winding-band-2d", "winding-band-4d", "winding-band-6d")
#: the winding band's width per dimension (module docstring)
BAND_WIDTH = {2: 0.08, 4: 0.15, 6: 0.15}
#: root seeds per run: ``--seed`` and the next ones
ROOT_SEEDS, QUICK_ROOT_SEEDS = 3, 2
#: the default-policy rule's tie margin: worst ratios within this factor of the smallest are tied
TIE_MARGIN = 1.05
#: bootstrap resamples of the default-policy rule (its stability)
RULE_RESAMPLES = 400
#: label -> (registry planner, search policy name or None, the extra options for a problem)
LIBRARY_CONFIGS: dict[str, tuple[str, str | None, Callable[[Problem], dict[str, Any]]]] = {
    "RRT": ("rrt", None, lambda problem: {}),
    "RRT range": ("rrt", None, lambda problem: {"look_ahead": False, "max_extension": ompl_range(problem)}),
    "ParallelRRT": ("prrt", None, lambda problem: {}),
    "QRRT paper": ("qrrt", "paper", lambda problem: {}),
    "QRRT adaptive": ("qrrt", "adaptive", lambda problem: {}),
    "QRRT bbht": ("qrrt", "bbht", lambda problem: {}),
    "QRRT thompson": ("qrrt", "thompson", lambda problem: {}),
    "PQRRT paper": ("pqrrt", "paper", lambda problem: {}),
    "PQRRT adaptive": ("pqrrt", "adaptive", lambda problem: {}),
    "PQRRT bbht": ("pqrrt", "bbht", lambda problem: {}),
    "PQRRT thompson": ("pqrrt", "thompson", lambda problem: {}),
}
OMPL_CONFIGS = ("OMPL RRT", "OMPL RRTConnect")
POLICY_CANDIDATES = ("paper", "adaptive", "bbht", "thompson")
GOAL_BIAS = 0.05
#: the narrow passage's hole: its share of the wall's cross-section, in every dimension
HOLE_SHARE = 0.01
#: OMPL's default range: this fraction of the space's largest extent (the bounds' diagonal)
RANGE_FRACTION = 0.2
#: the record column summed by each per-solution quantity
QUANTITY_COLUMN = {"calls_per_solution": "oracle_calls", "critical_path_per_solution": "critical_path_calls",
                   "classical_checks_per_solution": "classical_checks", "wall_time_per_solution_s": "wall_time_s"}
#: the summary's ``ours`` (with the success rate) ...
HEADLINE = ("calls_per_solution", "wall_time_per_solution_s")
#: ... and its ``details``
DETAILS = ("critical_path_per_solution", "classical_checks_per_solution", "path_length", "path_length_simplified")


def build_problem(family: str, replicate: int) -> Problem:
    """The problem of ``family`` for one replicate (a new maze or band per replicate, the others fixed).

    Args:
        family: One of ``FAMILIES``.
        replicate: The replicate index.

    Returns:
        A fresh problem (its predicate's ``evaluations`` at 0).
    """
    if family == "maze":
        return maze(4, replicate)
    if family.startswith("winding-band-"):
        dim = int(family.removeprefix("winding-band-").removesuffix("d"))
        return winding_band(dim, BAND_WIDTH[dim], replicate)
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
        roots = QUICK_ROOT_SEEDS if quick else ROOT_SEEDS
        return {"trials": trials or (2 if quick else 10), "root_seeds": [seed + i for i in range(roots)],
                "families": list(QUICK_FAMILIES if quick else FAMILIES), "band_width": BAND_WIDTH,
                "budget": 1500 if quick else 10000, "configs": configs, "ompl": _ompl_version(),
                "workers": 8, "num_qubits": 8, "backend": "statevector", "goal_bias": GOAL_BIAS,
                "range_fraction": RANGE_FRACTION,
                "policies": {name: POLICIES.create(name).describe() for name in POLICY_CANDIDATES},
                "seed": seed, "quick": quick}

    def trials(self, settings: Settings) -> list[Trial]:
        trials = []
        for root in settings["root_seeds"]:
            for replicate in range(settings["trials"]):
                seed = replicate_seed(root, replicate, TrialStream.PROBLEMS_PLANNERS)
                for family in settings["families"]:
                    for config in settings["configs"]:
                        trials.append(Trial(f"{family} {config}-s{root}-{replicate}",
                                            {"family": family, "config": config, "root_seed": root,
                                             "replicate": replicate}, seed))
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
        worlds: dict[str, int] = {}
        for index, family in enumerate(settings["families"]):
            units = family_units(records, family)
            worlds[family] = len({world for world, _ in units})
            counts = _counts(units, seed, index)
            ours[family], intervals[family], ratios[family], ratio_intervals[family] = {}, {}, {}, {}
            details[family], detail_intervals[family] = {}, {}
            for config in settings["configs"]:
                runs = [unit[config] for _, unit in units if config in unit]
                solved = sum(int(r["reached"]) for r in runs)
                values = {"success_rate": round(solved / len(runs), 4) if runs else math.nan}
                spans = {"success_rate": rounded_interval(binomial_interval(solved, len(runs)), 4)}
                for quantity in (*HEADLINE, *DETAILS):
                    values[quantity] = _rounded(_statistic(runs, quantity))
                    spans[quantity] = rounded_interval(percentile_interval(
                        _resampled(units, counts, config, quantity)), 4)
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
                        value, span = _paired_ratio(units, counts, config, reference, quantity)
                        ratios[family].setdefault(config, {})[key] = value
                        ratio_intervals[family].setdefault(config, {})[key] = span
        return {"ours": ours, "paper": self.paper, "interval_95": intervals, "details": details,
                "details_interval_95": detail_intervals, "ratios": ratios,
                "ratios_interval_95": ratio_intervals, "worlds": worlds,
                "default_policy": _default_policies(records, settings),
                "policy_candidates": list(POLICY_CANDIDATES), "tie_margin": TIE_MARGIN,
                "note": "per family and planner: success rate within the budget; calls, critical-path calls, "
                        "classical checks and wall time per solution (all runs' totals over the solved runs: the "
                        "expected cost of one solution with restarts after failures); mean path length of the "
                        "solved runs, raw and after the greedy shortcut; a run is one root seed and replicate; "
                        "intervals: two-level percentile bootstrap over the family's worlds ('worlds') and the "
                        "runs in each (a family with one world: over its runs), Clopper-Pearson over runs for "
                        "success rates; ratios resample the runs of both planners together",
                "labels": ["phase oracle from a classical lookup of all 2^8 database entries (simulation_checks: "
                           "2^8 predicate evaluations per database, inside classical_checks)",
                           "Pq-RRT: one search with 8 shots for 8 workers on the shared database (the paper's "
                           "schedule and Adaptive); under BBHT each worker runs its own loop of searches",
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
        axes[0, 0].legend(ncol=7, fontsize=7.5, loc="lower center", bbox_to_anchor=(0.5, 1.02), frameon=False)
        fig.suptitle(f"{settings['trials']} replicates x {len(settings['root_seeds'])} root seeds per family, "
                     f"budget {settings['budget']} calls", fontsize=10)
        fig.tight_layout(rect=(0.0, 0.0, 1.0, 0.97))
        return [save(fig, out_dir / "problems.png"), self._plot_policies(settings, summary, out_dir)]

    @staticmethod
    def _plot_policies(settings: Settings, summary: Summary, out_dir: Path) -> Path:
        """Each candidate policy's family ratio (its cost per solution over the best candidate's) with
        its interval over worlds and runs, per rule (q-RRT calls, Pq-RRT critical path and calls)."""
        rules = summary["default_policy"]
        families = settings["families"]
        fig, axes = new_figure(len(rules), 1, (max(9.0, 1.3 * len(families)), 3.4 * len(rules)))
        x = np.arange(len(families), dtype=float)
        offsets = dodge(len(POLICY_CANDIDATES), 0.6)
        colors = _colors(POLICY_CANDIDATES)
        for ax, (name, rule) in zip(axes[:, 0], rules.items(), strict=True):
            for offset, candidate in zip(offsets, POLICY_CANDIDATES, strict=True):
                ratios = rule["relative_cost"].get(candidate, {})
                values = [_finite_or_nan(ratios.get(f)) for f in families]
                spans = [rule["relative_cost_interval_95"].get(candidate, {}).get(f, [math.nan, math.nan])
                         for f in families]
                spans = [[_finite_or_nan(low), _finite_or_nan(high)] for low, high in spans]
                with_intervals(ax, x + offset, values, spans, fmt="o", ms=4, color=colors[candidate],
                               label=f"{candidate} (worst {_finite_or_nan(rule['worst'].get(candidate)):.2f})")
            ax.axhline(1.5, color="0.4", ls="--", lw=0.8)
            ax.set_yscale("log")
            ax.set_xticks(x, families, fontsize=8)
            ax.set_ylabel("cost / best candidate's")
            ax.set_title(f"{name}: {rule['quantity'].replace('_', ' ')}; chosen {rule['chosen']}", fontsize=9)
            ax.legend(fontsize=7.5, loc="upper right")
            ax.grid(alpha=0.3, axis="y", which="both")
        fig.tight_layout()
        return save(fig, out_dir / "problems_policies.png")


def _colors(configs: Sequence[str]) -> dict[str, Any]:
    import matplotlib

    cmap = matplotlib.colormaps["tab10" if len(configs) <= 10 else "tab20"]
    return {config: cmap(i % cmap.N) for i, config in enumerate(configs)}


def _finite_or_nan(value: Any) -> float:
    """A JSON number as a float for plotting: None (JSON's non-finite) and inf as NaN."""
    return float(value) if value is not None and math.isfinite(float(value)) else math.nan


def _rounded(value: float) -> float:
    return round(value, 4) if math.isfinite(value) else value


def _statistic(runs: Sequence[Record], quantity: str) -> float:
    """One quantity of ``HEADLINE`` or ``DETAILS`` over runs (module docstring); inf for a cost per solution
    without a solved run, NaN for a path length without one."""
    solved = [r for r in runs if int(r["reached"])]
    if quantity.startswith("path_length"):
        return float(np.mean([float(r[quantity]) for r in solved])) if solved else math.nan
    total = float(sum(float(r[QUANTITY_COLUMN[quantity]]) for r in runs))
    return total / len(solved) if solved else math.inf


def family_units(records: Sequence[Record], family: str) -> list[tuple[str, dict[str, Record]]]:
    """The runs of one family as ``(world, {config: record})``, one per root seed and replicate.

    A run's world is its replicate for ``WORLD_FAMILIES`` (the replicate seeds the world) and the
    run itself otherwise (one world: every run its own group of the two-level bootstrap).
    """
    units: dict[tuple[int, int], dict[str, Record]] = {}
    for record in records:
        if record["family"] == family:
            units.setdefault((int(record["root_seed"]), int(record["replicate"])), {})[record["config"]] = record
    return [(f"world {replicate}" if family in WORLD_FAMILIES else f"run {root}-{replicate}", unit)
            for (root, replicate), unit in sorted(units.items())]


def _counts(units: Sequence[tuple[str, dict[str, Record]]], seed: int, family_index: int,
            resamples: int = RESAMPLES) -> np.ndarray:
    """The two-level bootstrap counts of a family's runs (``intervals.two_level_bootstrap_counts``),
    shared by all its planners so that their ratios are paired."""
    sizes = [sum(1 for w, _ in units if w == world) for world in dict.fromkeys(w for w, _ in units)]
    if not sizes:
        return np.zeros((resamples, 0), dtype=np.int64)
    return two_level_bootstrap_counts(sizes, seed + 7919 * family_index, resamples)


def _column(units: Sequence[tuple[str, dict[str, Record]]], config: str, key: str) -> np.ndarray:
    """One record field of ``config`` per run (0 where the run lacks the planner or the value)."""
    values = []
    for _, unit in units:
        value = float(unit[config][key]) if config in unit else 0.0
        values.append(value if math.isfinite(value) else 0.0)
    return np.array(values)


def _resampled(units: Sequence[tuple[str, dict[str, Record]]], counts: np.ndarray, config: str,
               quantity: str) -> np.ndarray:
    """``_statistic`` of ``config``'s runs in every resample of ``counts`` (inf for a cost, NaN for
    a path length, where a resample has no solved run)."""
    if counts.shape[1] == 0:
        return np.full(counts.shape[0], np.nan)
    reached = _column(units, config, "reached")
    solved = counts @ reached
    if quantity.startswith("path_length"):
        top = counts @ (_column(units, config, quantity) * reached)
    else:
        top = counts @ _column(units, config, QUANTITY_COLUMN[quantity])
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(solved > 0, top / np.where(solved > 0, solved, 1),
                        np.nan if quantity.startswith("path_length") else np.inf)


def _paired_ratio(units: Sequence[tuple[str, dict[str, Record]]], counts: np.ndarray, config: str, reference: str,
                  quantity: str) -> tuple[float, list[float]]:
    """The ratio of ``quantity`` of ``config`` to that of ``reference`` and its two-level interval
    (the same resampled runs for both planners)."""
    top = _statistic([unit[config] for _, unit in units if config in unit], quantity)
    bottom = _statistic([unit[reference] for _, unit in units if reference in unit], quantity)
    value = round(top / bottom, 4) if math.isfinite(top) and math.isfinite(bottom) and bottom > 0 else math.nan
    bottoms = _resampled(units, counts, reference, quantity)
    with np.errstate(divide="ignore", invalid="ignore"):  # undefined where the reference solved none
        resampled = np.where(np.isfinite(bottoms), _resampled(units, counts, config, quantity) / bottoms, np.nan)
    return value, rounded_interval(percentile_interval(resampled), 4)


def family_ratios(costs: dict[str, dict[str, float]]) -> dict[str, dict[str, float]]:
    """Each candidate's cost over the smallest candidate's, per family (the rule's family ratio).

    Args:
        costs: Family -> candidate -> cost per solution (inf where the candidate solved none).

    Returns:
        Candidate -> family -> ratio; families where no candidate solved are left out, a candidate
        that solved none where another did has ratio inf.
    """
    relative: dict[str, dict[str, float]] = {}
    for family, by_candidate in costs.items():
        best = min(by_candidate.values(), default=math.inf)
        if not math.isfinite(best) or best <= 0:
            continue
        for candidate, cost in by_candidate.items():
            relative.setdefault(candidate, {})[family] = cost / best if math.isfinite(cost) else math.inf
    return relative


def choose_by_worst_ratio(relative: dict[str, dict[str, float]], order: Sequence[str],
                          margin: float = TIE_MARGIN) -> str | None:
    """The default-policy rule of the module docstring on family ratios.

    Args:
        relative: Candidate -> family -> ratio (``family_ratios``).
        order: The candidates in their tie-breaking order (earlier wins a full tie).
        margin: Worst ratios within this factor of the smallest are tied (>= 1).

    Returns:
        The chosen candidate, or None if no candidate has a family ratio.
    """
    worst = {c: max(relative[c].values()) for c in order if relative.get(c)}
    if not worst:
        return None
    smallest = min(worst.values())
    tied = [c for c in order if c in worst and worst[c] <= smallest * margin]
    return min(tied, key=lambda c: (_geometric_mean(relative[c].values()), order.index(c)))


def _geometric_mean(values: Any) -> float:
    values = list(values)
    if not values:
        return math.nan
    return math.inf if not all(math.isfinite(v) for v in values) else float(np.exp(np.mean(np.log(values))))


def _candidate_costs(records: Sequence[Record], families: Sequence[str], configs: dict[str, str],
                     quantity: str) -> dict[str, dict[str, float]]:
    costs: dict[str, dict[str, float]] = {}
    for family in families:
        for candidate, config in configs.items():
            runs = [r for r in records if r["family"] == family and r["config"] == config]
            if runs:
                costs.setdefault(family, {})[candidate] = _statistic(runs, quantity)
    return costs


def choose_default_policy(records: Sequence[Record], settings: Settings, planner: str, quantity: str,
                          resamples: int = RULE_RESAMPLES) -> dict[str, Any]:
    """The default search policy of ``planner`` by the rule of the module docstring.

    Args:
        records: The experiment's records.
        settings: Its settings (families, configs, root seeds, seed).
        planner: ``"QRRT"`` or ``"PQRRT"`` (its configs ``f"{planner} {policy}"``).
        quantity: ``"calls_per_solution"`` or ``"critical_path_per_solution"``.
        resamples: Two-level bootstrap resamples for the intervals and the rule's stability.

    Returns:
        ``{"rule", "quantity", "relative_cost": {policy: {family: ratio}}, "relative_cost_interval_95",
        "worst": {policy: worst ratio}, "geometric_mean", "chosen", "chosen_by_root_seed",
        "chosen_share_in_resamples", "goal_met"}``.
    """
    configs = {c: f"{planner} {c}" for c in POLICY_CANDIDATES if f"{planner} {c}" in settings["configs"]}
    families, seed = settings["families"], settings["seed"]
    relative = family_ratios(_candidate_costs(records, families, configs, quantity))
    order = list(configs)
    chosen = choose_by_worst_ratio(relative, order)
    by_root = {str(root): choose_by_worst_ratio(family_ratios(_candidate_costs(
        [r for r in records if int(r["root_seed"]) == int(root)], families, configs, quantity)), order)
        for root in settings["root_seeds"]}
    spans: dict[str, dict[str, list[float]]] = {c: {} for c in configs}
    resampled_costs: dict[str, np.ndarray] = {}  # family -> (resamples, candidates)
    for index, family in enumerate(families):
        units = family_units(records, family)
        if not units:
            continue
        counts = _counts(units, seed, index, resamples)
        costs = np.stack([_resampled(units, counts, config, quantity) for config in configs.values()], axis=1)
        resampled_costs[family] = costs
        best = costs.min(axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratios = np.where(np.isfinite(best)[:, None] & (best[:, None] > 0), costs / best[:, None], np.nan)
        for column, candidate in enumerate(configs):
            if family in relative.get(candidate, {}):  # inf (solved none in a resample) kept, NaN left out
                kept = ratios[~np.isnan(ratios[:, column]), column]
                spans[candidate][family] = ([round(float(np.quantile(kept, 0.025, method="lower")), 4),
                                             round(float(np.quantile(kept, 0.975, method="higher")), 4)]
                                            if kept.size else [math.nan, math.nan])
    shares = dict.fromkeys(configs, 0)
    for row in range(resamples):
        picked = choose_by_worst_ratio(family_ratios(
            {family: dict(zip(configs, map(float, costs[row]), strict=True))
             for family, costs in resampled_costs.items()}), order)
        if picked is not None:
            shares[picked] += 1
    worst = {c: _rounded(max(v.values())) for c, v in relative.items() if v}
    return {"rule": "per family, each candidate's cost per solution over the smallest candidate's; the candidate "
                    "with the smallest worst family ratio wins; worst ratios within 5 % are tied and go to the "
                    "lower geometric mean, then to the earlier candidate",
            "quantity": quantity,
            "relative_cost": {c: {f: _rounded(v) for f, v in fam.items()} for c, fam in relative.items()},
            "relative_cost_interval_95": spans, "worst": worst,
            "geometric_mean": {c: _rounded(_geometric_mean(v.values())) for c, v in relative.items()},
            "chosen": chosen, "chosen_by_root_seed": by_root,
            "chosen_share_in_resamples": {c: round(n / resamples, 4) for c, n in shares.items()},
            "goal_met": bool(chosen is not None and worst[chosen] <= 1.5)}


def _default_policies(records: Sequence[Record], settings: Settings) -> dict[str, Any]:
    """The rule for q-RRT (calls) and Pq-RRT (critical path; its total calls beside)."""
    out: dict[str, Any] = {}
    for key, planner, quantity in (("QRRT", "QRRT", "calls_per_solution"),
                                   ("PQRRT", "PQRRT", "critical_path_per_solution"),
                                   ("PQRRT_total_calls", "PQRRT", "calls_per_solution")):
        if any(f"{planner} {c}" in settings["configs"] for c in POLICY_CANDIDATES):
            out[key] = choose_default_policy(records, settings, planner, quantity)
    return out


def _evaluations(problem: Problem) -> int:
    """The predicate evaluations made so far through the problem's check (every family's check,
    ``ExactCheck``, ``GridCheck`` and ``RigidBodyCheck``, counts them in ``evaluations``)."""
    return int(problem.predicate.evaluations)  # type: ignore[attr-defined]
