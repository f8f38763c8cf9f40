"""The experiments' worlds: scenarios by registry name, cached per process (problems are
immutable, and building ``annealing_field`` or a predicate's index is not free)."""

from __future__ import annotations

import functools
from typing import Any

from ..problems.problem import Problem
from ..registry import SCENARIOS


@functools.lru_cache(maxsize=16)
def _cached_world(name: str, seed: int, options: tuple[tuple[str, Any], ...]) -> Problem:
    return SCENARIOS.create(name, seed=seed, **dict(options))


def world(name: str, seed: int, **options: Any) -> Problem:
    """The scenario ``name`` (a ``qrrt_circuits.registry.SCENARIOS`` name) for this seed.

    Args:
        name: A ``SCENARIOS`` name.
        seed: The world's seed (taken modulo 2^31).
        **options: The scenario's options (hashable values; the world is cached on them).

    Returns:
        The problem (shared between calls with the same arguments in one process).

    Raises:
        ValueError: If ``name`` is not a scenario or an option is refused by it.
    """
    return _cached_world(name, int(seed) % (2**31), tuple(sorted(options.items())))
