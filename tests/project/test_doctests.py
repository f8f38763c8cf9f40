"""The docstrings' examples run and print what they show (every module of the package that has
them; the OMPL adapter only where its extra is installed)."""

from __future__ import annotations

import doctest
import importlib
import pkgutil

import pytest

import qrrt_circuits

#: modules whose import needs an optional extra, with the module that extra provides
NEEDS_EXTRA = {"qrrt_circuits.adapters.ompl": "ompl"}


def _modules_with_examples() -> list[str]:
    names = []
    for info in pkgutil.walk_packages(qrrt_circuits.__path__, "qrrt_circuits."):
        if info.name == "qrrt_circuits._support.worker_warmup":  # importing it is the warm-up itself
            continue
        spec = importlib.util.find_spec(info.name)
        source = spec.loader.get_source(info.name) if spec and spec.loader else None  # type: ignore[attr-defined]
        if source and ">>> " in source:
            names.append(info.name)
    return sorted(names)


MODULES = _modules_with_examples()


def test_examples_are_found():
    assert len(MODULES) >= 10 and "qrrt_circuits.planners.termination" in MODULES


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    if name in NEEDS_EXTRA:
        pytest.importorskip(NEEDS_EXTRA[name])
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE, verbose=False)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples failed in {name}"
