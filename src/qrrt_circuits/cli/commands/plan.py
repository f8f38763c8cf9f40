"""``qrrt plan``: plan on a scenario, a scenario file or a problem file; print, plot, write JSON."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np

    from ...planners.base import Planner
    from ...planners.result import PlanResult
    from ...problems.problem import Problem



PLOT_FORMATS = (".png", ".pdf", ".svg", ".jpg", ".jpeg")


def _load_problem(args: argparse.Namespace) -> Problem:
    """The problem the arguments name: a ``--problem`` file (refused beside the options it
    replaces), a ``--scenario-file``, or a ``--scenario``; with the ``--predicate`` check."""
    if args.problem is not None:
        given = [option for option, given in (("--scenario-file", args.scenario_file is not None),
                                              ("--scenario", args.scenario != "paper_clutter"),
                                              ("--predicate", args.predicate != "exact")) if given]
        if given:
            raise ValueError(f"--problem fixes the world and the motion check: leave out {', '.join(given)}")
        if Path(args.problem).is_dir():
            raise ValueError(f"--problem: {args.problem!r} is a folder, not a problem file")
        from ...problems.families import load_problem

        return load_problem(args.problem, allow_outside=args.allow_outside_files)
    if args.allow_outside_files:
        raise ValueError("--allow-outside-files applies to a --problem file: give one, or leave it out")
    from ...registry import PREDICATES

    if args.scenario_file:
        from ...problems.families import box_world

        if Path(args.scenario_file).is_dir():
            raise ValueError(f"--scenario-file: {args.scenario_file!r} is a folder, not a scenario file")
        if not Path(args.scenario_file).is_file():
            raise ValueError(f"--scenario-file: no such file {args.scenario_file!r}")
        problem: Problem = box_world(args.scenario_file)
    else:
        from ...registry import SCENARIOS

        problem = SCENARIOS.create(args.scenario, seed=args.scenario_seed)
    return problem.replace(predicate=PREDICATES.create(args.predicate, env=problem.env))


def build_planner(args: argparse.Namespace, name: str | None = None) -> Planner:
    """The planner the arguments name (or planner ``name`` with the same flags, as far as it
    takes them): its options from the flags (``planner_flags``); a flag given to a planner that
    does not take it (``--qubits`` with ``rrt``) is refused, naming the planners that take it."""
    from ...registry import PLANNERS
    from ..planner_flags import planner_options

    chosen = name or args.planner
    options = planner_options(args, args.planner)
    if name is not None:  # a peer takes the flags it shares with the chosen planner
        options = {key: value for key, value in options.items() if key in PLANNERS.resolve(chosen).options()}
    planner: Planner = PLANNERS.create(chosen, **options)
    return planner


#: the classical planner each quantum planner is compared with: the same round structure without
#: quantum search (one worker for q-RRT, p workers on one tree snapshot for Pq-RRT)
CLASSICAL_PEERS = {"qrrt": "rrt", "pqrrt": "prrt", "pqrrt-unshared": "prrt"}
#: the share of verified measurements above which the output says why measurements failed
OVER_ROTATION_SHARE = 0.5
#: settings the default view leaves out (``--json`` writes every one): the headline's, the
#: arrays, and the internals of the goal region and the motion check
HIDDEN_SETTINGS = frozenset({"planner", "start", "goal", "termination", "oracle_errors", "dynamics", "centre",
                             "false_rejection_bound"})
#: seed of the bootstrap behind the verdict's intervals
VERDICT_SEED = 0


def _print_comparison(result: PlanResult, peer: PlanResult) -> None:
    """The quantum plan beside its classical peer's, in the same world and with the same seed,
    predicate and limits; the critical path named."""
    rows: list[tuple[str, Callable[[PlanResult], str]]] = [
        ("status", lambda r: f"{r.status}{' (safety limit)' if r.safety_limit else ''}"),
        ("nodes", lambda r: str(r.metrics.nodes)),
        ("oracle calls", lambda r: str(r.metrics.oracle_calls)),
        ("oracle calls per node", lambda r: _per_node(r.metrics.oracle_calls, r)),
        ("critical-path calls", lambda r: str(r.metrics.critical_path_oracle_calls)),
        ("critical-path calls per node", lambda r: _per_node(r.metrics.critical_path_oracle_calls, r)),
        ("wall ms per node", lambda r: _per_node(r.metrics.wall_time_s * 1e3, r)),
    ]
    print(f"beside {peer.planner} (the same world, seed, predicate and limits; `--no-compare` skips it):")
    print(f"  {'':30s} {result.planner:>14s} {peer.planner:>14s}")
    for label, value in rows:
        print(f"  {label:30s} {value(result):>14s} {value(peer):>14s}")
    print("  (critical-path calls: per round, the most calls any one worker made: the time of parallel devices)")


def _print_notes(result: PlanResult, planner: Planner) -> None:
    """What the quantum plan's counts mean where they mislead: most calls classical verifications,
    or most measurements failed (with the reason of the policy that ran)."""
    metrics = result.metrics
    quantum, verifications = metrics.quantum_oracle_calls, metrics.verification_calls
    if verifications > quantum:
        print(f"note: most oracle calls were classical verifications ({verifications} of {metrics.oracle_calls}; "
              f"{quantum} quantum): the searches ran {quantum / verifications:.2f} Grover iterations per "
              "measurement on average, and a measurement after 0 iterations is a uniform draw from the database, "
              "checked classically as RRT checks its samples: the fewer the iterations, the closer this plan's calls "
              "are to classical sampling's.")
    if verifications and metrics.rejected / verifications > OVER_ROTATION_SHARE:
        entries = int(result.history["entries"].sum())
        share = int(result.history["reachable"].sum()) / entries if entries else 0.0
        print(f"note: {metrics.rejected / verifications:.0%} of the measured candidates failed verification "
              f"({share:.0%} of the databases' entries were reachable on average): {planner.miss_reason()}.")


def _per_round(history: np.ndarray) -> list[int]:
    """A cumulative per-round count as the count of each round."""
    import numpy as np

    return [int(count) for count in np.diff(history, prepend=0)]


def _calls_per_node(result: PlanResult) -> tuple[float, tuple[float, float]]:
    """Oracle calls per node and its 95 % bootstrap interval over the plan's rounds."""
    from ...experiments.intervals import bootstrap_ratio_interval

    calls = _per_round(result.history["oracle_calls"])
    nodes = _per_round(result.history["nodes"])
    low, high = bootstrap_ratio_interval(calls, nodes, VERDICT_SEED)
    return result.metrics.oracle_calls / result.metrics.nodes, (low, high)


def _verdict(result: PlanResult, peer: PlanResult) -> str:
    """One line: which plan needed fewer oracle calls per node (DESIGN §2), and whether the
    difference is larger than its spread (the two 95 % bootstrap intervals over rounds apart)."""
    if not (result.metrics.nodes and peer.metrics.nodes):
        return "verdict: none: a plan added no node, so neither has calls per node"
    (value, (low, high)), (other, (other_low, other_high)) = _calls_per_node(result), _calls_per_node(peer)
    fewer, more = (result.planner, peer.planner) if value < other else (peer.planner, result.planner)
    apart = high < other_low or other_high < low
    spread = ("larger than its spread (the intervals are apart)" if apart
              else "within its spread (the intervals overlap)")
    return (f"verdict: {fewer} needed fewer oracle calls per node than {more}: {result.planner} "
            f"{value:.2f} [{low:.2f}, {high:.2f}], {peer.planner} {other:.2f} [{other_low:.2f}, {other_high:.2f}] "
            "(95 % bootstrap intervals over each plan's rounds); the difference is "
            f"{spread}; one plan each, in this world and at this tree size.")


def _per_node(value: float, result: PlanResult) -> str:
    return f"{value / result.metrics.nodes:.2f}" if result.metrics.nodes else "-"


def _shown_setting(value: object) -> str | None:
    """A setting as the default view shows it, None for one it leaves out (None, or internal)."""
    if isinstance(value, dict):  # the predicate's and the goal region's settings
        parts = [f"{key}={part}" for key, part in value.items() if key not in HIDDEN_SETTINGS and part is not None]
        return ", ".join(parts) or None
    return None if value is None else str(value)


def _print_plan(result: PlanResult, problem: Problem, seed: int, compile_s: float) -> None:
    metrics = result.metrics
    print(f"{result.planner} on {problem.name} (seed {seed}): {result.status}: {result.status_text}")
    print("settings (--json writes every setting):")
    for key, value in result.settings.items():
        shown = None if key in HIDDEN_SETTINGS else _shown_setting(value)
        if shown is not None:
            print(f"  {key:24s} {shown}")
    print("metrics:")
    for key, value in metrics.as_dict().items():
        shown = f"{value:.3f}" if isinstance(value, float) else str(value)
        compiled = (f"  (numba compiled for {compile_s:.1f} s during this plan: a first run only)"
                    if key == "wall_time_s" and compile_s >= COMPILE_SHOWN_S else "")
        print(f"  {key:28s} {shown:>12s}{compiled}")
    if metrics.nodes:
        print(f"  {'oracle_calls per node':28s} {metrics.oracle_calls / metrics.nodes:12.2f}")
        print(f"  {'wall ms per node':28s} {metrics.wall_time_s * 1e3 / metrics.nodes:12.2f}")
    if result.path is not None:
        print(f"path: {len(result.path)} nodes")
    for label in result.labels:
        print(f"note: {label}")


#: compile seconds below which the output does not mention compiling (a cached kernel loads in less)
COMPILE_SHOWN_S = 0.05


def _write_plan_outputs(args: argparse.Namespace, result: PlanResult, problem: Problem) -> None:
    """Write ``--json`` and ``--plot``; if a write fails (a full disk), the other is still written
    and one ``OSError`` names every failed output and says the plan finished."""
    from ..._support.output_files import write_replacing

    failures = []
    if args.json:
        try:  # streamed chunk by chunk (PlanResult.write_json), not built as one string
            write_replacing(Path(args.json), result.write_json)
            print(f"wrote {args.json}")
        except (OSError, MemoryError) as exc:
            failures.append(f"--json: writing {args.json!r} failed ({_write_failure(exc)})")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        from ...plotting import plot_tree

        fig, ax = plt.subplots(figsize=(7, 7))
        try:
            plot_tree(problem.env, result, ax=ax)
            suffix = Path(args.plot).suffix.lower().lstrip(".")
            write_replacing(Path(args.plot), lambda handle: fig.savefig(handle, format=suffix, dpi=130,
                                                                         bbox_inches="tight"), binary=True)
            print(f"wrote {args.plot}")
        except (OSError, MemoryError) as exc:
            failures.append(f"--plot: writing {args.plot!r} failed ({_write_failure(exc)})")
        finally:
            plt.close(fig)
    if failures:
        raise OSError(f"{'; '.join(failures)}; the plan finished (its metrics are printed above) but "
                      f"{'these outputs were' if len(failures) > 1 else 'this output was'} not (completely) written")


def _write_failure(exc: OSError | MemoryError) -> str:
    """Why an output was not written, in a few words (a file replaced whole is left as it was)."""
    if isinstance(exc, MemoryError):
        return f"out of memory: {' '.join(str(exc).split()) or 'MemoryError'}"
    return str(exc.strerror or exc)


def cmd_plan(args: argparse.Namespace) -> int:
    from ..._support.output_files import check_output_file, same_file
    from ...registry import PLANNERS
    from ..progress import CompileClock, PlanDisplay, shown

    check_output_file(args.json, "--json")
    check_output_file(args.plot, "--plot", PLOT_FORMATS)
    if args.json and args.plot and same_file(args.json, args.plot):
        raise ValueError(f"--json and --plot name the same file {args.plot!r} (the plot would overwrite the JSON)")
    clock = CompileClock()
    display = PlanDisplay(clock, enabled=shown() and not args.no_progress)
    # (the plan makes its one memory check before it allocates anything, and words a MemoryError as
    # one OutOfMemory line; --json adds no memory per node: PlanResult.write_json streams the arrays
    # chunk by chunk; the outputs are written only once the plan has finished)
    limits = {"max_nodes": args.max_nodes, "max_oracle_calls": args.max_oracle_calls, "max_rounds": args.max_rounds,
              "max_critical_path_calls": args.max_critical_path_calls, "stall_rounds": args.stall_rounds}
    peer: PlanResult | None = None
    try:
        with clock.running():
            display.stage("building the world", counted=False)
            problem = _load_problem(args)
            planner = build_planner(args)
            display.stage(planner.name, total=args.max_nodes)
            before = clock.seconds
            result = planner.plan(problem, **limits, on_round=display.on_round)
            compiled = clock.seconds - before
            display.close()
            _print_plan(result, problem, args.seed, compiled)
            peer_name = CLASSICAL_PEERS.get(PLANNERS.canonical(args.planner))
            if peer_name is not None and not args.no_compare:
                peer_planner = build_planner(args, peer_name)
                display.stage(peer_planner.name, total=args.max_nodes)
                peer = peer_planner.plan(problem, **limits, on_round=display.on_round)
                display.close()
    finally:
        display.close()
    if peer is not None:
        _print_comparison(result, peer)
        _print_notes(result, planner)
    if clock.seconds >= COMPILE_SHOWN_S:
        print(f"note: numba compiled the package's kernels for {clock.seconds:.1f} s of this run ({compiled:.1f} s "
              f"during the {result.planner} plan, in its wall time): a first run only; later runs load them from "
              "numba's cache.")
    _write_plan_outputs(args, result, problem)
    if peer is not None:
        print(_verdict(result, peer))
    return 0
