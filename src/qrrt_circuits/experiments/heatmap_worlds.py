"""Paper Figs. 10-12 in single worlds: which worlds give the paper's RRT, and what q-RRT gives there.

The paper ran its 100 trials in one world. Its q-RRT call totals (372 / 0.312 = 1 192,
650 / 0.310 = 2 097 and 1 091 / 0.260 = 4 196 calls over 100 trials: 11.9, 21.0 and 42.0 calls a
trial at the 10-, 20- and 40-call cuts) fit only a round of 3 calls (2 Grover iterations and one
verification): a run cut at b calls stops after the first round that reaches b, so it makes
c ceil(b / c) calls with rounds of c calls, and only c = 3 gives 12, 21 and 42 (``round_costs``).
So q-RRT runs here with ``FixedIterations(2)``. For contrast it also runs with the paper's schedule
(``PaperIterations``: 5 iterations, so 6-call rounds, until the tree passes 10 nodes), which cannot
give the paper's totals: with 6-call rounds a run cut at b calls adds at most ceil(b / 6) nodes,
200, 400 and 700 per 100 trials at the three cuts, below the paper's 372, 650 and 1 091.

Success after 2 iterations, sin^2(5 theta), is steeply non-linear in a world's reachable fraction,
so efficiencies pooled over worlds are not those of any one world. The experiment therefore runs
many single worlds (``paper_clutter`` with several obstacle counts, several world seeds each) and
applies an acceptance rule fixed before the run to RRT alone: **a world passes when the paper's
three RRT efficiencies (12.5 %, 11.6 % and 13.2 % at 10, 20 and 40 calls) all lie inside that
world's 95 % intervals from its RRT runs** (under one planner root seed). q-RRT's nodes and
efficiencies in exactly the passing worlds, with their intervals, are then set against the paper's.
Over all worlds, the 5 %, 50 % and 95 % quantiles of each planner's efficiency at 10 calls, and of
q-RRT's advantage over RRT (the difference and the ratio of their efficiencies in one world), show
how world-dependent the advantage is.

The runs also record the reachable share of the candidates they evaluated (q-RRT: its databases'
entries) up to each cut. With k iterations a database whose reachable share is f = sin^2 theta is
searched successfully with probability sin^2((2k + 1) theta), highest at f = sin^2(pi / (4k + 2)):
9.5 % for k = 2, 2.0 % for k = 5. A share that grows past that peak as the tree grows lowers the
efficiency at later cuts.

A trial is one block: ``RUNS`` runs of one planner variant in one world under one planner root seed, each
cut at 40 oracle calls (the 10- and 20-call cuts read from its history, ``cut_at``). The variants of
one world share its planner seeds. The worlds are fixed by their obstacle count and world seed; the
whole grid is run under several planner root seeds, and the rule is applied under each, so which
worlds pass, and how many pass again under another root seed, is measured rather than assumed. The
pooled q-RRT values over the passing worlds carry an interval whose unit is the world
(``two_level_bootstrap_interval``: worlds, then runs in each), beside the range of the passing
worlds' own values.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from ..search.policies.schedules import FixedIterations, PaperIterations
from .base import Experiment, Record, Settings, Summary, Trial, TrialStream, replicate_seed
from .figures import new_figure, save
from .intervals import bootstrap_ratio_interval, differs, rounded_interval, two_level_bootstrap_interval
from .measures import cut_at, dumps, loads, reachable_at
from .planners import experiment_problem, make_planner
from .worlds import world

BOX_COUNTS = (100, 150, 200, 250, 300, 400, 525)
#: the most world seeds per obstacle count (a world's planner seeds are keyed by count and seed)
WORLDS_PER_COUNT = 1000
CUTS = (10, 20, 40)
#: runs of each planner variant in one world under one root seed (a full run); the rule's intervals
#: come from these runs. The runs of a block are seeded by their index, so a block of r runs is the
#: first r runs of a longer one.
RUNS = 50
#: planner root seeds of a full run (``seed``, ``seed + 1``, ...): every world is run under each
PLANNER_ROOT_SEEDS = 3
#: label -> (registry planner, search policy): RRT, q-RRT with the 3-call round the paper's totals
#: imply, q-RRT with the paper's schedule (for contrast)
VARIANTS = {"RRT": ("rrt", None), "QRRT": ("qrrt", FixedIterations(2)), "QRRT_PAPER": ("qrrt", PaperIterations())}
#: the q-RRT variants, each compared with the paper's q-RRT
QUANTUM = ("QRRT", "QRRT_PAPER")
#: calls of one round of the paper's schedule while the tree is small (5 iterations + 1 verification)
PAPER_SCHEDULE_ROUND = 6
#: planner -> cut -> {"nodes" (per 100 trials), "efficiency"}
PAPER: dict[str, dict[str, dict[str, float]]] = {
    "RRT": {"10": {"nodes": 125, "efficiency": 0.125}, "20": {"nodes": 231, "efficiency": 0.116},
            "40": {"nodes": 526, "efficiency": 0.132}},
    "QRRT": {"10": {"nodes": 372, "efficiency": 0.312}, "20": {"nodes": 650, "efficiency": 0.310},
             "40": {"nodes": 1091, "efficiency": 0.260}}}
PAPER["QRRT_PAPER"] = PAPER["QRRT"]  # the paper's q-RRT, against either round
ACCEPTANCE_RULE = ("a world passes when the paper's RRT efficiencies at 10, 20 and 40 calls (0.125, 0.116, 0.132) "
                   "all lie inside that world's 95 % intervals from its RRT runs; fixed before the run, applied "
                   "to RRT only")


def calls_per_trial(round_cost: int, cut: int) -> int:
    """Oracle calls of a run cut at ``cut`` calls whose rounds cost ``round_cost``: the run stops
    after the first round that reaches the cut, so ``round_cost * ceil(cut / round_cost)``."""
    return round_cost * math.ceil(cut / round_cost)


def round_costs(paper: dict[str, dict[str, float]], costs: range = range(1, 13),
                tolerance: float = 0.1) -> dict[str, Any]:
    """The round costs that fit the paper's call totals.

    Args:
        paper: Cut -> {"nodes" per 100 trials, "efficiency"}: the paper's q-RRT numbers.
        costs: The round costs tried (calls per round).
        tolerance: The largest gap, in calls per trial, that counts as a fit.

    Returns:
        ``{"paper_calls_per_trial": {cut: nodes / efficiency / 100}, "fitting": [costs whose
        c ceil(b / c) is within ``tolerance`` of every cut's]}``.
    """
    implied = {cut: value["nodes"] / value["efficiency"] / 100.0 for cut, value in paper.items()}
    fitting = [c for c in costs if all(abs(calls_per_trial(c, int(cut)) - calls) <= tolerance
                                       for cut, calls in implied.items())]
    return {"paper_calls_per_trial": {cut: round(calls, 3) for cut, calls in implied.items()}, "fitting": fitting,
            "calls_per_trial_by_round": {str(c): {cut: calls_per_trial(c, int(cut)) for cut in paper}
                                         for c in (3, PAPER_SCHEDULE_ROUND)},
            "paper_schedule_most_nodes": {cut: most_nodes(PAPER_SCHEDULE_ROUND, int(cut)) for cut in paper}}


def most_nodes(round_cost: int, cut: int, trials: int = 100) -> int:
    """The most nodes ``trials`` runs cut at ``cut`` calls can add with rounds of ``round_cost``
    calls: one node a round at best, ``trials * ceil(cut / round_cost)``.

    With the paper's schedule a tree stays below its switch at 10 nodes up to 40 calls (at most 7
    rounds), so every round costs 6 calls and the most is 200, 400 and 700 nodes per 100 trials
    at 10, 20 and 40 calls.
    """
    return trials * math.ceil(cut / round_cost)


def peak_fraction(iterations: int) -> float:
    """The reachable share f at which k Grover iterations succeed for certain: sin^2((2k + 1) theta)
    = 1 with f = sin^2 theta, so f = sin^2(pi / (4k + 2)) (9.5 % for k = 2)."""
    return math.sin(math.pi / (4 * iterations + 2)) ** 2


def quantiles(values: list[float]) -> list[float] | None:
    """The 5 %, 50 % and 95 % quantiles, rounded to 4 digits (None for no values)."""
    return [round(float(q), 4) for q in np.quantile(values, [0.05, 0.5, 0.95])] if values else None


def passes(intervals: dict[str, list[float]], paper: dict[str, dict[str, float]]) -> bool:
    """The acceptance rule: every paper RRT efficiency inside its cut's interval.

    Args:
        intervals: Cut -> [low, high] of the world's RRT efficiency.
        paper: Cut -> {"efficiency"}: the paper's RRT numbers.

    Returns:
        Whether the world passes.
    """
    return all(intervals[cut][0] <= paper[cut]["efficiency"] <= intervals[cut][1] for cut in paper)


class HeatmapWorlds(Experiment):
    """The paper's heatmap numbers (Figs. 10-12) in single worlds, under a pre-stated acceptance rule
    (see the module docstring), repeated over several planner root seeds.

    The worlds depend only on their obstacle count and world seed; the experiment's ``--seed``
    drives the planners alone. ``settings["planner_root_seeds"]`` lists the root seeds (``seed``,
    ``seed + 1``, ...): every world is run once under each, with planner seeds
    ``replicate_seed(root, boxes * WORLDS_PER_COUNT + world_seed, HEATMAP_WORLDS)``, so the worlds
    stay the same and only the planners' draws change. Whether a world passes is decided per root
    seed; a world passing under one root seed and not under another shows the rule selecting runs
    as well as worlds.
    """

    name = "heatmap-worlds"
    title = "Heatmap numbers in single worlds: RRT calibrated per world (paper Figs. 10-12)"
    paper = PAPER

    def settings(self, quick: bool, trials: int | None, seed: int) -> Settings:
        return {"runs": trials or (20 if quick else RUNS), "worlds": 2 if quick else 40, "cuts": list(CUTS),
                "box_counts": [150, 525] if quick else list(BOX_COUNTS), "num_qubits": 8,
                "backend": "statevector", "scenario": "paper_clutter", "variants": list(VARIANTS),
                "planner_root_seeds": [seed + i for i in range(2 if quick else PLANNER_ROOT_SEEDS)],
                "acceptance_rule": ACCEPTANCE_RULE, "seed": seed, "quick": quick}

    def trials(self, settings: Settings) -> list[Trial]:
        # one seed per world (obstacle count, world seed) and planner root seed, shared by the
        # variants; independent of the grid's other worlds (at most WORLDS_PER_COUNT world seeds a count)
        return [Trial(f"{variant}-{boxes}-{w}-r{root}",
                      {"variant": variant, "boxes": boxes, "world_seed": w, "planner_root_seed": root},
                      replicate_seed(root, boxes * WORLDS_PER_COUNT + w, TrialStream.HEATMAP_WORLDS))
                for root in settings["planner_root_seeds"]
                for boxes in settings["box_counts"] for w in range(settings["worlds"])
                for variant in settings["variants"]]

    def run_trial(self, trial: Trial, settings: Settings) -> Record:
        problem = experiment_problem(settings, world(settings["scenario"], trial.params["world_seed"],
                                                     num_boxes=trial.params["boxes"]))
        planner_name, policy = VARIANTS[trial.params["variant"]]
        options: dict[str, Any] = {} if policy is None else {"search_policy": policy}
        nodes: dict[str, list[int]] = {str(cut): [] for cut in settings["cuts"]}
        calls: dict[str, list[int]] = {str(cut): [] for cut in settings["cuts"]}
        reachable: dict[str, list[int]] = {str(cut): [] for cut in settings["cuts"]}
        entries: dict[str, list[int]] = {str(cut): [] for cut in settings["cuts"]}
        for run in range(settings["runs"]):  # the planners of one world share their seeds across variants
            planner = make_planner(planner_name, replicate_seed(trial.seed, run),
                                  settings["backend"], num_qubits=settings["num_qubits"], **options)
            result = planner.plan(problem, max_oracle_calls=max(settings["cuts"]))
            for cut in settings["cuts"]:
                placed, spent = cut_at(result, cut)
                nodes[str(cut)].append(placed)
                calls[str(cut)].append(spent)
                good, seen = reachable_at(result, cut)
                reachable[str(cut)].append(good)
                entries[str(cut)].append(seen)
        return {"nodes_json": dumps(nodes), "calls_json": dumps(calls), "reachable_json": dumps(reachable),
                "entries_json": dumps(entries)}

    def summarize(self, records: list[Record], settings: Settings) -> Summary:
        seed, cuts, variants = settings["seed"], [str(c) for c in settings["cuts"]], settings["variants"]
        roots = [str(root) for root in settings["planner_root_seeds"]]
        columns = ("nodes", "calls", "reachable", "entries")
        blocks = {(r["variant"], f"{r['boxes']}-{r['world_seed']}", str(r["planner_root_seed"])):
                  {key: loads(r[f"{key}_json"]) for key in columns} for r in records}
        keys = [f"{boxes}-{w}" for boxes in settings["box_counts"] for w in range(settings["worlds"])]

        def runs(variant: str, pairs: list[tuple[str, str]], cut: str) -> dict[str, list[int]]:
            """The runs of ``variant`` in the (world, root seed) blocks ``pairs``, read at ``cut``, pooled."""
            return {column: [value for key, root in pairs for value in blocks[(variant, key, root)][column][cut]]
                    for column in columns}

        def measure(block: dict[str, list[int]]) -> dict[str, Any]:
            """One world's (or pooled) values, with 95 % bootstrap intervals over its runs."""
            nodes, calls, spent, seen = block["nodes"], block["calls"], sum(block["calls"]), sum(block["entries"])
            return {"nodes": round(100.0 * sum(nodes) / len(nodes), 1),
                    "efficiency": round(sum(nodes) / spent, 4) if spent else None,
                    "nodes_interval_95": rounded_interval(bootstrap_ratio_interval(nodes, None, seed,
                                                                                   per_trials=100.0), 1),
                    "efficiency_interval_95": rounded_interval(bootstrap_ratio_interval(nodes, calls, seed)),
                    "reachable_fraction": round(sum(block["reachable"]) / seen, 4) if seen else None}

        # each world, under each root seed: the rule on its RRT runs; the passing blocks' own values
        per_root: dict[str, dict[str, Any]] = {}
        for root in roots:
            rrt_intervals = {key: {cut: measure(runs("RRT", [(key, root)], cut))["efficiency_interval_95"]
                                   for cut in cuts} for key in keys}
            passing = [key for key in keys if passes(rrt_intervals[key], PAPER["RRT"])]
            values = {key: {variant: {cut: measure(runs(variant, [(key, root)], cut)) for cut in cuts}
                            for variant in variants} for key in passing}
            per_root[root] = {
                "passing_worlds": passing, "pass_rate": round(len(passing) / len(keys), 4),
                "rrt_efficiency_interval_95": rrt_intervals, "passing": values,
                "paper_inside": {variant: [key for key in passing if all(
                    not differs(PAPER[variant][cut][name], values[key][variant][cut][f"{name}_interval_95"])
                    for cut in cuts for name in ("nodes", "efficiency"))]
                    for variant in variants if variant in QUANTUM},
                **_pooled(variants, cuts, {key: [(key, root)] for key in passing}, runs, seed)}
        # each world over all root seeds' runs: where the world itself, not one draw of runs, stands
        per_world: dict[str, dict[str, Any]] = {}
        for key in keys:
            boxes, w = (int(part) for part in key.split("-"))
            entry: dict[str, Any] = {"boxes": boxes, "world_seed": w}
            for variant in variants:
                entry[variant] = {cut: measure(runs(variant, [(key, root) for root in roots], cut)) for cut in cuts}
            entry["passes_under_root_seeds"] = [int(root) for root in roots if key in per_root[root]["passing_worlds"]]
            per_world[key] = entry
        # every passing (world, root seed) block, grouped by world: the unit of the interval is the world
        by_world: dict[str, list[tuple[str, str]]] = {}
        for root in roots:
            for key in per_root[root]["passing_worlds"]:
                by_world.setdefault(key, []).append((key, root))
        pooled = _pooled(variants, cuts, by_world, runs, seed)
        blocks_passing = [pair for pairs in by_world.values() for pair in pairs]
        ours = {variant: {cut: {name: pooled["ours"][variant][cut][name] for name in ("nodes", "efficiency")}
                          for cut in cuts} for variant in variants}
        interval = pooled["interval_95_over_worlds"]
        differs_from_paper = {variant: {cut: {name: differs(PAPER[variant][cut][name], interval[variant][cut][name])
                                              if interval[variant][cut] else None for name in ("nodes", "efficiency")}
                                        for cut in cuts} for variant in variants}
        reachable = {variant: {cut: _fraction(runs(variant, blocks_passing, cut)) for cut in cuts}
                     for variant in variants}
        groups = [(str(boxes), [k for k, e in per_world.items() if e["boxes"] == boxes])
                  for boxes in settings["box_counts"]] + [("all", list(per_world))]
        spread = {label: {variant: quantiles([per_world[key][variant]["10"]["efficiency"] for key in group])
                          for variant in variants} for label, group in groups}
        advantage = {label: {variant: _advantage([per_world[key]["RRT"]["10"]["efficiency"] for key in group],
                                                 [per_world[key][variant]["10"]["efficiency"] for key in group])
                             for variant in variants if variant in QUANTUM} for label, group in groups}
        highest = {variant: {cut: _highest(per_world, variant, cut) for cut in cuts}
                   for variant in variants if variant in QUANTUM}
        return {"ours": ours, "paper": {variant: PAPER[variant] for variant in variants}, "interval_95": interval,
                "interval_unit": "worlds (two-level bootstrap: worlds, then runs in each)",
                "differs_from_paper": differs_from_paper,
                "acceptance_rule": ACCEPTANCE_RULE,
                "passing_worlds_by_root_seed": {root: per_root[root]["passing_worlds"] for root in roots},
                "pass_rate_by_root_seed": {root: per_root[root]["pass_rate"] for root in roots},
                "pass_overlap": pass_overlap({root: per_root[root]["passing_worlds"] for root in roots}),
                "passing_blocks": len(blocks_passing), "passing_worlds_any_root_seed": len(by_world),
                "range_over_passing_worlds": pooled["range_over_worlds"],
                "per_root_seed": per_root,
                "worlds_run": len(per_world), "root_seeds_run": len(roots), "per_world": per_world,
                "efficiency_at_10_quantiles_over_worlds": spread,
                "advantage_at_10_over_worlds": advantage,
                "highest_nodes_over_worlds": highest,
                "reachable_fraction_in_passing_worlds": reachable,
                "peak_reachable_fraction": {"QRRT": round(peak_fraction(2), 4),
                                            "QRRT_PAPER": round(peak_fraction(PaperIterations().early), 4)},
                "round_costs": round_costs(PAPER["QRRT"]),
                "note": "The rule is applied per planner root seed (per_root_seed: each seed's passing worlds, "
                        "their own values, and the pooled values over them). ours: pooled over the runs of every "
                        "passing (world, root seed) block (nodes per 100 runs); interval_95: a two-level bootstrap "
                        "over the passing worlds, then the runs in each (a world passing under several root seeds "
                        "is one world with all those runs); range_over_passing_worlds: the lowest and highest "
                        "value of one passing block. per_world gives each world's values over all root seeds' "
                        "runs (intervals over those runs); quantiles over worlds are the 5 %, 50 % and 95 % of the "
                        "worlds' values at 10 calls (advantage: q-RRT's efficiency minus RRT's, and their ratio "
                        "over the worlds where RRT added a node). pass_overlap: of the worlds passing under one "
                        "root seed, how many pass under another. QRRT_PAPER (the paper's schedule) is a contrast: "
                        "its 6-call rounds cannot reach the paper's totals (round_costs). The paper's Fig. 12 "
                        "caption says 60 calls where its text says 40; 40 is used.",
                "labels": ["phase oracle from a classical lookup of all 2^8 entries",
                           "backend: exact statevector (ideal; same statistics as Aer)",
                           "QRRT: 2 Grover iterations a round (the round the paper's call totals imply)",
                           "QRRT_PAPER: the paper's schedule (5 iterations, 3 after 10 nodes)"]}

    def plot(self, records: list[Record], settings: Settings, summary: Summary, out_dir: Path) -> list[Path]:
        """Left and middle: one point per world, over all root seeds' runs (RRT against q-RRT with 2
        iterations, at 10 and 40 calls), coloured by how many root seeds the world passes under,
        the paper's pair as a star. Right: the quantiles over worlds of each variant's efficiency at
        10 calls, by obstacle count."""
        fig, axes = new_figure(1, 3, (17, 4.8))
        worlds = summary["per_world"]
        roots = len(settings["planner_root_seeds"])
        shades = {0: ("tab:gray", 0.35)} | {n: (("tab:orange", "tab:red", "darkred")[min(n, 3) - 1], 0.9)
                                          for n in range(1, roots + 1)}
        for ax, cut, key in ((axes[0, 0], "10", "efficiency"), (axes[0, 1], "40", "nodes")):
            for entry in worlds.values():
                color, alpha = shades[len(entry["passes_under_root_seeds"])]
                ax.scatter(entry["RRT"][cut]["efficiency"], entry["QRRT"][cut][key], s=14, color=color, alpha=alpha)
            for count, (color, alpha) in shades.items():
                ax.scatter([], [], color=color, alpha=alpha, s=14,
                           label=f"passes under {count} of {roots} root seeds")
            ax.scatter([PAPER["RRT"][cut]["efficiency"]], [PAPER["QRRT"][cut][key]], marker="*", s=160,
                       color="k", label="paper")
            ax.set_xlabel(f"RRT efficiency at {cut} calls (one world, all root seeds)")
            ax.set_ylabel(f"q-RRT (k = 2) {'efficiency' if key == 'efficiency' else 'nodes per 100 runs'} "
                          f"at {cut} calls")
            ax.set_title(f"{summary['worlds_run']} single worlds, {roots} x {settings['runs']} runs each, "
                         f"{cut} calls", fontsize=10)
            ax.legend(fontsize=7)
            ax.grid(alpha=0.3)
        ax = axes[0, 2]
        counts = settings["box_counts"]
        colors = {"RRT": "tab:gray", "QRRT": "tab:orange", "QRRT_PAPER": "tab:blue"}
        for variant in settings["variants"]:
            bands = np.array([summary["efficiency_at_10_quantiles_over_worlds"][str(b)][variant] for b in counts])
            ax.fill_between(counts, bands[:, 0], bands[:, 2], color=colors[variant], alpha=0.2)
            ax.plot(counts, bands[:, 1], marker="o", ms=4, color=colors[variant], label=f"{variant}: median, 5-95 %")
        ax.axhline(PAPER["RRT"]["10"]["efficiency"], color="tab:gray", ls="--", lw=1, label="paper RRT")
        ax.axhline(PAPER["QRRT"]["10"]["efficiency"], color="tab:orange", ls="--", lw=1, label="paper q-RRT")
        ax.set_xlabel("obstacles in the 20 x 20 world")
        ax.set_ylabel("efficiency at 10 calls, over worlds")
        ax.set_title("How the advantage varies over worlds", fontsize=10)
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3)
        return [save(fig, out_dir / "heatmap_worlds.png")]


def pass_overlap(passing: dict[str, list[str]]) -> dict[str, Any]:
    """How far the worlds passing under one planner root seed pass under another.

    Args:
        passing: Root seed -> the worlds passing under it.

    Returns:
        ``{"pairs": {"a->b": {"passing": |P_a|, "pass_again": |P_a & P_b|}}`` over ordered pairs of
        root seeds, ``"fraction_passing_again"``: the pairs' pass_again summed over their passing
        summed (None without a passing world or with one root seed), ``"in_every_root_seed"`` and
        ``"in_any_root_seed"``: the worlds passing under every root seed, and under at least one}.
    """
    pairs = {f"{a}->{b}": {"passing": len(passing[a]), "pass_again": len(set(passing[a]) & set(passing[b]))}
             for a in passing for b in passing if a != b}
    total = sum(pair["passing"] for pair in pairs.values())
    every = set.intersection(*(set(worlds) for worlds in passing.values())) if passing else set()
    ordered = [key for worlds in passing.values() for key in worlds]
    return {"pairs": pairs,
            "fraction_passing_again": round(sum(p["pass_again"] for p in pairs.values()) / total, 4) if total else None,
            "in_every_root_seed": [key for key in dict.fromkeys(ordered) if key in every],
            "in_any_root_seed": list(dict.fromkeys(ordered))}


def _pooled(variants: list[str], cuts: list[str], groups: dict[str, list[tuple[str, str]]],
            runs: Any, seed: int) -> dict[str, Any]:
    """Values pooled over the runs of several worlds, with the interval over worlds.

    Args:
        variants: The planner variants.
        cuts: The cuts, as strings.
        groups: World -> its (world, root seed) blocks; a world is one unit of the interval.
        runs: ``runs(variant, blocks, cut)`` -> the pooled columns of those blocks at that cut.
        seed: Seed of the bootstrap.

    Returns:
        ``{"ours": variant -> cut -> {"nodes" (per 100 runs), "efficiency"}} (None without
        worlds), "interval_95_over_worlds": variant -> cut -> {"nodes", "efficiency"}: [low, high]
        from ``two_level_bootstrap_interval`` (empty without worlds), "range_over_worlds": variant
        -> cut -> {"nodes", "efficiency"}: [lowest, highest] value of one block}``.
    """
    ours: dict[str, dict[str, dict[str, float | None]]] = {}
    interval: dict[str, dict[str, dict[str, list[float]]]] = {}
    spread: dict[str, dict[str, dict[str, list[float]]]] = {}
    for variant in variants:
        ours[variant], interval[variant], spread[variant] = {}, {}, {}
        for cut in cuts:
            columns = {world: runs(variant, blocks, cut) for world, blocks in groups.items()}
            pooled = runs(variant, [pair for blocks in groups.values() for pair in blocks], cut)
            if not pooled["nodes"]:
                ours[variant][cut], interval[variant][cut], spread[variant][cut] = (
                    {"nodes": None, "efficiency": None}, {}, {})
                continue
            spent = sum(pooled["calls"])
            ours[variant][cut] = {"nodes": round(100.0 * sum(pooled["nodes"]) / len(pooled["nodes"]), 1),
                                  "efficiency": round(sum(pooled["nodes"]) / spent, 4) if spent else None}
            pairs = {world: list(zip(column["nodes"], column["calls"], strict=True))
                     for world, column in columns.items()}
            interval[variant][cut] = {
                "nodes": rounded_interval(two_level_bootstrap_interval(pairs, _nodes_per_100, seed), 1),
                "efficiency": rounded_interval(two_level_bootstrap_interval(pairs, _efficiency, seed))}
            one = [runs(variant, [pair], cut) for blocks in groups.values() for pair in blocks]
            per_100 = [100.0 * sum(block["nodes"]) / len(block["nodes"]) for block in one]
            efficiency = [sum(block["nodes"]) / sum(block["calls"]) for block in one if sum(block["calls"])]
            spread[variant][cut] = {"nodes": [round(min(per_100), 1), round(max(per_100), 1)],
                                    "efficiency": [round(min(efficiency), 4), round(max(efficiency), 4)]}
    return {"ours": ours, "interval_95_over_worlds": interval, "range_over_worlds": spread}


def _nodes_per_100(runs: list[tuple[int, int]]) -> float:
    """Nodes per 100 runs of (nodes, calls) runs."""
    return 100.0 * sum(nodes for nodes, _ in runs) / len(runs)


def _efficiency(runs: list[tuple[int, int]]) -> float:
    """Nodes per oracle call of (nodes, calls) runs (ZeroDivisionError without calls)."""
    return sum(nodes for nodes, _ in runs) / sum(calls for _, calls in runs)


def _fraction(block: dict[str, list[int]]) -> float | None:
    """The reachable share of the candidates of pooled runs (None without candidates)."""
    seen = sum(block["entries"])
    return round(sum(block["reachable"]) / seen, 4) if seen else None


def _advantage(rrt: list[float | None], quantum: list[float | None]) -> dict[str, Any]:
    """q-RRT's advantage over RRT across worlds: quantiles of the difference of their efficiencies
    (every world), of their ratio (the worlds where RRT added a node), and the worlds where q-RRT's
    efficiency is below RRT's."""
    pairs = [(r or 0.0, q or 0.0) for r, q in zip(rrt, quantum, strict=True)]
    return {"difference": quantiles([q - r for r, q in pairs]),
            "ratio": quantiles([q / r for r, q in pairs if r > 0]),
            "worlds_rrt_added_none": sum(1 for r, _ in pairs if r == 0),
            "worlds_quantum_below_rrt": sum(1 for r, q in pairs if q < r)}


def _highest(per_world: dict[str, dict[str, Any]], variant: str, cut: str) -> dict[str, Any]:
    """The world where ``variant`` placed the most nodes at ``cut`` over all root seeds' runs, with
    its interval over those runs, RRT's efficiency in the same world and the root seeds under which
    it passes."""
    key = max(per_world, key=lambda k: per_world[k][variant][cut]["nodes"])
    found = per_world[key]
    return {"world": key, "nodes": found[variant][cut]["nodes"],
            "nodes_interval_95": found[variant][cut]["nodes_interval_95"],
            "rrt_efficiency": found["RRT"][cut]["efficiency"],
            "passes_under_root_seeds": found["passes_under_root_seeds"]}
