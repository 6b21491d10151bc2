"""Stubs of the Rust extension `latentrl._native` (hand-written; checked by mypy.stubtest)."""

from collections.abc import Callable, Mapping, Sequence
from os import PathLike
from typing import Any, Literal, final

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "GpMap",
    "InternalError",
    "InvalidInputError",
    "LatentrlError",
    "NumericalError",
    "Sim",
    "__version__",
    "arms_elbows",
    "arms_fk",
    "arms_ik",
    "gplvm_nll_grad",
    "humanoid_fall_check",
    "run_arms_trials",
    "run_bimanual_trials",
    "run_lift_trials",
]

__version__: str

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
        cls, inputs: NDArray[np.float64], outputs: NDArray[np.float64], theta: NDArray[np.float64]
    ) -> GpMap:
        """Fits the map to `inputs` (N, q) and `outputs` (N, p) with `theta` = (θ1, θ2, θ3)."""
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
class Sim:
    """A URDF robot in a rapier3d world, every actuated joint PD-servoed to its target."""

    def __new__(
        cls,
        urdf: str | PathLike[str],
        *,
        root: Literal["fixed", "floating"] = "fixed",
        dt: float = ...,
        substeps: int = 12,
        solver_iterations: int = 4,
        pgs_iterations: int = 1,
        kp: float = 5000.0,
        kd: float = 50.0,
        max_force: float = ...,
        gravity: NDArray[np.float64] | None = None,
        ground: float | None = None,
    ) -> Sim:
        """Builds the world from `urdf`: a path, or the URDF XML itself (a str starting
        with `<`). `ground` is the height of a floor half-space (normal +z), or None for no
        floor."""
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
    def reset_on_ground(self, posture: NDArray[np.float64], sole: str, clearance: float = 5e-4) -> None:
        """Teleports a floating robot to `posture` at rest standing on the floor: the base is
        placed so that link `sole` lies flat, its lowest corner `clearance` m above the ground
        (needs `ground`)."""
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
        sensor: bool = True,
        name: str = "box",
    ) -> int:
        """Adds a static axis-aligned box at `center` (3,) with `half_extents` (3,); returns its
        id. A sensor (default) is passed through but still reported by `contacts`."""
    def contacts(self) -> list[tuple[str, int]]:
        """Every (link name, obstacle id) pair whose shapes are within the contact margin."""

def gplvm_nll_grad(
    latent: NDArray[np.float64], data: NDArray[np.float64], log_theta: NDArray[np.float64]
) -> tuple[float, NDArray[np.float64], NDArray[np.float64], float]:
    """GPLVM objective at `latent` (N, d) for centred `data` (N, D):
    returns (nll, dnll/dlatent (N, d), dnll/dlog_theta (3,), jitter)."""

def arms_fk(postures: NDArray[np.float64]) -> NDArray[np.float64]:
    """Hands `(N, 4)` `[x_L, y_L, x_R, y_R]` of postures `(N, 4)` `[q1_L, q2_L, q1_R, q2_R]`
    (default geometry: shoulders (±0.15, 0), links 0.3 + 0.3 m)."""

def arms_elbows(postures: NDArray[np.float64]) -> NDArray[np.float64]:
    """Elbows `(N, 4)` `[x_L, y_L, x_R, y_R]` of postures `(N, 4)` (for drawing)."""

def arms_ik(hands: NDArray[np.float64]) -> NDArray[np.float64]:
    """Postures `(N, 4)` (elbows outward, shoulder angles continuous in front of the body) that
    put the hands at `hands` `(N, 4)`; an unreachable row raises InvalidInputError."""

def humanoid_fall_check(
    urdf_path: str,
    start: NDArray[np.float64],
    targets: NDArray[np.float64],
    *,
    hold: float,
    kp: float,
    kd: float,
    max_force: float,
    dt: float,
    solver_iterations: int,
    pgs_iterations: int,
    grip_width: float,
    record_times: Sequence[float] = ...,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Fall check of the floating humanoid (SPEC §4.3): stand at `start` (D,), hold each row
    of `targets` (M, D) for `hold` s. Returns (table (M, 7): fell, min margin, final margin,
    grip error, max |grip error|, base height, fall time or NaN; frames (K, 9 + D) at the
    reached `record_times`: time, fell, base position, base quaternion (x, y, z, w), joints)."""

def run_bimanual_trials(
    learner: Literal["full", "latent"],
    *,
    n_trials: int,
    episodes: int,
    base_seed: int,
    first_trial: int | None = None,
    config: Mapping[str, object] | None = None,
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
    """Runs Experiment 1 (SPEC §4.1) trials in parallel in Rust; see
    `run_bimanual_trials.__doc__` for every argument and the returned arrays."""

def run_arms_trials(
    urdf: str | PathLike[str],
    *,
    decoder: GpMap,
    encoder: GpMap,
    latent_low: ArrayLike,
    latent_high: ArrayLike,
    n_trials: int,
    episodes: int,
    base_seed: int,
    first_trial: int | None = None,
    config: Mapping[str, object] | None = None,
    record_episodes: Sequence[int] | None = None,
    test_episodes: int | None = None,
    record_test_episodes: Sequence[int] | None = None,
    return_weights: bool = False,
    progress: Callable[[int, int], object] | None = None,
) -> dict[str, Any]:
    """Runs Experiment 2 (SPEC §4.2) trials in parallel in Rust on two simulated arms (rapier3d,
    PD servos) learning in a 2-D latent space; see `run_arms_trials.__doc__`."""

def run_lift_trials(
    urdf: str | PathLike[str],
    *,
    decoder: GpMap,
    encoder: GpMap,
    latent_low: ArrayLike,
    latent_high: ArrayLike,
    n_trials: int,
    episodes: int,
    base_seed: int,
    first_trial: int | None = None,
    config: Mapping[str, object] | None = None,
    record_episodes: Sequence[int] | None = None,
    test_episodes: int | None = None,
    record_test_episodes: Sequence[int] | None = None,
    return_weights: bool = False,
    progress: Callable[[int, int], object] | None = None,
) -> dict[str, Any]:
    """Runs Experiment 3 (SPEC §4.3) trials in parallel in Rust on the simulated humanoid
    (rapier3d, servo PD, floor) lifting an object from a 2-D latent space; see
    `run_lift_trials.__doc__`."""
