"""Writes demos.csv: up to 120 postures of pybullet_data's Franka Panda with its gripper pointing
down and its grasp point (panda_grasptarget) in the vertical plane x = 0.5 m over
y ∈ [-0.42, 0.42], z ∈ [0.05, 0.55] m (drawn from a seed), fingers open (0.04 m); row 0 is the
start posture, the grasp point at (0.5, -0.3, 0.1) in the right bin. The zoo's panda_bins
generator on the stock description: each posture is least squares on the plant's own kinematics
(grasp point position, gripper axis down, and a small pull towards a nominal posture turned to
the goal's azimuth, so the demos stay on one branch), with the arm's points pushed out of the
divider; postures a rule refuses at rest (plant.classify: the mesh hulls against the divider)
are dropped.

    python examples/stock/panda_bins/make_demos.py [--seed 0]
"""

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1] / "zoo"))

from _zoo import generator, pose_residual, write_demos, solve_ik  # noqa: E402


DIVIDER = ([0.30, -0.015, 0.0], [0.70, 0.015, 0.22])
CHAIN = ["panda_link3", "panda_link5", "panda_link7", "panda_hand", "panda_grasptarget"]
TOOL = "panda_grasptarget"
Q_NOM = np.array([0.0, 0.3, 0.0, -2.1, 0.0, 2.4, 0.785, 0.04])  # the last: panda_finger_joint1, open
ARM = 7  # IK moves the arm's joints; the fingers stay open


def main() -> None:
    rng, task, kin = generator(HERE)
    n = 140
    goals = np.column_stack([np.full(n, 0.5), rng.uniform(-0.42, 0.42, n), rng.uniform(0.05, 0.55, n)])
    goals[0] = [0.5, -0.3, 0.1]
    lower, upper = kin.lower[:ARM], kin.upper[:ARM]
    Q = []
    for goal in goals:
        nominal = Q_NOM[:ARM] + np.array([np.arctan2(goal[1], goal[0]), 0, 0, 0, 0, 0, 0])

        def residual(q: np.ndarray, goal: np.ndarray = goal, nominal: np.ndarray = nominal) -> np.ndarray:
            poses = kin.poses(np.append(q, Q_NOM[ARM:]))
            return pose_residual(kin, poses, TOOL, goal, [0, 0, -1], CHAIN, [DIVIDER], 0.08, q, nominal)

        q, _ = solve_ik(residual, nominal, lower, upper)
        q = np.append(q, Q_NOM[ARM:])
        if np.linalg.norm(kin.pos(kin.poses(q), TOOL) - goal) < 0.005:
            Q.append(q)
        elif len(Q) == 0:
            raise SystemExit("the start posture (row 0) has no IK solution")
    write_demos(kin, np.array(Q), 120, HERE)


if __name__ == "__main__":
    main()
