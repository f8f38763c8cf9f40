"""Deprecated names: one warning helper and the table of what replaces what.

Every deprecated name keeps working for one minor version and warns with a ``DeprecationWarning``
that names its replacement and the version that removes it (the ``deprecate_func`` pattern of
Qiskit, written here so that a plan on the statevector backend does not import Qiskit).
"""

from __future__ import annotations

import importlib
import sys
import warnings
from pathlib import Path
from types import FrameType

_PACKAGE = str(Path(__file__).resolve().parent.parent)
#: frames skipped besides the package's: the import machinery (a deprecated module warns on import)
_SKIPPED = (_PACKAGE, "<frozen importlib", str(Path(importlib.__file__).parent))

#: the version in which the names deprecated in 0.2 are removed
REMOVED_IN = "0.3"

#: deprecated name -> its replacement (the documentation's deprecations table is built from this)
DEPRECATED: dict[str, str] = {
    "PQRRT(oracle=...), QRRT(oracle=...), RRT(oracle=...), ParallelRRT(oracle=...)": "predicate=...",
    "PQRRT(iterations=...), QRRT(iterations=...)": "search_policy=...",
    "Planner.oracle": "Planner.predicate",
    "PQRRT.iterations_policy": "PQRRT.search_policy",
    "PolicyState.iterations(...)": "PolicyState.choose_iterations(...)",
    "qrrt_circuits.SearchPolicy, qrrt_circuits.search.policies.iteration.SearchPolicy": "IterationPolicy",
    "qrrt_circuits.search.schedules": "qrrt_circuits.search.policies.iteration",
    "qrrt_circuits.planners.base.DEFAULT_MAX_ROUNDS": "qrrt_circuits.planners.termination.DEFAULT_MAX_ROUNDS",
    "ExactCheck(check='time_samples', time_samples=K)": "TimeSampledCheck(env, dynamics, time_samples=K)",
    "PlanResult.budget_exhausted": "not PlanResult.reached",
    "ReachabilityOracle (the exact predicate)": "ExactCheck",
    "PaperSchedule (the paper's iteration counts)": "PaperIterations",
}


def _bootstrap(filename: str) -> bool:
    """Whether ``warnings.warn`` skips this frame when it counts ``stacklevel``."""
    return "importlib" in filename and "_bootstrap" in filename


def warn_deprecated(old: str, new: str) -> None:
    """Warn that ``old`` is deprecated in favour of ``new``, attributed to the first caller outside
    this package and the import machinery (so the warning points at the user's line, however deep
    the call).

    Args:
        old: The deprecated name as a user writes it.
        new: What to write instead.
    """
    level = 2  # warnings.warn counts this function as 1, its caller as 2
    frame: FrameType | None = sys._getframe(1)
    while frame is not None and frame.f_code.co_filename.startswith(_SKIPPED):
        frame = frame.f_back
        if frame is not None and not _bootstrap(frame.f_code.co_filename):
            level += 1  # (warnings.warn does not count the import system's bootstrap frames)
    warnings.warn(f"{old} is deprecated since qrrt_circuits 0.2 and will be removed in {REMOVED_IN}; "
                  f"use {new} instead", DeprecationWarning, stacklevel=level)


def moved_module(old: str, new: str) -> None:
    """Make the module ``old`` (a deprecated location) the module ``new``: warn, import ``new`` and
    put it in ``sys.modules`` under ``old``, so ``import old`` and ``from old import name`` give
    ``new``'s objects themselves.

    Args:
        old: The deprecated dotted name (the shim's ``__name__``).
        new: The module's dotted name now.
    """
    warn_deprecated(f"the module {old}", new)
    sys.modules[old] = importlib.import_module(new)
