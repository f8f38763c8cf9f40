"""``qrrt reproduce`` and ``qrrt compare-checks``: run the experiments, compare checks' records."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:

    pass



def cmd_reproduce(args: argparse.Namespace) -> int:
    from ...execution import WorkerPool
    from ...experiments import EXPERIMENTS
    from ...experiments.runner import check_experiment_arguments, run_experiments

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
    from ...experiments.compare import compare_checks

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
