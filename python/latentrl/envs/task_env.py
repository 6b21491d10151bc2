"""`TaskEnv`: any task (`latentrl.Task`, docs/tasks.md) as a Gymnasium environment over the native
plant, which applies the task's rules; and the demonstrations shipped for the shipped tasks."""

from __future__ import annotations

from importlib import resources
from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray

from latentrl._validation import positive
from latentrl.demos import load_demos
from latentrl.envs.contract import Obs, check_render_mode, checked_action, posture_option, step_info
from latentrl.task import Task, end_reasons

SHIPPED_DEMOS = {"two_arms": "two_arms_demos.csv", "humanoid_lift": "khr1hv_lift_demos_bridged.csv"}
"""The demonstrations shipped for each shipped task (package data)."""


def shipped_demos(name: str) -> NDArray[np.float64]:
    """The shipped demonstrations of the shipped task `name` (rows: postures in joint order)."""
    path = resources.files("latentrl") / "data" / SHIPPED_DEMOS[name]
    return load_demos(str(path), expected_joints=Task.shipped(name).joint_names).postures


class TaskEnv(gym.Env[Obs, Obs]):
    """A task's robot as an environment: the native plant of `task` (the task's physics, servos,
    reward and endings; docs/tasks.md).

    ## Action Space
    `Box(-max_step, max_step, (D,), float64)`: deltas of the joint targets, in the order of
    `task.joint_names`, added to the current servo targets (`action_origin`; the sim clamps
    targets to the joint limits). Zero holds the robot where it was sent.

    ## Observation Space
    `Box(low, high, (D + 3E,), float64)`: the reached joint positions (within the limits widened
    by 0.1; ±2π for continuous joints), then each effector's world position (x, y, z; within
    ±`reach` m).

    ## Rewards
    The task's: `exp(−θ ‖(h − h*)/ℓ‖²)` over the effector positions h; a step that ends the
    episode earns it plus the task's penalty.

    ## Starting State
    The task's start rule from the plant's side: demo `episode.start_demo` of `demos` plus uniform
    noise of ±`episode.start_noise` per joint (seeded by `reset(seed=)`), redrawn while it breaks
    a rule; `reset(options={"posture": q})` starts at `q` instead (refused postures raise).

    ## Episode End
    Terminated (with the penalty) when a step breaks a rule of the task: `info["end_reason"]` is
    "obstacle", "fall", "drop" (a constraint) or "box_exit"; `info["reached"]` says whether the
    effectors are within the target's reach radius. Truncated by the registration's
    `max_episode_steps` (the task's `episode.max_steps`), and with `info["end_reason"]`
    "success" when the task's `target.hold_steps` held (not a terminal state: bootstrap it).
    Built directly, as for your own task, nothing else truncates (Gymnasium's convention: the
    time limit is a wrapper): `gymnasium.wrappers.TimeLimit(TaskEnv(task),
    task.to_dict()["episode"]["max_steps"])` is what the registered ids are.

    ## Arguments
    `task` (a Task or a shipped task's name), `demos` (N, D in `task.joint_names` order, or a
    DataFrame whose columns name the joints, matched by name: `Task.postures_of`; default: the
    shipped demos of a shipped task, none otherwise), `max_step` (0.1 rad), `reach` (1 m, the observation bound of
    effector coordinates), `render_mode` (`None` or `"rgb_array"`), `view` (the frames' view:
    "top", "side", "front" or "3d", `latentrl.render.VIEWS`; default: chosen as `render` says).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 20}

    def __init__(
        self,
        task: Task | str,
        demos: Any = None,
        max_step: float = 0.1,
        reach: float = 1.0,
        render_mode: str | None = None,
        view: str | None = None,
    ) -> None:
        from latentrl.render import checked_view

        self.view = None if view is None else checked_view(view)
        if isinstance(task, str):
            if demos is None and task in SHIPPED_DEMOS:
                demos = shipped_demos(task)
            task = Task.shipped(task)
        self.task = task
        self.max_step = positive("max_step", max_step)
        self.render_mode = check_render_mode(render_mode, self.metadata["render_modes"])
        self.demos = None if demos is None else task.postures_of(demos)
        self.plant = task.plant(self.demos)
        self.dt = task.rl_dt
        """One env step (s): physics step × sub-steps."""
        self.joint_names = task.joint_names
        d, e = len(task.joint_names), len(task.effectors)
        lower = np.where(np.isfinite(task.lower), task.lower - 0.1, -2 * np.pi)
        upper = np.where(np.isfinite(task.upper), task.upper + 0.1, 2 * np.pi)
        self.action_space = spaces.Box(-max_step, max_step, (d,), np.float64)
        self.observation_space = spaces.Box(
            np.concatenate([lower, np.full(3 * e, -reach)]), np.concatenate([upper, np.full(3 * e, reach)]),
            (d + 3 * e,), np.float64,
        )
        self._draws = int(task.to_dict()["episode"]["max_start_draws"])

    @property
    def target(self) -> Obs:
        """h*: the target of every effector, flat (3E,)."""
        return np.asarray(self.task.to_dict()["target"]["position"], dtype=np.float64).ravel()

    @property
    def posture(self) -> Obs:
        """The reached joint positions (D,)."""
        return np.asarray(self.plant.joint_positions())

    @property
    def action_origin(self) -> Obs:
        """What an action's delta is added to: the servo targets (D,), so that a zero action
        holds the robot where it was sent (a reached posture sags under gravity)."""
        return np.asarray(self.plant.targets())

    def effectors(self) -> Obs:
        """The effector positions (3E,)."""
        return np.asarray(self.plant.effectors())

    def _obs(self) -> Obs:
        return np.concatenate([self.posture, self.effectors()])

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Obs, dict[str, Any]]:
        """Starts an episode by the task's start rule (seeded by `seed`), or at
        ``options["posture"]``; returns the observation and an empty info dict."""
        super().reset(seed=seed)
        posture = posture_option(options, len(self.joint_names))
        if posture is not None:
            end = self.plant.reset(posture)
            if end is not None:
                raise ValueError(f"options['posture'] breaks a rule of the task: {end_reasons()[end]}")
            return self._obs(), {}
        for _ in range(self._draws):
            start = self.plant.sample_start(int(self.np_random.integers(2**63)))
            if self.plant.reset(start) is None:
                return self._obs(), {}
        raise ValueError(f"no admissible start in {self._draws} draws of the task's start rule")

    def step(self, action: Obs) -> tuple[Obs, SupportsFloat, bool, bool, dict[str, Any]]:
        """Moves the servo targets by `action` (clipped to ±`max_step`) and runs one RL step;
        returns observation, reward, terminated (a rule broken), truncated (a success of the
        task's `target.hold_steps`: the episode is over, the state is not terminal) and info
        (``end_reason``, ``reached``)."""
        delta = np.clip(checked_action(action, len(self.joint_names)), -self.max_step, self.max_step)
        reward, end, _ = self.plant.step(self.action_origin + delta)
        success = end is not None and end_reasons()[end] == "success"
        info = step_info(end, self.plant.reached())
        return self._obs(), float(reward), end is not None and not success, success, info

    def render(self) -> NDArray[np.uint8] | None:
        """An RGB image (H, W, 3) of the robot's links, the target and the floor if `render_mode`
        is ``"rgb_array"``, else None: in the env's `view`, or by default the x–z side view of a
        floating robot and, for a fixed one, the plane its links and target spread over most
        (`latentrl.render.view_axes`)."""
        if self.render_mode != "rgb_array":
            return None
        from latentrl.render import draw_task

        return draw_task(self.task, self.plant, view=self.view)

