"""Making demonstrations: interpolate between keyframe postures, or record the postures a
simulated robot reaches while its servos track a sequence of targets. Both return
`Demonstrations` (joint names kept), ready for `save_demos` or a model's `fit`."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from latentrl._native import Sim
from latentrl._validation import int_at_least
from latentrl.demos import Demonstrations


def interpolate_keyframes(keyframes: Demonstrations, per_segment: int, *, breaks: Sequence[int] = ()) -> Demonstrations:
    """Joint-space straight lines between consecutive keyframes, `per_segment` postures per
    segment (the keyframe itself and `per_segment − 1` between it and the next), each
    sequence ending on its last keyframe. `breaks` are the rows that start a new sequence
    (another style), so no line joins row `b − 1` to row `b`: the shipped lift demos are two
    sequences, `breaks=(4,)`."""
    steps = int_at_least("per_segment", per_segment)
    frames = keyframes.postures
    cuts = sorted({int(b) for b in breaks})
    if any(not 0 < b < len(frames) for b in cuts):
        raise ValueError(f"breaks must be rows 1..{len(frames) - 1}, got {list(breaks)}")
    out = []
    for start, stop in zip([0, *cuts], [*cuts, len(frames)]):
        sequence = frames[start:stop]
        s = np.arange(steps)[:, None] / steps
        for a, b in zip(sequence[:-1], sequence[1:]):
            out.append(a + s * (b - a))
        out.append(sequence[-1:])
    return Demonstrations(np.vstack(out), keyframes.joint_names)


def record_postures(sim: Sim, targets: Any, *, hold_steps: int, every: int = 1) -> Demonstrations:
    """Drives `sim` (a `latentrl._native.Sim`) through `targets` (M, D), each held for
    `hold_steps` physics steps, and records the reached joint positions every `every` steps
    (M · ⌊hold_steps / every⌋ postures, named by `sim.joint_names`). The sim starts where it
    is: reset it (`reset`, `reset_on_ground`) first."""
    names = tuple(sim.joint_names)
    goal = np.asarray(targets, dtype=np.float64)
    if goal.ndim != 2 or goal.shape[1] != len(names) or len(goal) == 0:
        raise ValueError(f"targets must have shape (M >= 1, {len(names)}), got {goal.shape}")
    if not np.isfinite(goal).all():
        raise ValueError("targets must be finite")
    hold, stride = int_at_least("hold_steps", hold_steps), int_at_least("every", every)
    if stride > hold:
        raise ValueError(f"every ({stride}) must be at most hold_steps ({hold})")
    recorded = []
    for target in goal:
        sim.set_targets(target)
        for _ in range(hold // stride):
            sim.step(stride)
            recorded.append(np.asarray(sim.joint_positions(), dtype=np.float64))
    return Demonstrations(np.array(recorded), names)
