"""``build_parser``: the ``qrrt`` argument parser; every choice and its help text come from
``qrrt_circuits.registry``."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import TYPE_CHECKING, TypeAlias

if TYPE_CHECKING:

    from ..registry import Registry

from .commands.plan import PLOT_FORMATS, cmd_plan
from .commands.reproduce import cmd_compare_checks, cmd_reproduce
from .commands.search import cmd_search

#: the first line of ``qrrt --help``
DESCRIPTION = ("Motion planning with quantum search: Grover-search a database (search), plan a path (plan), "
               "reproduce the paper's figures (reproduce), compare collision checks (compare-checks).")


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """Help with each default said once: an option's help that names its default already (or an
    option whose default is None or a flag's False) gets no "(default: ...)" appended; the
    description and epilog keep their own lines (the list of experiments)."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = action.help or ""
        if "default" in text or action.default in (None, False, argparse.SUPPRESS) or not action.option_strings:
            return text
        return f"{text} (default: %(default)s)"

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




_Subparsers: TypeAlias = "argparse._SubParsersAction[argparse.ArgumentParser]"
_Formatter: TypeAlias = "type[argparse.HelpFormatter]"


def _add_search_parser(sub: _Subparsers, formatter: _Formatter) -> None:
    from ..registry import BACKENDS

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
    from ..problems.families import FAMILIES
    from ..registry import PLANNERS, PREDICATES, SCENARIOS
    from .planner_flags import add_planner_flags

    plan = sub.add_parser("plan", help="plan a path with one planner and print its metrics",
                          formatter_class=formatter)
    plan.add_argument("--scenario", type=_registered(SCENARIOS), choices=SCENARIOS.names(),
                      default="paper_clutter", help=SCENARIOS.help_text())
    plan.add_argument("--scenario-file", default=None, help="an environment JSON file instead")
    plan.add_argument("--problem", default=None,
                      help=f"a problem JSON file instead (qrrt-problem: {', '.join([*FAMILIES, 'boxes'])}); it fixes "
                           "the world, the motion check, the state space and the goal")
    plan.add_argument("--allow-outside-files", action="store_true",
                      help="let a --problem file name a scenario or image outside its own folder (an absolute "
                           "path or ..); by default such names are refused")
    plan.add_argument("--scenario-seed", type=_nonnegative_int, default=0,
                      help="seed of the scenario's random world")
    plan.add_argument("--planner", type=_registered(PLANNERS), choices=PLANNERS.names(), default="pqrrt",
                      help=PLANNERS.help_text())
    plan.add_argument("--predicate", type=_registered(PREDICATES), default="exact",
                      metavar="|".join(PREDICATES.labels()), help=f"reachability check: {PREDICATES.help_text()}")
    # the planners' options, one flag each, from their declarations; a flag only some planners take is
    # absent unless given, so that one given to a planner that does not take it is refused
    add_planner_flags(plan)
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
    plan.add_argument("--no-progress", action="store_true",
                      help="hide the progress bar (shown only when stdout and stderr are terminals)")
    plan.set_defaults(func=cmd_plan)


def _add_reproduce_parser(sub: _Subparsers, formatter: _Formatter) -> None:
    from ..experiments import EXPERIMENTS
    from ..registry import PREDICATES

    width = max(len(name) for name in EXPERIMENTS)
    listing = "\n".join(f"  {name:{width}s}  {experiment.title}" for name, experiment in EXPERIMENTS.items())
    reproduce = sub.add_parser("reproduce", help="reproduce the paper's figures and tables",
                               formatter_class=formatter, epilog=f"experiments:\n{listing}")
    reproduce.add_argument("experiment", metavar="EXPERIMENT",
                           help="an experiment's name (listed below) or 'all'")
    reproduce.add_argument("--quick", action="store_true", help="small settings (each < 2 min)")
    reproduce.add_argument("--trials", type=_positive_int, default=None,
                           help="the trial count (default: the experiment's own)")
    reproduce.add_argument("--out", default="results", help="output directory")
    reproduce.add_argument("--seed", type=_nonnegative_int, default=0,
                           help="root seed: every trial's seed is derived from it and the trial's key")
    reproduce.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    reproduce.add_argument("--executor", choices=["serial", "process", "dask"], default="serial",
                           help="where trials run (dask needs the [dask] extra)")
    reproduce.add_argument("--jobs", type=_positive_int, default=None,
                           help="worker processes (default: one per core, os.cpu_count())")
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
    from .. import __version__

    parser = argparse.ArgumentParser(prog="qrrt", description=DESCRIPTION)
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    formatter = HelpFormatter
    _add_search_parser(sub, formatter)
    _add_plan_parser(sub, formatter)
    _add_reproduce_parser(sub, formatter)
    _add_compare_checks_parser(sub, formatter)
    return parser
