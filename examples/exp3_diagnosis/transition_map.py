"""Exp 3 diagnosis (docs/exp3.md, issue #18): which one-step moves of the learner are safe, and
is there a path of them from the floor-level starts to h*?

Every cell of an N × N grid over the latent box whose decoded posture may start an episode
(`TaskPlant.reset`) is tried with each of the learner's 8 actions (step × RBF spacing per axis)
taken K times in a row as the learner takes them (target = encoding of the reached posture +
action), from rest: the first end code (0: none) and the cell of the last encoded reached
posture (K = 3 moves about one cell of a 40 × 40 grid). Cells where the robot at rest already reached h* are the goal. A breadth-first
search backwards over the safe moves gives every cell's distance to h* in RL steps.

    python transition_map.py OUT.npz [N] [DEMOS.csv|shipped] [encoder] [K] [TASK_OVERRIDES_JSON]
"""
import json
import sys
from collections import deque
from pathlib import Path

import numpy as np

from latentrl.experiments import exp3

out = Path(sys.argv[1])
n = int(sys.argv[2]) if len(sys.argv) > 2 else 40
if len(sys.argv) > 3 and sys.argv[3] != "shipped":
    exp3.demos_path = lambda heel=False, p=Path(sys.argv[3]).resolve(): p
encoder = sys.argv[4] if len(sys.argv) > 4 else "gp"
repeats = int(sys.argv[5]) if len(sys.argv) > 5 else 3
overrides = json.loads(sys.argv[6]) if len(sys.argv) > 6 else {}
preset = exp3.Exp3Preset(encoder=encoder, task=overrides)
f = exp3.fit(preset)
task = exp3.task_of(preset)
plant = task.plant(f.demos)
learner = task.to_dict()["learner"]
spacing = (f.high - f.low) / (learner["rbf_per_dim"] - 1)
actions = np.array([[1, 0], [-1, 0], [0, 1], [0, -1], [1, 1], [1, -1], [-1, 1], [-1, -1]]) * learner["step"] * spacing
gx, gy = (np.linspace(f.low[k], f.high[k], n) for k in range(2))
cells = np.array([[x, y] for y in gy for x in gx])


def cell_of(z):
    i = np.clip(np.rint((z[0] - f.low[0]) / (f.high[0] - f.low[0]) * (n - 1)), 0, n - 1)
    j = np.clip(np.rint((z[1] - f.low[1]) / (f.high[1] - f.low[1]) * (n - 1)), 0, n - 1)
    return int(j * n + i)


start_code = np.full(n * n, -1)
goal = np.zeros(n * n, bool)
hands_z = np.full(n * n, np.nan)
end = np.full((n * n, 8), -1)
nxt = np.full((n * n, 8), -1)
postures = f.model.inverse_transform(cells)
for c in range(n * n):
    code = plant.reset(postures[c])
    start_code[c] = 0 if code is None else code
    if code is not None:
        continue
    hands = plant.effectors()
    hands_z[c] = max(hands[2], hands[5])
    goal[c] = plant.reached()
    for a in range(8):
        plant.reset(postures[c])
        z = cells[c]
        for _ in range(repeats):
            _, code, reached = plant.step(f.model.inverse_transform((z + actions[a])[None])[0])
            z = f.model.transform(reached[None])[0]
            if code is not None:
                break
        end[c, a] = 0 if code is None else code
        nxt[c, a] = cell_of(z)
# Distance to the goal in RL steps over safe moves (end code 0), searched backwards.
into = [[] for _ in range(n * n)]
for c in range(n * n):
    for a in range(8):
        if end[c, a] == 0 and start_code[nxt[c, a]] == 0:
            into[nxt[c, a]].append(c)
dist = np.full(n * n, -1)
queue = deque(np.flatnonzero(goal))
dist[goal] = 0
while queue:
    c = queue.popleft()
    for b in into[c]:
        if dist[b] < 0:
            dist[b] = dist[c] + 1
            queue.append(b)
ok = start_code == 0
floor = ok & (hands_z <= 0.10)
np.savez(out, cells=cells, start_code=start_code, goal=goal, hands_z=hands_z, end=end, next=nxt, dist=dist,
         low=f.low, high=f.high, Z=f.model.Z_)
print(f"{out}: {ok.sum()} admissible of {n * n} cells, {goal.sum()} at h*, {floor.sum()} floor-level;"
      f" with a safe path to h*: {(ok & (dist >= 0)).sum()} admissible, {(floor & (dist >= 0)).sum()} floor-level")
print("end codes of the moves from admissible cells:", np.bincount(end[ok].ravel(), minlength=6))
print("floor-level cells: moves ending", np.bincount(end[floor].ravel(), minlength=6))
