"""Writes demos.csv: 80 postures of the glass arm holding its glass upright (q1 + q2 + q3 = 0, the
glass frame's y axis along the world y), the glass anywhere in x ∈ [-0.35, 0.35], y ∈ [0.15, 0.5],
elbow on the same side (analytic inverse kinematics of the first two links, then the wrist).

    python examples/glass_arm/make_demos.py
"""

from pathlib import Path

import numpy as np

from latentrl import Demonstrations, save_demos

L1, L2, L3 = 0.30, 0.25, 0.10


def upright(x: float, y: float) -> list[float]:
    """The posture putting the glass at (x, y) upright: the wrist at (x − L3, y), then IK."""
    wx, wy = x - L3, y
    c2 = (wx * wx + wy * wy - L1 * L1 - L2 * L2) / (2 * L1 * L2)
    q2 = float(np.arccos(np.clip(c2, -1.0, 1.0)))
    q1 = float(np.arctan2(wy, wx) - np.arctan2(L2 * np.sin(q2), L1 + L2 * np.cos(q2)))
    return [q1, q2, -q1 - q2]


def main() -> None:
    rng = np.random.default_rng(0)
    points = np.column_stack([rng.uniform(-0.35, 0.35, 80), rng.uniform(0.15, 0.5, 80)])
    postures = np.array([upright(x, y) for x, y in points])
    save_demos(Demonstrations(postures, ("shoulder", "elbow", "wrist")), Path(__file__).with_name("demos.csv"))


if __name__ == "__main__":
    main()
