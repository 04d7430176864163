"""Argument checks shared by the planners: a bad number is a ParameterError, never a NaN profile.

The GT layer maps :class:`~gtecat.errors.ParameterError` to return code 7
(manual table 3-1); the message names the argument and the value seen.
"""

from __future__ import annotations

import math
from numbers import Integral, Real

from ...errors import ParameterError


def real(name: str, value: object) -> float:
    """A finite real number (bool is refused: ``True`` is not an acceleration)."""
    if type(value) is float and math.isfinite(value):
        return value  # (the common case, without the abstract base class's look-up)
    if isinstance(value, bool) or not isinstance(value, Real):
        raise ParameterError(f"{name} must be a number, got {value!r}")
    x = float(value)
    if not math.isfinite(x):
        raise ParameterError(f"{name} must be finite, got {value!r}")
    return x


def positive(name: str, value: object) -> float:
    """A finite number > 0 (accelerations, decelerations, Trap speed, cycle time)."""
    x = real(name, value)
    if x <= 0.0:
        raise ParameterError(f"{name} must be > 0, got {value!r}")
    return x


def non_negative(name: str, value: object) -> float:
    """A finite number >= 0 (velStart)."""
    x = real(name, value)
    if x < 0.0:
        raise ParameterError(f"{name} must be >= 0, got {value!r}")
    return x


def integer(name: str, value: object) -> int:
    """An integer; a float is accepted only when it holds a whole number."""
    if type(value) is int:
        return value  # (the common case, without the abstract base classes' look-ups)
    if isinstance(value, bool):
        raise ParameterError(f"{name} must be an integer, got {value!r}")
    if isinstance(value, Integral):
        return int(value)
    if isinstance(value, Real) and math.isfinite(float(value)) and float(value).is_integer():
        return int(value)
    raise ParameterError(f"{name} must be an integer, got {value!r}")
