"""The ``qrrt`` command line: ``search``, ``plan`` and ``reproduce``.

Every choice (planners, backends, search policies, scenarios, predicates) and its help text comes
from ``qrrt_circuits.registry``, so the command line and the library mean the same thing by a name.

Every failure is one line on stderr, and the exit status says what happened (``EXIT_STATUSES``):
0 done, 1 the environment failed (a file that cannot be read or written, an unreachable Dask
scheduler, out of memory, an unreadable or corrupt numba cache), 2 bad input, 130 interrupted
(Ctrl-C, SIGINT), 143 and 129 terminated (SIGTERM, SIGHUP): 128 + the signal's number.

This module imports only the standard library; the package's heavy dependencies (numpy, numba,
scipy, Qiskit) are imported inside ``main`` once its signal handlers are installed, so an
interrupt during those imports is reported like any other.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import signal
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeAlias

if TYPE_CHECKING:
    import numpy as np

    from ._support.memory import MemoryEstimate
    from .planners.base import Planner
    from .planners.result import PlanResult
    from .registry import Registry
    from .search.backends.base import QuantumSearchBackend, SearchResult
    from .world.environment import Environment
    from .world.problems import Problem


def _positive_int(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be an integer >= 1, got {text}")
    return value


def _nonnegative_int(text: str) -> int:
    value = int(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be an integer >= 0, got {text}")
    return value


def _registered(registry: Registry) -> Callable[[str], str]:
    """argparse type: a name the registry knows, canonicalised (aliases accepted)."""
    def parse(text: str) -> str:
        try:
            return registry.canonical(text)
        except (ValueError, TypeError) as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None
    parse.__name__ = registry.kind
    return parse


# ----------------------------------------------------------------------------------------- search
def cmd_search(args: argparse.Namespace) -> int:
    from . import probability
    from .registry import BACKENDS

    backend = BACKENDS.create(args.backend, seed=args.seed)
    backend.check_qubits(args.qubits)  # before 2**qubits is computed (a huge --qubits is refused, not allocated)
    num_items = 1 << args.qubits
    if args.marked > num_items:
        raise ValueError(f"--marked must be in [0, 2**qubits = {num_items}], got {args.marked}")
    iterations = (probability.optimal_iterations(num_items, args.marked)
                  if args.iterations is None else args.iterations)
    from ._support.memory import OutOfMemory, check_fits, out_of_memory
    from .search.backends.base import validate_iterations, validate_shots

    shots = validate_shots(args.shots)
    estimate = _search_estimate(backend, shots, validate_iterations(iterations), args.marked)
    what = f"this {backend.name} search ({shots} shots, {iterations} iterations, {args.marked} marked)"
    check_fits(estimate, args.qubits, what)  # the command's one memory check, before the marks exist
    try:
        marks, result = _run_search(args, backend, num_items, iterations)
    except OutOfMemory:
        raise
    except MemoryError as error:
        raise out_of_memory(error, estimate, args.qubits, what) from error
    _print_search(args, marks, iterations, result)
    return 0


def _run_search(args: argparse.Namespace, backend: QuantumSearchBackend, num_items: int,
                iterations: int) -> tuple[np.ndarray, SearchResult]:
    """The marks (``--marked`` entries drawn with ``--seed``) and their search, which the
    command's own memory check covered."""
    import numpy as np

    rng = np.random.default_rng(args.seed)
    marks = np.zeros(num_items, dtype=bool)
    marks[rng.choice(num_items, args.marked, replace=False)] = True
    return marks, backend._search_covered(marks, iterations, shots=args.shots)


#: the marks (1 byte per entry) and numpy's draw of the marked entries (a permutation, 8 bytes)
SEARCH_MARKS_BYTES_PER_ENTRY = 9


def _search_estimate(backend: QuantumSearchBackend, shots: int, iterations: int,
                     marked: int) -> Callable[[int], MemoryEstimate]:
    """``qrrt search``'s peak as a function of n: the marks and the search of ``marked`` entries."""
    from dataclasses import replace

    def estimate(n: int) -> MemoryEstimate:
        search = backend.memory_estimate(n, shots, iterations, marked)
        return replace(search, resident_bytes=SEARCH_MARKS_BYTES_PER_ENTRY << n)

    return estimate


def _print_search(args: argparse.Namespace, marks: np.ndarray, iterations: int, result: SearchResult) -> None:
    import numpy as np

    from . import probability

    num_items = marks.shape[0]
    rate = float(marks[result.indices].mean())
    theory = probability.success_probability(num_items, args.marked, iterations)
    sigma = math.sqrt(max(theory * (1 - theory), 1e-300) / args.shots)
    print(f"Grover search on {args.backend}: n = {args.qubits} qubits (N = {num_items}), "
          f"m = {args.marked} marked, k = {iterations} iterations"
          f"{' (optimal for the known m)' if args.iterations is None else ''}, "
          f"{args.shots} shots, seed {args.seed}")
    print(f"success rate      {rate:.4f}")
    print(f"sin^2((2k+1)th)   {theory:.4f}   (binomial sigma {sigma:.4f}, "
          f"deviation {(rate - theory) / sigma if sigma > 0 else 0.0:+.2f} sigma)")
    print(f"oracle calls      {result.oracle_calls}  (= k x shots)")
    values, counts = np.unique(result.indices, return_counts=True)
    order = np.argsort(-counts, kind="stable")[: args.top]
    print(f"top {len(order)} measured indices:")
    width = max(5, len(str(num_items - 1)))  # the widest index
    bits = max(args.qubits, len("bitstring"))
    print(f"  {'index':>{width}}   {'bitstring':<{bits}}  count  marked")
    for j in order:
        index = int(values[j])
        print(f"  {index:{width}d}   {index:0{args.qubits}b}{'':<{bits - args.qubits}}  "
              f"{counts[j]:5d}  {'yes' if marks[index] else 'no'}")
    print("note: the phase oracle is built from a classical lookup of the marks "
          "(a simulation shortcut); m is known here")


# ----------------------------------------------------------------------------------------- plan
PLOT_FORMATS = (".png", ".pdf", ".svg", ".jpg", ".jpeg")


def _load_environment(args: argparse.Namespace) -> Environment:
    if args.scenario_file:
        from .world.environment import Environment

        if Path(args.scenario_file).is_dir():
            raise ValueError(f"--scenario-file: {args.scenario_file!r} is a folder, not a scenario file")
        if not Path(args.scenario_file).is_file():
            raise ValueError(f"--scenario-file: no such file {args.scenario_file!r}")
        return Environment.load(args.scenario_file)
    from .registry import SCENARIOS

    return SCENARIOS.create(args.scenario, seed=args.scenario_seed)


def _load_problem(args: argparse.Namespace) -> Problem | None:
    """The ``--problem`` file's problem, or None; refused beside the options it replaces."""
    if args.problem is None:
        return None
    given = [option for option, given in (("--scenario-file", args.scenario_file is not None),
                                          ("--scenario", args.scenario != "paper_clutter"),
                                          ("--predicate", args.predicate != "exact")) if given]
    if given:
        raise ValueError(f"--problem fixes the world and the motion check: leave out {', '.join(given)}")
    if Path(args.problem).is_dir():
        raise ValueError(f"--problem: {args.problem!r} is a folder, not a problem file")
    from .world.problems import load_problem

    return load_problem(args.problem)


#: ``qrrt plan``'s options that only some planners take: option -> (the planner's keyword, the
#: default used where the planner takes it and the option is not given)
PLANNER_SPECIFIC_OPTIONS: dict[str, tuple[str, Any]] = {
    "qubits": ("num_qubits", 8),
    "workers": ("workers", 8),
    "backend": ("backend", "aer"),
    "policy": ("search_policy", None),  # None: the planner's own default
}


def _planner_specific(args: argparse.Namespace) -> dict[str, Any]:
    """The planner-specific options of ``args`` (``PLANNER_SPECIFIC_OPTIONS``), defaults filled in
    for the ones the planner takes; one that was given but that the planner does not take is
    refused (``ValueError``) instead of being ignored."""
    from .registry import PLANNERS

    accepted = PLANNERS.resolve(args.planner).options()
    given = vars(args)
    chosen: dict[str, Any] = {}
    for option, (keyword, default) in PLANNER_SPECIFIC_OPTIONS.items():
        value = given.get(option)
        if keyword in accepted:
            chosen[option] = default if value is None else value
        elif value is not None:
            takers = [name for name in PLANNERS.names() if keyword in PLANNERS.resolve(name).options()]
            raise ValueError(f"--{option} does not apply to --planner {args.planner} (it applies to "
                             f"{', '.join(takers)}); leave it out")
    return chosen


def build_planner(args: argparse.Namespace, env: Environment, name: str | None = None,
                  problem: Problem | None = None) -> Planner:
    """The planner the arguments name (or planner ``name`` with the same options, as far as it
    takes them), with only the options that apply to it; a planner-specific option given to a
    planner that does not take it (``--qubits`` with ``rrt``) is refused."""
    from .registry import BACKENDS, PLANNERS, POLICIES, PREDICATES

    specific = _planner_specific(args)
    options: dict[str, Any] = {"goal_bias": args.goal_bias, "max_extension": args.max_extension, "seed": args.seed}
    options |= problem.planner_options() if problem is not None else {
        "predicate": PREDICATES.create(args.predicate, env=env)}
    made: dict[str, Callable[[Any], Any]] = {"backend": lambda name: BACKENDS.create(name, seed=args.seed),
                                             "policy": lambda name: None if name is None else POLICIES.create(name)}
    for option, value in specific.items():  # each under the planner's keyword, backends and policies made
        options[PLANNER_SPECIFIC_OPTIONS[option][0]] = made[option](value) if option in made else value
    chosen = name or args.planner
    planner: Planner = PLANNERS.create(chosen, env=env, **PLANNERS.applicable(chosen, options))
    return planner


#: the classical planner each quantum planner is compared with: the same round structure without
#: quantum search (one worker for q-RRT, p workers on one tree snapshot for Pq-RRT)
CLASSICAL_PEERS = {"qrrt": "rrt", "pqrrt": "prrt", "pqrrt-unshared": "prrt"}
#: the share of verified measurements above which the output says the iterations over-rotate
OVER_ROTATION_SHARE = 0.5


def _print_comparison(result: PlanResult, peer: PlanResult) -> None:
    """The quantum plan beside its classical peer's, in the same world and with the same seed,
    predicate and limits; the critical path named; a note where most measurements failed."""
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
    metrics = result.metrics
    if metrics.verification_calls and metrics.rejected / metrics.verification_calls > OVER_ROTATION_SHARE:
        entries = int(result.history["entries"].sum())
        share = int(result.history["reachable"].sum()) / entries if entries else 0.0
        print(f"note: {metrics.rejected / metrics.verification_calls:.0%} of the measured candidates failed "
              f"verification. {share:.0%} of the databases' entries were reachable on average; a fixed "
              "iteration count tuned for a small share over-rotates past the peak of sin^2((2k+1)theta) "
              "as the share grows, and BBHT's random counts miss often by design. --policy thompson or adaptive "
              "learn the iteration count from verified outcomes.")


def _per_node(value: float, result: PlanResult) -> str:
    return f"{value / result.metrics.nodes:.2f}" if result.metrics.nodes else "-"


def _print_plan(result: PlanResult, env: Environment, seed: int) -> None:
    metrics = result.metrics
    print(f"{result.planner} on {env.name} (seed {seed}): {result.status}: {result.status_text}")
    for key, value in result.settings.items():
        if key in ("start", "goal", "termination", "oracle_errors", "dynamics"):
            continue
        if isinstance(value, dict):  # the predicate: its settings without the dynamics matrices
            value = ", ".join(f"{k}={v}" for k, v in value.items() if k != "dynamics")
        print(f"  {key:24s} {value}")
    print("metrics:")
    for key, value in metrics.as_dict().items():
        shown = f"{value:.3f}" if isinstance(value, float) else str(value)
        print(f"  {key:28s} {shown:>12s}")
    if metrics.nodes:
        print(f"  {'oracle_calls per node':28s} {metrics.oracle_calls / metrics.nodes:12.2f}")
        print(f"  {'wall ms per node':28s} {metrics.wall_time_s * 1e3 / metrics.nodes:12.2f}")
    if result.path is not None:
        print(f"path: {len(result.path)} nodes")
    for label in result.labels:
        print(f"note: {label}")


def _write_plan_outputs(args: argparse.Namespace, result: PlanResult, env: Environment) -> None:
    """Write ``--json`` and ``--plot``; if a write fails (a full disk), the other is still written
    and one ``OSError`` names every failed output and says the plan finished."""
    from ._support.output_files import write_replacing

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

        from .plotting import plot_tree

        fig, ax = plt.subplots(figsize=(7, 7))
        try:
            plot_tree(env, result, ax=ax)
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
    from ._support.output_files import check_output_file, same_file
    from .registry import PLANNERS

    check_output_file(args.json, "--json")
    check_output_file(args.plot, "--plot", PLOT_FORMATS)
    if args.json and args.plot and same_file(args.json, args.plot):
        raise ValueError(f"--json and --plot name the same file {args.plot!r} (the plot would overwrite the JSON)")
    problem = _load_problem(args)
    env = _load_environment(args) if problem is None else problem.env
    planner = build_planner(args, env, problem=problem)
    # (the plan makes its one memory check before it allocates anything, and words a MemoryError as
    # one OutOfMemory line; --json adds no memory per node: PlanResult.write_json streams the arrays
    # chunk by chunk; the outputs are written only once the plan has finished)
    limits = {"max_nodes": args.max_nodes, "max_oracle_calls": args.max_oracle_calls, "max_rounds": args.max_rounds,
              "max_critical_path_calls": args.max_critical_path_calls, "stall_rounds": args.stall_rounds}
    goal = None if problem is None else problem.goal
    result = planner.plan(goal=goal, **limits)
    _print_plan(result, env, args.seed)
    peer = CLASSICAL_PEERS.get(PLANNERS.canonical(args.planner))
    if peer is not None and not args.no_compare:
        _print_comparison(result, build_planner(args, env, peer, problem).plan(goal=goal, **limits))
    _write_plan_outputs(args, result, env)
    return 0


# ----------------------------------------------------------------------------------------- reproduce
def cmd_reproduce(args: argparse.Namespace) -> int:
    from .execution import WorkerPool
    from .experiments import EXPERIMENTS
    from .experiments.runner import check_experiment_arguments, run_experiments

    if str(args.out).strip() == "":
        raise ValueError("--out must name a folder, got ''")
    if Path(args.out).exists() and not Path(args.out).is_dir():
        raise ValueError(f"--out: {args.out!r} exists and is not a folder")
    if args.experiment != "all" and args.experiment not in EXPERIMENTS:
        raise ValueError(f"EXPERIMENT must be one of {sorted(EXPERIMENTS)} or 'all', got {args.experiment!r}")
    if args.jobs is not None and args.executor == "serial":
        raise ValueError("--jobs needs --executor process or dask (the serial executor runs every trial here)")
    names = sorted(EXPERIMENTS) if args.experiment == "all" else [args.experiment]
    if args.predicate != "exact":  # 'all' with another check: the experiments that plan with one
        names = [name for name in names if EXPERIMENTS[name].uses_predicate or args.experiment != "all"]
    for name in names:  # bad arguments and folders are refused before any experiment runs
        check_experiment_arguments(name, trials=args.trials, seed=args.seed, executor=args.executor,
                                   jobs=args.jobs, scheduler=args.scheduler, predicate=args.predicate,
                                   out=args.out, quick=args.quick)
    # one pool or Dask cluster for every experiment, started when the first trial needs it; with
    # workers, an experiment's summary and figures are made while the next one's trials run
    with WorkerPool(args.executor, args.jobs, args.scheduler) as pool:
        run_experiments(names, pool, lambda name, summary: _print_summary(name, summary, args.out),
                        out=args.out, quick=args.quick, trials=args.trials, seed=args.seed,
                        progress=not args.no_progress, predicate=args.predicate)
    return 0


def cmd_compare_checks(args: argparse.Namespace) -> int:
    from .experiments.compare import compare_checks

    print(f"wrote {compare_checks(args.folders, args.figure)}")
    return 0


def _print_summary(name: str, summary: dict, out: str) -> None:
    print(f"== {name}: {summary.get('title', '')}")
    print(f"   ours : {summary['ours']}")
    print(f"   paper: {summary['paper']}")
    for key in ("ordering_reproduced", "ratio_qda_over_uniform", "speedup_over_paper_per_node"):
        if key in summary:
            print(f"   {key}: {summary[key]}")
    print(f"   wrote {Path(out).resolve() / name}/ (records.csv, summary.json, "
          f"{', '.join(summary['figures'])})")


# ----------------------------------------------------------------------------------------- parser
_Subparsers: TypeAlias = "argparse._SubParsersAction[argparse.ArgumentParser]"
_Formatter: TypeAlias = "type[argparse.HelpFormatter]"


def _add_search_parser(sub: _Subparsers, formatter: _Formatter) -> None:
    from .registry import BACKENDS

    search = sub.add_parser("search", help="Grover-search a random marked database", formatter_class=formatter)
    search.add_argument("--qubits", type=_positive_int, default=8, help="n: the database has 2^n entries")
    search.add_argument("--marked", type=_nonnegative_int, default=12,
                        help="m: marked entries, drawn at random (0 .. 2^n)")
    search.add_argument("--shots", type=_positive_int, default=2000, help="measurements")
    # (a help text with %(default)s keeps argparse from appending "(default: None)" after it)
    search.add_argument("--iterations", type=_nonnegative_int, default=None,
                        help="Grover iterations k (default %(default)s: the optimal k for the known m, about "
                             "(pi/4) sqrt(2^n / m), so gate-level searches of large n with few marks take long)")
    search.add_argument("--backend", type=_registered(BACKENDS), choices=BACKENDS.names(), default="aer",
                        help=BACKENDS.help_text())
    search.add_argument("--seed", type=_nonnegative_int, default=0, help="seed of the marks and the search")
    search.add_argument("--top", type=_positive_int, default=10, help="most frequent indices to list")
    search.set_defaults(func=cmd_search)


def _add_plan_parser(sub: _Subparsers, formatter: _Formatter) -> None:
    from .registry import BACKENDS, PLANNERS, POLICIES, PREDICATES, SCENARIOS

    plan = sub.add_parser("plan", help="plan a path with one planner and print its metrics",
                          formatter_class=formatter)
    plan.add_argument("--scenario", type=_registered(SCENARIOS), choices=SCENARIOS.names(),
                      default="paper_clutter", help=SCENARIOS.help_text())
    plan.add_argument("--scenario-file", default=None, help="an environment JSON file instead")
    plan.add_argument("--problem", default=None,
                      help="a problem JSON file instead (qrrt-problem: open-space, narrow-passage, se2-gap, boxes "
                           "or image); it fixes the world, the motion check, the state space and the goal")
    plan.add_argument("--scenario-seed", type=_nonnegative_int, default=0,
                      help="seed of the scenario's random world")
    plan.add_argument("--planner", type=_registered(PLANNERS), choices=PLANNERS.names(), default="pqrrt",
                      help=PLANNERS.help_text())
    # the planner-specific options are absent unless given (their defaults are PLANNER_SPECIFIC_OPTIONS'),
    # so that one given to a planner that does not take it is refused instead of ignored
    plan.add_argument("--backend", type=_registered(BACKENDS), choices=BACKENDS.names(), default=argparse.SUPPRESS,
                      help=f"(quantum planners; default aer) {BACKENDS.help_text()}")
    plan.add_argument("--qubits", type=_positive_int, default=argparse.SUPPRESS,
                      help="database of 2^qubits (quantum planners; default 8)")
    plan.add_argument("--workers", type=_positive_int, default=argparse.SUPPRESS,
                      help="workers (prrt, pqrrt, pqrrt-unshared; default 8)")
    plan.add_argument("--policy", type=_registered(POLICIES), default=argparse.SUPPRESS,
                      metavar="|".join(POLICIES.labels()),
                      help=f"search policy (quantum planners, default the planner's: thompson for qrrt, adaptive for "
                           f"pqrrt; paper: the paper's schedule): {POLICIES.help_text()}")
    plan.add_argument("--predicate", type=_registered(PREDICATES), default="exact",
                      metavar="|".join(PREDICATES.labels()), help=f"reachability check: {PREDICATES.help_text()}")
    plan.add_argument("--goal-bias", type=float, default=0.0, help="probability of sampling the goal, in [0, 1)")
    plan.add_argument("--max-extension", type=float, default=None,
                      help="longest step from a parent (OMPL's RRT range), > 0 (default: none, the raw samples)")
    plan.add_argument("--seed", type=_nonnegative_int, default=0, help="the plan's seed")
    # (a help text with %(default)s keeps argparse from appending "(default: None)" after it)
    plan.add_argument("--max-nodes", type=_positive_int, default=None,
                      help="node limit (default %(default)s: the limit of 1000000 nodes always in force)")
    plan.add_argument("--max-oracle-calls", type=_positive_int, default=None,
                      help="oracle-call budget (DESIGN section 2 counting)")
    plan.add_argument("--max-critical-path-calls", type=_positive_int, default=None,
                      help="stop on the critical path (the time of p parallel devices)")
    plan.add_argument("--max-rounds", type=_positive_int, default=None,
                      help="round limit (default %(default)s: the limit of 20000 rounds always in force)")
    plan.add_argument("--stall-rounds", type=_positive_int, default=None,
                      help="stop after this many consecutive rounds without a new node (default "
                           "%(default)s: the limit of 5000 always in force)")
    plan.add_argument("--plot", default=None,
                      help=f"write a figure of the tree ({', '.join(PLOT_FORMATS)}; default %(default)s: none)")
    plan.add_argument("--json", default=None, help="write the result as JSON (default %(default)s: none)")
    plan.add_argument("--no-compare", action="store_true",
                      help="do not plan with the quantum planner's classical peer (RRT for q-RRT, parallel RRT "
                           "for Pq-RRT) in the same world to print the two side by side")
    plan.set_defaults(func=cmd_plan)


def _add_reproduce_parser(sub: _Subparsers, formatter: _Formatter) -> None:
    from .registry import PREDICATES

    reproduce = sub.add_parser("reproduce", help="reproduce the paper's figures and tables",
                               formatter_class=formatter)
    reproduce.add_argument("experiment", help="an experiment name or 'all'")
    reproduce.add_argument("--quick", action="store_true", help="small settings (each < 2 min)")
    reproduce.add_argument("--trials", type=_positive_int, default=None, help="override the trial count")
    reproduce.add_argument("--out", default="results", help="output directory (default results/)")
    reproduce.add_argument("--seed", type=_nonnegative_int, default=0)
    reproduce.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    reproduce.add_argument("--executor", choices=["serial", "process", "dask"], default="serial",
                           help="where trials run (dask needs the [dask] extra)")
    reproduce.add_argument("--jobs", type=_positive_int, default=None, help="worker processes (default: cores)")
    reproduce.add_argument("--scheduler", default=None,
                           help="address of an existing Dask scheduler (with --executor dask)")
    reproduce.add_argument("--predicate", type=_registered(PREDICATES), default="exact",
                           metavar="|".join(PREDICATES.labels()),
                           help=f"the planners' reachability check: {PREDICATES.help_text()}")
    reproduce.set_defaults(func=cmd_reproduce)


def _add_compare_checks_parser(sub: _Subparsers, formatter: _Formatter) -> None:
    compare = sub.add_parser("compare-checks", formatter_class=formatter,
                             help="draw the paper's numbers beside runs of `reproduce` with different checks")
    compare.add_argument("folders", nargs="+", metavar="FOLDER",
                         help="--out folders of `qrrt reproduce`, one per check (docs/results docs/results/authors)")
    compare.add_argument("--figure", default=None,
                         help="the figure's path (default %(default)s: checks_vs_paper.png in the last FOLDER)")
    compare.set_defaults(func=cmd_compare_checks)


def build_parser() -> argparse.ArgumentParser:
    from . import __version__

    parser = argparse.ArgumentParser(prog="qrrt", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    formatter = argparse.ArgumentDefaultsHelpFormatter
    _add_search_parser(sub, formatter)
    _add_plan_parser(sub, formatter)
    _add_reproduce_parser(sub, formatter)
    _add_compare_checks_parser(sub, formatter)
    return parser


#: ``qrrt``'s exit statuses (every one but 0 comes with one line on stderr)
EXIT_STATUSES = {
    0: "done",
    1: "the environment failed: a file that cannot be read or written, an unreachable Dask scheduler, "
       "out of memory, or numba's compiled-function cache unreadable or corrupt",
    2: "bad input (the line names the argument and what it accepts)",
    128 + signal.SIGINT: "interrupted (Ctrl-C, SIGINT)",
    128 + signal.SIGTERM: "terminated (SIGTERM)",
    **({128 + signal.SIGHUP: "terminated (SIGHUP: the terminal closed)"} if hasattr(signal, "SIGHUP") else {}),
}

#: the signals that stop a command the way Ctrl-C does, besides SIGINT
STOP_SIGNALS = tuple(getattr(signal, name) for name in ("SIGTERM", "SIGHUP") if hasattr(signal, name))


class Terminated(KeyboardInterrupt):
    """Raised in the main thread by a signal of ``STOP_SIGNALS`` while ``main`` runs.

    A ``KeyboardInterrupt``, so that it travels the way Ctrl-C's does: ``except Exception`` does not
    catch it, and every ``with`` block and ``finally`` clause on the way out runs (worker pools and
    Dask clusters are shut down, the progress bar is closed). ``signum`` is the signal's number.
    """

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


class _Received:
    """The first stop signal received while ``main`` runs (its number), or None; while
    ``deferring`` is set, a signal is only recorded, and ``deferred`` raises it at the block's end."""

    signum: int | None = None
    deferring: bool = False

    @contextlib.contextmanager
    def deferred(self) -> Iterator[None]:
        """Hold stop signals back while the block runs (an interrupt inside a C extension's import
        is printed and turned into an ``ImportError`` by numba), then raise the one received."""
        self.deferring = True
        try:
            yield
        finally:
            self.deferring = False
        stop = self.stop()
        if stop is not None:
            raise stop

    def stop(self) -> KeyboardInterrupt | None:
        """The interrupt that signal stands for, or None."""
        if self.signum is None:
            return None
        return KeyboardInterrupt() if self.signum == signal.SIGINT else Terminated(self.signum)


@contextlib.contextmanager
def _stop_signals() -> Iterator[_Received]:
    """While the block runs, each signal of ``STOP_SIGNALS`` whose disposition is the default raises
    ``Terminated`` (once: a repeat while the command shuts down is ignored, so the shut-down
    finishes); a signal that is ignored (``nohup``) or has a handler of the caller's keeps it.
    Ctrl-C keeps Python's ``KeyboardInterrupt``, recorded too. The block gets the record
    (``_Received``): a library that turns an interrupt into an error of its own (numba's C import
    does) cannot hide that the command was stopped. The previous dispositions are restored on exit.
    Outside the main thread (where Python cannot set handlers) nothing changes."""
    received = _Received()

    def stop(signum: int, frame: object) -> None:
        if received.signum is None:
            received.signum = signum
            if not received.deferring:
                raise Terminated(signum)

    def interrupt(signum: int, frame: object) -> None:
        if received.signum is None:
            received.signum = signum
        if not received.deferring:
            raise KeyboardInterrupt

    saved: dict[int, Any] = {}
    try:
        for signum in STOP_SIGNALS:
            if signal.getsignal(signum) == signal.SIG_DFL:
                signal.signal(signum, stop)
                saved[signum] = signal.SIG_DFL
        if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            signal.signal(signal.SIGINT, interrupt)
            saved[signal.SIGINT] = signal.default_int_handler
    except ValueError:  # not the main thread
        pass
    try:
        yield received
    finally:
        for signum, previous in saved.items():
            signal.signal(signum, previous)


def _chain(exc: BaseException) -> Iterator[BaseException]:
    """``exc`` and its causes and contexts, each once."""
    seen: set[int] = set()
    current: BaseException | None = exc
    while current is not None and id(current) not in seen:
        seen.add(id(current))
        yield current
        current = current.__cause__ or current.__context__


def _interrupt_in(exc: BaseException) -> KeyboardInterrupt | None:
    """The ``KeyboardInterrupt`` (or ``Terminated``) in ``exc``'s chain of causes and contexts, if any:
    numba wraps one raised while a compiled function runs in ``SystemError: ... returned a result
    with an exception set``, and an error raised while an interrupt was being handled is its
    consequence."""
    return next((error for error in _chain(exc) if isinstance(error, KeyboardInterrupt)), None)


def _command_in(words: list[str]) -> str | None:
    """The command named in ``words`` (the first word that is not an option), if it is one."""
    first = next((word for word in words if not word.startswith("-")), None)
    return first if first in ("search", "plan", "reproduce") else None


def _what_is_kept(command: str | None, args: argparse.Namespace | None) -> str:
    """What an interrupted command leaves behind, and what to do about it."""
    if command != "reproduce":
        return "nothing was written"
    if args is None:  # stopped before the arguments were read
        where = "records.csv under the --out folder"
    elif args.experiment == "all":
        where = f"each experiment's records.csv under {args.out}"
    else:
        where = str(Path(args.out) / args.experiment / "records.csv")
    return f"finished trials are kept in {where}; run the same command again to resume"


def _stopped(stop: KeyboardInterrupt, command: str | None, args: argparse.Namespace | None) -> int:
    """Report a command stopped by a signal in one line; the exit status 128 + the signal's number
    (130 for Ctrl-C, 143 for SIGTERM, 129 for SIGHUP).

    CPython (3.11 to 3.13 at least) marks a ``KeyboardInterrupt`` that escaped code run by ``exec``
    of a string (``dataclasses`` and ``collections.namedtuple`` build their methods that way, so an
    interrupt during the imports is often one), and a process started with ``python -m`` then dies
    by SIGINT at exit instead of exiting with the status returned here, although the interrupt was
    handled. An ``exec`` of a string that runs to its end clears the mark, hence the empty one."""
    exec("")  # (see the docstring)
    signum = stop.signum if isinstance(stop, Terminated) else signal.SIGINT
    how = "interrupted" if signum == signal.SIGINT else f"terminated ({signal.Signals(signum).name})"
    print(f"qrrt{f' {command}' if command else ''}: {how}; {_what_is_kept(command, args)}", file=sys.stderr)
    return 128 + signum


#: numba's module that reads and writes its on-disk cache of compiled functions
_NUMBA_CACHING = os.path.join("numba", "core", "caching.py")


def _numba_cache_failure(exc: BaseException) -> tuple[BaseException, str | None] | None:
    """The error in ``exc``'s chain that numba raised while loading a compiled function from its
    on-disk cache (an index ``*.nbi`` or data ``*.nbc`` file it could not read or unpickle), with the
    folder of the file it was reading where the traceback shows it; None for any other error. An
    error raised in a worker process is recognised by the text of its traceback (which
    ``concurrent.futures`` attaches as its cause)."""
    for error in _chain(exc):
        loading, folder = False, None
        tb = error.__traceback__
        while tb is not None:
            code, names = tb.tb_frame.f_code, tb.tb_frame.f_locals
            if code.co_filename.endswith(_NUMBA_CACHING) and "load" in code.co_name:
                loading = True
                read = getattr(names.get("f"), "name", None) or names.get("path")  # the file being read
                folder = os.path.dirname(read) if isinstance(read, str) else folder
            tb = tb.tb_next
        if loading:
            return error, folder
        remote = error.__cause__
        text = str(remote) if type(remote).__name__ == "_RemoteTraceback" else ""
        if _NUMBA_CACHING in text and any(f"in {name}\n" in text for name in
                                          ("load_overload", "_load_overload", "_load_index", "_load_data")):
            return error, None
    return None


def _numba_cache_text(error: BaseException, folder: str | None) -> str:
    """One line for a failed load from numba's cache: where the cache is, and what to do."""
    import numba

    reason = f"{type(error).__name__}: {' '.join(str(error).split())}".rstrip(": ")
    cache_dir = getattr(numba.config, "CACHE_DIR", "")  # NUMBA_CACHE_DIR: every cached function is under it
    if cache_dir:
        return (f"numba's compiled-function cache in {cache_dir} is unreadable or corrupt "
                f"({reason}); delete that folder (or unset NUMBA_CACHE_DIR) and run again")
    where = (folder if folder is not None else
             f"the __pycache__ folders under {Path(__file__).resolve().parent}")
    return (f"numba's compiled-function cache in {where} is unreadable or corrupt ({reason}); delete its "
            f"*.nbi and *.nbc files (or set NUMBA_CACHE_DIR to an empty folder) and run again")


def main(argv: list[str] | None = None) -> int:
    """Run ``qrrt`` with ``argv`` (default: ``sys.argv[1:]``) and return its exit status.

    A failure prints one line on stderr and exits with its status (``EXIT_STATUSES``): bad input 2,
    an environment error 1, through ``SystemExit``. While it runs, SIGTERM and SIGHUP stop the
    command as Ctrl-C does (``Terminated``), from the first moment: the handlers are installed
    before anything else is imported. A stopped command reports what was kept in one line and
    returns 128 + the signal's number; the previous signal handlers are restored on return.
    """
    words = sys.argv[1:] if argv is None else list(argv)
    args: argparse.Namespace | None = None
    with _stop_signals() as received:
        try:
            with received.deferred():  # the parser's registries import numpy, numba and scipy
                parser = build_parser()
            args = parser.parse_args(argv)
            status: int = args.func(args)
            return status
        except KeyboardInterrupt as stop:
            return _stopped(stop, args.command if args is not None else _command_in(words), args)
        except Exception as exc:
            command = args.command if args is not None else _command_in(words)
            stop_in_chain = _interrupt_in(exc) or received.stop()  # (an error a signal caused)
            if stop_in_chain is not None:
                return _stopped(stop_in_chain, command, args)
            _exit(command, exc)
            raise


def _exit(command: str | None, exc: Exception) -> None:
    """Exit with ``exc`` as one line on stderr and its status, if it is a failure ``qrrt`` reports
    (``EXIT_STATUSES``); return for any other (a bug, which keeps its traceback)."""
    prefix = f"qrrt{f' {command}' if command else ''}: error:"
    cache = _numba_cache_failure(exc)
    if cache is not None:
        status, text = 1, _numba_cache_text(*cache)
    elif isinstance(exc, ValueError | TypeError):
        status, text = 2, str(exc)
    elif isinstance(exc, OSError):  # unreadable files, an unreachable Dask scheduler, a full disk
        status, text = 1, f"{type(exc).__name__}: {exc}"
    elif isinstance(exc, MemoryError):  # a plan's or a search's is a one-line memory.OutOfMemory naming the size
        status, text = 1, _memory_error_text(exc)
    else:
        return
    print(f"{prefix} {text}", file=sys.stderr)
    raise SystemExit(status)


def _memory_error_text(exc: MemoryError) -> str:
    """One line for a ``MemoryError``: an ``OutOfMemory``'s own message (the size that did not fit
    and the largest smaller one whose estimate fits), else what the allocator reported."""
    from ._support.memory import OutOfMemory

    text = " ".join(str(exc).split())
    return text if isinstance(exc, OutOfMemory) and text else f"out of memory ({text or 'MemoryError'})"


if __name__ == "__main__":
    sys.exit(main())
