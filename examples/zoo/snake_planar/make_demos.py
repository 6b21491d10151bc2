"""Writes demos.csv: up to 120 postures of the planar snake with its tip spread over the half
disc in front of it (y ≥ 0.005, 0.06–0.27 m from the base), each by least squares on the plant's
own kinematics from one coiled nominal posture, with the links' points pushed out of the wall
(inflated by 2 cm); postures a rule refuses at rest (plant.classify) are dropped.

    python examples/zoo/snake_planar/make_demos.py [--seed 0]
"""

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from _zoo import generator, box_penetration, chain_points, write_demos, solve_ik  # noqa: E402


WALL = ([0.06, -0.05, -0.05], [0.08, 0.10, 0.05])
CHAIN = ["seg1", "seg2", "seg3", "seg4", "seg5", "seg6", "tip"]
Q_NOM = np.array([1.2, -0.4, -0.4, -0.4, -0.4, -0.4])


def main() -> None:
    rng, task, kin = generator(HERE)
    r = np.sqrt(rng.uniform(0.06 ** 2, 0.27 ** 2, 400))
    a = rng.uniform(0.02, np.pi - 0.02, 400)
    goals = np.column_stack([r * np.cos(a), np.maximum(r * np.sin(a), 0.005)])
    Q = []
    for g in goals:
        def residual(q: np.ndarray, g: np.ndarray = g) -> np.ndarray:
            poses = kin.poses(q)
            tip = kin.pos(poses, "tip")[:2]
            pen = [box_penetration(p, *WALL, inflate=0.02) for p in chain_points(kin, poses, CHAIN)]
            return np.concatenate([(tip - g) / 0.001, np.array(pen) / 0.001, 0.1 * (q - Q_NOM)])

        q, _ = solve_ik(residual, Q_NOM, kin.lower, kin.upper)
        tip = kin.pos(kin.poses(q), "tip")[:2]
        if np.linalg.norm(tip - g) < 0.002:
            Q.append(q)
    write_demos(kin, np.array(Q), 120, HERE)


if __name__ == "__main__":
    main()
