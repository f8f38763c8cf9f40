"""Argument checks shared by the whole library: one place for the integer, float, probability and
seed rules, so every error names the argument and the accepted range and nothing is coerced.

Each function returns the value as a plain Python ``int`` / ``float`` (never a numpy scalar or a
``bool`` passed for a number) or raises ``ValueError`` (a wrong value) / ``TypeError`` (a wrong
type), before any work is done.
"""

from __future__ import annotations

import math
import numbers
from typing import Any

import numpy as np


def _range_text(minimum: float | None, maximum: float | None) -> str:
    if minimum is not None and maximum is not None:
        return f"in [{minimum}, {maximum}]"
    if minimum is not None:
        return f">= {minimum}"
    if maximum is not None:
        return f"<= {maximum}"
    return "any value"


def check_int(value: Any, name: str, minimum: int | None = 0, maximum: int | None = None) -> int:
    """An integer (Python or numpy, not ``bool``, not a float) within [minimum, maximum]."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{name} must be an integer {_range_text(minimum, maximum)}, got {value!r}")
    value = int(value)
    if (minimum is not None and value < minimum) or (maximum is not None and value > maximum):
        raise ValueError(f"{name} must be an integer {_range_text(minimum, maximum)}, got {value!r}")
    return value


def check_optional_int(value: Any, name: str, minimum: int | None = 0, maximum: int | None = None) -> int | None:
    return None if value is None else check_int(value, name, minimum, maximum)


def check_float(value: Any, name: str, minimum: float | None = None, maximum: float | None = None,
                open_minimum: bool = False) -> float:
    """A finite real number (not ``bool``, not complex) within the range; ``open_minimum`` excludes
    the minimum itself."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a real number, got {value!r}")
    value = float(value)
    low = "(" if open_minimum else "["
    text = (f"a finite number in {low}{minimum}, {maximum}]" if minimum is not None and maximum is not None
            else f"a finite number {'>' if open_minimum else '>='} {minimum}" if minimum is not None
            else f"a finite number <= {maximum}" if maximum is not None else "a finite number")
    if not math.isfinite(value):
        raise ValueError(f"{name} must be {text}, got {value!r}")
    too_low = minimum is not None and (value <= minimum if open_minimum else value < minimum)
    if too_low or (maximum is not None and value > maximum):
        raise ValueError(f"{name} must be {text}, got {value!r}")
    return value


def check_positive_float(value: Any, name: str) -> float:
    return check_float(value, name, 0.0, open_minimum=True)


def check_probability(value: Any, name: str) -> float:
    """A probability: a finite real number in [0, 1]."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a probability in [0, 1], got {value!r}")
    value = float(value)
    if not (0.0 <= value <= 1.0):
        raise ValueError(f"{name} must be a probability in [0, 1], got {value!r}")
    return value


def check_seed(value: Any, name: str = "seed") -> int | None:
    """A non-negative integer or None (fresh entropy)."""
    return None if value is None else check_int(value, name, 0)


def check_bool(value: Any, name: str) -> bool:
    if not isinstance(value, bool | np.bool_):
        raise TypeError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def check_choice(value: Any, name: str, choices: tuple[str, ...]) -> str:
    if value not in choices:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, choices))}, got {value!r}")
    return value


def check_instance(value: Any, name: str, kind: type | tuple[type, ...], what: str) -> Any:
    if not isinstance(value, kind):
        raise TypeError(f"{name} must be {what}, got {type(value).__name__}")
    return value
