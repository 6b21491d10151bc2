"""Input checks shared by the public API: every failure names the argument and what was wrong."""

from __future__ import annotations

import sys
from typing import Any

import numpy as np
from numpy.typing import NDArray


class ComplexDataError(TypeError, ValueError):
    """Complex values where real numbers are expected: a TypeError (a wrong dtype, as
    latentrl has always raised) and a ValueError (what scikit-learn raises and checks)."""


def as_matrix(
    name: str, value: Any, *, n_cols: int | None = None, min_rows: int = 1
) -> NDArray[np.float64]:
    """`value` as a C-ordered float64 (rows, cols) array, or a ValueError/TypeError saying why not."""
    array = _floats(name, value, "a 2-D array")
    if array.ndim != 2:
        hint = (
            f". Reshape your data: {name}.reshape(1, -1) if it is one row, "
            f"{name}.reshape(-1, 1) if it is one column"
            if array.ndim == 1
            else ""
        )
        raise ValueError(
            f"{name}: expected a 2-D array (rows, columns), got shape {array.shape}{hint}"
        )
    if n_cols is not None and array.shape[1] != n_cols:
        raise ValueError(f"{name}: expected {n_cols} columns, got shape {array.shape}")
    if array.shape[0] < min_rows:
        raise ValueError(f"{name}: expected at least {min_rows} rows, got shape {array.shape}")
    if array.shape[1] == 0:
        # scikit-learn's wording: its estimator checks match it.
        raise ValueError(
            f"{name}: 0 feature(s) (shape={array.shape}) while a minimum of 1 is required."
        )
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
    (a sparse matrix too; complex values too, as a `ComplexDataError`: casting would
    silently drop their imaginary parts)."""
    sparse = sys.modules.get("scipy.sparse")  # a sparse matrix exists only once SciPy made one
    if sparse is not None and sparse.issparse(value):
        raise TypeError(
            f"{name}: sparse input is not supported, expected {expected} "
            f"(densify it: {name}.toarray())"
        )

    def not_numbers(err: Exception) -> TypeError:
        got = type(value).__name__
        return TypeError(f"{name}: expected {expected} of numbers, got {got} ({err})")

    try:
        array = np.asarray(value)
    except (TypeError, ValueError) as err:  # ragged nested lists
        raise not_numbers(err) from err
    if array.dtype.kind == "c":
        raise ComplexDataError(
            f"{name}: Complex data not supported, expected {expected} of real numbers"
        )
    try:
        return array.astype(np.float64, copy=False)
    except (TypeError, ValueError) as err:  # strings, objects
        raise not_numbers(err) from err


def check_finite(name: str, array: NDArray[np.float64]) -> None:
    """ValueError naming the first NaN/inf entry of `array`, if any."""
    bad = np.argwhere(~np.isfinite(array))
    if bad.size:
        index = tuple(int(i) for i in bad[0])
        value = "NaN" if np.isnan(array[index]) else array[index]
        raise ValueError(f"{name}: non-finite value {value} at index {index}")


def int_at_least(name: str, value: Any, minimum: int = 1) -> int:
    """`value` as an int if it is an integer (not a bool) >= `minimum`, else a ValueError."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise ValueError(f"{name} must be an int >= {minimum}, got {value!r}")
    return int(value)


def positive(name: str, value: float) -> float:
    """`value` if it is a finite number > 0, else a ValueError."""
    if not (isinstance(value, (int, float, np.integer, np.floating)) and np.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return float(value)
