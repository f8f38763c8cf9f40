"""The progress display of ``qrrt plan``: one tqdm bar per stage on stderr (the world being built,
then each plan's nodes, rounds and oracle calls), and the seconds numba spent compiling.

The bar is shown only when stdout and stderr are both terminals (a pipe or a file gets the printed
results alone). The planners print nothing: a plan shows its progress through the ``on_round``
observer ``Planner.plan`` takes, which this display passes.

numba compiles the package's kernels on their first call and caches them on disk; a first run
spends seconds there that later runs do not. ``CompileClock`` measures them from numba's own
``numba:compile`` events (a load from the cache fires none), and the bar says while it happens.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ..planners.termination import Progress


def shown() -> bool:
    """Whether a progress display belongs on this terminal: stdout and stderr both terminals."""
    return sys.stdout.isatty() and sys.stderr.isatty()


class CompileClock:
    """The seconds numba spent compiling while ``running`` was active (outermost compilations only:
    a kernel compiled inside another's compilation is not counted twice), and a hook for the
    display to say that it is compiling."""

    def __init__(self) -> None:
        self.seconds = 0.0
        self.on_change: Any = None  # called with True when a compilation starts, False when it ends
        self._depth = 0
        self._began = 0.0

    @contextmanager
    def running(self) -> Iterator[CompileClock]:
        """Listen to numba's compile events while the block runs."""
        from numba.core import event

        clock = self

        class _Listener(event.Listener):
            def on_start(self, ev: Any) -> None:
                clock._start()

            def on_end(self, ev: Any) -> None:
                clock._end()

        with event.install_listener("numba:compile", _Listener()):
            yield self

    def _start(self) -> None:
        if self._depth == 0:
            self._began = time.perf_counter()
            if self.on_change is not None:
                self.on_change(True)
        self._depth += 1

    def _end(self) -> None:
        self._depth -= 1
        if self._depth == 0:
            self.seconds += time.perf_counter() - self._began
            if self.on_change is not None:
                self.on_change(False)


class PlanDisplay:
    """The bars of one ``qrrt plan`` (none when ``enabled`` is False): ``stage`` opens one, and
    ``on_round`` (given to ``Planner.plan``) moves a plan's bar to its node count, with its rounds
    and oracle calls beside it."""

    def __init__(self, clock: CompileClock, enabled: bool) -> None:
        self.enabled = enabled
        self.clock = clock
        self.bar: Any = None
        self.label = ""
        clock.on_change = self._compiling

    def stage(self, label: str, total: int | None = None, counted: bool = True) -> None:
        """Close the open bar and open one for ``label``: counting nodes up to ``total``, or
        (``counted`` False) a status with its elapsed time alone."""
        self.close()
        if not self.enabled:
            return
        from tqdm.auto import tqdm

        self.label = label
        self.bar = tqdm(total=total, desc=label, unit=" nodes", file=sys.stderr, leave=False, dynamic_ncols=True,
                        bar_format=None if counted else "{desc} [{elapsed}]")

    def on_round(self, progress: Progress) -> None:
        """A plan's counters after a round: the bar's count is its nodes."""
        if self.bar is None:
            return
        self.bar.set_postfix_str(f"rounds={progress.rounds}, oracle calls={progress.oracle_calls}", refresh=False)
        self.bar.update(progress.nodes - self.bar.n)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None

    def _compiling(self, started: bool) -> None:
        if self.bar is not None:
            self.bar.set_description_str(f"{self.label} (numba compiling its kernels: first run only)"
                                         if started else self.label)
