"""Would an action filter on the decoded target see Exp 3's obstacle endings coming? (issue #18)

    python target_at_rest.py runs/exp3-full [starts per trial] [trials]

Runs each trial's learnt greedy policy (no learning) from uniform latent starts and classifies,
at rest (`TaskPlant.classify`), the posture every chosen latent target decodes to. Counts, for
the episodes that end on the block, how many had a target touching the block at rest in their
last steps, and, for the episodes that run to the step limit, how many passed through such a target
(the good paths a filter would cut).
"""
import sys
from pathlib import Path

import numpy as np

from saved_policies import load

LAST = 3
out = Path(sys.argv[1])
starts = int(sys.argv[2]) if len(sys.argv) > 2 else 200
_, fitted, task, policies = load(out)
max_steps = task.to_dict()["episode"]["max_steps"]
trials = int(sys.argv[3]) if len(sys.argv) > 3 else len(policies)
low, high = fitted.low, fitted.high
plant, judge = task.plant(fitted.demos), task.plant(fitted.demos)

rng = np.random.default_rng(12345)
totals = {"episodes": 0, "obstacle": 0, "obstacle_seen_last": 0, "obstacle_seen_any": 0,
          "timeout": 0, "timeout_touching_target": 0, "targets": 0, "targets_touching": 0}
for t in range(trials):
    policy = policies[t]
    for _ in range(starts):
        z0 = rng.uniform(low, high)
        if plant.reset(fitted.model.inverse_transform(z0[None])[0]) is not None:
            continue
        totals["episodes"] += 1
        end, targets, reached_h = None, [], False
        while end is None and len(targets) < max_steps:
            target, _, _ = policy.act(np.asarray(plant.joint_positions()))
            _, end, _ = plant.step(target)
            targets.append(target)
        codes = judge.classify(np.array(targets))[0]
        touching = codes == 1
        totals["targets"] += len(codes)
        totals["targets_touching"] += int(touching.sum())
        if end == 1:
            totals["obstacle"] += 1
            totals["obstacle_seen_last"] += bool(touching[-LAST:].any())
            totals["obstacle_seen_any"] += bool(touching.any())
        elif end is None:
            totals["timeout"] += 1
            totals["timeout_touching_target"] += bool(touching.any())
print(out, f"{trials} trials × {starts} uniform starts, last {LAST} targets:", totals)
