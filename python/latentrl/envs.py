"""Gymnasium environments of the paper's tasks, registered on import of `latentrl.envs`.

- `latentrl/BimanualReach-v0`: Experiment 1's kinematic toy (SPEC §4.1), in NumPy.
- `latentrl/TwoArms-v0`: Experiment 2's two planar arms (SPEC §4.2), simulated by the Rust
  `Sim` (rapier3d, PD servos).
- `latentrl/HumanoidLift-v0`: the 19-DoF KHR-1HV-like humanoid of Experiment 3 (SPEC §4.3)
  standing on a floor, lifting an object with both hands, simulated by the same `Sim`.
- `LatentSpaceWrapper`: observations and actions in the latent space of a fitted `PCA` or
  `GPLVM` (SPEC §3.1): an action is a latent delta, the target latent point is decoded to a
  posture target, and the reached posture is encoded back.

Every environment exposes `posture` (the current posture, (D,)) so the wrapper can encode
it, and `action_origin`, what an action (a delta, clipped to the action space) is added to.
"""

from __future__ import annotations

from importlib import resources
from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray

from latentrl import _native, humanoid
from latentrl._validation import positive
from latentrl.datasets import OFFSET, arms_forward
from latentrl.demos import load_demos

__all__ = ["BimanualReachEnv", "HumanoidLiftEnv", "LatentSpaceWrapper", "TwoArmsEnv"]

Obs = NDArray[np.float64]


def _canvas(size: int = 400) -> tuple[Any, Any]:
    """A matplotlib Figure on an Agg canvas (no pyplot, no display) and its axes."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(size / 100, size / 100), dpi=100)
    FigureCanvasAgg(fig)
    return fig, fig.add_subplot(aspect="equal")


def _pixels(fig: Any) -> NDArray[np.uint8]:
    fig.canvas.draw()
    return np.asarray(fig.canvas.buffer_rgba())[..., :3].copy()


def _posture_option(options: dict[str, Any] | None, n: int = 4) -> Obs | None:
    if not options or options.get("posture") is None:
        return None
    posture = np.asarray(options["posture"], dtype=np.float64)
    if posture.shape != (n,) or not np.all(np.isfinite(posture)):
        raise ValueError(f"options['posture']: expected {n} finite values, got {posture!r}")
    return posture



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


class BimanualReachEnv(gym.Env[Obs, Obs]):
    """Two planar hands carrying an object to a target (paper Sec. IV-A, SPEC §4.1).

    ## Description
    The kinematic toy of Experiment 1: the state is the two hand positions and a step moves
    them exactly to the commanded targets. The hands hold an object, so the right hand must
    stay at the left hand + (0.1, 0); a disc obstacle lies between the start and the target.

    ## Action Space
    `Box(-max_step, max_step, (4,), float64)`: deltas of the hand targets
    `(Δx_L, Δy_L, Δx_R, Δy_R)` in metres (clipped to the box).

    ## Observation Space
    `Box(-0.5 - max_step, 1.5 + max_step, (4,), float64)`: the hand positions
    `(x_L, y_L, x_R, y_R)`; leaving the state box `[-0.5, 1.5]²` per hand ends the episode, so
    the last observation may lie up to one step outside it.

    ## Rewards
    `exp(−θ ‖x − x*‖²)` with `x* = (0, 0, 0.1, 0)`, θ = 0.75 (Eq. 12); a step that ends the
    episode earns that reward plus the penalty −1.

    ## Starting State
    Left hand ~ N((1, 1), 0.1²·I), right hand = left + (0.1, 0). `reset(options={"posture":
    x})` starts at `x` instead.

    ## Episode End
    Terminated (with the penalty) when a coordinate leaves `[-0.5, 1.5]` (`"box_exit"`), a
    hand enters the disc of radius 0.2 at (0.5, 0.5) (`"obstacle"`) or
    `‖(x_R − x_L) − (0.1, 0)‖ > drop_tolerance` (`"drop"`); `info["end_reason"]` says which.
    Truncated after 500 steps (the paper's episode length).

    ## Arguments
    `drop_tolerance` (0.1: SPEC's RL default; 0.005 the paper-strict variant), `max_step`
    (0.05 m per coordinate), `render_mode` (`None` or `"rgb_array"`).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 20}
    target = np.array([0.0, 0.0, 0.1, 0.0])
    theta = 0.75
    penalty = -1.0
    box = (-0.5, 1.5)
    obstacle_centre = np.array([0.5, 0.5])
    obstacle_radius = 0.2
    dt = 0.05
    """One RL step (s): the paper's δt; the toy has no physics sub-steps."""

    def __init__(
        self,
        drop_tolerance: float = 0.1,
        max_step: float = 0.05,
        render_mode: str | None = None,
    ) -> None:
        self.drop_tolerance = positive("drop_tolerance", drop_tolerance)
        self.max_step = positive("max_step", max_step)
        self.render_mode = _check_render_mode(render_mode, self.metadata["render_modes"])
        self.action_space = spaces.Box(-max_step, max_step, (4,), np.float64)
        low, high = self.box[0] - max_step, self.box[1] + max_step
        self.observation_space = spaces.Box(low, high, (4,), np.float64)
        self.posture = np.zeros(4)

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
        posture = _posture_option(options)
        if posture is None:
            left = self.np_random.normal([1.0, 1.0], 0.1)
            posture = np.concatenate([left, left + OFFSET])
        self.posture = posture
        return self.posture.copy(), {}

    def _end_reason(self, x: Obs) -> str | None:
        if np.any(x < self.box[0]) or np.any(x > self.box[1]):
            return "box_exit"
        r2 = self.obstacle_radius**2
        if any(np.sum((h - self.obstacle_centre) ** 2) < r2 for h in (x[:2], x[2:])):
            return "obstacle"
        if np.linalg.norm(x[2:] - x[:2] - OFFSET) > self.drop_tolerance:
            return "drop"
        return None

    def step(self, action: Obs) -> tuple[Obs, SupportsFloat, bool, bool, dict[str, Any]]:
        """Moves the joints by `action` (clipped to ±`max_step`); returns observation,
        reward, terminated (obstacle, box exit or drop), truncated (never) and info
        (``end_reason``, ``reached``)."""
        delta = np.clip(np.asarray(action, dtype=np.float64), -self.max_step, self.max_step)
        self.posture = self.posture + delta
        reward = float(np.exp(-self.theta * np.sum((self.posture - self.target) ** 2)))
        reason = self._end_reason(self.posture)
        if reason is not None:
            reward += self.penalty
        rms = float(np.sqrt(np.sum((self.posture - self.target) ** 2) / 2))
        info = {"end_reason": reason, "reached": rms <= 0.1}
        return self.posture.copy(), reward, reason is not None, False, info

    def render(self) -> NDArray[np.uint8] | None:
        """An RGB image (H, W, 3) of the arms, target and obstacles if `render_mode` is
        ``"rgb_array"``, else None."""
        if self.render_mode != "rgb_array":
            return None
        from matplotlib.patches import Circle

        fig, ax = _canvas()
        ax.set(xlim=self.box, ylim=self.box)
        ax.add_patch(Circle(tuple(self.obstacle_centre), self.obstacle_radius, color="0.6"))
        ax.plot(*self.target.reshape(2, 2).T, "g*", ms=10)
        ax.plot(*self.posture.reshape(2, 2).T, "o-", color="C0", lw=3)
        return _pixels(fig)


WALLS = ((-1.0, 0.30, -0.36, 0.37), (-0.06, 0.30, 1.0, 0.37))
"""The corridor of Experiment 2 (SPEC §4.2 table): walls (x_min, y_min, x_max, y_max), metres."""


OBS_LOW = np.array([-3.6, -3.4, -3.6, -0.4, -0.76, -0.61, -0.76, -0.61])
OBS_HIGH = np.array([6.7, 0.4, 6.7, 3.4, 0.76, 0.61, 0.76, 0.61])
"""TwoArms observation bounds: the URDF joint limits widened by 0.1 rad; hands within the reach
(shoulders (±0.15, 0), links 0.3 + 0.3 m) plus 1 cm."""


def arms_urdf() -> str:
    """Path of the shipped two-arm URDF (shoulders (±0.15, 0), links 0.3 + 0.3 m)."""
    return str(resources.files("latentrl") / "data" / "two_arms.urdf")


class TwoArmsEnv(gym.Env[Obs, Obs]):
    """Two simulated planar 2-link arms holding an object (paper Sec. IV-B, SPEC §4.2).

    ## Description
    The arms of Experiment 2 in a rapier3d world (`latentrl._native.Sim`), each joint
    PD-servoed to its target; a step sets the targets and advances one RL step (12 physics
    steps of 1/240 s). Both hands must pass a corridor in a wall and reach a target above it
    without breaking the grip (right hand = left hand + (0.1, 0)).

    ## Action Space
    `Box(-max_step, max_step, (4,), float64)`: deltas of the joint targets
    `(q1_L, q2_L, q1_R, q2_R)` in radians, added to the reached posture (clipped to the box;
    the sim clamps targets to the joint limits).

    ## Observation Space
    `Box(low, high, (8,), float64)`: the 4 joint angles (rad, within the URDF joint limits
    widened by 0.1), then the hands `(x_L, y_L, x_R, y_R)` (m, within the arms' reach) from
    the simulated hand frames.

    ## Rewards
    `exp(−0.35 ‖(h − h*)/0.3‖²)` with `h* = (−0.05, 0.47, 0.05, 0.47)` (Eq. 12 with a length
    unit); a step that ends the episode earns that reward plus the penalty −1.

    ## Starting State
    Left hand uniform in (−0.25, 0.15) ± 0.03 m, right hand 0.1 m to its right, postures from
    the analytic IK (elbows outward): below the wall. `reset(options={"posture": q})` starts
    at the joint angles `q` instead.

    ## Episode End
    Terminated (with the penalty) when a hand lies in a wall (`"obstacle"`; walls are tested
    on the hand positions only, SPEC §4.2) or `‖(h_R − h_L) − (0.1, 0)‖ > drop_tolerance`
    (`"drop"`); `info["end_reason"]` says which. Truncated after 1000 steps (the paper's).

    ## Arguments
    `drop_tolerance` (0.005 m, SPEC), `max_step` (0.1 rad), `render_mode`
    (`None` or `"rgb_array"`).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 20}
    target = np.array([-0.05, 0.47, 0.05, 0.47])
    theta = 0.35
    length_scale = 0.3
    penalty = -1.0

    def __init__(
        self,
        drop_tolerance: float = 0.005,
        max_step: float = 0.1,
        render_mode: str | None = None,
    ) -> None:
        self.drop_tolerance = positive("drop_tolerance", drop_tolerance)
        self.max_step = positive("max_step", max_step)
        self.render_mode = _check_render_mode(render_mode, self.metadata["render_modes"])
        self.sim = _native.Sim(arms_urdf(), solver_iterations=2)
        self.dt = self.sim.dt
        """One RL step (s): physics step × sub-steps."""
        self.action_space = spaces.Box(-max_step, max_step, (4,), np.float64)
        self.observation_space = spaces.Box(OBS_LOW, OBS_HIGH, (8,), np.float64)

    @property
    def posture(self) -> Obs:
        """The reached joint angles (4,)."""
        return self.sim.joint_positions()

    @property
    def action_origin(self) -> Obs:
        """What an action's delta is added to: the reached posture (4,)."""
        return self.posture

    def hands(self) -> Obs:
        """The simulated hand positions `(x_L, y_L, x_R, y_R)`."""
        left = self.sim.frame_position("left_hand")[:2]
        return np.concatenate([left, self.sim.frame_position("right_hand")[:2]])

    def _obs(self) -> Obs:
        return np.concatenate([self.posture, self.hands()])

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Obs, dict[str, Any]]:
        """Starts an episode near the default grip (seeded by `seed`), or at
        ``options["posture"]``; returns the observation and an empty info dict."""
        super().reset(seed=seed)
        posture = _posture_option(options)
        if posture is None:
            left = np.array([-0.25, 0.15]) + self.np_random.uniform(-0.03, 0.03, 2)
            posture = _native.arms_ik(np.concatenate([left, left + OFFSET])[None])[0]
        self.sim.reset(posture)
        return self._obs(), {}

    def _end_reason(self, hands: Obs) -> str | None:
        for x, y in (hands[:2], hands[2:]):
            if any(x0 <= x <= x1 and y0 <= y <= y1 for x0, y0, x1, y1 in WALLS):
                return "obstacle"
        if np.linalg.norm(hands[2:] - hands[:2] - OFFSET) > self.drop_tolerance:
            return "drop"
        return None

    def step(self, action: Obs) -> tuple[Obs, SupportsFloat, bool, bool, dict[str, Any]]:
        """Sets the servo targets to the posture plus `action` (clipped to ±`max_step`) and
        runs the physics sub-steps; returns observation, reward, terminated (obstacle or
        drop), truncated (never) and info (``end_reason``, ``reached``)."""
        delta = np.clip(np.asarray(action, dtype=np.float64), -self.max_step, self.max_step)
        self.sim.set_targets(self.posture + delta)
        self.sim.step()
        obs = self._obs()
        hands = obs[4:]
        d2 = float(np.sum((hands - self.target) ** 2))
        reward = float(np.exp(-self.theta * d2 / self.length_scale**2))
        reason = self._end_reason(hands)
        if reason is not None:
            reward += self.penalty
        info = {"end_reason": reason, "reached": bool(np.sqrt(d2 / 2) <= 0.05)}
        return obs, reward, reason is not None, False, info

    def render(self) -> NDArray[np.uint8] | None:
        """An RGB image (H, W, 3) of the arms, target and obstacles if `render_mode` is
        ``"rgb_array"``, else None."""
        if self.render_mode != "rgb_array":
            return None
        from matplotlib.patches import Rectangle

        fig, ax = _canvas()
        ax.set(xlim=(-0.7, 0.7), ylim=(-0.2, 0.8))
        for x0, y0, x1, y1 in WALLS:
            ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, color="0.6"))
        ax.plot(*self.target.reshape(2, 2).T, "g*", ms=10)
        q = self.posture[None]
        elbows, hands = arms_forward(q, elbows=True)[0], self.hands()
        for arm, shoulder in enumerate((-0.15, 0.15)):
            xs = [shoulder, elbows[2 * arm], hands[2 * arm]]
            ys = [0.0, elbows[2 * arm + 1], hands[2 * arm + 1]]
            ax.plot(xs, ys, "o-", color="C0", lw=3)
        return _pixels(fig)


class HumanoidLiftEnv(gym.Env[Obs, Obs]):
    """The 19-DoF KHR-1HV-like humanoid lifting an object with both hands (SPEC §4.3).

    ## Description
    The shipped robot (`humanoid.urdf_path()`, 0.34 m, 1.29 kg) stands on a floor under
    gravity in a rapier3d world, every joint servo-PD'd to its target with the gains of the
    fall check (`humanoid.SERVO`: kp 8 N·m/rad, kd 0.1, torque cap 1.2 N·m; physics step
    1/240 s, 4 solver iterations, 12 steps = 0.05 s per env step). It holds an object of
    `humanoid.GRIP_WIDTH` (0.10 m) between its hands and should raise it to the top of the
    demonstrated lift without dropping it or falling.

    ## Action Space
    `Box(-max_step, max_step, (19,), float64)`: deltas of the joint targets (rad, in the order
    of `joint_names`), added to the current targets (`action_origin`; the sim clamps targets
    to the limits). Zero holds the robot where it was sent.

    ## Observation Space
    `Box(low, high, (25,), float64)`: the 19 joint angles (rad, within the URDF limits
    widened by 0.1), then the hands `(x, y, z)` left and right (m, world frame: x forward,
    y left, z up; within ±1 m).

    ## Rewards
    `exp(−0.35 ‖(h − h*)/0.1 m‖²)` over both hands (Eq. 12 with a length unit at the robot's
    scale; ours), `h*` = the hands of the demonstrated pose that holds them highest, that
    pose standing on the floor. A step that ends the episode earns that reward plus −1.

    ## Starting State
    The first pose of the lift demonstrations (`humanoid.demos_path()`: object low, straight
    arms) plus uniform noise of ±`start_noise` rad per joint, standing flat on the left sole.
    `reset(options={"posture": q})` starts at the joint angles `q` instead.

    ## Episode End
    Terminated (with the penalty) on a fall (`"fall"`: a sole tilting more than 20°, another
    link touching the floor, or the base height halving from the start) or a drop
    (`"drop"`: | ‖h_R − h_L‖ − 0.10 | > `drop_tolerance`); `info["end_reason"]` says which,
    `info["reached"]` whether the RMS per-hand distance to `h*` is ≤ 0.02 m. Truncated after
    200 steps (SPEC §4.3).

    ## Arguments
    `drop_tolerance` (0.02 m, ours), `max_step` (0.1 rad), `start_noise` (0.01 rad),
    `render_mode` (`None` or `"rgb_array"`: a side view of the links).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 20}
    theta = 0.35
    length_scale = 0.1
    reach_radius = 0.02
    penalty = -1.0
    soles = ["l_foot", "r_foot"]
    hand_links = ("l_hand", "r_hand")

    def __init__(
        self,
        drop_tolerance: float = 0.02,
        max_step: float = 0.1,
        start_noise: float = 0.01,
        render_mode: str | None = None,
    ) -> None:
        self.drop_tolerance = positive("drop_tolerance", drop_tolerance)
        self.max_step = positive("max_step", max_step)
        if not (np.isfinite(start_noise) and start_noise >= 0):
            raise ValueError(f"start_noise must be finite and >= 0, got {start_noise!r}")
        self.start_noise = float(start_noise)
        self.render_mode = _check_render_mode(render_mode, self.metadata["render_modes"])
        self.sim = self._new_sim()
        self.dt = self.sim.dt
        """One env step (s): physics step × sub-steps."""
        self.joint_names = self.sim.joint_names
        demos = load_demos(humanoid.demos_path(), expected_joints=self.joint_names).postures
        self.start_posture = demos[0]
        standing_hands = []
        for pose in demos:
            self.sim.reset_on_ground(pose, self.soles[0])
            standing_hands.append(self.hands())
        self.target = max(standing_hands, key=lambda hands: float(hands[[2, 5]].mean()))
        n = len(self.joint_names)
        self.action_space = spaces.Box(-max_step, max_step, (n,), np.float64)
        limits = humanoid.model()
        reach = np.tile([1.0, 1.0, 1.0], 2)
        self.observation_space = spaces.Box(
            np.concatenate([limits.lower - 0.1, -reach]), np.concatenate([limits.upper + 0.1, reach]), (n + 6,), np.float64
        )
        self.min_base_height = 0.0

    @staticmethod
    def _new_sim() -> _native.Sim:
        # A fresh world per episode: rapier keeps contact impulses (warm start) and rounds
        # joint coordinates relative to the previous state across a teleport, so a reset
        # in place would make an episode depend on the one before it.
        return _native.Sim(
            str(humanoid.urdf_path()), root="floating", ground=0.0, substeps=12, **humanoid.SERVO, **humanoid.PHYSICS
        )

    @property
    def posture(self) -> Obs:
        """The reached joint angles (19,)."""
        return self.sim.joint_positions()

    @property
    def action_origin(self) -> Obs:
        """What an action's delta is added to: the servo targets (19,), so that a zero
        action holds the robot where it was sent (the reached posture sags under gravity)."""
        return self.sim.targets()

    def hands(self) -> Obs:
        """The simulated hand positions `(x_L, y_L, z_L, x_R, y_R, z_R)` (m)."""
        return np.concatenate([self.sim.frame_position(link) for link in self.hand_links])

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Obs, dict[str, Any]]:
        """Stands the robot at the first demonstrated pose plus noise (seeded by `seed`), or at
        ``options["posture"]``; returns the observation and an empty info dict."""
        super().reset(seed=seed)
        posture = _posture_option(options, len(self.joint_names))
        if posture is None:
            noise = self.np_random.uniform(-self.start_noise, self.start_noise, len(self.joint_names))
            limits = humanoid.model()
            posture = np.clip(self.start_posture + noise, limits.lower, limits.upper)
        self.sim = self._new_sim()
        self.sim.reset_on_ground(posture, self.soles[0])
        self.min_base_height = 0.5 * float(self.sim.base_position()[2])
        return np.concatenate([self.posture, self.hands()]), {}

    def step(self, action: Obs) -> tuple[Obs, SupportsFloat, bool, bool, dict[str, Any]]:
        """Moves the servo targets by `action` (clipped to ±`max_step`) and runs the physics
        sub-steps; returns observation, reward, terminated (fall or drop), truncated (never)
        and info (``end_reason``, ``reached``)."""
        delta = np.clip(np.asarray(action, dtype=np.float64), -self.max_step, self.max_step)
        self.sim.set_targets(self.action_origin + delta)
        self.sim.step()
        hands = self.hands()
        d2 = float(np.sum((hands - self.target) ** 2))
        reward = float(np.exp(-self.theta * d2 / self.length_scale**2))
        fell = self.sim.fall_status(self.soles, min_base_height=self.min_base_height)[0]
        grip = abs(float(np.linalg.norm(hands[3:] - hands[:3])) - humanoid.GRIP_WIDTH)
        reason = "fall" if fell else "drop" if grip > self.drop_tolerance else None
        if reason is not None:
            reward += self.penalty
        info = {"end_reason": reason, "reached": bool(np.sqrt(d2 / 2) <= self.reach_radius)}
        return np.concatenate([self.posture, hands]), reward, reason is not None, False, info

    def render(self) -> NDArray[np.uint8] | None:
        """An RGB side view (H, W, 3) of the robot's links (x–z plane), the hands' target and
        the floor if `render_mode` is ``"rgb_array"``, else None."""
        if self.render_mode != "rgb_array":
            return None
        fig, ax = _canvas()
        base = self.sim.base_position()
        ax.set(xlim=(base[0] - 0.25, base[0] + 0.25), ylim=(-0.05, 0.45))
        ax.axhline(0.0, color="0.4", lw=2)
        for parent, child in humanoid.model().edges:
            a, b = self.sim.frame_position(parent), self.sim.frame_position(child)
            ax.plot([a[0], b[0]], [a[2], b[2]], "o-", color="C0", lw=2, ms=3)
        ax.plot(self.target[[0, 3]], self.target[[2, 5]], "g*", ms=10)
        return _pixels(fig)


class LatentSpaceWrapper(gym.Wrapper[Obs, Obs, Obs, Obs], gym.utils.RecordConstructorArgs):
    """RL in the latent space of a fitted `PCA` or `GPLVM` (SPEC §3.1, Fig. 3).

    The observation is the encoded reached posture `z = g(x̃)` (`model.transform`), clipped
    into the latent box. An action is a latent delta `u` (clipped to the action space): a
    target `z + u` outside the latent box is refused (no plant step, reward −1, terminated,
    `info["end_reason"] = "box_exit"`, SPEC §3.1 step 2); otherwise it is decoded
    (`model.inverse_transform`) to a posture target and handed to the wrapped environment as
    the delta `x̂ − o` from its `action_origin` `o` (the reached posture of the toy and the
    arms, the servo targets of the humanoid), which it clips to its own action space. With
    `variance_threshold`, a target whose predictive variance (`model.predict_variance`,
    GPLVM only) exceeds it is refused the same way (`"gated"`, SPEC §3.2).

    `latent_box` = (low, high), each (d,); default: the bounding box of the GPLVM's latent
    points `Z_` + 10 % per side (SPEC §4.2), or ± 3 s.d. (`explained_variance_`) for PCA.
    `max_step`: the largest latent delta per dimension; default 0.02 × the box width
    (about 0.4 RBF spacings of a 20-per-dimension grid).
    """

    penalty = -1.0

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
            self,
            model=model,
            variance_threshold=variance_threshold,
            latent_box=latent_box,
            max_step=max_step,
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
        d = int(model.n_components)
        if latent_box is None:
            if hasattr(model, "Z_"):
                z = np.asarray(model.Z_)
                pad = 0.1 * (z.max(axis=0) - z.min(axis=0))
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
        the wrapped env towards that posture. A target outside the latent box, or above
        `variance_threshold`, ends the episode with the penalty instead (``end_reason``
        ``"box_exit"`` / ``"gated"``)."""
        u = np.clip(np.asarray(action, dtype=np.float64), -self.max_step, self.max_step)
        target_z = self.z + u
        refused = None
        if np.any(target_z < self.latent_low) or np.any(target_z > self.latent_high):
            refused = "box_exit"
        elif self.variance_threshold is not None:
            if float(self.model.predict_variance(target_z[None])[0]) > self.variance_threshold:
                refused = "gated"
        if refused is not None:
            return self.z.copy(), self.penalty, True, False, {"end_reason": refused}
        target = self.model.inverse_transform(target_z[None])[0]
        origin = np.asarray(self.env.unwrapped.action_origin)  # type: ignore[attr-defined]
        _, reward, terminated, truncated, info = self.env.step(target - origin)
        self.z = self._encode()
        return self.z.copy(), reward, terminated, truncated, info


def _register() -> None:
    for env_id, entry, steps in (
        ("latentrl/BimanualReach-v0", "latentrl.envs:BimanualReachEnv", 500),
        ("latentrl/TwoArms-v0", "latentrl.envs:TwoArmsEnv", 1000),
        ("latentrl/HumanoidLift-v0", "latentrl.envs:HumanoidLiftEnv", 200),
    ):
        if env_id not in gym.registry:
            gym.register(id=env_id, entry_point=entry, max_episode_steps=steps)


_register()
