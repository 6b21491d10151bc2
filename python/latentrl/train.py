"""A trained latent-space TD(0) policy (docs/method.md §RL loop): act, values, roll out, save
and load.

    policy = train_latent_policy(model, task, demos=postures, trials=2, episodes=300)
    policy.save("runs/my_robot/policy.npz")
    target = LatentPolicy.load("runs/my_robot/policy.npz").act(posture)   # next servo target

`train_latent_policy` (`latentrl.train_latent_policy`) assembles the training run; it is
`latentrl train`'s experiment and lives with it (`latentrl.experiments.training`). Every step runs
in Rust: decode the latent target with the GPLVM's GP, track it with the simulated servos for one
RL step, encode the reached posture, update V.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from latentrl import _native
from latentrl._persistence import FORMAT_VERSION, PathLike, atomic_write, check_format, read_npz
from latentrl.episode_ends import end_reasons
from latentrl.gplvm import GPLVM, check_model_joints
from latentrl.rollout_summary import format_rollout, rollout_summary
from latentrl.task import Task, task_digest

__all__ = ["POLICIES", "RECORD", "LatentPolicy", "format_rollout", "rollout_summary"]


POLICIES = ("greedy", "softmax", "random")
"""How a rollout acts: greedily, by the learner's soft-max, or uniformly at random (the control)."""


RECORD = ("returns", "ends", "reached", "test_returns", "test_ends", "test_reached")
"""What a policy keeps of its training: per episode and per frozen test episode, each (trials, episodes)."""


class LatentPolicy:
    """What `train_latent_policy` learnt: the value weights of each trial over the RBF grid of the
    latent box, the GPLVM that maps it, the task, and the record of the training. It acts
    greedily (`act`), runs (`rollout`), and saves to and loads from one NPZ file."""

    def __init__(
        self,
        *,
        task: Task,
        model: GPLVM,
        demos: NDArray[np.float64],
        latent_low: NDArray[np.float64],
        latent_high: NDArray[np.float64],
        weights: NDArray[np.float64],
        preset: Any = None,
        record: Mapping[str, NDArray[Any]] | None = None,
    ) -> None:
        for name, value in (("demos", demos), ("latent_low", latent_low), ("latent_high", latent_high),
                            ("weights", weights)):  # issue #38: complex values were cast with a warning
            if np.asarray(value).dtype.kind not in "fiu":
                raise ValueError(f"{name}: expected real numbers, got {np.asarray(value).dtype}")
        self.task, self.model, self.demos = task, model, np.asarray(demos, dtype=np.float64)
        joints = len(task.joint_names)
        if self.demos.ndim != 2 or self.demos.shape[1] != joints or not np.isfinite(self.demos).all():
            raise ValueError(f"demos: expected finite postures of shape (N, {joints}), got shape {self.demos.shape}"
                             + ("" if np.isfinite(self.demos).all() else " with NaN or infinite values"))
        check_model_joints(model, task.joint_names, "model")
        self.latent_low, self.latent_high = np.asarray(latent_low), np.asarray(latent_high)
        self.weights = np.asarray(weights, dtype=np.float64)
        """(trials, rbf_per_dim^d) final TD(0) weights of V; with `learner.move_correction`
        (trials, rbf_per_dim^d · (1 + actions)): V's, then each action's correction."""
        self.preset = preset
        """The preset the trials ran with (None for a loaded policy)."""
        self.record = dict(record or {})
        """Per training episode: returns, ends (codes of `end_reasons()`), reached; the same for
        the frozen test episodes (`test_*`); each (trials, episodes)."""
        for name, values in self.record.items():
            if name not in RECORD:
                raise ValueError(f"record.{name}: not one of {list(RECORD)}")
            if np.ndim(values) != 2 or len(values) != len(self.weights):
                raise ValueError(f"record.{name}: expected (trials, episodes) with {len(self.weights)} trials, "
                                 f"got shape {np.shape(values)}")
            if name.endswith("ends"):  # codes of end_reasons(), −1 after a trial stopped (issue #38)
                codes = np.asarray(values)
                count = len(end_reasons())
                if codes.dtype.kind not in "iu" or codes.size and not (-1 <= codes.min() and codes.max() < count):
                    raise ValueError(f"record.{name}: expected end codes, integers in -1..{count - 1}, got "
                                     f"{codes.dtype} values in {codes.min() if codes.size else '-'}.."
                                     f"{codes.max() if codes.size else '-'}")
        learner = task.to_dict()["learner"]
        self._native = [
            _native.LatentPolicy(learner, list(self.latent_low), list(self.latent_high), w, model.decoder_, model.loop_encoder_)
            for w in self.weights
        ]

    def __getattr__(self, name: str) -> Any:
        record = self.__dict__.get("record", {})
        if name in record:
            return record[name]
        raise AttributeError(name)

    def act(self, posture: Any, trial: int = 0) -> NDArray[np.float64]:
        """The next servo target (D,) for the reached `posture` (D,): encoded, one greedy latent
        step of trial `trial`'s policy (clamped into the latent box), decoded."""
        reached = np.ascontiguousarray(posture, dtype=np.float64)
        joints = self.task.joint_names
        if reached.shape != (len(joints),) or not np.isfinite(reached).all():
            raise ValueError(f"posture: expected the {len(joints)} finite joint positions {list(joints)}, "
                             f"got shape {reached.shape}" + ("" if np.isfinite(reached).all() else " with NaN or inf"))
        target, _, _ = self._policy(trial).act(reached)
        return np.asarray(target)

    def value(self, z: Any, trial: int = 0) -> NDArray[np.float64]:
        """V(z) of trial `trial` at latent points `z` (M, d): the learner's own values."""
        points = np.asarray(z, dtype=np.float64)
        if points.ndim != 2 or points.shape[1] != len(self.latent_low):
            raise ValueError(f"z must have shape (M, {len(self.latent_low)}), got {points.shape}")
        return np.asarray(self._policy(trial).values(np.ascontiguousarray(points)))

    def _policy(self, trial: int) -> _native.LatentPolicy:
        if not (isinstance(trial, (int, np.integer)) and 0 <= trial < len(self._native)):
            raise ValueError(f"trial must be an int in 0..{len(self._native) - 1}, got {trial!r}")
        return self._native[int(trial)]

    def rollout(self, episodes: int = 20, *, trial: int | None = None, seed: int = 0, policy: str = "greedy",
                starts: str = "test", progress: Any = None) -> dict[str, Any]:
        """Runs the policy frozen (no learning) for `episodes` episodes per trial (every trial, or
        `trial`); returns the native dict (returns, ends, reached, paths of the first 20
        episodes) plus a "summary" (`rollout_summary`).

        `policy`: ``"greedy"`` (what `act` does), ``"softmax"`` (draws from the learner's soft-max
        on the learnt V, as a run's frozen tests do; on Exp 3 the greedy policy lifts from fewer
        starts: docs/exp3.md) or ``"random"``, the control: each move uniformly at random, which
        cannot learn by construction. `starts`: ``"test"`` draws them as the task's frozen tests
        do (`episode.test_start`), ``"train"`` as its training episodes. Each episode draws from
        its own generator of (`seed`, trial, episode), so the three policies meet the same starts."""
        if policy not in POLICIES:
            raise ValueError(f"policy must be one of {list(POLICIES)}, got {policy!r}")
        if starts not in ("test", "train"):
            raise ValueError(f"starts must be 'test' or 'train', got {starts!r}")
        if not (isinstance(seed, (int, np.integer)) and not isinstance(seed, bool) and 0 <= seed < 2**64):
            raise ValueError(f"seed must be an int in 0..2**64 - 1, got {seed!r}")
        trials = range(len(self.weights)) if trial is None else range(self._check_trial(trial), trial + 1)
        run = _native.run_task_trials(  # the trials side by side, each from its own weights
            self.task._native, decoder=self.model.decoder_, encoder=self.model.loop_encoder_,
            latent_low=self.latent_low, latent_high=self.latent_high, demos=self.demos, n_trials=len(trials),
            episodes=episodes, base_seed=seed, first_trial=trials.start,
            weights=np.ascontiguousarray(np.asarray(self.weights)[trials.start:trials.stop]),
            rollout=policy, test_starts=starts == "test", record_episodes=list(range(min(episodes, 20))),
            progress=progress,
        )
        result = {key: run[key] for key in ("returns", "ends", "reached")}
        result["paths"] = run["trajectories"]
        return {"trials": list(trials), **result, "summary": rollout_summary(result["ends"], result["reached"],
                                                                             result["returns"], self.task)}

    def _check_trial(self, trial: int) -> int:
        self._policy(trial)
        return int(trial)

    def end_counts(self, last: int | None = None) -> dict[str, int]:
        """How many of the (`last`) training episodes each trial ran ended each way."""
        if "ends" not in self.record:
            raise ValueError("this policy has no training record (record.ends): it was not made by training")
        run = [row[row >= 0] for row in np.asarray(self.record["ends"])]  # −1: after a trial stopped
        ends = np.concatenate([row if last is None else row[-last:] for row in run])
        names = end_reasons()
        return {names[int(c)]: int(n) for c, n in zip(*np.unique(ends, return_counts=True))}

    def save(self, path: PathLike) -> None:
        """Writes the policy to one NPZ file (atomically): the GPLVM, every trial's weights, the
        latent box, the demos, the task (its keys, its folder and a hash of it and its URDF) and
        the training record. No pickles."""
        arrays: dict[str, Any] = {
            "format": np.array("latentrl.LatentPolicy"),
            "format_version": np.array(FORMAT_VERSION),
            "task": np.array(json.dumps(self.task.to_dict(), allow_nan=True)),
            "task_dir": np.array(str(self.task.base_dir.resolve())),
            "task_digest": np.array(self.task.digest()),
            "latent_low": self.latent_low,
            "latent_high": self.latent_high,
            "weights": self.weights,
            "demos": self.demos,
            **{f"record.{k}": v for k, v in self.record.items()},
            **{f"model.{k}": v for k, v in self.model._arrays().items()},
        }
        atomic_write(path, lambda fh: np.savez(fh, **arrays))

    @classmethod
    def load(cls, path: PathLike) -> LatentPolicy:
        """Reads a policy written by `save`; its task is rebuilt from the saved keys and folder, and
        those keys and the URDF must hash as when saved (a changed URDF is refused; a key added to
        latentrl since takes its default). Errors are ValueErrors naming the file."""
        try:
            arrays = read_npz(path)
        except ValueError as err:
            raise ValueError(f"{path}: {err}") from err
        check_format(arrays, "latentrl.LatentPolicy", str(path))
        missing = [k for k in ("task", "task_dir", "task_digest", "latent_low", "latent_high", "weights", "demos")
                   if k not in arrays]
        if missing:
            raise ValueError(f"{path}: not a complete policy file (missing {missing})")
        try:
            keys = json.loads(str(arrays["task"]))
        except (ValueError, RecursionError) as err:  # issue #38: the message names the file and the array
            raise ValueError(f"{path}: its task is not valid JSON ({err})") from None
        if not isinstance(keys, dict):
            raise ValueError(f"{path}: its task is not a table of task keys (a JSON object), got {type(keys).__name__}")
        try:
            task = Task.from_dict(keys, Path(str(arrays["task_dir"])), f"the task of {path}")
        except TypeError as err:  # a key of the wrong type: the file is damaged, not the call
            raise ValueError(str(err)) from None
        # Keys added to the schema since the save are at their defaults, the behaviour before they
        # existed (`task_schema.ran_with`): the recorded keys and the URDF must still give the digest.
        if task_digest(keys, task.urdf_path) != str(arrays["task_digest"]):
            raise ValueError(f"{path}: its task (or the task's URDF in {arrays['task_dir']}) changed since it was saved")
        model = GPLVM._from_arrays({k[6:]: v for k, v in arrays.items() if k.startswith("model.")}, str(path))
        record = {k[7:]: v for k, v in arrays.items() if k.startswith("record.")}
        for part in (RECORD[:3], RECORD[3:]):  # issue #38: a record without its ends was a KeyError in `report`
            lost = [f"record.{k}" for k in part if k not in record]
            if any(k in record for k in part) and lost:
                raise ValueError(f"{path}: its training record is incomplete (missing {lost})")
        try:
            return cls(task=task, model=model, demos=arrays["demos"], latent_low=arrays["latent_low"],
                       latent_high=arrays["latent_high"], weights=arrays["weights"], record=record)
        except (TypeError, ValueError) as err:
            raise ValueError(f"{path}: {err}") from err

    def __repr__(self) -> str:
        return f"LatentPolicy({self.task.name!r}, {len(self.weights)} trials, latent box {len(self.latent_low)}-D)"
