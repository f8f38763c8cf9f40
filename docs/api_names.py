"""Which names of a public module the API reference documents (``conf.py``; the docs-inventory
test asks the same question of this function)."""

from __future__ import annotations

import inspect
import types


def public_names(module: types.ModuleType) -> list[str]:
    """A module's public names: its ``__all__``, else the public classes and functions it defines
    and its UPPER_CASE constants that carry a ``#:`` doc comment (``registry.PLANNERS``,
    ``termination.DEFAULT_MAX_ROUNDS``; not ``TYPE_CHECKING`` or an undocumented constant)."""
    from sphinx.pycode import ModuleAnalyzer

    names = getattr(module, "__all__", None)
    if names is not None:
        return list(names)
    documented = {name for (_, name) in ModuleAnalyzer.for_module(module.__name__).find_attr_docs()}

    def public(name: str, obj: object) -> bool:
        if name.startswith("_") or isinstance(obj, types.ModuleType):
            return False
        if inspect.isclass(obj) or inspect.isfunction(obj):
            return getattr(obj, "__module__", None) == module.__name__
        return name.isupper() and name in documented

    return sorted(name for name, obj in vars(module).items() if public(name, obj))
