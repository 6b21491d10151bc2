"""Train a latent-space TD(0) policy (SPEC §3.1) on a shipped simulated robot from your own
fitted GPLVM: the learner of Experiments 2 and 3, without their demonstrations and figures.

The task is the experiment's: ``"two_arms"`` (Exp. 2: both hands to the target through the
corridor, `latentrl.experiments.exp2`) or ``"humanoid_lift"`` (Exp. 3: lift the object past
the obstacle, `latentrl.experiments.exp3`). Every step runs in Rust: decode the latent target
with the GPLVM's GP, track it with the simulated servos for one RL step, encode the reached
posture, update V; trials run in parallel with the GIL released.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray
from tqdm import tqdm

from latentrl import humanoid
from latentrl._reference import value_function
from latentrl.experiments import exp2, exp3
from latentrl.experiments.presets import latent_box
from latentrl.experiments.runner import END_CODES, RunTrials, Setup, episodes_per_trial, run_in_process
from latentrl.gplvm import GPLVM


class Task(NamedTuple):
    """A task of `train_latent_policy`: its experiment's preset and learner, and the joints
    (in column order) of the robot whose postures the GPLVM must be fitted to."""

    preset: type
    learner: Callable[[Any, GPLVM, NDArray[np.float64], NDArray[np.float64]], RunTrials]
    joint_names: Callable[[], tuple[str, ...]]


TASKS = {
    "two_arms": Task(exp2.Exp2Preset, exp2.learner, lambda: exp2.JOINT_NAMES),
    "humanoid_lift": Task(exp3.Exp3Preset, exp3.learner, lambda: tuple(humanoid.model().joint_names)),
}
"""The tasks by name: Experiment 2's two arms and Experiment 3's humanoid lift."""


@dataclass(frozen=True, eq=False)
class LatentPolicy:
    """What `train_latent_policy` learnt: the value weights of each trial over the RBF grid of
    the latent box, and the per-episode record of the training (each (trials, episodes))."""

    task: str
    preset: Any
    """The experiment preset the trials ran with (`Exp2Preset` or `Exp3Preset`)."""
    latent_low: NDArray[np.float64]
    latent_high: NDArray[np.float64]
    weights: NDArray[np.float64]
    """(trials, rbf_per_dim²) final TD(0) weights."""
    returns: NDArray[np.float64]
    """Return of every training episode."""
    ends: NDArray[np.int8]
    """How every training episode ended, a code of `END_CODES`."""
    reached: NDArray[np.bool_]
    """Whether the hands came within `reach_radius` of the target in each episode."""
    test_returns: NDArray[np.float64]
    """Return of every frozen test episode after training (the learnt weights, no TD updates,
    starts as the preset's `test_episodes` say), each (trials, test_episodes)."""
    test_ends: NDArray[np.int8]
    """How every frozen test episode ended, a code of `END_CODES`."""
    test_reached: NDArray[np.bool_]
    """Whether the hands came within `reach_radius` of the target in each test episode."""

    def value(self, z: Any, trial: int = 0) -> NDArray[np.float64]:
        """V(z) of trial `trial` at latent points `z` (M, 2)."""
        points = np.asarray(z, dtype=np.float64)
        if points.ndim != 2 or points.shape[1] != len(self.latent_low):
            raise ValueError(f"z must have shape (M, {len(self.latent_low)}), got {points.shape}")
        if not 0 <= trial < len(self.weights):
            raise ValueError(f"trial must be in 0..{len(self.weights) - 1}, got {trial!r}")
        return value_function(self.weights[trial], self.latent_low, self.latent_high, points)

    def end_counts(self, last: int | None = None) -> dict[str, int]:
        """How many of the (`last`) training episodes of all trials ended each way."""
        ends = self.ends if last is None else self.ends[:, -last:]
        return {END_CODES[int(c)]: int(n) for c, n in zip(*np.unique(ends, return_counts=True))}

    def __repr__(self) -> str:
        trials, episodes = self.returns.shape
        return f"LatentPolicy({self.task!r}, {trials} trials × {episodes} episodes)"


def train_latent_policy(
    model: GPLVM,
    task: str = "two_arms",
    *,
    preset: str = "quick",
    progress: bool = False,
    **fields: Any,
) -> LatentPolicy:
    """Trains the latent TD(0) learner of `task` through the physics sim in the latent space of
    `model`, a GPLVM fitted to postures of the task's robot (columns in its joint order:
    `experiments.exp2.JOINT_NAMES`, `humanoid.model().joint_names`).

    `preset` is ``"quick"`` (the experiment's smoke-test budget) or ``"paper"``; any `fields`
    of the experiment's preset override it (``trials=4, episodes=500, seed=1, ...``, see
    ``latentrl run exp2 --help``). The latent box is the bounding box of ``model.Z_`` widened
    by ``latent_margin``. Ctrl-C stops the run with `KeyboardInterrupt`.
    """
    if task not in TASKS:
        raise ValueError(f"task must be one of {sorted(TASKS)}, got {task!r}")
    if preset not in ("quick", "paper"):
        raise ValueError(f"preset must be 'quick' or 'paper', got {preset!r}")
    if not isinstance(model, GPLVM) or not hasattr(model, "decoder_"):
        raise TypeError(f"model must be a fitted latentrl.GPLVM, got {model!r}")
    chosen_task = TASKS[task]
    cls = chosen_task.preset
    known = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(set(fields) - known)
    if unknown:
        raise ValueError(f"unknown preset fields {unknown}; {cls.__name__} has {sorted(known)}")
    chosen = dataclasses.replace(cls.quick() if preset == "quick" else cls(), **fields)  # type: ignore[attr-defined]
    chosen.validate()
    joints = chosen_task.joint_names()
    if model.n_features_in_ != len(joints) or model.n_components != 2:
        raise ValueError(
            f"{task} needs a GPLVM with n_components=2 fitted to postures of its {len(joints)} "
            f"joints {list(joints)}; got n_components={model.n_components}, "
            f"n_features_in_={model.n_features_in_}"
        )
    if getattr(chosen, "start_demo", 0) >= len(model.X_train_):
        raise ValueError(f"start_demo={chosen.start_demo} is not a row of the model's {len(model.X_train_)} postures")
    low, high = latent_box(model.Z_, chosen.latent_margin)
    built = Setup(learners={"latent": chosen_task.learner(chosen, model, low, high)})
    with tqdm(total=chosen.trials * episodes_per_trial(chosen), unit="ep", desc="episodes", disable=not progress) as bar:
        *_, result = next(iter(run_in_process(built, [("latent", 0, chosen.trials)], bar.update)))
    return LatentPolicy(
        task=task,
        preset=chosen,
        latent_low=low,
        latent_high=high,
        weights=np.asarray(result["weights"]),
        returns=np.asarray(result["returns"]),
        ends=np.asarray(result["ends"]),
        reached=np.asarray(result["reached"]),
        test_returns=np.asarray(result["test_returns"]),
        test_ends=np.asarray(result["test_ends"]),
        test_reached=np.asarray(result["test_reached"]),
    )
