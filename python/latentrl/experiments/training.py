"""`latentrl train`: a latent policy on any task from a demo file (or a saved GPLVM), run with
the one runner (docs/method.md §Results layout, resumable) and saved as `DIR/policy.npz`."""

from __future__ import annotations

import dataclasses
import hashlib
import json
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from latentrl._base import read_npz
from latentrl._files import MAX_TASK_FILE_BYTES, MAX_URDF_BYTES, read_bounded
from latentrl.demos import load_demos
from latentrl.recorded import recording_kind
from latentrl.recorded.options import DemoOptions
from latentrl.experiments.presets import latent_box
from latentrl.gplvm import GPLVM
from latentrl.task import Task
from latentrl.train import LatentPolicy, TrainPreset

if TYPE_CHECKING:  # the fit, the runner and the derivations load with the first run, not with `train --help`
    from latentrl.derive import Derived
    from latentrl.experiments.runner import Setup


@dataclass(frozen=True)
class TrainRun(TrainPreset, DemoOptions):
    """A training run of `latentrl train`: the preset, the task file, the demos (and how they are
    read), and the model."""

    task_file: str = ""
    """The task file (TOML); `latentrl train` records it as an absolute path."""
    demos: str = ""
    """The demonstrations (CSV with a header of joint names, NPZ, JSON, or a recording: docs/demos.md); `latentrl train` records an absolute path."""
    model: str = ""
    """A saved GPLVM to use instead of fitting one to the demos ("" = fit, d = 2)."""

    def validate(self) -> None:
        """ValueError naming the first impossible field, file, task key or demo column."""
        super().validate()
        if not self.task_file or not self.demos:
            raise ValueError("a training run needs a task file and a demo file")
        fitted(self)


@lru_cache(maxsize=2)
def _load(task_file: str, overrides: str, demos: str, options: DemoOptions, model: str,
          seed: int, max_iter: int, encoder: str) -> tuple[Task, np.ndarray, GPLVM]:
    task = Task.load(task_file).replace(json.loads(overrides))
    # A recording's other joints (a gripper, a wheel) are dropped; a file of postures names the robot's.
    recorded = recording_kind(Path(demos)) is not None
    loaded = load_demos(demos, min_postures=3, expected_joints=task.joint_names if recorded else None,
                        **options.load_kwargs())
    postures = task.demo_postures(loaded.joint_names, loaded.postures, demos)
    gplvm = GPLVM.load(model) if model else GPLVM(n_components=2, max_iter=max_iter, random_state=seed, encoder=encoder)
    if model:
        if gplvm.n_features_in_ != len(task.joint_names):
            raise ValueError(f"{model}: fitted to {gplvm.n_features_in_} joints, the task's robot has {len(task.joint_names)}")
    else:
        try:
            gplvm.fit(postures)
        except ValueError as err:  # e.g. identical postures: say which file holds them
            raise ValueError(f"{demos}: {err}") from err
    return task, postures, gplvm


def fitted(run: TrainRun, out: Path | None = None) -> tuple[Task, np.ndarray, GPLVM]:
    """The task (with the run's overrides and the settings derived where they are silent), the
    demo postures and the GPLVM (fitted or loaded; with `out`, the one saved in that run
    directory: `latent_runs.run_fit`); cached, so validation and setup share the fit."""
    task, demos, model, _ = prepared(run, out)
    return task, demos, model


def prepared(run: TrainRun, out: Path | None = None) -> tuple[Task, np.ndarray, GPLVM, tuple[Derived, ...]]:
    """`fitted`, and the settings `latentrl.derive` derived for it (cached per task, fit and
    margin)."""
    from latentrl.derive import applied, derive
    from latentrl.experiments.latent_runs import Fitted, run_fit
    from latentrl.experiments.results import read_results
    from latentrl.experiments.runner import MODEL_FILE, check_inputs

    overrides = json.dumps(run.task, sort_keys=True)  # hashable for the cache, list values too
    options = DemoOptions(**{f.name: getattr(run, f.name) for f in dataclasses.fields(DemoOptions)})
    task, demos, model = _load(run.task_file, overrides, run.demos, options, run.model, run.seed, run.gplvm_max_iter,
                               run.encoder)
    if out is not None:
        model = run_fit(out, run.latent_margin, lambda: Fitted.of_model(model, run.latent_margin)).model
        meta = Path(out) / "results.json"
        if meta.is_file():  # a run read back (resume, replay, rollout, plot): made from these inputs?
            recorded = read_results(meta).get("setup", {}).get("inputs") or {}
            saved = read_npz(Path(out) / MODEL_FILE) if (Path(out) / MODEL_FILE).is_file() else model._arrays()
            check_inputs(recorded, input_digests(run.task_file, task, demos, saved), Path(out))
    fit = hashlib.sha256(np.ascontiguousarray(model.Z_).tobytes() + np.ascontiguousarray(demos).tobytes())
    key = (task.digest(), fit.hexdigest(), task.given, run.latent_margin)
    if key not in _DERIVED:
        low, high = latent_box(model.Z_, run.latent_margin)
        _DERIVED[key] = tuple(derive(task, model, low, high, demos, set(task.given)))
    settings = _DERIVED[key]
    return applied(task, settings), demos, model, settings


_DERIVED: dict[tuple[Any, ...], tuple[Derived, ...]] = {}
"""The derived settings per (task digest, fit, given keys, margin)."""


def setup(run: TrainRun, out: Path | None = None) -> Setup:
    """The task's learner on the GPLVM's latent box (the run's in directory `out`); results.json
    records the derived settings (`setup.derived`)."""
    from latentrl.experiments.latent_runs import latent_setup

    task, demos, model, settings = prepared(run, out)
    built = latent_setup(run, task, model, latent_box(model.Z_, run.latent_margin), demos)
    built.info["derived"] = [d.to_dict() for d in settings]
    built.info["inputs"] = input_digests(run.task_file, task, demos, model._arrays())
    return built


def input_digests(task_file: str, task: Task, demos: np.ndarray, model: Mapping[str, np.ndarray]) -> dict[str, str]:
    """SHA-256 of what a run is made from: the task file's and the URDF's bytes, the demo
    postures as the learner gets them (joint order, float64) and the GPLVM's arrays as saved
    (`model`: a run's gplvm.npz as read, so a parameter a later version adds does not change
    it); a resume compares them (`runner.check_inputs`)."""
    def sha(data: bytes) -> str:
        return hashlib.sha256(data).hexdigest()

    return {
        "task file": sha(read_bounded(task_file, MAX_TASK_FILE_BYTES, "a task file")),
        "urdf": sha(read_bounded(task.urdf_path, MAX_URDF_BYTES, "a URDF")),
        "demos": sha(np.ascontiguousarray(demos, dtype=np.float64).tobytes()),
        "model": sha(b"".join(k.encode() + np.ascontiguousarray(model[k]).tobytes() for k in sorted(model))),
    }


def save_policy(run: TrainRun, out: Path) -> LatentPolicy:
    """`out/policy.npz` from the finished trials of the run in `out`."""
    from latentrl.experiments.runner import finished_trials, load_arrays

    task, demos, model = fitted(run, out)
    arrays, done = finished_trials(load_arrays(out))
    if not done:
        raise ValueError(f"{out}: no finished trial, so no policy")
    low, high = latent_box(model.Z_, run.latent_margin)
    record = {what: arrays[f"latent{suffix}"] for what, suffix in (
        ("returns", ""), ("ends", "_end"), ("reached", "_reached"))}
    if "latent_test" in arrays:
        record.update(test_returns=arrays["latent_test"], test_ends=arrays["latent_test_end"],
                      test_reached=arrays["latent_test_reached"])
    policy = LatentPolicy(task=task, model=model, demos=demos, latent_low=low, latent_high=high,
                          weights=arrays["latent_weights"], preset=run, record=record)
    policy.save(out / "policy.npz")
    return policy
