"""Demonstration generators for the bimanual task (docs/method.md §Experiment 1, §Experiment 2):
postures that satisfy the constraint "the right hand is 0.1 m to the right of the left hand" (the
arms' kinematics, `arms_forward`, are the native plant's; `_reference.arms_forward` is their NumPy
oracle).

Every generator takes a seeded `numpy.random.Generator` and is deterministic given it.

Sampling regions (ours: the paper does not give them):

- End-effector space (Exp 1, Table I top): the left hand is uniform over the box
  x ∈ [−0.5, 1.4], y ∈ [−0.5, 1.5] — the Exp 1 state box (each hand in [−0.5, 1.5]²) shrunk by
  the 0.1 m offset so the right hand stays inside it too. The obstacle is not avoided.
- Joint space (Exp 2, Table I bottom): the left hand is uniform over the points in front of the
  body (y ≥ 0.05 m) from which *both* arms reach their hand, each hand between 0.1 m and
  0.55 m from its shoulder (links 0.3 + 0.3 m: full stretch, where the elbow branch is
  degenerate, is avoided); postures come from the analytic IK with elbows outward. That region
  holds the Exp 2 target (left hand (−0.05, 0.47)) and the corridor gap.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numpy.typing import NDArray

from latentrl._native import arms_elbows, arms_fk, arms_ik, bimanual_config
from latentrl._native import grip_error as native_grip_error
from latentrl._validation import as_matrix, int_at_least

OFFSET = np.array(bimanual_config()[0]["grip"], dtype=np.float64)
"""The constraint: hand_R − hand_L (metres), docs/method.md §Experiment 1: the bimanual plant's
`grip` (`sim::bimanual::GRIP`, the offset of the native `grip_error` too)."""

SHOULDERS = np.array([[-0.15, 0.0], [0.15, 0.0]])
"""Left and right shoulder (x, y) in metres (ours; docs/method.md §Experiment 2). Mirrors
`sim::PlanarArms`."""

LINKS = (0.3, 0.3)
"""Upper arm and forearm lengths in metres (ours; docs/method.md §Experiment 2)."""

EE_LEFT_BOX = ((-0.5, -0.5), (1.4, 1.5))
"""Default region of the left hand for end-effector demos: ((x_min, y_min), (x_max, y_max))."""

ARM_REACH = (0.1, 0.55)
"""Default shoulder→hand distance range (metres) of both arms for joint-space demos."""

ARM_Y_MIN = 0.05
"""Default lowest hand height (metres) for joint-space demos: hands in front of the body."""


def _check_noise(noise: float) -> float:
    if not (
        isinstance(noise, (int, float, np.integer, np.floating))
        and np.isfinite(noise)
        and noise >= 0
    ):
        raise ValueError(f"noise must be a finite number >= 0, got {noise!r}")
    return float(noise)


def bimanual_pairs(
    n: int,
    rng: np.random.Generator,
    *,
    noise: float = 0.0,
    left_box: tuple[tuple[float, float], tuple[float, float]] = EE_LEFT_BOX,
) -> NDArray[np.float64]:
    """`n` hand pairs (n, 4) `[x_L, y_L, x_R, y_R]` with `hand_R = hand_L + (0.1, 0)`.

    The left hand is uniform over `left_box`; `noise` > 0 adds independent Gaussian noise of
    that standard deviation (metres) to every coordinate afterwards (a "slightly noisy"
    demonstrator, docs/method.md §Table I).
    """
    n = int_at_least("n", n)
    noise = _check_noise(noise)
    low, high = np.asarray(left_box[0], dtype=float), np.asarray(left_box[1], dtype=float)
    if low.shape != (2,) or high.shape != (2,) or not np.all(high > low):
        raise ValueError(
            f"left_box must be ((x_min, y_min), (x_max, y_max)) with max > min, got {left_box!r}"
        )
    left = rng.uniform(low, high, size=(n, 2))
    pairs = np.hstack([left, left + OFFSET])
    if noise > 0:
        pairs += rng.normal(scale=noise, size=pairs.shape)
    return pairs


def arm_hands(
    n: int,
    rng: np.random.Generator,
    *,
    reach: tuple[float, float] = ARM_REACH,
    y_min: float = ARM_Y_MIN,
) -> NDArray[np.float64]:
    """`n` constraint-satisfying hand pairs (n, 4) that both planar arms can reach.

    The left hand is uniform over the region where both shoulder→hand distances lie in
    `reach` and both hands have y ≥ `y_min` (rejection sampling from its bounding box).
    """
    n = int_at_least("n", n)
    r_min, r_max = float(reach[0]), float(reach[1])
    if not (0 <= r_min < r_max <= sum(LINKS) and abs(LINKS[0] - LINKS[1]) <= r_max):
        raise ValueError(f"reach must satisfy 0 <= min < max <= {sum(LINKS)}, got {reach!r}")
    # Left hand h must satisfy: |h − s_L| in reach, |h + offset − s_R| in reach.
    centres = np.array([SHOULDERS[0], SHOULDERS[1] - OFFSET])
    low = np.array([centres[:, 0].min() - r_max, max(y_min, -r_max)])
    high = np.array([centres[:, 0].max() + r_max, r_max])
    if not np.all(high > low):
        raise ValueError(f"no reachable hand with y >= y_min={y_min}")
    out = np.empty((0, 2))
    for _ in range(1000):
        left = rng.uniform(low, high, size=(max(64, 4 * n), 2))
        dist = np.linalg.norm(left[:, None, :] - centres[None, :, :], axis=2)
        ok = np.all((dist >= r_min) & (dist <= r_max), axis=1) & (left[:, 1] >= y_min)
        out = np.vstack([out, left[ok]])
        if len(out) >= n:
            break
    else:  # pragma: no cover - only for absurd regions
        raise ValueError(f"the region reach={reach}, y_min={y_min} is (nearly) empty")
    left = out[:n]
    return np.hstack([left, left + OFFSET])


def arm_postures(
    n: int,
    rng: np.random.Generator,
    *,
    noise: float = 0.0,
    reach: tuple[float, float] = ARM_REACH,
    y_min: float = ARM_Y_MIN,
) -> NDArray[np.float64]:
    """`n` joint-space postures (n, 4) `[q1_L, q2_L, q1_R, q2_R]` (radians) of the two planar
    arms with `hand_R − hand_L = (0.1, 0)`, by analytic IK (elbows outward).

    Hands come from `arm_hands`. Shoulder angles are continuous over the whole set (hands in
    front of the body never cross the IK's angle cut behind the shoulder), so there are no 2π
    jumps. `noise` > 0 adds independent Gaussian noise of that s.d. (radians) to every angle.
    """
    noise = _check_noise(noise)
    postures = np.asarray(arms_ik(arm_hands(n, rng, reach=reach, y_min=y_min)))
    if noise > 0:
        postures = postures + rng.normal(scale=noise, size=postures.shape)
    return postures


def arms_forward(postures: NDArray[np.float64], *, elbows: bool = False) -> NDArray[np.float64]:
    """Hands (N, 4) `[x_L, y_L, x_R, y_R]` of postures (N, 4) `[q1_L, q2_L, q1_R, q2_R]` — `q1`
    from the +x axis, `q2` relative to the upper arm; with `elbows=True`, the elbows (N, 4). The
    plant's own kinematics (`_native.arms_fk`, `arms_elbows`); `_reference.arms_forward` is the
    NumPy oracle they are tested against."""
    q = np.ascontiguousarray(as_matrix("postures", postures, n_cols=4))
    hands: NDArray[np.float64] = np.asarray((arms_elbows if elbows else arms_fk)(q))
    return hands


def grip_error(
    hands: NDArray[np.float64], *, test: Literal["distance", "vector"] = "distance"
) -> NDArray[np.float64]:
    """How far each hand pair (N, 4) is from holding the object, in metres.

    `"distance"`: `| ‖hand_R − hand_L‖ − 0.1 |` (the paper's Fig. 5: "distance between the
    end-effectors within 0.005 of 0.1"); `"vector"`: `‖(hand_R − hand_L) − (0.1, 0)‖`
    (Experiment 1's drop test, docs/method.md §Experiment 1, which also catches a rotated object).
    The plant's own rule (`_native.grip_error`); `_reference.grip_error` is its NumPy oracle.
    """
    hands = np.ascontiguousarray(as_matrix("hands", hands, n_cols=4))
    error: NDArray[np.float64] = np.asarray(native_grip_error(hands, test))
    return error
