"""Writes demos.csv: 100 postures of the biped standing on both feet, drawn from a seed over a
two-parameter family: a squat of depth a ∈ [0, 1.0] rad (hips -a, knees 2a, ankles -a: torso
upright, feet flat, hips over the ankles) and both arms raised forwards by b ∈ [0, 1.6] rad
(shoulders -b, elbows -b/2). Row 0 is the straight stance with the arms down. Postures a rule
refuses at rest (plant.classify: a fall, the centre of mass too near the support edge, a hand
below 0.35 m) are dropped. Prints the hands of the pick posture (a = 0.95, b = 0.6) from the
left sole, the task's target.

    python examples/zoo/biped_pick/make_demos.py [--seed 0]
"""

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from _zoo import generator, write_demos  # noqa: E402



def posture(names: tuple[str, ...], a: float, b: float) -> np.ndarray:
    value = {"hip": -a, "knee": 2 * a, "ankle": -a, "shoulder": -b, "elbow": -b / 2}
    return np.array([value[n.split("_", 1)[1]] for n in names])


def main() -> None:
    rng, task, kin = generator(HERE)
    ab = np.column_stack([rng.uniform(0.0, 1.0, 110), rng.uniform(0.0, 1.6, 110)])
    ab[0] = [0.0, 0.0]
    Q = np.array([posture(task.joint_names, a, b) for a, b in ab])
    write_demos(kin, Q, 100, HERE)
    pick = posture(task.joint_names, 0.95, 0.6)
    poses = kin.poses(pick)
    foot = kin.pos(poses, "l_foot")
    print("target (hands from l_foot):", [list(np.round(kin.pos(poses, h) - foot, 4)) for h in ("l_hand", "r_hand")])


if __name__ == "__main__":
    main()
