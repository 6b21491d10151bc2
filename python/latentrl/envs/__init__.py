"""Gymnasium environments, registered when `latentrl` is imported (as `import ale_py` does;
Gymnasium itself loads when first imported, the environments registered then:
`latentrl._gym_registration`).

- `TaskEnv(task)`: any task (`latentrl.Task`, docs/tasks.md) as an environment over the native
  plant, which applies the task's rules. The registered robot environments are instances:
  `latentrl/TwoArms-v0` (Experiment 2's arms, `tasks/two_arms.toml`) and
  `latentrl/HumanoidLift-v0` (Experiment 3's humanoid, `tasks/humanoid_lift.toml`).
- `latentrl/BimanualReach-v0` (`BimanualReachEnv`): Experiment 1's kinematic toy over the native
  toy plant.
- `LatentSpaceWrapper`: observations and actions in the latent space of a fitted `PCA` or
  `GPLVM` (docs/method.md §RL loop): an action is a latent delta, the target latent point is decoded
  to a posture target, and the reached posture is encoded back.

Every environment exposes `posture` (the current posture, (D,)) so the wrapper can encode it,
and `action_origin`, what an action (a delta, clipped to the action space) is added to.
"""

from __future__ import annotations

import gymnasium as gym

from latentrl import _native
from latentrl.envs.bimanual_reach import BimanualReachEnv
from latentrl.envs.latent_space import LatentSpaceWrapper
from latentrl.envs.task_env import SHIPPED_DEMOS, TaskEnv, shipped_demos
from latentrl.task import Task

__all__ = ["BimanualReachEnv", "LatentSpaceWrapper", "TaskEnv", "SHIPPED_DEMOS", "shipped_demos"]

REGISTERED = {"latentrl/TwoArms-v0": "two_arms", "latentrl/HumanoidLift-v0": "humanoid_lift"}
"""The registered task environments and their shipped tasks."""


def register() -> None:
    """Registers latentrl's environments with Gymnasium (done on `import latentrl`); a task
    environment's episodes are truncated at its task's `episode.max_steps`."""
    if "latentrl/BimanualReach-v0" not in gym.registry:
        steps = _native.bimanual_config()[0]["max_steps"]
        gym.register(id="latentrl/BimanualReach-v0", entry_point="latentrl.envs:BimanualReachEnv", max_episode_steps=steps)
    for env_id, name in REGISTERED.items():
        if env_id not in gym.registry:
            steps = Task.shipped(name).to_dict()["episode"]["max_steps"]
            gym.register(id=env_id, entry_point="latentrl.envs:TaskEnv", kwargs={"task": name}, max_episode_steps=steps)


register()
