"""`BimanualReachEnv`: Experiment 1's kinematic toy (paper Sec. IV-A) as a Gymnasium environment
over the native toy plant."""

from __future__ import annotations

from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray

from latentrl import _native
from latentrl._validation import positive
from latentrl.envs.contract import Obs, check_render_mode, checked_action, posture_option, step_info


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
        self.render_mode = check_render_mode(render_mode, self.metadata["render_modes"])
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
        posture = posture_option(options, 4)
        if posture is None:
            posture = self.plant.sample_start(int(self.np_random.integers(2**63)))
        self.plant.reset(posture)
        return self.posture, {}

    def step(self, action: Obs) -> tuple[Obs, SupportsFloat, bool, bool, dict[str, Any]]:
        """Moves the hands by `action` (clipped to ±`max_step`); returns observation, reward,
        terminated (obstacle, box exit or drop), truncated (never) and info (``end_reason``,
        ``reached``)."""
        delta = np.clip(checked_action(action, len(self.posture)), -self.max_step, self.max_step)
        reward, end = self.plant.step(self.posture + delta)
        return self.posture, float(reward), end is not None, False, step_info(end, self.plant.reached())

    def render(self) -> NDArray[np.uint8] | None:
        """An RGB image (H, W, 3) of the hands, the target and the obstacle if `render_mode` is
        ``"rgb_array"``, else None."""
        if self.render_mode != "rgb_array":
            return None
        from latentrl.render import draw_bimanual

        return draw_bimanual(self.config, self.posture)

