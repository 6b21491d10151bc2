"""Which postures a model gets when a recording has more frames than it should take: farthest-point
sampling in joint space (`load_demos(..., max_postures=N)`, ``--max-postures N``)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray


def farthest_points(X: NDArray[np.float64], m: int) -> NDArray[np.intp]:
    """Indices of at most `m` rows of `X` (N, D) chosen by farthest-point sampling in joint space,
    in row order.

    The rule: the first row is chosen; then, `m` − 1 times, the row whose Euclidean distance (in
    radians, over all joints) to its nearest chosen row is largest (of equals, the first). It
    stops early when every row lies on a chosen one (fewer than `m` distinct postures). So the
    choice is deterministic, spreads over every region the demonstrations visit instead of
    crowding where the recorder dwelt (a robot at rest for seconds is one posture, not hundreds),
    and keeps the extremes. O(N · m · D) time, O(N · D) memory. With `m` ≥ N every row is kept."""
    n = len(X)
    if m >= n:
        return np.arange(n)
    columns = np.ascontiguousarray(np.asarray(X, dtype=np.float64).T)  # a joint's values side by side: 2.5× faster
    nearest, squared, part = np.full(n, np.inf), np.empty(n), np.empty(n)
    chosen, far = [0], 0
    while True:
        np.subtract(columns[0], columns[0, far], out=squared)
        np.multiply(squared, squared, out=squared)
        for column in columns[1:]:
            np.subtract(column, column[far], out=part)
            squared += np.multiply(part, part, out=part)
        np.minimum(nearest, squared, out=nearest)
        if len(chosen) == m:
            break
        far = int(np.argmax(nearest))
        if nearest[far] == 0.0:
            break
        chosen.append(far)
    return np.sort(np.asarray(chosen, dtype=np.intp))
