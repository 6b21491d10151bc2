"""Exp 1's latent TD(0) loop: latentrl's Rust loop against a straightforward NumPy loop of the
same maths (dense normalised RBFs, soft-max look-ahead, GP decode and encode, TD(0)).

    .venv/bin/python benches/bench_td.py [--steps 20000] [--out benches/results/bench_td.json]

Both run one trial on one thread (RAYON_NUM_THREADS=1 is set before latentrl loads), on the
same fitted GPLVM and preset; the figure is RL steps per second. Also records the peak
resident memory of this benchmark process.
"""

from __future__ import annotations

import os

os.environ.setdefault("RAYON_NUM_THREADS", "1")

import argparse  # noqa: E402
import json  # noqa: E402
import platform  # noqa: E402
import resource  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from latentrl import GPLVM, _native  # noqa: E402
from latentrl._reference import rbf_centres, rbf_features, td0_update  # noqa: E402
from latentrl.datasets import bimanual_pairs  # noqa: E402
from latentrl.experiments.exp1 import Exp1Preset, configs  # noqa: E402
from latentrl.run_settings import latent_box  # noqa: E402
from latentrl.results import environment, write_json  # noqa: E402


def numpy_loop(model: GPLVM, preset: Exp1Preset, low, high, steps: int, seed: int) -> float:
    """Steps per second of the plain NumPy latent loop (episodes restart on termination)."""
    plant, learner = configs(preset)
    rng = np.random.default_rng(seed)
    centres, spacing = rbf_centres(low, high, learner["rbf_per_dim"])
    sigma = spacing * learner["rbf_width"]
    weights = np.full(len(centres), learner["initial_weight"])
    actions = np.array([[1, 0], [-1, 0], [0, 1], [0, -1]]) * learner["step"] * spacing
    grip, centre, target = (np.asarray(plant[k]) for k in ("grip", "obstacle_centre", "target"))
    dec = _gp_mean_factory(model.Z_, model.X_train_, model.theta_)
    enc = _gp_mean_factory(model.X_train_, model.Z_, model.encoder_theta_)
    alpha, gamma = learner["alpha"], learner["gamma"]

    def start():
        left = np.asarray(plant["start_mean"]) + plant["start_sd"] * rng.standard_normal(2)
        return enc(np.concatenate([left, left + grip]))

    z, t = start(), 0
    begin = time.perf_counter()
    for _ in range(steps):
        b = rbf_features(z, centres, sigma)
        q = np.array([weights @ rbf_features(z + a, centres, sigma) for a in actions])
        p = np.exp(learner["beta"] * (q - q.max()))
        u = actions[rng.choice(len(actions), p=p / p.sum())]
        goal = z + u
        hands = dec(goal)
        dropped = np.linalg.norm(hands[2:] - hands[:2] - grip) > plant["drop_tolerance"]
        hit = min(np.linalg.norm(hands[:2] - centre), np.linalg.norm(hands[2:] - centre)) < plant["obstacle_radius"]
        outside = np.any(goal < low) or np.any(goal > high)
        reward = np.exp(-plant["theta"] * np.sum((hands - target) ** 2))
        z_next = enc(hands)
        t += 1
        if dropped or hit or outside:
            td0_update(weights, b, reward + plant["penalty"], 0.0, alpha, gamma)
            z, t = start(), 0
            continue
        v_next = weights @ rbf_features(z_next, centres, sigma)
        td0_update(weights, b, reward, v_next, alpha, gamma)
        z = z_next
        if t >= plant["max_steps"]:
            z, t = start(), 0
    return steps / (time.perf_counter() - begin)


def _gp_mean_factory(inputs, outputs, theta):
    """GP mean predictor with K⁻¹Y pre-computed (Eq. 4), one point at a time."""
    mean = outputs.mean(axis=0)
    k = theta[0] * np.exp(-0.5 * np.sum((inputs[:, None] - inputs[None]) ** 2, -1) / theta[1])
    alpha = np.linalg.solve(k + theta[2] * np.eye(len(inputs)), outputs - mean)

    def predict(x):
        k_star = theta[0] * np.exp(-0.5 * np.sum((x - inputs) ** 2, -1) / theta[1])
        return k_star @ alpha + mean

    return predict


def rust_loop(model: GPLVM, preset: Exp1Preset, low, high, episodes: int, seed: int) -> float:
    """Steps per second of latentrl's latent loop (one trial)."""
    begin = time.perf_counter()
    plant, learner = configs(preset)
    out = _native.run_bimanual_trials(
        n_trials=1, episodes=episodes, base_seed=seed, plant=plant, learner=learner,
        decoder=model.decoder_, encoder=model.encoder_, latent_low=low, latent_high=high,
    )
    return float(out["steps"].sum()) / (time.perf_counter() - begin)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--steps", type=int, default=20000, help="NumPy loop steps")
    parser.add_argument("--episodes", type=int, default=2000, help="Rust loop episodes")
    parser.add_argument("--out", type=Path, default=Path("benches/results/bench_td.json"))
    args = parser.parse_args()
    preset = Exp1Preset()
    demos = bimanual_pairs(preset.n_demos, np.random.default_rng(0))
    model = GPLVM(random_state=0).fit(demos)
    low, high = latent_box(model.Z_, preset.latent_margin)
    rust_loop(model, preset, low, high, 20, 1)  # warm-up
    numpy_loop(model, preset, low, high, 200, 1)
    rust = rust_loop(model, preset, low, high, args.episodes, 0)
    numpy = numpy_loop(model, preset, low, high, args.steps, 0)
    figures = {
        "latent_step_per_s": {"latentrl": rust, "numpy": numpy, "speedup": rust / numpy},
        "latent_step_us": {"latentrl": 1e6 / rust, "numpy": 1e6 / numpy},
        "peak_rss_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        "rayon_threads": os.environ["RAYON_NUM_THREADS"],
        "machine": platform.machine(),
        "environment": environment(),
    }
    print(json.dumps({k: v for k, v in figures.items() if k != "environment"}, indent=2))
    write_json(args.out, figures)


if __name__ == "__main__":
    main()
