"""An off-the-shelf agent on the latent-space task: Stable-Baselines3 PPO trains on
`latentrl.envs.LatentSpaceWrapper` as it is (plus Gymnasium's own `RescaleAction`).

A GPLVM (d = 2) is fitted to demonstrated postures, the task is wrapped so that observations
and actions live in its latent space, and SB3's `PPO("MlpPolicy")` trains on it for a fixed
budget. The trained policy (deterministic) and a uniform-random policy are then scored on the
same seeded evaluation episodes. On one core, BimanualReach (the kinematic toy) learns in about
a minute; TwoArms (rapier physics) too, at about 1.5 times the cost per step.

    pip install "latentrl[sb3]"
    python examples/sb3_ppo.py [--env BimanualReach] [--timesteps 150000] [--out result.json]
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import stable_baselines3
import torch
from numpy.typing import NDArray
from stable_baselines3 import PPO

import latentrl
from latentrl import GPLVM
from latentrl.datasets import arm_postures, bimanual_pairs
from latentrl.envs import LatentSpaceWrapper  # importing latentrl.envs registers latentrl/*

Demos = Callable[[int, np.random.Generator], NDArray[np.float64]]
ENVS: dict[str, tuple[str, Demos]] = {
    "BimanualReach": ("latentrl/BimanualReach-v0", bimanual_pairs),  # hand positions
    "TwoArms": ("latentrl/TwoArms-v0", arm_postures),  # joint angles
}


def make_env(env_id: str, model: GPLVM) -> gym.Env[Any, Any]:
    """The task in `model`'s latent space, actions rescaled to [-1, 1] (PPO's Gaussian
    policy starts with unit s.d.; the latent steps are a few hundredths wide)."""
    latent = LatentSpaceWrapper(gym.make(env_id), model)
    return gym.wrappers.RescaleAction(latent, np.float64(-1), np.float64(1))


def evaluate(
    env: gym.Env[Any, Any], act: Callable[[Any], Any], episodes: int, seed: int
) -> list[float]:
    """Undiscounted returns of `act` on episodes reset with seeds seed, seed + 1, ..."""
    returns = []
    for i in range(episodes):
        obs, _ = env.reset(seed=seed + i)
        total, done = 0.0, False
        while not done:
            obs, reward, terminated, truncated, _ = env.step(act(obs))
            total += float(reward)
            done = terminated or truncated
        returns.append(total)
    return returns


def main(argv: Sequence[str] | None = None) -> dict[str, Any]:
    """Trains PPO, evaluates it against a random policy, prints and returns the figures."""
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--env", choices=sorted(ENVS), default="BimanualReach")
    parser.add_argument("--timesteps", type=int, default=150_000)
    parser.add_argument("--eval-episodes", type=int, default=20)
    parser.add_argument("--demos", type=int, default=50, help="demonstrated postures for the GPLVM")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, help="also write the result as JSON here")
    args = parser.parse_args(argv)
    torch.set_num_threads(1)  # small MLP: one thread is fastest, and deterministic

    start = time.perf_counter()
    env_id, demonstrations = ENVS[args.env]
    demos = demonstrations(args.demos, np.random.default_rng(args.seed))
    model = GPLVM(n_components=2, random_state=args.seed).fit(demos)
    # SB3's defaults but longer rollouts, larger minibatches and a little entropy: the learnt
    # path skirts the obstacle, and with the defaults it flips into it and back between updates.
    agent = PPO("MlpPolicy", make_env(env_id, model), n_steps=4096, batch_size=256,
                ent_coef=0.01, seed=args.seed, device="cpu")
    agent.learn(total_timesteps=args.timesteps)
    train_time = time.perf_counter() - start

    env = make_env(env_id, model)
    eval_seed = 10_000 + args.seed  # fresh seeded start states, the same for both policies
    ppo = evaluate(env, lambda obs: agent.predict(obs, deterministic=True)[0],
                   args.eval_episodes, eval_seed)
    env.action_space.seed(eval_seed)
    random = evaluate(env, lambda obs: env.action_space.sample(), args.eval_episodes, eval_seed)

    result = {
        "env": args.env,
        "timesteps": agent.num_timesteps,  # --timesteps rounded up to whole rollouts
        "seed": args.seed,
        "eval_episodes": args.eval_episodes,
        "ppo_return_mean": float(np.mean(ppo)),
        "ppo_return_sd": float(np.std(ppo)),
        "random_return_mean": float(np.mean(random)),
        "random_return_sd": float(np.std(random)),
        "ppo_returns": ppo,
        "random_returns": random,
        "train_time_s": train_time,
        "wall_time_s": time.perf_counter() - start,
        "versions": {
            "latentrl": latentrl.__version__,
            "stable_baselines3": stable_baselines3.__version__,
            "torch": torch.__version__,
            "gymnasium": gym.__version__,
        },
    }
    print(f"{args.env}: {agent.num_timesteps} PPO steps, {args.eval_episodes} evaluation episodes")
    for name, returns in (("PPO", ppo), ("random", random)):
        print(f"  {name:6} return {np.mean(returns):6.1f} ± {np.std(returns):5.1f}")
    print(f"  wall time {result['wall_time_s']:.0f} s ({train_time:.0f} s training)")
    if args.out is not None:
        args.out.write_text(json.dumps(result, indent=2) + "\n")
    return result


if __name__ == "__main__":
    main()
