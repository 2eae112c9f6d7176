"""Argument checks shared by the scene, the catenary and the statics.

Each returns the checked value or raises :class:`~cdpr_exu.core.errors.SceneError` naming the
parameter and the value. Text (``"1.0"``) and booleans are refused, not converted, wherever a
number is expected (:func:`is_number`), in scalars and arrays alike.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
from typing import Any, Mapping

import numpy as np

from cdpr_exu.core.errors import SceneError


def plain(value: Any) -> Any:
    """``value`` with NumPy scalars as Python numbers and arrays as lists, recursively (tuples kept)."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, tuple):
        return tuple(plain(v) for v in value)
    if isinstance(value, list):
        return [plain(v) for v in value]
    if isinstance(value, dict):
        return {k: plain(v) for k, v in value.items()}
    return value


def shown(value: Any) -> str:
    """``value`` as a message shows it: the repr of :func:`plain` (``-2.0``, never ``np.float64(-2.0)``)."""
    return repr(plain(value))


def is_number(value: Any) -> bool:
    """True for an int, a float, a NumPy integer or float scalar or one-element array; False for text,
    booleans, None and everything else."""
    if isinstance(value, (bool, np.bool_)):
        return False
    if isinstance(value, numbers.Real):
        return True
    return isinstance(value, np.ndarray) and value.size == 1 and value.dtype.kind in "iuf"


def _refuse_non_numbers(value: Any, message: str) -> None:
    """Raise SceneError(``message``) if ``value`` (a number, nested list or array) holds anything else."""
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "iuf":
            return
        if value.dtype.kind != "O":
            raise SceneError(message)
        value = value.tolist()
    if isinstance(value, (list, tuple)):
        for item in value:
            _refuse_non_numbers(item, message)
    elif not is_number(value):
        raise SceneError(message)


def _unit(unit: str) -> str:
    """`` [unit]`` for a message, or nothing."""
    return f" [{unit}]" if unit else ""


def finite(name: str, value: Any, unit: str = "") -> float:
    """``value`` as a finite float (``unit``, e.g. ``"kg"``, named in the message)."""
    if not is_number(value):
        raise SceneError(f"{name} must be a real number{_unit(unit)}, got {shown(value)}")
    number = float(value)
    if not math.isfinite(number):
        raise SceneError(f"{name} must be finite{_unit(unit)}, got {shown(value)}")
    return number


def positive(name: str, value: Any, unit: str = "") -> float:
    """``value`` as a finite float > 0."""
    number = finite(name, value, unit)
    if number <= 0.0:
        raise SceneError(f"{name} must be positive{_unit(unit)}, got {shown(value)}")
    return number


def non_negative(name: str, value: Any, unit: str = "") -> float:
    """``value`` as a finite float >= 0."""
    number = finite(name, value, unit)
    if number < 0.0:
        raise SceneError(f"{name} must be zero or positive{_unit(unit)}, got {shown(value)}")
    return number


def real_array(name: str, value: Any, *, require_finite: bool = True):
    """``value`` as a float ndarray (any shape); text, booleans, objects and NaN/inf are refused."""
    _refuse_non_numbers(value, f"{name} must be real numbers, got {shown(value)}")
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise SceneError(f"{name} must be real numbers, got {shown(value)}") from None
    if require_finite and not np.all(np.isfinite(array)):
        raise SceneError(f"{name} must be finite, got {shown(value)}")
    return array


def whole_array(name: str, value: Any):
    """``value`` as an int64 ndarray whose entries are whole numbers (2.5 is refused, not truncated)."""
    array = real_array(name, value)
    if not np.all(array == np.round(array)):
        raise SceneError(f"{name} must be whole numbers, got {shown(value)}")
    return array.astype(np.int64)


def flat_coordinates(name: str, value: Any, n_coordinates: int | None = None):
    """``value`` as a C-contiguous float64 array (2 n_nodes,) ``x0, y0, x1, ...`` (``n_coordinates`` long)."""
    array = np.ascontiguousarray(real_array(name, value), dtype=np.float64)
    if array.ndim != 1 or array.shape[0] % 2 != 0:
        raise SceneError(f"{name} must be a flat array (2 n_nodes,) x0, y0, x1, ...; got shape {array.shape}")
    if n_coordinates is not None and array.shape[0] != n_coordinates:
        raise SceneError(f"{name} has {array.shape[0]} coordinates, expected {n_coordinates}")
    return array


def entries(path: str, value: Any, length: int, unit: str = "") -> tuple[float, ...]:
    """``value`` as a tuple of ``length`` finite floats (a scene field such as a pulley's centre)."""
    units = f" [{unit}]" if unit else ""
    if isinstance(value, (str, bytes, Mapping)):
        raise SceneError(f"{path} must be a list of {length} numbers{units}, got {shown(value)}")
    try:
        items = list(value)
    except TypeError:
        raise SceneError(f"{path} must be a list of {length} numbers{units}, got {shown(value)}") from None
    if len(items) != length:
        raise SceneError(f"{path} must have {length} entries{units}, got {len(items)}: {shown(value)}")
    return tuple(finite(f"{path}[{i}]", v) for i, v in enumerate(items))


def vector(name: str, value: Any, length: int, meaning: str = ""):
    """``value`` as a finite float ndarray (length,); ``meaning`` (e.g. ``" (x, z) [m]"``) in the message."""
    _refuse_non_numbers(value, f"{name} must be {length} numbers{meaning}, got {shown(value)}")
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise SceneError(f"{name} must be a {length}-vector{meaning}, got {shown(value)}") from None
    if array.shape != (length,) or not np.all(np.isfinite(array)):
        raise SceneError(f"{name} must be a finite {length}-vector{meaning}, got {shown(value)}")
    return array


def per_item(name: str, values: Any, count: int, positive: bool = False):
    """One finite, non-negative (or positive) value per item, a scalar repeated: float64 (count,)."""
    array = real_array(name, values)
    if array.ndim == 0:
        array = np.full(count, float(array))
    elif array.shape != (count,):
        raise SceneError(f"{name} must be a scalar or have shape ({count},); got shape {array.shape}")
    array = np.ascontiguousarray(array, dtype=np.float64)
    if not np.isfinite(array).all() or (array <= 0.0 if positive else array < 0.0).any():
        raise SceneError(f"{name} must be finite and {'positive' if positive else 'zero or positive'}; got {shown(values)}")
    return array


def points_per_item(name: str, values: Any, count: int):
    """One finite planar point per item, shape (count, 2) [m]: a single (2,) point is repeated."""
    array = np.asarray(real_array(name, values), dtype=np.float64)
    if array.shape == (2,):
        array = np.tile(array, (count, 1))
    if array.shape != (count, 2) or not np.isfinite(array).all():
        raise SceneError(f"{name} must be finite, shape (2,) or ({count}, 2); got shape {array.shape}")
    return np.ascontiguousarray(array)


def from_table(cls: type, data: Any, path: str, head: str) -> Any:
    """The dataclass ``cls`` from a scene file's table ``data``, unknown fields refused; its messages name
    fields under ``path`` (``pulleys[1].radius``), not ``head`` (``pulley.radius``)."""
    if not isinstance(data, Mapping):
        raise SceneError(f"{path} must be a table, got {shown(data)}")
    known = {f.name for f in dataclasses.fields(cls)}
    unknown = set(data) - known
    if unknown:
        raise SceneError(f"{path} has unknown field(s) {sorted(unknown)}; known: {sorted(known)}")
    try:
        return cls(**data)
    except SceneError as err:
        message = str(err)
        if path != head and message.startswith(head + "."):
            message = path + message[len(head):]
        raise SceneError(message) from None
    except TypeError as err:
        raise SceneError(f"{path}: {err}") from None
