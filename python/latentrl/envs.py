"""Gymnasium environments, registered when `latentrl` is imported (as `import ale_py` does).

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

from importlib import resources
from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray

from latentrl import _native
from latentrl._validation import positive
from latentrl.demos import load_demos
from latentrl.task import Task, end_reasons, run_default

__all__ = ["BimanualReachEnv", "LatentSpaceWrapper", "TaskEnv"]

Obs = NDArray[np.float64]

SHIPPED_DEMOS = {"two_arms": "two_arms_demos.csv", "humanoid_lift": "khr1hv_lift_demos_bridged.csv"}
"""The demonstrations shipped for each shipped task (package data)."""


def shipped_demos(name: str) -> NDArray[np.float64]:
    """The shipped demonstrations of the shipped task `name` (rows: postures in joint order)."""
    path = resources.files("latentrl") / "data" / SHIPPED_DEMOS[name]
    return load_demos(str(path), expected_joints=Task.shipped(name).joint_names).postures


def _check_render_mode(render_mode: str | None, modes: list[str]) -> str | None:
    """`render_mode` if it is None or one of `modes` (these need matplotlib), else a ValueError."""
    if render_mode not in (None, *modes):
        raise ValueError(f"render_mode must be None or one of {modes}, got {render_mode!r}")
    if render_mode is not None:
        try:
            import matplotlib  # noqa: F401
        except ModuleNotFoundError as err:
            raise ModuleNotFoundError(
                f"render_mode={render_mode!r} draws with matplotlib: pip install 'latentrl[plot]'",
                name="matplotlib",
            ) from err
    return render_mode


def _posture_option(options: dict[str, Any] | None, n: int) -> Obs | None:
    if not options or options.get("posture") is None:
        return None
    posture = np.asarray(options["posture"], dtype=np.float64)
    if posture.shape != (n,) or not np.all(np.isfinite(posture)):
        raise ValueError(f"options['posture']: expected {n} finite values, got {posture!r}")
    return posture


def _action(action: Any, n: int) -> Obs:
    """`action` as n finite floats, or a ValueError naming it (issue #38: a NaN action was clipped
    to NaN and stepped without a word; one of another length failed in NumPy's broadcasting)."""
    try:
        values = np.asarray(action, dtype=np.float64)
    except (TypeError, ValueError) as err:
        raise ValueError(f"action: expected {n} finite numbers, got {action!r} ({err})") from None
    if values.shape != (n,) or not np.all(np.isfinite(values)):
        raise ValueError(f"action: expected {n} finite numbers, got {values!r}")
    return values


def _info(end: int | None, reached: bool) -> dict[str, Any]:
    return {"end_reason": None if end is None else end_reasons()[end], "reached": reached}


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

    ## Arguments
    `task` (a Task or a shipped task's name), `demos` (N, D; default: the shipped demos of a
    shipped task, none otherwise), `max_step` (0.1 rad), `reach` (1 m, the observation bound of
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
        self.render_mode = _check_render_mode(render_mode, self.metadata["render_modes"])
        self.demos = None if demos is None else np.ascontiguousarray(demos, dtype=np.float64)
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
        posture = _posture_option(options, len(self.joint_names))
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
        delta = np.clip(_action(action, len(self.joint_names)), -self.max_step, self.max_step)
        reward, end, _ = self.plant.step(self.action_origin + delta)
        success = end is not None and end_reasons()[end] == "success"
        info = _info(end, self.plant.reached())
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


class BimanualReachEnv(gym.Env[Obs, Obs]):
    """Two planar hands carrying an object to a target (paper Sec. IV-A,
    docs/method.md §Experiment 1), over the native toy plant of Experiment 1 (its rules and
    defaults: `latentrl run exp1 --help`).

    ## Action Space
    `Box(-max_step, max_step, (4,), float64)`: deltas of the hand targets
    `(Δx_L, Δy_L, Δx_R, Δy_R)` in metres (clipped to the box).

    ## Observation Space
    `Box(box_low - max_step, box_high + max_step, (4,), float64)`: the hand positions
    `(x_L, y_L, x_R, y_R)`; leaving the state box ends the episode, so the last observation may
    lie up to one step outside it.

    ## Rewards
    `exp(−θ ‖x − x*‖²)` with `x* = (0, 0, 0.1, 0)`, θ = 0.75 (Eq. 12); a step that ends the
    episode earns that reward plus the penalty −1.

    ## Starting State
    Left hand ~ N((1, 1), 0.1²·I), right hand = left + (0.1, 0). `reset(options={"posture":
    x})` starts at `x` instead.

    ## Episode End
    Terminated (with the penalty) when a coordinate leaves the box (`"box_exit"`), a hand
    enters the disc obstacle (`"obstacle"`) or the grip breaks by more than `drop_tolerance`
    (`"drop"`); `info["end_reason"]` says which. Truncated after 500 steps (the paper's).

    ## Arguments
    `drop_tolerance` (0.1: our RL default, docs/method.md §Experiment 1; 0.005 the paper-strict
    variant), `max_step` (0.05 m per coordinate), `render_mode` (`None` or `"rgb_array"`).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 20}
    dt = 0.05
    """One RL step (s): the paper's δt; the toy has no physics sub-steps."""

    def __init__(self, drop_tolerance: float = 0.1, max_step: float = 0.05, render_mode: str | None = None) -> None:
        self.plant = _native.BimanualPlant({"drop_tolerance": drop_tolerance})
        self.config = self.plant.config()
        self.max_step = positive("max_step", max_step)
        self.render_mode = _check_render_mode(render_mode, self.metadata["render_modes"])
        self.action_space = spaces.Box(-max_step, max_step, (4,), np.float64)
        low, high = self.config["box_low"] - max_step, self.config["box_high"] + max_step
        self.observation_space = spaces.Box(low, high, (4,), np.float64)

    @property
    def posture(self) -> Obs:
        """The hand positions (4,)."""
        return np.asarray(self.plant.state())

    @property
    def action_origin(self) -> Obs:
        """What an action's delta is added to: the current state (4,)."""
        return self.posture

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Obs, dict[str, Any]]:
        """Starts an episode near the default grip (seeded by `seed`), or at
        ``options["posture"]``; returns the observation and an empty info dict."""
        super().reset(seed=seed)
        posture = _posture_option(options, 4)
        if posture is None:
            posture = self.plant.sample_start(int(self.np_random.integers(2**63)))
        self.plant.reset(posture)
        return self.posture, {}

    def step(self, action: Obs) -> tuple[Obs, SupportsFloat, bool, bool, dict[str, Any]]:
        """Moves the hands by `action` (clipped to ±`max_step`); returns observation, reward,
        terminated (obstacle, box exit or drop), truncated (never) and info (``end_reason``,
        ``reached``)."""
        delta = np.clip(_action(action, len(self.posture)), -self.max_step, self.max_step)
        reward, end = self.plant.step(self.posture + delta)
        return self.posture, float(reward), end is not None, False, _info(end, self.plant.reached())

    def render(self) -> NDArray[np.uint8] | None:
        """An RGB image (H, W, 3) of the hands, the target and the obstacle if `render_mode` is
        ``"rgb_array"``, else None."""
        if self.render_mode != "rgb_array":
            return None
        from latentrl.render import draw_bimanual

        return draw_bimanual(self.config, self.posture)


class LatentSpaceWrapper(gym.Wrapper[Obs, Obs, Obs, Obs], gym.utils.RecordConstructorArgs):
    """RL in the latent space of a fitted `PCA` or `GPLVM` (docs/method.md §RL loop, paper Fig. 3).

    The observation is the encoded reached posture `z = g(x̃)` (`model.transform`), clipped
    into the latent box. An action is a latent delta `u` (clipped to the action space); the
    target `z + u` is refused as the learner refuses it (`latent_core::refused`: outside the
    latent box, `"box_exit"`; with `variance_threshold`, a GPLVM variance above it, `"variance_gate"`
    — docs/method.md §RL loop step 2, §Variance gating): no plant step, the wrapped task's penalty,
    terminated. Otherwise it is decoded (`model.inverse_transform`) and handed to the wrapped
    environment as the delta `x̂ − o` from its `action_origin` `o`, which it clips to its own action
    space.

    `latent_box` = (low, high), each (d,); default: the bounding box of the GPLVM's latent
    points `Z_` widened by the `[run]` table's default `latent_margin` per side (10 %;
    docs/method.md §RL loop), or ± 3 s.d. (`explained_variance_`) for
    PCA. `max_step`: the largest latent delta per dimension; default 0.02 × the box width
    (about 0.4 RBF spacings of a 20-per-dimension grid).
    """

    def __init__(
        self,
        env: gym.Env[Obs, Obs],
        model: Any,
        variance_threshold: float | None = None,
        *,
        latent_box: tuple[Any, Any] | None = None,
        max_step: float | None = None,
    ) -> None:
        gym.utils.RecordConstructorArgs.__init__(
            self, model=model, variance_threshold=variance_threshold, latent_box=latent_box, max_step=max_step,
        )
        gym.Wrapper.__init__(self, env)
        posture = np.asarray(env.unwrapped.posture)  # type: ignore[attr-defined]
        if getattr(model, "n_features_in_", None) != posture.shape[0]:
            raise ValueError(
                f"model must be fitted to postures of {posture.shape[0]} values, "
                f"got n_features_in_={getattr(model, 'n_features_in_', None)!r}"
            )
        if variance_threshold is not None:
            if not hasattr(model, "predict_variance"):
                raise ValueError("variance_threshold needs a model with predict_variance (GPLVM)")
            if not (np.isfinite(variance_threshold) and variance_threshold > 0):
                raise ValueError(f"variance_threshold must be > 0, got {variance_threshold!r}")
        d = int(model.n_components_)
        if latent_box is None:
            if hasattr(model, "Z_"):
                z = np.asarray(model.Z_)
                pad = run_default("latent_margin") * (z.max(axis=0) - z.min(axis=0))
                low, high = z.min(axis=0) - pad, z.max(axis=0) + pad
            else:
                sd = np.sqrt(np.asarray(model.explained_variance_))
                low, high = -3 * sd, 3 * sd
        else:
            low, high = (np.asarray(b, dtype=np.float64) for b in latent_box)
        if low.shape != (d,) or high.shape != (d,) or not np.all(high > low):
            raise ValueError(f"latent_box must be (low, high) of shape ({d},) with high > low")
        step = 0.02 * (high - low) if max_step is None else np.full(d, max_step, dtype=np.float64)
        if not np.all(np.isfinite(step) & (step > 0)):
            raise ValueError(f"max_step must be finite and > 0, got {max_step!r}")
        self.model = model
        task = getattr(env.unwrapped, "task", None)
        config = task.to_dict()["episode"] if task is not None else getattr(env.unwrapped, "config", {})
        self.penalty = float(config.get("penalty", -1.0))
        """The penalty of a refused target: the wrapped task's."""
        self.variance_threshold = variance_threshold
        self.latent_low, self.latent_high, self.max_step = low, high, step
        self.action_space = spaces.Box(-step, step, (d,), np.float64)
        self.observation_space = spaces.Box(low, high, (d,), np.float64)
        self.z = np.zeros(d)

    def _encode(self) -> Obs:
        posture = np.asarray(self.env.unwrapped.posture)  # type: ignore[attr-defined]
        z = np.asarray(self.model.transform(posture[None])[0], dtype=np.float64)
        return np.clip(z, self.latent_low, self.latent_high)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Obs, dict[str, Any]]:
        """Resets the wrapped env and returns the encoded latent point of its posture."""
        _, info = self.env.reset(seed=seed, options=options)
        self.z = self._encode()
        return self.z.copy(), info

    def step(self, action: Obs) -> tuple[Obs, SupportsFloat, bool, bool, dict[str, Any]]:
        """Moves the latent point by `action` (clipped to ±`max_step`), decodes it and steps
        the wrapped env towards that posture; a refused target ends the episode with the
        penalty instead (``end_reason`` ``"box_exit"`` / ``"variance_gate"``)."""
        u = np.clip(np.asarray(action, dtype=np.float64), -self.max_step, self.max_step)
        target_z = self.z + u
        variance = None
        if self.variance_threshold is not None:  # a GPLVM: mean and variance in one native call
            decoded, variances = self.model.inverse_transform(target_z[None], return_variance=True)
            variance = float(variances[0])
        else:
            decoded = self.model.inverse_transform(target_z[None])
        refused = _native.latent_refusal(
            list(target_z), list(self.latent_low), list(self.latent_high), variance, self.variance_threshold
        )
        if refused is not None:
            return self.z.copy(), self.penalty, True, False, {"end_reason": end_reasons()[refused]}
        target = decoded[0]
        origin = np.asarray(self.env.unwrapped.action_origin)  # type: ignore[attr-defined]
        _, reward, terminated, truncated, info = self.env.step(target - origin)
        self.z = self._encode()
        return self.z.copy(), reward, terminated, truncated, info


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
