"""Exp 3 diagnosis (docs/exp3.md, issue #18): where a start puts the feet. A floating start
stands the robot with its base over the origin (`reset_on_ground`), so the feet land where
the posture puts them; during the episode they stay planted, while h* is a fixed world point
(the hands of demo 6 standing with demo 6's feet). Over the admissible cells of a grid over the
latent box: the first sole's x offset from demo 6's, i.e. how far h* is from where the robot's
hands can be at demo 6's posture from that start.

    python stance.py [DEMOS.csv|shipped] [N]
"""
import sys
from pathlib import Path

import numpy as np

from latentrl.experiments import exp3

if len(sys.argv) > 1 and sys.argv[1] != "shipped":
    exp3.demos_path = lambda heel=False, p=Path(sys.argv[1]).resolve(): p
n = int(sys.argv[2]) if len(sys.argv) > 2 else 40
preset = exp3.Exp3Preset()
f = exp3.fit(preset)
task = exp3.task_of(preset)
plant = task.plant(f.demos)
foot = task.link_names.index(task.to_dict()["fall"]["soles"][0])


def sole_xy(posture):
    code = plant.reset(posture)
    return code, plant.link_poses()[foot, :2]


_, home = sole_xy(f.demos[6])
for i, d in enumerate(f.demos):
    print(f"demo {i}: sole x {sole_xy(d)[1][0] - home[0]:+.3f} m from demo 6's")
gx, gy = (np.linspace(f.low[k], f.high[k], n) for k in range(2))
offsets = []
for z in np.array([[x, y] for y in gy for x in gx]):
    code, xy = sole_xy(f.model.inverse_transform(z[None])[0])
    if code is None:
        offsets.append(np.linalg.norm(xy - home))
offsets = np.array(offsets)
print(f"{len(offsets)} admissible starts of {n * n}: sole offset from demo 6's median {np.median(offsets):.3f} m, "
      f"> 0.02 m (h* out of reach with the feet planted) {np.mean(offsets > 0.02):.0%}, > 0.01 m {np.mean(offsets > 0.01):.0%}")
