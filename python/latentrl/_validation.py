"""Input checks shared by the public API: every failure names the argument and what was wrong."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray


def as_matrix(
    name: str, value: Any, *, n_cols: int | None = None, min_rows: int = 1
) -> NDArray[np.float64]:
    """`value` as a C-ordered float64 (rows, cols) array, or a ValueError/TypeError saying why not."""
    array = _floats(name, value, "a 2-D array")
    if array.ndim != 2:
        raise ValueError(f"{name}: expected a 2-D array (rows, columns), got shape {array.shape}")
    if n_cols is not None and array.shape[1] != n_cols:
        raise ValueError(f"{name}: expected {n_cols} columns, got shape {array.shape}")
    if array.shape[0] < min_rows:
        raise ValueError(f"{name}: expected at least {min_rows} rows, got shape {array.shape}")
    if array.shape[1] == 0:
        raise ValueError(f"{name}: has no columns, shape {array.shape}")
    check_finite(name, array)
    return np.ascontiguousarray(array)


def as_vector(name: str, value: Any, *, length: int | None = None) -> NDArray[np.float64]:
    """`value` as a float64 1-D array (of `length` if given), or a ValueError/TypeError saying why not."""
    array = _floats(name, value, "a 1-D array")
    if array.ndim != 1:
        raise ValueError(f"{name}: expected a 1-D array, got shape {array.shape}")
    if length is not None and array.shape[0] != length:
        raise ValueError(f"{name}: expected shape ({length},), got {array.shape}")
    check_finite(name, array)
    return np.ascontiguousarray(array)


def _floats(name: str, value: Any, expected: str) -> NDArray[np.float64]:
    """`value` as a float64 array, or a TypeError naming `name` and what was `expected`
    (complex values too: casting would silently drop their imaginary parts)."""
    if np.iscomplexobj(value):
        raise TypeError(f"{name}: expected {expected} of real numbers, got complex values")
    try:
        return np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as err:
        raise TypeError(f"{name}: expected {expected} of numbers, got {type(value).__name__}") from err


def check_finite(name: str, array: NDArray[np.float64]) -> None:
    """ValueError naming the first NaN/inf entry of `array`, if any."""
    bad = np.argwhere(~np.isfinite(array))
    if bad.size:
        index = tuple(int(i) for i in bad[0])
        raise ValueError(f"{name}: non-finite value {array[index]} at index {index}")


def positive(name: str, value: float) -> float:
    """`value` if it is a finite number > 0, else a ValueError."""
    if not (isinstance(value, (int, float, np.integer, np.floating)) and np.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return float(value)
