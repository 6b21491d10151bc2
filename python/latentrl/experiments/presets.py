"""Helpers shared by the experiment presets (frozen dataclasses, one docstring per field)."""

from __future__ import annotations

import ast
import dataclasses
import inspect
import textwrap
from functools import cache
from typing import Any

import numpy as np

from latentrl._validation import int_at_least


@cache
def field_docs(preset_cls: type) -> dict[str, str]:
    """The attribute docstrings of a dataclass (the string literal under each field)."""
    tree = ast.parse(textwrap.dedent(inspect.getsource(preset_cls)))
    body = tree.body[0].body  # type: ignore[attr-defined]
    docs = {}
    for field, doc in zip(body, body[1:]):
        if (
            isinstance(field, ast.AnnAssign)
            and isinstance(field.target, ast.Name)
            and isinstance(doc, ast.Expr)
            and isinstance(doc.value, ast.Constant)
            and isinstance(doc.value.value, str)
        ):
            docs[field.target.id] = " ".join(doc.value.value.split())
    return docs


def describe(preset: Any) -> dict[str, Any]:
    """Every field of a preset with its value, for the results metadata."""
    return {"name": type(preset).__name__, **dataclasses.asdict(preset)}


def latent_box(latent: np.ndarray, margin: float) -> tuple[np.ndarray, np.ndarray]:
    """The bounding box of the latent points, widened by `margin` of its width per side."""
    low, high = latent.min(axis=0), latent.max(axis=0)
    pad = margin * (high - low)
    return low - pad, high + pad


def check_ints(preset: Any, names: tuple[str, ...], minimum: int = 1) -> None:
    """ValueError naming the first of `names` that is not an int >= `minimum`."""
    for name in names:
        int_at_least(name, getattr(preset, name), minimum)


def check_floats(preset: Any, names: tuple[str, ...], *, positive: bool) -> None:
    """ValueError naming the first of `names` that is not finite and > 0 (or >= 0)."""
    for name in names:
        value = getattr(preset, name)
        ok = isinstance(value, (int, float, np.integer, np.floating)) and np.isfinite(value)
        if not ok or value < 0 or (positive and value == 0):
            bound = "> 0" if positive else ">= 0"
            raise ValueError(f"{name} must be a finite number {bound}, got {value!r}")
