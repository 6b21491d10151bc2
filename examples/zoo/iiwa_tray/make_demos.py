"""Writes demos.csv: up to 120 postures of the iiwa-style arm holding its tray level, the tray
0.55 m from the base axis at an azimuth in [-1.0, 1.0] rad (table side to shelf side) and a
height in [0.35, 0.78] m, drawn from a seed. Each posture is least squares on the plant's own
kinematics (tray position, tray normal up, and a small pull towards one nominal elbow-up
posture turned to the azimuth, so the demos stay on one branch of the redundancy), with the
arm's points pushed out of the table and shelf; postures a rule refuses at rest
(plant.classify) are dropped.

    python examples/zoo/iiwa_tray/make_demos.py [--seed 0]
"""

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from _zoo import generator, pose_residual, write_demos, solve_ik  # noqa: E402


BOXES = [([0.35, -0.75, 0.0], [0.85, -0.15, 0.25]), ([0.35, 0.15, 0.60], [0.85, 0.75, 0.63])]
CHAIN = ["iiwa_link_2", "iiwa_link_4", "iiwa_link_6", "tray"]
Q_NOM = np.array([0.0, 0.55, 0.0, -0.97, 0.0, 1.6, 0.0])


def main() -> None:
    rng, task, kin = generator(HERE)
    n = 140
    phi, z = rng.uniform(-1.0, 1.0, n), rng.uniform(0.35, 0.78, n)
    Q = []
    for a, h in zip(phi, z):
        goal = np.array([0.55 * np.cos(a), 0.55 * np.sin(a), h])
        nominal = Q_NOM + np.array([a, 0, 0, 0, 0, 0, 0])

        def residual(q: np.ndarray, goal: np.ndarray = goal, nominal: np.ndarray = nominal) -> np.ndarray:
            return pose_residual(kin, kin.poses(q), "tray", goal, [0, 0, 1], CHAIN, BOXES, 0.06, q, nominal)

        q, _ = solve_ik(residual, nominal, kin.lower, kin.upper)
        poses = kin.poses(q)
        if np.linalg.norm(kin.pos(poses, "tray") - goal) < 0.005:
            Q.append(q)
    write_demos(kin, np.array(Q), 120, HERE)


if __name__ == "__main__":
    main()
