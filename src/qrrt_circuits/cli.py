"""The ``qrrt`` command line."""

from __future__ import annotations

import argparse
import math
import sys

import numpy as np

from . import probability
from .search import AerBackend, StatevectorBackend

BACKENDS = {"aer": AerBackend, "statevector": StatevectorBackend}


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


def make_backend(name: str, seed: int | None):
    if name not in BACKENDS:
        raise ValueError(f"--backend must be one of {sorted(BACKENDS)}, got {name!r}")
    return BACKENDS[name](seed=seed)


def cmd_search(args: argparse.Namespace) -> int:
    num_items = 1 << args.qubits
    if args.marked > num_items:
        raise ValueError(f"--marked must be in [0, 2**qubits = {num_items}], got {args.marked}")
    backend = make_backend(args.backend, args.seed)
    backend.check_qubits(args.qubits)
    rng = np.random.default_rng(args.seed)
    marks = np.zeros(num_items, dtype=bool)
    marks[rng.choice(num_items, args.marked, replace=False)] = True
    iterations = (probability.optimal_iterations(num_items, args.marked)
                  if args.iterations is None else args.iterations)
    result = backend.search(marks, iterations, shots=args.shots)
    hits = marks[result.indices]
    rate = float(hits.mean())
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
    print("  index   bitstring        count  marked")
    for j in order:
        index = int(values[j])
        print(f"  {index:5d}   {index:0{args.qubits}b}{'':>{max(16 - args.qubits, 1)}} "
              f"{counts[j]:5d}  {'yes' if marks[index] else 'no'}")
    print("note: the phase oracle is built from a classical lookup of the marks "
          "(a simulation shortcut); m is known here")
    return 0


PLANNERS = ("rrt", "prrt", "qrrt", "pqrrt", "pqrrt-unshared")


def make_planner(args: argparse.Namespace, env):
    from . import planners
    from .search.schedules import parse_policy

    common = {"goal_bias": args.goal_bias, "seed": args.seed}
    if args.planner == "rrt":
        return planners.RRT(env, **common)
    if args.planner == "prrt":
        return planners.ParallelRRT(env, workers=args.workers, **common)
    backend = make_backend(args.backend, args.seed)
    policy = parse_policy(args.schedule)
    if args.planner == "qrrt":
        return planners.QRRT(env, backend=backend, num_qubits=args.qubits, iterations=policy, **common)
    return planners.PQRRT(env, backend=backend, num_qubits=args.qubits, workers=args.workers,
                          shared_database=args.planner == "pqrrt", iterations=policy, **common)


def _check_output_file(path: str | None, option: str) -> None:
    from pathlib import Path

    if path is not None and not Path(path).resolve().parent.is_dir():
        raise ValueError(f"{option}: the folder of {path!r} does not exist")


def cmd_plan(args: argparse.Namespace) -> int:
    import json
    from pathlib import Path

    from . import scenarios

    _check_output_file(args.json, "--json")
    _check_output_file(args.plot, "--plot")
    if args.scenario_file and not Path(args.scenario_file).is_file():
        raise ValueError(f"--scenario-file: no such file {args.scenario_file!r}")
    if args.scenario_file:
        from .environment import Environment

        env = Environment.load(args.scenario_file)
    else:
        env = scenarios.by_name(args.scenario, seed=args.scenario_seed)
    planner = make_planner(args, env)
    result = planner.plan(max_nodes=args.max_nodes, max_oracle_calls=args.max_oracle_calls,
                          max_rounds=args.max_rounds)
    metrics = result.metrics
    print(f"{result.planner} on {env.name} (seed {args.seed}): {result.status}")
    for key, value in result.settings.items():
        if key in ("start", "goal", "budgets", "oracle_errors"):
            continue
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
    if args.json:
        Path(args.json).write_text(json.dumps(result.to_dict(), indent=1))
        print(f"wrote {args.json}")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        from .plotting import plot_tree

        fig, ax = plt.subplots(figsize=(7, 7))
        plot_tree(env, result, ax=ax)
        fig.savefig(args.plot, dpi=130, bbox_inches="tight")
        plt.close(fig)
        print(f"wrote {args.plot}")
    return 0


def cmd_reproduce(args: argparse.Namespace) -> int:
    from pathlib import Path

    from .experiments import EXPERIMENTS, run_experiment

    if Path(args.out).exists() and not Path(args.out).is_dir():
        raise ValueError(f"--out: {args.out!r} exists and is not a folder")

    names = sorted(EXPERIMENTS) if args.experiment == "all" else [args.experiment]
    if args.experiment != "all" and args.experiment not in EXPERIMENTS:
        raise ValueError(f"EXPERIMENT must be one of {sorted(EXPERIMENTS)} or 'all', got {args.experiment!r}")
    for name in names:
        summary = run_experiment(name, out=args.out, quick=args.quick, trials=args.trials, seed=args.seed,
                                 progress=not args.no_progress, executor=args.executor, jobs=args.jobs,
                                 scheduler=args.scheduler)
        print(f"== {name}: {summary.get('title', '')}")
        print(f"   ours : {summary['ours']}")
        print(f"   paper: {summary['paper']}")
        for key in ("ordering_reproduced", "ratio_qda_over_uniform", "speedup_over_paper_per_node"):
            if key in summary:
                print(f"   {key}: {summary[key]}")
        print(f"   wrote {args.out}/{name}/ (records.csv, summary.json, {', '.join(summary['figures'])})")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="qrrt", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    formatter = argparse.ArgumentDefaultsHelpFormatter
    search = sub.add_parser("search", help="Grover-search a random marked database", formatter_class=formatter)
    search.add_argument("--qubits", type=_positive_int, default=8)
    search.add_argument("--marked", type=_nonnegative_int, default=12)
    search.add_argument("--shots", type=_positive_int, default=2000)
    search.add_argument("--iterations", type=_nonnegative_int, default=None,
                        help="Grover iterations (default: optimal for the known m)")
    search.add_argument("--backend", choices=sorted(BACKENDS), default="aer")
    search.add_argument("--seed", type=_nonnegative_int, default=0)
    search.add_argument("--top", type=_positive_int, default=10)
    search.set_defaults(func=cmd_search)

    plan = sub.add_parser("plan", help="plan a path with one planner and print its metrics",
                          formatter_class=formatter)
    plan.add_argument("--scenario", default="paper_clutter",
                      choices=["paper_clutter", "narrow_corridor", "annealing_field", "lattice"])
    plan.add_argument("--scenario-file", default=None, help="an environment JSON file instead")
    plan.add_argument("--scenario-seed", type=_nonnegative_int, default=0)
    plan.add_argument("--planner", choices=PLANNERS, default="pqrrt")
    plan.add_argument("--backend", choices=sorted(BACKENDS), default="aer")
    plan.add_argument("--qubits", type=_positive_int, default=8, help="database of 2^qubits (quantum planners)")
    plan.add_argument("--workers", type=_positive_int, default=8, help="workers (prrt, pqrrt, pqrrt-unshared)")
    plan.add_argument("--schedule", default="paper",
                      help="paper | optimal | bbht | adaptive | fixed:K (default paper)")
    plan.add_argument("--goal-bias", type=float, default=0.0)
    plan.add_argument("--seed", type=_nonnegative_int, default=0)
    plan.add_argument("--max-nodes", type=_positive_int, default=None)
    plan.add_argument("--max-oracle-calls", type=_positive_int, default=None)
    plan.add_argument("--max-rounds", type=_positive_int, default=None)
    plan.add_argument("--plot", default=None, help="write a PNG of the tree")
    plan.add_argument("--json", default=None, help="write the result as JSON")
    plan.set_defaults(func=cmd_plan)

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
    reproduce.set_defaults(func=cmd_reproduce)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except ValueError as exc:
        parser.exit(2, f"qrrt {args.command}: error: {exc}\n")
    except OSError as exc:  # unreadable files, an unreachable Dask scheduler, a full disk
        parser.exit(1, f"qrrt {args.command}: error: {type(exc).__name__}: {exc}\n")


if __name__ == "__main__":
    sys.exit(main())
