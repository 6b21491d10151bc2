"""Exp 3 diagnosis (docs/exp3.md, "Why the lift from the floor fails"): the GPLVM's latent box
on a 60 × 60 grid, each decoded posture classified at rest by the native plant (. admissible,
O block, B outside the joint limits, D drop; lower case: hands at floor level, _ admissible).

    python latent_map.py [DEMOS.csv]      # default: the shipped demos
"""
import numpy as np
import sys
from pathlib import Path
from latentrl.experiments import exp3
if len(sys.argv) > 1:
    exp3.demos_path = lambda heel=False, p=Path(sys.argv[1]).resolve(): p
from latentrl.experiments.exp3 import Exp3Preset, fit, task_of
from latentrl.task import end_reasons

preset = Exp3Preset()
f = fit(preset)
task = task_of(preset)
plant = task.plant(f.demos)
n = 60
gx = np.linspace(f.low[0], f.high[0], n)
gy = np.linspace(f.low[1], f.high[1], n)
Z = np.array([[x, y] for y in gy for x in gx])
X = f.model.inverse_transform(Z)
codes, hands, _ = plant.classify(X)
codes = codes.reshape(n, n)
hz = np.maximum(hands[:, 2], hands[:, 5]).reshape(n, n)
names = end_reasons()
print("latent box", f.low, f.high)
print("demo latent points:\n", np.round(f.model.Z_, 2))
print("codes over the box:", {names[c] if c else 'ok': int((codes == c).sum()) for c in np.unique(codes)})
floor = hz <= 0.10
print("floor-level points:", floor.sum(), "of which ok", (floor & (codes == 0)).sum())
sym = {0: '.', 1: 'O', 2: 'B', 3: 'D', 4: 'F'}
for j in range(n - 1, -1, -3):
    row = ''.join((sym.get(int(codes[j, i]), '?') if not floor[j, i] else ('_' if codes[j, i] == 0 else sym.get(int(codes[j, i])).lower())) for i in range(0, n, 1))
    print(f"{gy[j]:+.2f} {row}")
print("demo hand z:", np.round(plant.classify(f.demos)[1][:, [2, 5]].max(1), 3), "codes", plant.classify(f.demos)[0])

