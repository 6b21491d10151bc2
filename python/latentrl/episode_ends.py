"""How an episode ends, by code: the native end reasons, named, and counted."""

from __future__ import annotations

from typing import Any

from numpy.typing import NDArray

from latentrl import _native


def end_reasons() -> tuple[str, ...]:
    """How an episode ended, by code (`returns.npz`'s `<learner>_end`; −1: not run)."""
    return tuple(_native.end_reasons())


def end_counts(ends: NDArray[Any]) -> dict[str, int]:
    """How many of `ends` (end codes) ended each way, by name, every ending listed."""
    return {label: int((ends == code).sum()) for code, label in enumerate(end_reasons())}
