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
    """An integer (Python or numpy, not ``bool``, not a float) within [minimum, maximum].

    Args:
        value: The value to check.
        name: The argument's name for the error message.
        minimum: Smallest accepted value (default 0), or None for no bound.
        maximum: Largest accepted value (default None: no bound).

    Returns:
        ``value`` as a Python ``int``.

    Raises:
        TypeError: Not an integer (a ``bool`` or a float included).
        ValueError: Outside [minimum, maximum].

    Example:
        >>> from qrrt_circuits._support.validation import check_int
        >>> check_int(3, "workers", 1)
        3
        >>> check_int(0, "workers", 1)
        Traceback (most recent call last):
        ...
        ValueError: workers must be an integer >= 1, got 0
    """
    if type(value) is not int:  # (a plain int, the common case, needs no abstract-class checks)
        if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Integral):
            raise TypeError(f"{name} must be an integer {_range_text(minimum, maximum)}, got {value!r}")
        value = int(value)
    if (minimum is not None and value < minimum) or (maximum is not None and value > maximum):
        raise ValueError(f"{name} must be an integer {_range_text(minimum, maximum)}, got {value!r}")
    return value


def check_optional_int(value: Any, name: str, minimum: int | None = 0, maximum: int | None = None) -> int | None:
    """None, or ``check_int(value, name, minimum, maximum)``.

    Args:
        value: The value to check.
        name: The argument's name for the error message.
        minimum: Smallest accepted value (default 0), or None.
        maximum: Largest accepted value, or None (default).

    Returns:
        None, or ``value`` as a Python ``int``.

    Raises:
        TypeError: Neither None nor an integer.
        ValueError: Outside [minimum, maximum].
    """
    return None if value is None else check_int(value, name, minimum, maximum)


def check_float(value: Any, name: str, minimum: float | None = None, maximum: float | None = None,
                open_minimum: bool = False) -> float:
    """A finite real number (not ``bool``, not complex) within the range; ``open_minimum`` excludes
    the minimum itself.

    Args:
        value: The value to check.
        name: The argument's name for the error message.
        minimum: Lower bound, or None (default).
        maximum: Upper bound, or None (default).
        open_minimum: Whether the minimum itself is refused (default False).

    Returns:
        ``value`` as a Python ``float``.

    Raises:
        TypeError: Not a real number (a ``bool`` or a complex included).
        ValueError: Not finite, or outside the range.
    """
    if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a real number, got {value!r}")
    low = "(" if open_minimum else "["
    text = (f"a finite number in {low}{minimum}, {maximum}]" if minimum is not None and maximum is not None
            else f"a finite number {'>' if open_minimum else '>='} {minimum}" if minimum is not None
            else f"a finite number <= {maximum}" if maximum is not None else "a finite number")
    try:
        value = float(value)
    except OverflowError:  # an integer too large for a float
        raise ValueError(f"{name} must be {text}, got an integer of {len(str(abs(int(value))))} digits") from None
    if not math.isfinite(value):
        raise ValueError(f"{name} must be {text}, got {value!r}")
    too_low = minimum is not None and (value <= minimum if open_minimum else value < minimum)
    if too_low or (maximum is not None and value > maximum):
        raise ValueError(f"{name} must be {text}, got {value!r}")
    return value


def check_positive_float(value: Any, name: str) -> float:
    """A finite real number > 0 (``check_float`` with an open minimum 0).

    Args:
        value: The value to check.
        name: The argument's name for the error message.

    Returns:
        ``value`` as a Python ``float``.

    Raises:
        TypeError: Not a real number.
        ValueError: Not finite, or <= 0.
    """
    return check_float(value, name, 0.0, open_minimum=True)


def check_probability(value: Any, name: str) -> float:
    """A probability: a finite real number in [0, 1].

    Args:
        value: The value to check.
        name: The argument's name for the error message.

    Returns:
        ``value`` as a Python ``float``.

    Raises:
        TypeError: Not a real number (a ``bool`` included).
        ValueError: Outside [0, 1] (NaN included).
    """
    if isinstance(value, bool | np.bool_) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a probability in [0, 1], got {value!r}")
    try:
        value = float(value)
    except OverflowError:  # an integer too large for a float
        raise ValueError(f"{name} must be a probability in [0, 1], got an integer of "
                         f"{len(str(abs(int(value))))} digits") from None
    if not (0.0 <= value <= 1.0):
        raise ValueError(f"{name} must be a probability in [0, 1], got {value!r}")
    return value


def check_seed(value: Any, name: str = "seed") -> int | None:
    """A non-negative integer or None (fresh entropy).

    Args:
        value: The seed.
        name: The argument's name for the error message (default ``"seed"``).

    Returns:
        The seed as an ``int``, or None.

    Raises:
        TypeError: Neither None nor an integer.
        ValueError: A negative integer.
    """
    return None if value is None else check_int(value, name, 0)


def check_bool(value: Any, name: str) -> bool:
    """A ``bool`` (or ``numpy.bool_``), not a number standing for one.

    Args:
        value: The value to check.
        name: The argument's name for the error message.

    Returns:
        ``value`` as a Python ``bool``.

    Raises:
        TypeError: Anything else.
    """
    if not isinstance(value, bool | np.bool_):
        raise TypeError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def check_choice(value: Any, name: str, choices: tuple[str, ...]) -> str:
    """One of ``choices``.

    Args:
        value: The value to check.
        name: The argument's name for the error message.
        choices: The accepted strings.

    Returns:
        ``value``.

    Raises:
        ValueError: Not one of them (the message lists them).
    """
    if value not in choices:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, choices))}, got {value!r}")
    return value


def check_instance(value: Any, name: str, kind: type | tuple[type, ...], what: str) -> Any:
    """An instance of ``kind``; ``what`` describes it in the message ("an Environment").

    Args:
        value: The value to check.
        name: The argument's name for the error message.
        kind: The accepted type or types.
        what: The accepted type in words.

    Returns:
        ``value``.

    Raises:
        TypeError: Not an instance of ``kind``.
    """
    if not isinstance(value, kind):
        raise TypeError(f"{name} must be {what}, got {type(value).__name__}")
    return value


def check_real_array(value: Any, name: str) -> np.ndarray:
    """``value`` as a float array, refusing what ``np.asarray(value, dtype=float)`` would coerce:
    booleans and strings (anywhere in a nested sequence, where numpy would turn ``True`` into 1.0
    and ``"2"`` into 2.0), and arrays of other dtypes than integers, floats and objects that are
    real numbers.

    Args:
        value: An array or a (nested) sequence of real numbers.
        name: The argument's name, for the error message.

    Returns:
        A new float array (shape as numpy reads it).

    Raises:
        ValueError: Booleans, strings, ragged or other non-real values.
    """
    if isinstance(value, np.ndarray) and value.dtype.kind in "iuf":
        return np.array(value, dtype=float)
    if isinstance(value, np.ndarray) and value.dtype.kind != "O":
        raise ValueError(f"{name} must hold real numbers, got an array of dtype {value.dtype}")
    try:
        objects = np.array(value, dtype=object)  # one pass in numpy; a ragged or cyclic list leaves lists
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name} must be numeric, got {_shown(value)}") from exc
    for kind in set(map(type, objects.ravel())):
        if issubclass(kind, bool | np.bool_ | str | bytes | list | tuple | dict | np.ndarray):
            bad = next(item for item in objects.ravel() if type(item) is kind)
            raise ValueError(f"{name} must hold real numbers, got {_shown(bad)}")
    try:
        return objects.astype(float)
    except (TypeError, ValueError, OverflowError) as exc:
        raise ValueError(f"{name} must be numeric, got {_shown(value)}") from exc


def _shown(value: Any) -> str:
    """``repr(value)``, cut to 80 characters."""
    shown = repr(value)
    return f"{shown[:80]}{'...' if len(shown) > 80 else ''}"
