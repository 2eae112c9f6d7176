"""Argument checks shared by the scene, the catenary and the statics.

Each returns the value as a float or raises :class:`~cdpr_exu.errors.SceneError`
naming the parameter and the offending value. Booleans are refused: ``True`` is no
length.
"""

from __future__ import annotations

import math
from typing import Any

from .errors import SceneError


def finite(name: str, value: Any) -> float:
    """``value`` as a finite float."""
    if isinstance(value, bool):
        raise SceneError(f"{name} must be a real number, got {value!r}")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise SceneError(f"{name} must be a real number, got {value!r}") from None
    if not math.isfinite(number):
        raise SceneError(f"{name} must be finite, got {value!r}")
    return number


def positive(name: str, value: Any) -> float:
    """``value`` as a finite float > 0."""
    number = finite(name, value)
    if number <= 0.0:
        raise SceneError(f"{name} must be positive, got {value!r}")
    return number


def non_negative(name: str, value: Any) -> float:
    """``value`` as a finite float >= 0."""
    number = finite(name, value)
    if number < 0.0:
        raise SceneError(f"{name} must be zero or positive, got {value!r}")
    return number
