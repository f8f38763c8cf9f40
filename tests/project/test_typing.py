"""The public API is fully annotated (issue 13, item 3).

Walks every public callable reachable from ``qrrt_circuits.__all__`` (functions, classes' public
methods, properties and ``__init__``; the public submodules named there, and the modules the API
reference documents beyond it) and requires an annotation on every parameter but ``self`` /
``cls`` and on the return. ``mypy`` (``disallow_untyped_defs`` in pyproject.toml) checks the whole
package statically; this test checks what users actually import, at runtime, so a public function
added without annotations fails here even where mypy is not run.
"""

from __future__ import annotations

import importlib
import inspect
import types
from collections.abc import Callable, Iterator
from typing import Any

import pytest

import qrrt_circuits

#: public modules documented beyond ``qrrt_circuits.__all__`` (``EXTRA_MODULES`` in docs/conf.py)
#: and the experiments' entry points
EXTRA_MODULES = ("qrrt_circuits.plotting", "qrrt_circuits.execution", "qrrt_circuits.experiments")


def _ours(obj: object) -> bool:
    return getattr(obj, "__module__", "").startswith("qrrt_circuits")


def _module_names(module: types.ModuleType) -> list[str]:
    """A module's public names: its ``__all__``, else what it defines without a leading underscore."""
    names = getattr(module, "__all__", None)
    if names is not None:
        return list(names)
    return sorted(name for name, obj in vars(module).items()
                  if not name.startswith("_") and not isinstance(obj, types.ModuleType) and _ours(obj))


def _public_objects() -> Iterator[tuple[str, object]]:
    """(qualified name, object) of every public name of the API, modules expanded once."""
    modules = [importlib.import_module(name) for name in EXTRA_MODULES]
    for name in qrrt_circuits.__all__:
        obj = getattr(qrrt_circuits, name)
        if isinstance(obj, types.ModuleType):
            modules.append(obj)
        else:
            yield f"qrrt_circuits.{name}", obj
    for module in modules:
        for name in _module_names(module):
            yield f"{module.__name__}.{name}", getattr(module, name)


def _class_callables(cls: type) -> Iterator[tuple[str, Callable[..., Any], bool]]:
    """(name, function, takes self/cls) of a class's public methods, properties and ``__init__``,
    from every class of its MRO that this package defines."""
    seen: set[str] = set()
    for klass in cls.__mro__:
        if not _ours(klass):
            continue
        for name, member in vars(klass).items():
            if name in seen or (name.startswith("_") and name != "__init__"):
                continue
            seen.add(name)
            if isinstance(member, staticmethod):
                yield name, member.__func__, False
            elif isinstance(member, classmethod):
                yield name, member.__func__, True
            elif isinstance(member, property):
                if member.fget is not None:
                    yield name, member.fget, True
            elif inspect.isfunction(member) and _ours(member):
                yield name, member, True


def missing_annotations(func: Callable[..., Any], bound: bool = False) -> list[str]:
    """What of ``func``'s signature lacks an annotation: parameter names and ``"return"``.

    Args:
        func: A function (a numba dispatcher is read through its ``py_func``).
        bound: Whether its first parameter is ``self`` / ``cls`` (exempt).

    Returns:
        The unannotated parameters (``*args`` / ``**kwargs`` included) and ``"return"`` if the
        return is unannotated; empty when the signature is fully annotated.
    """
    func = getattr(func, "py_func", func)
    signature = inspect.signature(func)
    parameters = list(signature.parameters.values())
    if bound and parameters:
        parameters = parameters[1:]
    missing = [p.name for p in parameters if p.annotation is inspect.Parameter.empty]
    if signature.return_annotation is inspect.Signature.empty:
        missing.append("return")
    return missing


def _unannotated() -> dict[str, list[str]]:
    problems: dict[str, list[str]] = {}
    checked: set[int] = set()
    for qualified, obj in _public_objects():
        if id(obj) in checked:
            continue
        checked.add(id(obj))
        if inspect.isclass(obj):
            if not _ours(obj):
                continue
            for name, func, bound in _class_callables(obj):
                if missing := missing_annotations(func, bound):
                    problems[f"{qualified}.{name}"] = missing
        elif callable(obj) and _ours(obj) and (inspect.isfunction(obj) or hasattr(obj, "py_func")):
            if missing := missing_annotations(obj):
                problems[qualified] = missing
    return problems


def test_public_api_is_fully_annotated() -> None:
    problems = _unannotated()
    assert not problems, "unannotated public API (parameter names, 'return'):\n" + "\n".join(
        f"  {name}: {', '.join(missing)}" for name, missing in sorted(problems.items()))


def test_the_walk_reaches_the_api() -> None:
    """The walk sees the planners' ``plan``, the backends' ``search``, the probability functions
    and the experiments' runner (so an empty walk cannot pass the test above)."""
    names = {qualified for qualified, _ in _public_objects()}
    assert {"qrrt_circuits.QRRT", "qrrt_circuits.AerBackend", "qrrt_circuits.probability.success_probability",
            "qrrt_circuits.experiments.run_experiment", "qrrt_circuits.plotting.plot_tree"} <= names
    methods = {name for name, _, _ in _class_callables(qrrt_circuits.PQRRT)}
    assert {"plan", "__init__", "settings"} <= methods


def _unannotated_example(x, y: int = 0, *args, **kwargs):  # deliberately unannotated
    return x


class _Example:
    def method(self, value: int):  # return not annotated
        return value


@pytest.mark.parametrize(("func", "bound", "expected"), [
    (_unannotated_example, False, ["x", "args", "kwargs", "return"]),
    (_Example.method, True, ["return"]),
    (missing_annotations, False, []),
])
def test_missing_annotations_finds_what_lacks_one(func: Callable[..., Any], bound: bool,
                                                  expected: list[str]) -> None:
    assert missing_annotations(func, bound) == expected
