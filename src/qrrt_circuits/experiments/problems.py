"""Beyond the paper: every planner of the library on standard problem families, beside OMPL's RRT
and RRTConnect on the same motion check, at equal budgets in motion checks.

**Problems** (``problems.families``, built by the library): ``open-space`` (one box in [0, 10]^2),
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

**Planners**: RRT; RRT with OMPL's range (``max_extension`` = 0.2 of the bounds' diagonal: the
algorithm of OMPL's RRT, its rounds tested ahead as the library's RRT tests them by default: the
tree and the oracle calls of testing one round at a time, and checks thrown away besides);
manager-worker parallel RRT (8 workers); q-RRT under the paper's schedule, ``Adaptive``, ``BBHT``
and ``ThompsonIterations``; Pq-RRT (8 workers, shared database) under the same four; and, when the
``ompl`` extra is installed, OMPL's RRT and RRTConnect (``experiments.ompl_runs``). All with goal
bias 0.05 (OMPL's default; RRTConnect has none), 2^8-entry databases on the exact statevector.

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

**The default search policy** is chosen from this experiment by the rule of
``experiments.default_policy``, fixed before the run: for q-RRT on its calls per solution, for
Pq-RRT on its critical-path calls per solution (its total calls reported beside), the candidate
with the smallest worst family ratio, also applied to each root seed alone and to resamples.
"""

from __future__ import annotations

import importlib.util
import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..planners.paths import path_length, shortcut
from ..problems.families import Problem, maze, narrow_passage, open_space, se2_gap, winding_band
from ..registry import POLICIES
from .base import Experiment, Record, Settings, Summary, Trial, TrialStream, replicate_seed
from .connect_star import NO_ANYTIME, anytime_columns, connect_summary, star_summary
from .default_policy import POLICY_CANDIDATES, TIE_MARGIN, default_policies
from .family_runs import family_counts, family_units, paired_ratio, resampled, statistic
from .figures import dodge, new_figure, save, with_intervals
from .intervals import binomial_interval, percentile_interval, rounded_interval
from .planners import BACKEND_LABEL, make_planner

FAMILIES = ("open-space", "maze", "narrow-passage-2d", "narrow-passage-4d", "narrow-passage-6d", "se2-gap",
            "winding-band-2d", "winding-band-4d", "winding-band-6d")
QUICK_FAMILIES = ("open-space", "maze", "se2-gap", "winding-band-2d")
#: the winding band's width per dimension (module docstring)
BAND_WIDTH = {2: 0.08, 4: 0.15, 6: 0.15}
#: root seeds per run: ``--seed`` and the next ones
ROOT_SEEDS, QUICK_ROOT_SEEDS = 3, 2
#: label -> (registry planner, search policy name or None, the extra options for a problem)
LIBRARY_CONFIGS: dict[str, tuple[str, str | None, Callable[[Problem], dict[str, Any]]]] = {
    "RRT": ("rrt", None, lambda problem: {}),
    "RRT range": ("rrt", None, lambda problem: {"max_extension": ompl_range(problem)}),
    "ParallelRRT": ("prrt", None, lambda problem: {}),
    "QRRT paper": ("qrrt", "paper", lambda problem: {}),
    "QRRT adaptive": ("qrrt", "adaptive", lambda problem: {}),
    "QRRT bbht": ("qrrt", "bbht", lambda problem: {}),
    "QRRT thompson": ("qrrt", "thompson", lambda problem: {}),
    "PQRRT paper": ("pqrrt", "paper", lambda problem: {}),
    "PQRRT adaptive": ("pqrrt", "adaptive", lambda problem: {}),
    "PQRRT bbht": ("pqrrt", "bbht", lambda problem: {}),
    "PQRRT thompson": ("pqrrt", "thompson", lambda problem: {}),
    "QRRTConnect": ("qrrt-connect", "thompson", lambda problem: {"goal_bias": 0.0,
                                                                 "max_extension": ompl_range(problem)}),
    "QRRTStar": ("qrrt-star", "thompson", lambda problem: {"max_extension": ompl_range(problem)}),
}
OMPL_CONFIGS = ("OMPL RRT", "OMPL RRTConnect", "OMPL RRTstar")
#: the quantum RRT-Connect and RRT* beside their OMPL peers (``experiments.connect_star``)
CONNECT_PAIR = ("QRRTConnect", "OMPL RRTConnect")
STAR_PAIR = ("QRRTStar", "OMPL RRTstar")
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


#: points ``load_kernels`` puts in each family's nearest-neighbour structure: more than any
#: structure searches by brute force (``world.nearest.BRUTE_FORCE_BELOW``), so that it builds its grid
GRID_POINTS = 512


def load_kernels(calls: int = 40) -> None:
    """Plan ``calls`` oracle calls of RRT (with OMPL's range) and of q-RRT (exact statevector) on
    each family's first world, and fill the family's nearest-neighbour structure with
    ``GRID_POINTS`` points and query it: this loads into the process the compiled kernels of the
    families' checks, goals, statevector draws and nearest-neighbour structures, small and large
    (once per process and argument types; the process pools' warm-up, so that a worker's first
    trial on a family does not count their loading in its wall time).

    Args:
        calls: The oracle calls of each plan (default 40).
    """
    rng = np.random.default_rng(0)
    for family in FAMILIES:
        problem = build_problem(family, 0)
        step = ompl_range(problem)
        make_planner("rrt", 0, goal_bias=GOAL_BIAS, max_extension=step).plan(problem, max_oracle_calls=calls)
        make_planner("qrrt", 0, "statevector", goal_bias=GOAL_BIAS, max_extension=step).plan(
            problem, max_oracle_calls=calls)
        neighbors = problem.space.nearest_neighbors()
        points = problem.env.sample_uniform(GRID_POINTS, rng)
        neighbors.add(points)
        neighbors.nearest(points[:2])


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
        planner = make_planner(kind, trial.seed, settings["backend"], settings["workers"],
                               settings["num_qubits"], search_policy=policy,
                               **({"goal_bias": settings["goal_bias"]} | options(problem)))
        result = planner.plan(problem, max_oracle_calls=settings["budget"])
        m = result.metrics
        record = {"status": str(result.status), "reached": int(result.reached), "oracle_calls": m.oracle_calls,
                  "critical_path_calls": m.critical_path_oracle_calls, "simulation_checks": m.simulation_checks,
                  "classical_checks": _evaluations(problem), "nodes": m.nodes,
                  "wall_time_s": m.wall_time_s}
        # an anytime planner's best cost against its calls (NaN columns for the others: one header for all rows)
        record |= anytime_columns(result.history["oracle_calls"], result.history["path_cost"], settings["budget"]) \
            if config in STAR_PAIR else NO_ANYTIME
        return record | self._paths(problem, result.path)

    @staticmethod
    def _ompl_trial(problem: Problem, config: str, seed: int, settings: Settings) -> Record:
        from .ompl_runs import ompl_run

        run = ompl_run(problem, config, settings["budget"], seed % (2**31 - 1) + 1, settings["goal_bias"])
        record = {"status": "reached" if run.reached else "max_oracle_calls", "reached": int(run.reached),
                  "oracle_calls": run.motion_checks, "critical_path_calls": run.motion_checks,
                  "simulation_checks": 0, "classical_checks": _evaluations(problem),
                  "nodes": math.nan, "wall_time_s": run.wall_time_s}
        record |= anytime_columns([0, *(calls for calls, _ in run.anytime)],
                                  [math.nan, *(cost for _, cost in run.anytime)], settings["budget"]) \
            if config in STAR_PAIR else NO_ANYTIME
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
            counts = family_counts(units, seed, index)
            ours[family], intervals[family], ratios[family], ratio_intervals[family] = {}, {}, {}, {}
            details[family], detail_intervals[family] = {}, {}
            for config in settings["configs"]:
                runs = [unit[config] for _, unit in units if config in unit]
                solved = sum(int(r["reached"]) for r in runs)
                values = {"success_rate": round(solved / len(runs), 4) if runs else math.nan}
                spans = {"success_rate": rounded_interval(binomial_interval(solved, len(runs)), 4)}
                for quantity in (*HEADLINE, *DETAILS):
                    values[quantity] = _rounded(statistic(runs, quantity))
                    spans[quantity] = rounded_interval(percentile_interval(
                        resampled(units, counts, config, quantity)), 4)
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
                        value, span = paired_ratio(units, counts, config, reference, quantity)
                        ratios[family].setdefault(config, {})[key] = value
                        ratio_intervals[family].setdefault(config, {})[key] = span
        connect: dict[str, dict] = {}
        star: dict[str, dict] = {}
        for index, family in enumerate(settings["families"]):
            units = family_units(records, family)
            counts = family_counts(units, seed, index)
            if all(config in settings["configs"] for config in CONNECT_PAIR):
                connect[family] = connect_summary(units, counts, *CONNECT_PAIR)
            if all(config in settings["configs"] for config in STAR_PAIR):
                star[family] = star_summary(units, counts, *STAR_PAIR)
        return {"ours": ours, "paper": self.paper, "interval_95": intervals, "details": details,
                "connect_vs_ompl": connect, "star_vs_ompl": star,
                "details_interval_95": detail_intervals, "ratios": ratios,
                "ratios_interval_95": ratio_intervals, "worlds": worlds,
                "default_policy": default_policies(records, settings),
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


def _evaluations(problem: Problem) -> int:
    """The predicate evaluations made so far through the problem's check (every family's check,
    ``ExactCheck``, ``GridCheck`` and ``RigidBodyCheck``, counts them in ``evaluations``)."""
    return int(problem.predicate.evaluations)  # type: ignore[attr-defined]
