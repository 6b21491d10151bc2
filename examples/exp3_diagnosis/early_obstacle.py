"""Are Exp 3's early obstacle endings avoidable? (issue #18, docs/exp3.md)

    python early_obstacle.py runs/exp3-full [starts per trial] [trials]

From uniform latent starts, runs each trial's learnt greedy policy (no learning). For every
episode that ends on the block within `EARLY` steps, it replays the start with each latent
action held for `EARLY` steps and with the start posture held, and counts the starts from which
some choice stays clear of the block: what a better policy could save, against what the start
itself decides.
"""
import sys
from pathlib import Path

import numpy as np

from saved_policies import load

EARLY = 10
out = Path(sys.argv[1])
starts = int(sys.argv[2]) if len(sys.argv) > 2 else 200
_, fitted, task, policies = load(out)
learner = task.to_dict()["learner"]
trials = int(sys.argv[3]) if len(sys.argv) > 3 else len(policies)
low, high = fitted.low, fitted.high
spacing = (high - low) / (learner["rbf_per_dim"] - 1)
directions = np.array([[1, 0], [-1, 0], [0, 1], [0, -1], [1, 1], [1, -1], [-1, 1], [-1, -1]], float)
plant = task.plant(fitted.demos)
decode = fitted.model.inverse_transform


def held(z0: np.ndarray, direction: np.ndarray, posture: np.ndarray) -> int | None:
    """End code within EARLY steps when the latent target moves along `direction` every step."""
    plant.reset(posture)
    z = z0.copy()
    for _ in range(EARLY):
        z = np.clip(z + learner["step"] * spacing * direction, low, high)
        _, end, _ = plant.step(decode(z[None])[0])
        if end is not None:
            return end
    return None


rng = np.random.default_rng(12345)
totals = {"episodes": 0, "obstacle": 0, "early": 0, "avoidable": 0, "hold_clear": 0}
early_z = []
for t in range(trials):
    policy = policies[t]
    for _ in range(starts):
        z0 = rng.uniform(low, high)
        posture = decode(z0[None])[0]
        if plant.reset(posture) is not None:
            continue
        totals["episodes"] += 1
        end, steps = None, 0
        while end is None and steps < task.to_dict()["episode"]["max_steps"]:
            target, _, _ = policy.act(np.asarray(plant.joint_positions()))
            _, end, _ = plant.step(target)
            steps += 1
        if end != 1:
            continue
        totals["obstacle"] += 1
        if steps > EARLY:
            continue
        totals["early"] += 1
        early_z.append(z0)
        clear = [held(z0, d, posture) != 1 for d in directions]
        hold = held(z0, np.zeros(2), posture) != 1
        totals["avoidable"] += any(clear) or hold
        totals["hold_clear"] += hold
print(out, f"{trials} trials × {starts} uniform starts:", totals)
print("early-obstacle starts (z):", np.round(np.array(early_z), 3).tolist())
