"""Learning assertions that a non-learner fails (issue #22).

The control is the same preset, seeds and budget with the learning rate α = 1e-12: its value
weights never move from w₀, so its soft-max picks among equal values, a random policy. A
metric shows learning only where a threshold lies above the control on every seed and below
the learner on every seed. Each test runs the control beside the learner (`control`) and
checks both sides (`assert_separated`), so the separation is re-checked on every run, not
remembered; the distributions over ≥ 10 seeds that chose the threshold are in each test's
docstring (measured with `latentrl sweep`, grid `alpha = [<paper's α>, 1e-12]`, 10 trials).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from latentrl.run_settings import with_overrides

CONTROL_ALPHA = 1e-12
"""α of the non-learning control."""


def control(preset: Any) -> Any:
    """`preset` with the control's learning rate (the task key `learner.alpha`)."""
    return with_overrides(preset, {"learner.alpha": CONTROL_ALPHA})


def assert_separated(learner: Any, control_values: Any, threshold: float, what: str) -> None:
    """Every learner value above `threshold` and every control value below it."""
    learner, control_values = np.asarray(learner, dtype=float), np.asarray(control_values, dtype=float)
    detail = f"{what}: learner {np.round(learner, 3)}, control {np.round(control_values, 3)}, threshold {threshold}"
    assert np.all(learner > threshold), detail
    assert np.all(control_values < threshold), detail
