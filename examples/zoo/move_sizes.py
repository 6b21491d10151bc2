"""How far one learner move takes a trained run's robot, in reach radii: from random latent points
`z`, one of the learner's moves at its step (`z + step · spacing · u`, `u` a unit action of
`learner.actions`), both points decoded, the plant reset at the first and stepped towards the
second. Prints the effectors' move at rest and how far they are from the second posture's
effectors at rest after 1 and 4 RL steps (median and 90th percentile; `examples/zoo/README.md`,
"Session 14").

    python examples/zoo/move_sizes.py RUN_DIR [RUN_DIR ...]   # folders of `latentrl train`
"""

from __future__ import annotations

import sys

import numpy as np

from latentrl import LatentPolicy

MOVES = 150
"""Moves measured per robot."""

for run in sys.argv[1:]:
    policy = LatentPolicy.load(f"{run}/policy.npz")
    config = policy.task.to_dict()
    radius, learner = config["target"]["reach_radius"], config["learner"]
    low, high = policy.latent_low, policy.latent_high
    spacing = (high - low) / (learner["rbf_per_dim"] - 1)
    units = np.vstack([np.eye(len(low)), -np.eye(len(low))])
    if learner["actions"] != "axes":
        units = np.vstack([units, [[a, b] for a in (1, -1) for b in (1, -1)]]) if len(low) == 2 else units
    plant = policy.task.plant(policy.demos)
    rng = np.random.default_rng(0)
    moved: list[float] = []
    off: dict[int, list[float]] = {1: [], 4: []}

    while len(moved) < MOVES:
        z = rng.uniform(low, high)
        to = np.clip(z + learner["step"] * spacing * units[rng.integers(len(units))], low, high)
        start, goal = policy.model.inverse_transform(np.vstack([z, to]))
        if plant.reset(goal) is not None:
            continue
        rest = plant.effectors().reshape(-1, 3).copy()
        if plant.reset(start) is not None:
            continue
        moved.append(float(np.linalg.norm(rest - plant.effectors().reshape(-1, 3), axis=1).max()))
        for k in range(1, 5):
            if plant.step(goal)[1] is not None:
                break
            if k in off:
                off[k].append(float(np.linalg.norm(plant.effectors().reshape(-1, 3) - rest, axis=1).max()))
    shown = " | ".join(f"after {k}: {np.median(v) / radius:.2f} r / {np.percentile(v, 90) / radius:.2f} r"
                       for k, v in off.items() if v)
    print(f"{config['name']}: step {learner['step']}, moved {np.median(moved) / radius:.2f} r | {shown}")
