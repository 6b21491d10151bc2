"""Writes demos.csv: the two arms holding the object (hands 0.15 m apart, level, each hand link
pointing at the object) with its centre on a 13 × 9 grid over x ∈ [-0.15, 0.15], y ∈ [0.15,
0.45], jittered by ±3 mm (seeded) except on the top row, whose centre row the target is. Analytic
inverse kinematics, elbows outward; postures a rule refuses at rest (the sensor block, by
plant.classify) are dropped, and every kept posture is checked on the plant's kinematics.

    python examples/zoo/bimanual_box/make_demos.py [--seed 0]
"""

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from _zoo import generator, write_demos  # noqa: E402


L1, L2, L3 = 0.30, 0.25, 0.08
SHOULDER = {"l": -0.12, "r": 0.12}


def arm(side: str, hx: float, hy: float) -> list[float]:
    """Shoulder, elbow, wrist putting this hand at (hx, hy) with its hand link pointing at the
    object (+x for the left hand, -x for the right), elbow outward."""
    heading = 0.0 if side == "l" else np.pi
    wx, wy = hx - L3 * np.cos(heading) - SHOULDER[side], hy - L3 * np.sin(heading)
    c2 = (wx * wx + wy * wy - L1 * L1 - L2 * L2) / (2 * L1 * L2)
    q2 = float(np.arccos(np.clip(c2, -1.0, 1.0))) * (-1 if side == "l" else 1)
    q1 = float(np.arctan2(wy, wx) - np.arctan2(L2 * np.sin(q2), L1 + L2 * np.cos(q2)))
    q3 = float(np.arctan2(np.sin(heading - q1 - q2), np.cos(heading - q1 - q2)))
    return [q1, q2, q3]


def main() -> None:
    rng, task, kin = generator(HERE)
    Q, centres = [], []
    for cy in np.linspace(0.15, 0.45, 9):
        for cx in np.linspace(-0.15, 0.15, 13):
            jx, jy = (0.0, 0.0) if cy == 0.45 else rng.uniform(-0.003, 0.003, 2)
            x, y = cx + jx, cy + jy
            left, right = arm("l", x - 0.075, y), arm("r", x + 0.075, y)
            q = np.array(left + right)
            order = [task.joint_names.index(n) for n in ("l_shoulder", "l_elbow", "l_wrist",
                                                         "r_shoulder", "r_elbow", "r_wrist")]
            qq = np.empty(6)
            qq[order] = q
            poses = kin.poses(qq)
            assert np.allclose(kin.pos(poses, "l_hand")[:2], [x - 0.075, y], atol=1e-5)
            assert np.allclose(kin.pos(poses, "r_hand")[:2], [x + 0.075, y], atol=1e-5)
            Q.append(qq)
            centres.append((x, y))
    write_demos(kin, np.array(Q), 150, HERE)


if __name__ == "__main__":
    main()
