"""The experiments' worlds: scenarios by registry name, cached per process (environments are
immutable, and building ``annealing_field`` or a predicate's index is not free)."""

from __future__ import annotations

import functools
from typing import Any

from ..registry import SCENARIOS
from ..world.environment import Environment


@functools.lru_cache(maxsize=16)
def _cached_world(name: str, seed: int, options: tuple[tuple[str, Any], ...]) -> Environment:
    return SCENARIOS.create(name, seed=seed, **dict(options))


def world(name: str, seed: int, **options: Any) -> Environment:
    """The scenario ``name`` (a ``qrrt_circuits.registry.SCENARIOS`` name) for this seed.

    Args:
        name: A ``SCENARIOS`` name.
        seed: The world's seed (taken modulo 2^31).
        **options: The scenario's options (hashable values; the world is cached on them).

    Returns:
        The environment (shared between calls with the same arguments in one process).

    Raises:
        ValueError: If ``name`` is not a scenario or an option is refused by it.
    """
    return _cached_world(name, int(seed) % (2**31), tuple(sorted(options.items())))
