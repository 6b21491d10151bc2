"""Writes demos.csv: up to 120 postures of the UR5-style arm with its tool in the vertical plane
y = 0 over x ∈ [0.12, 0.75], z ∈ [0.06, 0.65] m (drawn from a seed), in front of, over and
behind the wall. Each posture is least squares on the plant's own kinematics (tool position, a
soft pull of the tool axis downwards and towards one nominal elbow-up posture, so the demos
stay on one branch), with the arm's points pushed out of the wall; postures a rule refuses at
rest (plant.classify) are dropped.

    python examples/zoo/ur_reach/make_demos.py [--seed 0]
"""

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from _zoo import generator, box_penetration, chain_points, write_demos, solve_ik  # noqa: E402


WALL = ([0.30, -0.30, 0.0], [0.36, 0.30, 0.25])
CHAIN = ["upper_arm_link", "forearm_link", "wrist_1_link", "wrist_3_link", "tool0"]
Q_NOM = np.array([0.0, -1.12, 1.78, -2.23, -1.57, 0.0])


def main() -> None:
    rng, task, kin = generator(HERE)
    n = 140
    goals = np.column_stack([rng.uniform(0.12, 0.75, n), np.zeros(n), rng.uniform(0.06, 0.65, n)])
    Q = []
    for goal in goals:
        def residual(q: np.ndarray, goal: np.ndarray = goal) -> np.ndarray:
            poses = kin.poses(q)
            pen = [box_penetration(p, *WALL, 0.07) for p in chain_points(kin, poses, CHAIN)]
            return np.concatenate([(kin.pos(poses, "tool0") - goal) / 0.001,
                                   (kin.axis(poses, "tool0", [0, 0, 1]) - [0, 0, -1]) / 0.1,
                                   np.array(pen) / 0.001, 0.1 * (q - Q_NOM)])

        q, _ = solve_ik(residual, Q_NOM, kin.lower, kin.upper)
        if np.linalg.norm(kin.pos(kin.poses(q), "tool0") - goal) < 0.005:
            Q.append(q)
    write_demos(kin, np.array(Q), 120, HERE)


if __name__ == "__main__":
    main()
