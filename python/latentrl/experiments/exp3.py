"""Experiment 3 (paper Sec. IV-C, Fig. 7b–e and 8): the 19-DoF KHR-1HV-like humanoid lifts an
object with both hands, learning in the GPLVM latent space of its 7 lift demonstrations
through a physics simulation (rapier3d, floor, gravity, servo PD).

The GPLVM (d = 2) is fitted to the shipped centred lift demos (4 straight-arm hip-hinge poses,
3 knee-squat poses). A TD(0) learner with 8 latent actions and 20 × 20 RBFs steers the robot:
each decoded posture is the servo target for one RL step (0.05 s). The task is that of
`latentrl.envs.HumanoidLiftEnv`: reward `exp(−0.35 ‖(h − h*)/0.1 m‖²)` over both hands, h* the
hands of the demo holding them highest (the top of the squat); −1 and the episode ends on a
fall, a drop (| ‖h_R − h_L‖ − 0.10 | > 0.02 m) or a contact with the obstacle: a box in front
of the robot that the straight-arm lift (upper body bent over it) touches and the squat lift
clears (`OBSTACLE`).

Figures: Fig. 7e (return per episode, mean ± s.d. over trials), 7b/7c (value function before
and after learning over the latent box, GPLVM variance shaded, the obstacle, falls at rest
and drops mapped into latent space), 7d (hand paths in the side view x–z with the obstacle),
Fig. 8 (frames of a learnt lift, drawn kinematically from the recorded postures).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from latentrl import _native, humanoid
from latentrl.demos import load_demos
from latentrl.experiments.latent_runs import (
    gplvm_info,
    recorded_episodes,
    recorded_tests,
    robot_learner,
)
from latentrl.experiments.presets import check_floats, check_ints, latent_box
from latentrl.experiments.runner import RunTrials, Setup, run_rl
from latentrl.gplvm import GPLVM

OBSTACLE = (0.215, 0.0, 0.175, 0.05, 0.12, 0.125)
"""The obstacle (ours): an axis-aligned box (cx, cy, cz, hx, hy, hz) in metres, world frame of
the standing robot (x forward, z up; the left sole's frame at x = y = 0): x ∈ [0.165, 0.265],
|y| ≤ 0.12, z ∈ [0.05, 0.30]. Demos 0–2 (straight arms, upper body bent over, hands 18–19 cm
forward) touch it; demo 3 and the squat demos 4–6 (hands ≤ 12 cm forward) keep clear."""
TASK_HEAD = 13
"""Columns of a recorded trajectory row before the joint angles: hands (6), base position (3),
base orientation quaternion (x, y, z, w)."""
STARTS = ("uniform", "demo")
"""Start modes: uniform over the latent box (redrawn while refused) or a demo + noise."""


@dataclass(frozen=True)
class Exp3Preset:
    """Exp 3: the KHR-1HV-like humanoid lifts an object, latent-space TD(0) through physics (Fig. 7, 8)."""

    trials: int = 4
    """Independent RL trials (paper: "several"; ours: 4, which fill 2 cores in two rounds)."""
    episodes: int = 6000
    """Training episodes per trial (paper: about 6000)."""
    steps: int = 200
    """Steps per episode before a time-out (paper: 200)."""
    seed: int = 0
    """Base seed: GPLVM fit and every trial's RNG derive from it."""
    gplvm_max_iter: int = 1000
    """L-BFGS iteration cap of the GPLVM fit."""
    latent_margin: float = 0.1
    """Latent box = bounding box of the fitted latent points, widened by this share per side (ours)."""
    drop_tolerance: float = 0.02
    """Dropped when | ‖h_R − h_L‖ − 0.10 | exceeds this, metres (ours, as HumanoidLiftEnv)."""
    reward_theta: float = 0.35
    """θ of the reward exp(−θ ‖(h − h*)/ℓ‖²) (paper)."""
    reward_length: float = 0.1
    """Length unit ℓ of the reward, metres (ours: the robot's scale, as HumanoidLiftEnv)."""
    reach_radius: float = 0.02
    """'Reached the target': RMS per-hand distance to h* at most this, metres (ours)."""
    rbf_per_dim: int = 20
    """RBF centres per latent dimension (paper: 20)."""
    rbf_cutoff: float = 3.0
    """Sparse RBFs: centres farther than this many σ contribute nothing (ours)."""
    beta: float = 20.0
    """Soft-max inverse temperature β (ours: Exp. 2's)."""
    alpha: float = 0.8
    """TD(0) learning rate α (ours: Exp. 2's)."""
    gamma: float = 0.99
    """Discount γ (ours: Exp. 2's)."""
    step_fraction: float = 0.2
    """Latent step length as a share of the RBF spacing per dimension, diagonals √2 longer (ours)."""
    initial_weight: float = 0.0
    """Initial value weights (0 paper-like; 1/(1−γ) = 100 is optimistic)."""
    variance_threshold: float = 0.0
    """Latent targets with GPLVM variance above this are infeasible (−1, end); 0 = off (SPEC §3.2)."""
    start: str = "uniform"
    """Starts: "uniform" over the latent box, redrawn while the decoded posture at rest is outside
    the joint limits, touches the obstacle, breaks the grip, has a non-sole link on the floor or
    its centre of mass outside the feet; or "demo": the demo `start_demo` (default the low knee-squat pose)
    plus uniform noise of ±start_noise per joint, encoded (ours)."""
    start_demo: int = 4
    """Demo row of the "demo" start (ours: 4, the low knee-squat pose; rows 0–2 touch the
    obstacle, so they cannot start an episode)."""
    start_noise: float = 0.01
    """Noise of the "demo" start, rad per joint (ours, as HumanoidLiftEnv)."""
    test_episodes: int = 20
    """Frozen test episodes per trial after training (no TD updates; ours: 20, Fig. 7d and 8
    draw the first ten)."""
    physics_dt: float = humanoid.PHYSICS["dt"]
    """Physics time step, s; one RL step = physics_dt × substeps = 0.05 s (ours, as Exp. 2)."""
    substeps: int = 12
    """Physics steps per RL step."""
    solver_iterations: int = humanoid.PHYSICS["solver_iterations"]
    """rapier solver iterations per physics step (humanoid.PHYSICS)."""
    pgs_iterations: int = humanoid.PHYSICS["pgs_iterations"]
    """PGS passes per solver iteration (humanoid.PHYSICS: stands 10 s within 1 mm)."""
    kp: float = humanoid.SERVO["kp"]
    """Servo stiffness of every joint, N·m/rad (humanoid.SERVO, SPEC §4.3's MuJoCo study)."""
    kd: float = humanoid.SERVO["kd"]
    """Servo damping of every joint, N·m·s/rad (humanoid.SERVO)."""
    max_force: float = humanoid.SERVO["max_force"]
    """Servo torque cap, N·m (humanoid.SERVO, the URDF effort)."""
    curve_window: int = 500
    """Running-mean window of Fig. 7e (at most episodes // 5 for short runs)."""
    map_grid: int = 50
    """Grid points per latent dimension where Fig. 7b/7c test the decoded postures at rest for
    obstacle contact, falls and drops in the sim (ours)."""

    def validate(self) -> None:
        """ValueError naming the first field with an impossible value."""
        check_ints(
            self,
            ("trials", "episodes", "steps", "gplvm_max_iter", "rbf_per_dim", "substeps", "solver_iterations",
             "pgs_iterations", "curve_window", "map_grid"),
        )
        check_ints(self, ("seed", "test_episodes", "start_demo"), minimum=0)
        if self.start_demo >= 7:
            raise ValueError(f"start_demo must be a row of the 7 lift demos (0–6), got {self.start_demo!r}")
        check_floats(
            self,
            ("drop_tolerance", "reward_theta", "reward_length", "reach_radius", "rbf_cutoff", "beta", "alpha",
             "step_fraction", "physics_dt", "kp", "max_force"),
            positive=True,
        )
        check_floats(self, ("latent_margin", "variance_threshold", "kd", "start_noise"), positive=False)
        if not np.isfinite(self.initial_weight):
            raise ValueError(f"initial_weight must be finite, got {self.initial_weight!r}")
        if not 0 <= self.gamma < 1:
            raise ValueError(f"gamma must lie in [0, 1), got {self.gamma!r}")
        if self.start not in STARTS:
            raise ValueError(f"start must be one of {STARTS}, got {self.start!r}")

    @classmethod
    def quick(cls) -> Exp3Preset:
        """The default test suite's run: 2 trials × 300 episodes × 100 steps, w₀ = 100
        (optimistic), step 0.5 × spacing, 10 frozen test episodes, a 20 × 20 map in Fig. 7b/7c
        (≈ 1 min on 2 cores); long enough for the return and the reach rate to rise."""
        return dataclasses.replace(
            cls(), trials=2, episodes=300, steps=100, initial_weight=100.0, step_fraction=0.5, test_episodes=10,
            map_grid=20,
        )


@lru_cache(maxsize=1)
def target() -> tuple[float, ...]:
    """h* = (x_L, y_L, z_L, x_R, y_R, z_R): the hands of the demo holding them highest, standing
    (from HumanoidLiftEnv, so that both define one task)."""
    from latentrl.envs import HumanoidLiftEnv

    return tuple(float(v) for v in HumanoidLiftEnv().target)


def native_config(preset: Exp3Preset, start_posture: NDArray[np.float64]) -> dict[str, Any]:
    """The preset in the configuration keys of `_native.run_lift_trials`."""
    return {
        "target": list(target()),
        "theta": preset.reward_theta,
        "length_scale": preset.reward_length,
        "grip_width": humanoid.GRIP_WIDTH,
        "drop_tolerance": preset.drop_tolerance,
        "reached_rms": preset.reach_radius,
        "obstacles": [list(OBSTACLE)],
        "start_posture": start_posture.tolist(),
        "start_noise": preset.start_noise,
        "dt": preset.physics_dt,
        "substeps": preset.substeps,
        "solver_iterations": preset.solver_iterations,
        "pgs_iterations": preset.pgs_iterations,
        "kp": preset.kp,
        "kd": preset.kd,
        "max_force": preset.max_force,
        "alpha": preset.alpha,
        "gamma": preset.gamma,
        "initial_weight": preset.initial_weight,
        "beta": preset.beta,
        "step_fraction": preset.step_fraction,
        "max_steps": preset.steps,
        "centres_per_dim": preset.rbf_per_dim,
        "rbf_cutoff": preset.rbf_cutoff,
        "variance_threshold": preset.variance_threshold or None,
        "start": "uniform" if preset.start == "uniform" else "plant",
    }


@dataclass(frozen=True)
class Fitted:
    """The demonstrations, the GPLVM fitted to them and the latent box of the learner."""

    demos: NDArray[np.float64]
    model: GPLVM
    low: NDArray[np.float64]
    high: NDArray[np.float64]


def fit(preset: Exp3Preset) -> Fitted:
    """Demos, GPLVM and latent box; cached on the fields they depend on."""
    return _fit(preset.seed, preset.gplvm_max_iter, preset.latent_margin)


@lru_cache(maxsize=4)
def _fit(seed: int, max_iter: int, margin: float) -> Fitted:
    demos = load_demos(humanoid.demos_path(), expected_joints=humanoid.model().joint_names).postures
    model = GPLVM(n_components=2, max_iter=max_iter, random_state=seed).fit(demos)
    low, high = latent_box(model.Z_, margin)
    return Fitted(demos, model, low, high)


def learner(preset: Exp3Preset, model: GPLVM, low: NDArray[np.float64], high: NDArray[np.float64]) -> RunTrials:
    """The latent learner of `preset` on the humanoid, in the latent box (`low`, `high`) of a
    GPLVM fitted to lift postures (19 joints, `humanoid.model().joint_names` order); the
    "demo" start uses the training posture `start_demo`."""
    config = native_config(preset, model.X_train_[preset.start_demo])
    return robot_learner(_native.run_lift_trials, str(humanoid.urdf_path()), preset, model, (low, high), config)


def setup(preset: Exp3Preset) -> Setup:
    """The GPLVM on the lift demos, its latent box and the latent learner's runner."""
    fitted = fit(preset)
    model = fitted.model
    info = {
        "gplvm": gplvm_info(model),
        "latent_box": {"low": fitted.low, "high": fitted.high},
        "demo_latent": model.Z_,
        "recorded_episodes": recorded_episodes(preset.episodes),
        "recorded_test_episodes": recorded_tests(preset.test_episodes),
        "obstacle": list(OBSTACLE),
        "target": list(target()),
    }
    return Setup(learners={"latent": learner(preset, model, fitted.low, fitted.high)}, info=info)


def rest_map(preset: Exp3Preset, postures: NDArray[np.float64]) -> tuple[NDArray[np.int8], NDArray[np.float64]]:
    """For each posture (clipped to the joint limits), standing at rest in the sim: the code 1
    touches the obstacle, 4 a non-sole link on the floor (fall), 3 the grip broken by more than
    the drop tolerance, 0 none (the plant's start test, without the support margin); and the
    hands (M, 6)."""
    sim = _native.Sim(str(humanoid.urdf_path()), root="floating", ground=0.0, **humanoid.SERVO, **humanoid.PHYSICS)
    cx, cy, cz, hx, hy, hz = OBSTACLE
    sim.add_box_obstacle(np.array([cx, cy, cz]), np.array([hx, hy, hz]))
    h = humanoid.model()
    out = np.zeros(len(postures), dtype=np.int8)
    all_hands = np.zeros((len(postures), 6))
    for i, q in enumerate(np.clip(postures, h.lower, h.upper)):
        sim.reset_on_ground(q, "l_foot")
        hands = np.concatenate([sim.frame_position("l_hand"), sim.frame_position("r_hand")])
        all_hands[i] = hands
        grip = abs(float(np.linalg.norm(hands[3:] - hands[:3])) - humanoid.GRIP_WIDTH)
        if sim.contacts():
            out[i] = 1
        elif sim.fall_status(["l_foot", "r_foot"], min_base_height=0.0)[0]:
            out[i] = 4
        elif grip > preset.drop_tolerance:
            out[i] = 3
    return out, all_hands


def run_exp3(preset: Exp3Preset, out_dir: Path | str, *, progress: bool = True) -> dict[str, Any]:
    """Runs (or continues) Experiment 3 into `out_dir` (results.json, returns.npz, fig7b–e, fig8)."""
    from latentrl.experiments.exp3_figures import figures  # matplotlib: the [plot] extra

    return run_rl(preset, out_dir, setup=setup, figures=figures, progress=progress)
