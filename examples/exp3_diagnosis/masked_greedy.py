"""Would masking the latent actions whose target touches the block at rest save Exp 3's obstacle
endings? (issue #18)

    python masked_greedy.py runs/exp3-full [starts per trial] [first trial] [trials]

From the same uniform latent starts, runs each trial's learnt greedy policy twice without
learning: as learnt, and with every action whose decoded target posture touches the block at rest
(`TaskPlant.classify`, end code 1) left out of the look-ahead (all left out: as learnt). Prints
the endings and the successes of both (ended by the step limit with h* reached at some step,
the runner's rule, and with the hands at h* at the last step), and for the unmasked runs how many
obstacle endings had a touching target among their last 3.
"""
import sys
from pathlib import Path

import numpy as np

from latentrl import _native
from saved_policies import load

LAST = 3
DIRECTIONS = np.array([[1, 0], [-1, 0], [0, 1], [0, -1], [1, 1], [1, -1], [-1, 1], [-1, -1]], float)
out = Path(sys.argv[1])
starts = int(sys.argv[2]) if len(sys.argv) > 2 else 50
first = int(sys.argv[3]) if len(sys.argv) > 3 else 0
_, fitted, task, policies = load(out)
config = task.to_dict()
learner, max_steps = config["learner"], config["episode"]["max_steps"]
trials = int(sys.argv[4]) if len(sys.argv) > 4 else len(policies) - first
low, high = fitted.low, fitted.high
steps = learner["step"] * (high - low) / (learner["rbf_per_dim"] - 1)
if learner["actions"] != "axes_and_diagonals":
    raise SystemExit("this script knows the 8 axes-and-diagonals actions only")
if learner["move_correction"]:
    raise SystemExit("its masked look-ahead is V's alone (Eq. 11): a run with learner.move_correction would be compared "
                     "with another policy")
plant, judge = task.plant(fitted.demos), task.plant(fitted.demos)
decode = fitted.model.inverse_transform


def episode(policy, posture, masked):
    """(end code or None, h* reached at some step, at h* at the end, touching flags of the
    chosen targets)."""
    plant.reset(posture)
    end, touching, ever = None, [], False
    for _ in range(max_steps):
        target, z, _ = policy.act(np.asarray(plant.joint_positions()))
        if masked:
            candidates = z + steps * DIRECTIONS
            q = policy.values(candidates)
            clear = judge.classify(decode(np.clip(candidates, low, high)))[0] != 1
            if clear.any():
                a = int(np.argmax(np.where(clear, q, -np.inf)))
                target = decode(np.clip(candidates[a], low, high)[None])[0]
        touching.append(bool(judge.classify(target[None])[0][0] == 1))
        _, end, _ = plant.step(np.ascontiguousarray(target))
        ever |= plant.reached()
        if end is not None:
            break
    return end, ever, plant.reached(), touching


rng = np.random.default_rng(12345 + first)
totals = {m: {"episodes": 0, "success": 0, "at_h_at_end": 0, "ends": {}} for m in ("learnt", "masked")}
seen = {"obstacle": 0, "touching_target_last": 0}
for t in range(first, first + trials):
    policy = policies[t]
    for _ in range(starts):
        posture = decode(rng.uniform(low, high)[None])[0]
        if plant.reset(posture) is not None:
            continue
        for mode in ("learnt", "masked"):
            end, ever, at_end, touching = episode(policy, posture, mode == "masked")
            tally = totals[mode]
            tally["episodes"] += 1
            tally["success"] += end is None and ever
            tally["at_h_at_end"] += end is None and at_end
            name = "timeout" if end is None else _native.end_reasons()[end]
            tally["ends"][name] = tally["ends"].get(name, 0) + 1
            if mode == "learnt" and end == 1:
                seen["obstacle"] += 1
                seen["touching_target_last"] += any(touching[-LAST:])
print(out, f"trials {first}..{first + trials - 1} × {starts} uniform starts:", totals, seen)
