"""Stubs of the Rust extension `latentrl._native` (hand-written; checked by mypy.stubtest)."""

from collections.abc import Callable, Mapping, Sequence
from os import PathLike
from typing import Any, Literal, final

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "MAX_EPISODES",
    "MAX_GP_POINTS",
    "BimanualPlant",
    "GpMap",
    "InternalError",
    "InvalidInputError",
    "LatentPolicy",
    "LatentrlError",
    "NumericalError",
    "Projection",
    "Sim",
    "Task",
    "TaskPlant",
    "__version__",
    "arms_elbows",
    "arms_fk",
    "arms_ik",
    "bimanual_config",
    "bimanual_schema",
    "end_reasons",
    "fall_check",
    "gplvm_back_constrained_nll_grad",
    "gplvm_nll_grad",
    "grip_error",
    "latent_refusal",
    "learner_values",
    "run_bimanual_trials",
    "run_task_trials",
    "latent_survey",
    "task_schema",
    "run_config",
    "urdf_info",
    "demo_columns",
]

__version__: str
MAX_GP_POINTS: int
"""The most points of a GP map or the GPLVM objective (a 2 GiB N×N kernel matrix)."""
MAX_EPISODES: int
"""The most episode records of one run: trials × (episodes + test_episodes)."""

class LatentrlError(ValueError):
    """Base class of latentrl's errors (a ValueError)."""

class InvalidInputError(LatentrlError):
    """An argument had the wrong shape, a non-finite value or an impossible value."""

class InternalError(LatentrlError):
    """A bug in latentrl's Rust core (a caught panic); please report it with the message."""

class NumericalError(LatentrlError):
    """A computation could not be carried out stably
    (e.g. a kernel matrix not positive definite)."""

@final
class GpMap:
    """A fitted GP map (paper Eq. 4): predictive mean and variance from inputs to outputs."""

    def __new__(
        cls,
        inputs: NDArray[np.float64],
        outputs: NDArray[np.float64],
        theta: NDArray[np.float64],
        inducing: NDArray[np.float64] | None = None,
    ) -> GpMap:
        """Fits the map to `inputs` (N, q) and `outputs` (N, p) with `theta` = (θ1, θ2, θ3); with
        `inducing` (m, q), the sparse (DTC) map through those inducing inputs."""
    @staticmethod
    def back_constraint(inputs: NDArray[np.float64], weights: NDArray[np.float64], log_beta: float) -> GpMap:
        """The back-constrained GPLVM's encoder: mean `weights · k_b(inputs, x)` with `weights`
        (N, p) and the back-constraint kernel of squared length-scale `exp(log_beta)`."""
    def predict(
        self, queries: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Means (M, p) and variances (M,) at `queries` (M, q)."""
    def predict_mean(self, queries: NDArray[np.float64]) -> NDArray[np.float64]:
        """Means only (M, p) at `queries` (M, q): no variance, several times faster."""
    def predict_one(self, x: NDArray[np.float64]) -> tuple[NDArray[np.float64], float]:
        """Mean (p,) and variance at one point `x` (q,)."""
    @property
    def input_dim(self) -> int:
        """Input dimension q."""
    @property
    def output_dim(self) -> int:
        """Output dimension p."""
    @property
    def jitter(self) -> float:
        """Jitter added to the kernel matrix's diagonal to factorise it (0.0 if none)."""
    @property
    def theta(self) -> list[float]:
        """(θ1, θ2, θ3)."""

@final
class Projection:
    """The iterative-projection encoder posture → latent of a GPLVM decoder (docs/encoders.md)."""

    def __new__(
        cls,
        decoder: GpMap,
        postures: NDArray[np.float64],
        *,
        max_iter: int = ...,
        margin: float = ...,
        tracking: bool = ...,
    ) -> Projection:
        """The projection under `decoder` (a GpMap latent → posture) fitted to `postures` (N, D),
        with `max_iter` L-BFGS iterations per stage and the latent box widened by `margin`;
        `tracking`: after a move, search from the commanded latent point (docs/encoders.md).
        Defaults are the core's (`ProjectionConfig::DEFAULT`: 200 iterations, margin 0.5, no
        tracking)."""
    def encode(self, postures: NDArray[np.float64]) -> NDArray[np.float64]:
        """Latent points (M, d) of `postures` (M, D), in parallel."""
    def encode_one(self, posture: NDArray[np.float64]) -> NDArray[np.float64]:
        """The latent point (d,) of one `posture` (D,): the call the Rust RL loop makes each step."""
    @property
    def input_dim(self) -> int:
        """Posture dimension D."""
    @property
    def output_dim(self) -> int:
        """Latent dimension d."""

@final
class Sim:
    """A URDF robot in a rapier3d world, every actuated joint PD-servoed to its target."""

    def __new__(
        cls,
        urdf: str | PathLike[str],
        *,
        root: Literal["fixed", "floating"] = ...,
        floor: float | None = None,
        physics: Mapping[str, object] | None = None,
        servo: Mapping[str, object] | None = None,
        balance_inertia: bool = ...,
    ) -> Sim:
        """Builds the world from `urdf`: a path, or the URDF XML itself (a str starting with `<`).
        `root` "fixed" (default, `RootMode::default`) or "floating"; `floor` the height of a floor
        half-space (normal +z) or None; `physics` and `servo` dicts of the task file's `[physics]`
        and `[servo]` keys; `balance_inertia` repairs inertias the physics cannot take
        (`urdf-info --balance-inertia`; off by default, `LoadOptions::default`)."""
    @property
    def joint_names(self) -> list[str]:
        """Names of the actuated joints, in the order of postures and targets."""
    @property
    def dt(self) -> float:
        """Duration of one RL step, `dt · substeps` (s)."""
    @property
    def time(self) -> float:
        """Simulated time since the last reset (s)."""
    def reset(self, posture: NDArray[np.float64]) -> None:
        """Teleports the robot to `posture` (num_joints,) at rest and aims the servos at it."""
    def reset_on_ground(self, posture: NDArray[np.float64], sole: str, clearance: float = ...) -> None:
        """Teleports a floating robot to `posture` at rest standing on the floor: the base is
        placed so that link `sole` lies flat, its lowest corner `clearance` m above the ground
        (needs a `floor`; default `sim::fall::GROUND_CLEARANCE`, 0.5 mm)."""
    def base_position(self) -> NDArray[np.float64]:
        """World position (3,) of the root link's origin (the floating base)."""
    def fall_status(
        self, soles: list[str], *, min_base_height: float, max_sole_tilt: float = ...
    ) -> tuple[bool, float, float, str | None]:
        """The fall test now: `(fell, base_height, sole_tilt, ground_contact)`, fallen when the
        base origin is below `min_base_height` (m), a link of `soles` tilts more than
        `max_sole_tilt` (rad) or another link touches the floor (the first such link, else None)."""
    def set_targets(self, targets: NDArray[np.float64]) -> None:
        """Sets every servo target (num_joints,), clamped to the joint limits."""
    def targets(self) -> NDArray[np.float64]:
        """The servo targets after clamping (num_joints,)."""
    def step(self, n: int | None = None) -> None:
        """Advances `n` physics steps of `dt`, or one RL step when `n` is None."""
    def joint_positions(self) -> NDArray[np.float64]:
        """The joint positions (num_joints,): the reached posture."""
    def joint_velocities(self) -> NDArray[np.float64]:
        """The joint velocities (num_joints,)."""
    def frame_position(self, link: str) -> NDArray[np.float64]:
        """World position (3,) of link `link`'s frame (e.g. a hand)."""
    def add_box_obstacle(
        self,
        center: NDArray[np.float64],
        half_extents: NDArray[np.float64],
        *,
        sensor: bool = ...,
        name: str = ...,
    ) -> int:
        """Adds a static axis-aligned box at `center` (3,) with `half_extents` (3,); returns its
        id. A sensor (default) is passed through but still reported by `contacts`. Defaults are
        a task file's obstacle's (`ObstacleConfig`: a sensor named "box")."""
    def contacts(self) -> list[tuple[str, int]]:
        """Every (link name, obstacle id) pair whose shapes are within the contact margin."""

def gplvm_nll_grad(
    latent: NDArray[np.float64],
    data: NDArray[np.float64],
    log_theta: NDArray[np.float64],
    inducing: NDArray[np.float64] | None = None,
) -> tuple[float, NDArray[np.float64], NDArray[np.float64], float]:
    """GPLVM objective at `latent` (N, d) for centred `data` (N, D): returns (nll, dnll/dlatent
    (N, d), dnll/dlog_theta (3,), jitter); with `inducing` (m, d) the sparse (DTC) bound, its
    gradient (N + m, d) that of the latent points then of the inducing inputs."""
def gplvm_back_constrained_nll_grad(
    weights: NDArray[np.float64], data: NDArray[np.float64], log_theta: NDArray[np.float64], log_beta: float
) -> tuple[float, NDArray[np.float64], NDArray[np.float64], float, NDArray[np.float64], float]:
    """Back-constrained GPLVM objective at `weights` (N, d) for centred `data` (N, D), GPLVM kernel
    `exp(log_theta)` and back-constraint squared length-scale `exp(log_beta)`: returns (nll,
    dnll/dweights (N, d), dnll/dlog_theta (3,), dnll/dlog_beta, latent points (N, d), jitter)."""

def arms_fk(postures: NDArray[np.float64]) -> NDArray[np.float64]:
    """Hands `(N, 4)` `[x_L, y_L, x_R, y_R]` of postures `(N, 4)` `[q1_L, q2_L, q1_R, q2_R]`
    (default geometry: shoulders (±0.15, 0), links 0.3 + 0.3 m)."""

def arms_elbows(postures: NDArray[np.float64]) -> NDArray[np.float64]:
    """Elbows `(N, 4)` `[x_L, y_L, x_R, y_R]` of postures `(N, 4)` (for drawing)."""

def arms_ik(hands: NDArray[np.float64]) -> NDArray[np.float64]:
    """Postures `(N, 4)` (elbows outward, shoulder angles continuous in front of the body) that
    put the hands at `hands` `(N, 4)`; an unreachable row raises InvalidInputError."""

def grip_error(hands: NDArray[np.float64], test: str = ...) -> NDArray[np.float64]:
    """Grip error `(N,)` in metres of hands `(N, 4)` by `test`: `"distance"` (default,
    `GripTest::DEFAULT`) `| ‖hand_R − hand_L‖ − 0.1 |` or `"vector"`
    `‖(hand_R − hand_L) − (0.1, 0)‖`."""

def fall_check(
    task: Task,
    start: NDArray[np.float64],
    targets: NDArray[np.float64],
    *,
    hold: float,
    record_times: Sequence[float] = ...,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Runs the fall check (`sim::fallcheck::run_fall_check`) of `task` (a floating robot with a
    `[fall]` rule and a distance constraint, the grip): in the task's world, stand at `start`
    `(D,)`, hold each row of `targets` `(M, D)` for `hold` s.
    Returns `(table, frames)`. `table` `(M, 7)`: fell (0/1), smallest support margin (m),
    final support margin (m), grip error at the end (hand distance − `grip_width`, m),
    largest |grip error| (m), base height at the end (m), time of the fall (s since the
    start, NaN while standing). `frames` `(K, 9 + D)`, one per `record_times` entry (s) that
    the check reaches, taken at the first check (every 4 physics steps) at or after it: time
    (s), fell (0/1), base position (m), base quaternion (x, y, z, w), joint positions."""

def run_bimanual_trials(
    *,
    n_trials: int,
    episodes: int,
    base_seed: int,
    first_trial: int | None = None,
    plant: Mapping[str, object] | None = None,
    learner: Mapping[str, object] | None = None,
    decoder: GpMap | None = None,
    encoder: GpMap | None = None,
    latent_low: ArrayLike | None = None,
    latent_high: ArrayLike | None = None,
    record_episodes: Sequence[int] | None = None,
    test_episodes: int | None = None,
    record_test_episodes: Sequence[int] | None = None,
    return_weights: bool = False,
    progress: Callable[[int, int], object] | None = None,
) -> dict[str, Any]:
    """Runs Experiment 1 (docs/method.md §Experiment 1) trials in parallel in Rust and returns their
    records.

    With `decoder`, `encoder`, `latent_low` and `latent_high` the latent learner runs (the
    actions of `learner`, default the 2d axes; RBFs over [latent_low, latent_high]); without
    them the full-space learner (12 actions, RBFs over the hands' box).
    n_trials, episodes: T trials of E episodes each.
    base_seed: trial i draws from ChaCha8(base_seed, stream i): same seed ⇒ same arrays,
        whatever the thread count.
    first_trial: run trials first_trial .. first_trial + n_trials (to resume); None means 0.
    plant: a dict of BimanualConfig keys (`bimanual_schema()`); learner: a dict of LearnerConfig
        keys; keys left out keep their defaults, unknown keys are errors.
    decoder, encoder: a GpMap latent (d) → posture (4), and a GpMap or a Projection posture (4)
        → latent (d).
    latent_low, latent_high: (d,) corners of the latent box.
    record_episodes: episode indices whose hand trajectories are recorded in every trial.
    test_episodes: K frozen test episodes after training (no TD updates); None or 0 for none.
    record_test_episodes: test-episode indices whose hand trajectories are recorded.
    return_weights: also return each trial's final value-function weights.
    progress: called as progress(episodes_done, episodes_total) about every 0.1 s and at
        the end (test episodes count); an exception in it stops the run and propagates.

    Returns a dict: "returns" (T, E) float64 (NaN where not run), "ends" (T, E) int8 (the
    codes of END_REASONS; -1 not run), "steps" (T, E) int64, "reached" (T, E) bool, "passed"
    (T, E) bool (always False here), the same five for the test episodes as "test_returns",
    "test_ends", "test_steps", "test_reached", "test_passed" (T, K), "finished" (T,) bool,
    "trials" (T,) int64, "trajectories" (T, R, max_steps + 1, 4) float64 hands (x_L, y_L,
    x_R, y_R) after the reset and after each plant step, NaN-padded, "test_trajectories"
    likewise, "test_starts" (T, K, 4) the row at the start of every test episode (NaN where
    not run), "mean_states" (T, E, n) each training episode's mean learner state (n: 4 full,
    d latent; NaN where not run), "weights" (T, M) float64 or None, "learner_low" /
    "learner_high" / "spacing" (d,) of the RBF grid, "n_actions", "n_centres" (the effective
    configurations are `bimanual_config`'s). Ctrl-C stops all trials and raises KeyboardInterrupt."""

def bimanual_config(
    plant: Mapping[str, object] | None = None, learner: Mapping[str, object] | None = None
) -> tuple[dict[str, Any], dict[str, Any]]:
    """Experiment 1's configuration checked: `(plant, learner)` dicts with every key's effective
    value, or InvalidInputError naming the key and its rule."""

def latent_refusal(
    z: Sequence[float],
    low: Sequence[float],
    high: Sequence[float],
    variance: float | None = None,
    threshold: float | None = None,
) -> int | None:
    """Whether a latent target `z` (d,) is refused (`latent_core::refused`): the code of the box
    exit (2) or the variance gate (5; `variance` and `threshold` given), or None."""

@final
class BimanualPlant:
    """Experiment 1's kinematic two-hand toy as a plant (`sim::bimanual::BimanualPlant`): the
    Gymnasium environment's state and rules."""

    def __new__(cls, plant: Mapping[str, object] | None = None) -> BimanualPlant:
        """The toy with `plant` (a dict of BimanualConfig keys; defaults for the rest)."""
    def reset(self, posture: NDArray[np.float64]) -> int | None:
        """Puts the hands at `posture` (4,): None, or the code of the rule it breaks."""
    def step(self, target: NDArray[np.float64]) -> tuple[float, int | None]:
        """Moves the hands to `target` (4,): `(reward, end code or None)`."""
    def sample_start(self, seed: int) -> NDArray[np.float64]:
        """A start (4,) by the toy's rule (left hand Gaussian around `start_mean`, right = left +
        grip) from ChaCha8 seeded with `seed`."""
    def state(self) -> NDArray[np.float64]:
        """The hands (4,): x_L, y_L, x_R, y_R."""
    def reached(self) -> bool:
        """Whether the hands are within the reach radius of the target."""
    def config(self) -> dict[str, Any]:
        """The effective configuration."""

@final
class Task:
    """A checked task: its configuration and its robot (docs/tasks.md)."""

    @staticmethod
    def load(path: str | PathLike[str]) -> Task:
        """Reads a TOML task file (the URDF path relative to its folder)."""
    @staticmethod
    def from_dict(config: Mapping[str, object], base_dir: str | PathLike[str] = ..., origin: str = ...) -> Task:
        """A task from a dict of task-file keys; the URDF path is relative to `base_dir` (default
        the working folder, `Task::CONFIG_BASE_DIR`), `origin` names the task in errors (default
        "<dict>", `Task::CONFIG_ORIGIN`)."""
    def to_dict(self) -> dict[str, Any]:
        """Every key with its effective value, as a dict of task-file keys."""
    @property
    def name(self) -> str:
        """The task's name."""
    @property
    def origin(self) -> str:
        """Where the task came from (its file, or the name given)."""
    @property
    def joint_names(self) -> list[str]:
        """Names of the robot's actuated joints, the columns of its postures."""
    @property
    def link_names(self) -> list[str]:
        """Names of every URDF link, in URDF order."""
    def collision_shapes(self) -> list[dict[str, Any]]:
        """Every collision shape as a dict (`urdf_info`'s shapes), to draw the robot."""
    @property
    def warnings(self) -> list[str]:
        """What loading its URDF repaired (`balance_inertia` and the like), one sentence each."""
    @property
    def effectors(self) -> list[str]:
        """The names of the task's effectors."""
    @property
    def edges(self) -> list[tuple[str, str]]:
        """`(parent link, child link)` of every URDF joint: the kinematic tree."""
    @property
    def lower(self) -> NDArray[np.float64]:
        """Lower joint limits (rad or m; -inf for continuous joints)."""
    @property
    def upper(self) -> NDArray[np.float64]:
        """Upper joint limits."""
    @property
    def row_len(self) -> int:
        """Columns of a recorded path row: 3 per effector, base pose (7), joints."""
    @property
    def rl_dt(self) -> float:
        """Duration of one RL step (s)."""

@final
class TaskPlant:
    """The robot of a task in its world: the one plant of the learner, the environments and the
    figures (docs/tasks.md has the rules it applies)."""

    def __new__(cls, task: Task, demos: NDArray[np.float64] | None = None) -> TaskPlant:
        """The task's robot standing at its home posture."""
    def reset(self, posture: NDArray[np.float64]) -> int | None:
        """Puts the robot at `posture` (D,); None if it may start an episode, else the code of
        the rule it breaks (END_REASONS: 1 obstacle, 2 outside the joint limits, 3 drop, 4 fall)."""
    def step(self, target: NDArray[np.float64]) -> tuple[float, int | None, NDArray[np.float64]]:
        """Tracks `target` (D,) for one RL step: `(reward, end code or None, reached posture (D,))`."""
    def classify(self, postures: NDArray[np.float64]) -> tuple[NDArray[np.int8], NDArray[np.float64], NDArray[np.float64]]:
        """For each posture (M, D) at rest: the code of the rule it breaks (0: none), the
        effector positions (M, 3E) and the target's (M, 3E) in the world (they differ by posture
        if `target.relative_to` is set)."""
    def sample_start(self, seed: int) -> NDArray[np.float64]:
        """A start posture drawn by the task's start rule (its home plus ±`episode.start_noise`
        uniform noise per joint) from ChaCha8 seeded with `seed`."""
    def effectors(self) -> NDArray[np.float64]:
        """The effector positions (3E,): x, y, z per effector."""
    def target_position(self) -> NDArray[np.float64]:
        """The target h* in the world now (E, 3), moved with `target.relative_to` if set."""
    def joint_positions(self) -> NDArray[np.float64]:
        """The reached joint positions (D,)."""
    def targets(self) -> NDArray[np.float64]:
        """The servo targets after clamping (D,)."""
    def row(self) -> NDArray[np.float64]:
        """The task-space row recorded in paths: effectors, base position and quaternion (x, y,
        z, w), joints."""
    def link_poses(self) -> NDArray[np.float64]:
        """World poses (L, 7) of every URDF link (position, quaternion x, y, z, w), in the order
        of `Task.link_names`; NaN for a link without a body."""
    def constraint_errors(self) -> NDArray[np.float64]:
        """Each constraint's error now (distance: signed m; offset: m; orientation: rad; plane: m
        outside the bounds), in task-file order."""
    def support_margin(self) -> float:
        """The static support margin now (m, positive inside the soles' polygon; needs a fall rule)."""
    def pose_links(self, base: NDArray[np.float64], joints: NDArray[np.float64]) -> NDArray[np.float64]:
        """Link poses (L, 7) of the robot at `joints` (D,) with its base at `base` (7,: position,
        quaternion x, y, z, w; ignored for a fixed root): the native kinematics of a recorded
        path row, to draw it. Moves the robot there."""
    def center_of_mass(self) -> NDArray[np.float64]:
        """The robot's centre of mass now (3,), from the URDF inertials."""
    def reward(self) -> float:
        """The reward now."""
    def reached(self) -> bool:
        """Whether the effectors are within the task's reach radius of the target."""

@final
class LatentPolicy:
    """A trained latent policy: the learner's grid and weights over the latent box with the GPLVM's
    maps; it acts greedily (the action of the largest look-ahead value)."""

    def __new__(
        cls,
        learner: Mapping[str, object],
        low: Sequence[float],
        high: Sequence[float],
        weights: NDArray[np.float64],
        decoder: GpMap,
        encoder: GpMap | Projection,
    ) -> LatentPolicy:
        """The policy of `learner` (a dict of LearnerConfig keys) over [low, high] with `weights`,
        decoding with `decoder` (latent → posture) and encoding with `encoder`."""
    def act(
        self, posture: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """The next servo target for the reached `posture` (D,): encode it, take the greedy latent
        step (clamped into the box), decode. Returns `(target (D,), z (d,), next z (d,))`."""
    def values(self, points: NDArray[np.float64]) -> NDArray[np.float64]:
        """V(z) at `points` (M, d): the learner's own values."""

def run_task_trials(
    task: Task,
    *,
    decoder: GpMap,
    encoder: GpMap | Projection,
    latent_low: ArrayLike,
    latent_high: ArrayLike,
    n_trials: int,
    episodes: int,
    base_seed: int,
    demos: NDArray[np.float64] | None = None,
    weights: NDArray[np.float64] | None = None,
    rollout: str | None = None,
    test_starts: bool = False,
    first_trial: int | None = None,
    record_episodes: Sequence[int] | None = None,
    test_episodes: int | None = None,
    record_test_episodes: Sequence[int] | None = None,
    return_weights: bool = False,
    progress: Callable[[int, int], object] | None = None,
) -> dict[str, Any]:
    """One trial runner for every task: trials of the task's latent learner (`task.learner`,
    `task.episode`) in parallel in Rust, one plant per trial (a fresh world per episode for a
    floating robot).

    decoder: GpMap latent (d) → posture (D); encoder: GpMap or Projection posture → latent.
    latent_low, latent_high: (d,) corners of the latent box. demos: (N, D) demonstrations (a
    "demo" start uses row `episode.start_demo`). weights: (1, M) value weights every trial starts
    from, or (n_trials, M), one row per trial (a saved policy's; default w₀ everywhere). rollout: run the `episodes` frozen, each action
    "greedy", "softmax" or "random" (the control), each episode from its own generator (the
    same starts for each); test_starts: a rollout starts where the frozen tests do.
    n_trials, episodes, base_seed, first_trial, record_episodes, test_episodes,
    record_test_episodes, return_weights, progress: as for run_bimanual_trials.

    Returns the dict of run_bimanual_trials with paths of `task.row_len` columns (effectors,
    base pose, joints); the effective task is `task.to_dict()`."""

def latent_survey(
    task: Task,
    *,
    decoder: GpMap,
    latent_low: ArrayLike,
    latent_high: ArrayLike,
    demos: NDArray[np.float64] | None = None,
    max_points: int = ...,
    physics: bool = False,
    progress: Callable[[int, int], object] | None = None,
) -> dict[str, Any]:
    """The task's latent space at rest on a grid over [latent_low, latent_high] at its learner
    step (coarsened to at most `max_points` points), each point decoded by `decoder` and
    classified by the task's plant: {shape, stride, spacing, points (M, d), codes (M,), reward
    (M,), distance (M,), reached (M,), effectors (M, 3E), moves (M,): fewest learner moves to
    the target region, -1 for none; with `physics` each move also run from rest through the
    physics: blocked (M·A,) and moves_in_physics (M,)};
    `region_points` (the region's points at the learner's step) and `closest` (the admissible
    point closest to the target: point, effectors, distance, reward; absent if none).
    `max_points` defaults to `sim::task::survey::DEFAULT_MAX_POINTS` (20 000)."""

def learner_values(
    learner: Mapping[str, object],
    low: Sequence[float],
    high: Sequence[float],
    weights: NDArray[np.float64] | None,
    points: NDArray[np.float64],
) -> NDArray[np.float64]:
    """V(z) = wᵀ b(z) (Eq. 7) at `points` (M, d) for `learner` (a dict of LearnerConfig keys)
    over the latent box [low, high] with `weights`: the learner's own sparse features, as its
    look-ahead sees them; weights None: as built (w₀)."""

def task_schema() -> list[dict[str, Any]]:
    """Every key of a task file as dicts `{key, doc, rule, kind, default}`, table by table: the
    source of docs/tasks.md and of the CLI's flags."""

def run_config(run: Mapping[str, object] | None = None) -> dict[str, Any]:
    """The run settings `run` (a dict of `[run]` keys; defaults for the rest) checked: every
    key's effective value, or InvalidInputError naming `run.<key>` and its rule."""

def bimanual_schema() -> list[dict[str, Any]]:
    """The keys of Experiment 1's configuration (`plant.*`, `learner.*`), as `task_schema`."""

def urdf_info(path: str | PathLike[str], *, balance_inertia: bool = ...) -> dict[str, Any]:
    """Reads and checks a URDF file (meshes hulled, through the cache; inertias repaired with
    `balance_inertia`, off by default) and returns what it holds: `{name, joints, links, collision, visual,
    total_mass, warnings}` (warnings: what was repaired, one sentence each); each joint a dict `{name, type,
    lower, upper, effort, velocity, damping, friction, mimic}` (mimic: `{leader, multiplier,
    offset}` or None), actuated joints first in URDF order, then the mimic ones. Each shape a
    dict `{link, kind, size, origin, file, hull}` (origin: position and quaternion x, y, z, w in
    the link's frame; file: a mesh's resolved path or None; hull: `{triangles, vertices,
    cached}` for a collision mesh, else None)."""
def demo_columns(path: str | PathLike[str], names: list[str], postures: NDArray[np.float64]) -> list[int]:
    """The columns of demonstrations named `names` as the URDF's postures: for each actuated
    joint in URDF order, the index of its column (any order; a mimic joint's column is checked
    against its leader, within 1e-3, and dropped). InvalidInputError naming the missing,
    unknown or repeated joint, or the first row where a mimic column disagrees."""
def end_reasons() -> list[str]:
    """The end reasons by code: their names in results files (0 timeout … 6 success)."""
