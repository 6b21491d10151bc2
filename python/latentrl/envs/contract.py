"""What the environments share: the observation type, the checks of their arguments (a
`render_mode`, a reset's ``options["posture"]``, an action) and the info a step returns."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from latentrl.task import end_reasons

Obs = NDArray[np.float64]


def check_render_mode(render_mode: str | None, modes: list[str]) -> str | None:
    """`render_mode` if it is None or one of `modes` (these need matplotlib), else a ValueError."""
    if render_mode not in (None, *modes):
        raise ValueError(f"render_mode must be None or one of {modes}, got {render_mode!r}")
    if render_mode is not None:
        try:
            import matplotlib  # noqa: F401
        except ModuleNotFoundError as err:
            raise ModuleNotFoundError(
                f"render_mode={render_mode!r} draws with matplotlib: pip install 'latentrl[plot]'",
                name="matplotlib",
            ) from err
    return render_mode


def posture_option(options: dict[str, Any] | None, n: int) -> Obs | None:
    """A reset's ``options["posture"]`` as n finite floats (None if not given), or a ValueError."""
    if not options or options.get("posture") is None:
        return None
    posture = np.asarray(options["posture"], dtype=np.float64)
    if posture.shape != (n,) or not np.all(np.isfinite(posture)):
        raise ValueError(f"options['posture']: expected {n} finite values, got {posture!r}")
    return posture


def checked_action(action: Any, n: int) -> Obs:
    """`action` as n finite floats, or a ValueError naming it (issue #38: a NaN action was clipped
    to NaN and stepped without a word; one of another length failed in NumPy's broadcasting)."""
    try:
        values = np.asarray(action, dtype=np.float64)
    except (TypeError, ValueError) as err:
        raise ValueError(f"action: expected {n} finite numbers, got {action!r} ({err})") from None
    if values.shape != (n,) or not np.all(np.isfinite(values)):
        raise ValueError(f"action: expected {n} finite numbers, got {values!r}")
    return values


def step_info(end: int | None, reached: bool) -> dict[str, Any]:
    """The info of a step: how the episode ended (None: it goes on), whether the target is reached."""
    return {"end_reason": None if end is None else end_reasons()[end], "reached": reached}

