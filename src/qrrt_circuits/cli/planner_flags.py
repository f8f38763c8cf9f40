"""The planners' command-line flags, derived from their declared options (``planners.options``):
one flag per option that declares one, its help and default from the declaration, and a rule for a
flag the chosen planner does not take (refused, naming the planners that take it)."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ..planners.options import OptionSpec
    from ..registry import Registry

#: the command line's own defaults where they differ from the Python API's: a reproducible seed, and
#: a backend named so that it is built with that seed
CLI_DEFAULTS: dict[str, Any] = {"seed": 0, "backend": "aer"}


def _registries() -> dict[str, Registry]:
    """The options whose value the command line names from a registry."""
    from ..registry import BACKENDS, POLICIES

    return {"backend": BACKENDS, "search_policy": POLICIES}


def flagged_options() -> dict[str, tuple[OptionSpec, tuple[str, ...]]]:
    """Every option some registered planner declares with a flag: name -> (its spec, the planners
    that take it), in declaration order."""
    from ..registry import PLANNERS

    found: dict[str, tuple[OptionSpec, tuple[str, ...]]] = {}
    for name in PLANNERS.names():
        for spec in PLANNERS.resolve(name).specs:
            if spec.flag is not None:
                first, takers = found.get(spec.name, (spec, ()))
                found[spec.name] = (first, (*takers, name))
    return found


def _flag_type(spec: OptionSpec, registry: Registry | None) -> Callable[[str], Any]:
    """argparse type: a registered name (canonical), or the text as the option's value, checked."""
    def parse(text: str) -> Any:
        try:
            if registry is not None:
                return registry.canonical(text)
            return spec.check(spec.text(text), spec.flag or spec.name)
        except (ValueError, TypeError) as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None
    parse.__name__ = spec.name
    return parse


def add_planner_flags(parser: argparse.ArgumentParser) -> None:
    """Add one flag per flagged option: a flag every planner takes gets its default; one only some
    take is absent unless given, so that ``planner_options`` can refuse it for the others."""
    from ..registry import PLANNERS

    registries = _registries()
    everyone = set(PLANNERS.names())
    for name, (spec, takers) in flagged_options().items():
        registry = registries.get(name)
        default = CLI_DEFAULTS.get(name, spec.default)
        shown = "the planner's own" if default is None and name == "search_policy" else default
        scope = "" if set(takers) == everyone else f"{', '.join(takers)}; "
        choices = f": {registry.help_text()}" if registry is not None else ""
        parser.add_argument(str(spec.flag), dest=name, type=_flag_type(spec, registry),
                            default=default if set(takers) == everyone else argparse.SUPPRESS,
                            metavar="|".join(registry.labels()) if registry is not None else None,
                            help=f"{spec.help} ({scope}default {shown}){choices}".replace("%", "%%")
                            if scope else f"{spec.help} (default %(default)s)")


def planner_options(args: argparse.Namespace, planner: str) -> dict[str, Any]:
    """The options of ``planner`` from the flags (given, or the declared default where the planner
    takes them; backends and policies built from their names, a backend with ``--seed``).

    Raises:
        ValueError: A flag given that ``planner`` does not take, naming the planners that take it.
    """
    from ..registry import PLANNERS

    accepted = PLANNERS.resolve(planner).options()
    registries = _registries()
    given = vars(args)
    options: dict[str, Any] = {}
    for name, (spec, takers) in flagged_options().items():
        value = given.get(name, CLI_DEFAULTS.get(name, spec.default))
        if name not in accepted:
            if name in given:
                raise ValueError(f"{spec.flag} does not apply to --planner {planner} (it applies to "
                                 f"{', '.join(takers)}); leave it out")
            continue
        if name in registries and value is not None:
            value = registries[name].create(value, **({"seed": given.get("seed")} if name == "backend" else {}))
        options[name] = value
    return options
