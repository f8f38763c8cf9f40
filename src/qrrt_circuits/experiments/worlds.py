"""The experiments' worlds: scenarios by registry name, cached per process (environments are
immutable, and building ``annealing_field`` or a predicate's index is not free)."""

from __future__ import annotations

import functools

from ..environment import Environment
from ..registry import SCENARIOS


@functools.lru_cache(maxsize=16)
def _cached_world(name: str, seed: int, options: tuple) -> Environment:
    return SCENARIOS.create(name, seed=seed, **dict(options))


def world(name: str, seed: int, **options) -> Environment:
    """The scenario ``name`` (a ``qrrt_circuits.registry.SCENARIOS`` name) for this seed."""
    return _cached_world(name, int(seed) % (2**31), tuple(sorted(options.items())))
