"""`latentrl train`: a latent policy on any task from a demo file (or a saved GPLVM), run with
the one runner (docs/method.md §Results layout, resumable) and saved as `DIR/policy.npz`, with
its figures: the return curve and, for a 2-D latent space, the value function before and after
learning and where late episodes failed (the `[plot]` extra, imported when they are drawn).
The same training from Python, in memory: `train_latent_policy` (`latentrl.train_latent_policy`)."""

from __future__ import annotations

import copy
import dataclasses
import json
import warnings
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from latentrl._files import MAX_MESH_BYTES, MAX_TASK_FILE_BYTES, MAX_URDF_BYTES, read_bounded
from latentrl.recorded.options import DemoOptions
from latentrl.gplvm import GPLVM, check_fitted_gplvm, check_model_joints, name_joints
from latentrl.task import SHIPPED, Task, end_reasons
from latentrl.run_settings import TrainPreset, latent_box, with_overrides, with_task_run
from latentrl.train import RECORD, LatentPolicy

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
def _inputs(task_file: str, overrides: str, demos: str, options: DemoOptions) -> tuple[Task, np.ndarray]:
    """The task with its overrides and the demo postures in its joints' order."""
    task = Task.load(task_file).replace(json.loads(overrides))
    return task, task.demos(demos, min_postures=3, **options.load_kwargs()).postures


@lru_cache(maxsize=2)
def _load(task_file: str, overrides: str, demos: str, options: DemoOptions, model: str,
          seed: int, max_iter: int, encoder: str, spacing: str) -> tuple[Task, np.ndarray, GPLVM]:
    task, postures = _inputs(task_file, overrides, demos, options)
    try:
        task.plant(postures)  # the home posture (a demo) the robot must take, before any fit
    except ValueError as err:
        raise ValueError(f"{demos}: {err}") from err
    gplvm = GPLVM.load(model) if model else GPLVM(n_components=2, max_iter=max_iter, random_state=seed, encoder=encoder,
                                                  spacing=spacing)
    if model:
        check_model_joints(gplvm, task.joint_names, model)
        use_encoder(gplvm, encoder, model)
    else:
        try:
            gplvm.fit(postures)
        except ValueError as err:  # e.g. identical postures: say which file holds them
            raise ValueError(f"{demos}: {err}") from err
        name_joints(gplvm, task.joint_names)  # the run's model.npz is refused for other joints
    return task, postures, gplvm


FIT_SETTINGS = ("gplvm_max_iter", "latent_spacing")
"""Run settings of the GPLVM fit: a given model (`--model`, `train_latent_policy`'s) skips them."""


def use_encoder(model: GPLVM, encoder: str, where: str, *, api: bool = False) -> None:
    """Sets the run's `encoder` (flag, `[run]` table, preset default) on the fitted `model`, the
    map of the RL loop's states (`latentrl train --model`, `train_latent_policy`): "projection"
    and "tracking" run on either fit, "gp" and "back_constrained" only on their own (each is
    another fit); a ValueError naming the setting (`--encoder`, or with `api` `encoder=`) and
    `where` (the model) otherwise."""
    fit = model.fitted_encoder_
    if encoder in ("gp", "back_constrained") and encoder != fit:
        q, given, refit = (repr, "encoder=", "GPLVM(encoder={!r})") if api else (str, "--encoder ", "latentrl fit --encoder {}")
        raise ValueError(f"{given}{q(encoder)}: {where} was fitted with the {fit!r} encoder, which is another fit; refit it "
                         f"({refit.format(encoder)}) or give {given}{q(fit)}, {q('projection')} or {q('tracking')}")
    model.set_params(encoder=encoder)


def fitted(run: TrainRun, out: Path | None = None) -> tuple[Task, np.ndarray, GPLVM]:
    """The task (with the run's overrides and the settings derived where they are silent), the
    demo postures and the GPLVM (fitted or loaded; with `out`, the one saved in that run
    directory: `latent_runs.run_fit`); cached, so validation and setup share the fit."""
    task, demos, model, _ = prepared(run, out)
    return task, demos, model


def prepared(run: TrainRun, out: Path | None = None) -> tuple[Task, np.ndarray, GPLVM, tuple[Derived, ...]]:
    """`fitted`, and the settings `latentrl.derive` derived for it (cached per task, fit and
    margin). With `latent_spacing = "auto"` the fit's points are evenly spaced where the derive
    rule says so (`derive.SPACING`), before a new run saves its model."""
    from latentrl.derive import SPACING, applied, even_twin
    from latentrl.experiments.latent_runs import Fitted, run_fit
    from latentrl.experiments.run_folder import RunFolder

    def load(spacing: str) -> tuple[Task, np.ndarray, GPLVM]:
        return _load(*_keys(run), run.model, run.seed, run.gplvm_max_iter, run.encoder, spacing)

    auto = run.latent_spacing == "auto"
    task, demos, model = load("fit" if auto else run.latent_spacing)
    even = None if run.model else even_twin(model, run.latent_spacing)
    if even is not None and any(d.key == SPACING for d in _derived(task, model, demos, run.latent_margin, even)):
        model = even()
    if out is not None:
        folder = RunFolder(out)  # gplvm.npz and results.json read once, for the fit and the digests
        fresh = model
        model = run_fit(folder, run.latent_margin, lambda: Fitted.of_model(fresh, run.latent_margin)).model
        if folder.results_path.is_file():  # a run read back (resume, replay, rollout, plot): made from these inputs?
            saved = folder.model_arrays()
            folder.check_inputs(input_digests(run.task_file, task, demos, model._arrays() if saved is None else saved))
    settings = _derived(task, model, demos, run.latent_margin, even)
    return applied(task, settings), demos, model, settings


def _keys(run: TrainRun) -> tuple[str, str, str, DemoOptions]:
    """`_inputs`' arguments for `run`: the task file, its overrides (as JSON: hashable for the
    cache, list values too), the demos and how they are read."""
    options = DemoOptions(**{f.name: getattr(run, f.name) for f in dataclasses.fields(DemoOptions)})
    return run.task_file, json.dumps(run.task, sort_keys=True), run.demos, options


def check_resumable(run: TrainRun, out: Path) -> None:
    """Before the fit: the run saved in `out`, if any, is of `run`'s preset and was made from its
    task file, URDF and demos (their recorded digests); a ValueError naming what differs. The
    model's digest is compared once the run's model is read (`prepared`)."""
    from latentrl.experiments.run_folder import RunFolder

    folder = RunFolder(out)
    if folder.results_path.is_file():
        folder.check_preset(run)
        folder.check_inputs(input_digests(run.task_file, *_inputs(*_keys(run))))


def _derived(task: Task, model: GPLVM, demos: np.ndarray, margin: float,
             even: Callable[[], GPLVM] | None) -> tuple[Derived, ...]:
    """`derive.derive` for `task` on `model` (cached per task, fit, given keys, margin and whether
    the spacing may be derived; a spacing it derives is cached for the evenly spaced fit too)."""
    import hashlib  # OpenSSL: loaded by a run, not by `train --help`

    from latentrl.derive import SPACING, derive

    def key(m: GPLVM) -> tuple[Any, ...]:
        fit = hashlib.sha256(np.ascontiguousarray(m.Z_).tobytes() + np.ascontiguousarray(demos).tobytes())
        return task.digest(), fit.hexdigest(), task.given, margin, even is not None

    if key(model) not in _DERIVED:
        low, high = latent_box(model.Z_, margin)
        settings = tuple(derive(task, model, low, high, demos, set(task.given), even))
        _DERIVED[key(model)] = settings
        if even is not None and any(d.key == SPACING for d in settings):
            _DERIVED[key(even())] = settings
    return _DERIVED[key(model)]


_DERIVED: dict[tuple[Any, ...], tuple[Derived, ...]] = {}
"""The derived settings per (task digest, fit, given keys, margin, spacing derived)."""


def setup(run: TrainRun, out: Path | None = None) -> Setup:
    """The task's learner on the GPLVM's latent box (the run's in directory `out`); results.json
    records the derived settings (`setup.derived`)."""
    from latentrl.experiments.latent_runs import latent_setup

    task, demos, model, settings = prepared(run, out)
    built = latent_setup(run, task, model, latent_box(model.Z_, run.latent_margin), demos)
    built.info["derived"] = [d.to_dict() for d in settings]
    built.info["inputs"] = input_digests(run.task_file, task, demos, model._arrays())
    return built


def input_digests(task_file: str, task: Task, demos: np.ndarray,
                  model: Mapping[str, np.ndarray] | None = None) -> dict[str, str]:
    """SHA-256 of what a run is made from: the task file's and the URDF's bytes, its collision
    meshes' (by file name and bytes, if it has any: a moved robot folder keeps them), the demo
    postures as the learner gets them (joint order, float64) and the GPLVM's arrays as saved
    (`model`: a run's gplvm.npz as read, so a parameter a later version adds does not change
    it; None: no model digest, as `check_resumable` asks before the fit); a resume compares them
    (`RunFolder.check_inputs`)."""
    import hashlib  # OpenSSL: loaded by a run, not by `train --help`

    def sha(data: bytes) -> str:
        return hashlib.sha256(data).hexdigest()

    digests = {
        "task file": sha(read_bounded(task_file, MAX_TASK_FILE_BYTES, "a task file")),
        "urdf": sha(read_bounded(task.urdf_path, MAX_URDF_BYTES, "a URDF")),
        "demos": sha(np.ascontiguousarray(demos, dtype=np.float64).tobytes()),
    }
    if model is not None:
        digests["model"] = sha(b"".join(k.encode() + np.ascontiguousarray(model[k]).tobytes() for k in sorted(model)))
    meshes = sorted({Path(s["file"]) for s in task._native.collision_shapes() if s.get("file")}, key=lambda p: p.name)
    if meshes:
        digests["meshes"] = sha(b"".join(m.name.encode() + read_bounded(m, MAX_MESH_BYTES, "a mesh") for m in meshes))
    return digests


def save_policy(run: TrainRun, out: Path) -> LatentPolicy:
    """`out/policy.npz` from the finished trials of the run in `out`."""
    from latentrl.experiments.run_folder import RunFolder

    task, demos, model = fitted(run, out)
    arrays, done = RunFolder(out).finished()
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


# --- the same training from Python, in memory ---------------------------------------------


def _preset_for(task: Task | str, quick: bool, fields: Mapping[str, Any]) -> tuple[Task, Any]:
    """The task and the preset of a training run: a shipped task's name takes its experiment's
    preset (Exp. 2, 3), a Task the `TrainPreset`; the task's `[run]` (where the preset holds its
    class's default), then `fields` override either."""
    if isinstance(task, str):
        if task not in SHIPPED:
            raise ValueError(f"task must be a Task or one of {list(SHIPPED)}, got {task!r}")
        from latentrl.experiments import exp2, exp3

        cls: Any = {"two_arms": exp2.Exp2Preset, "humanoid_lift": exp3.Exp3Preset}[task]
        task = Task.shipped(task)
    elif isinstance(task, Task):
        cls = TrainPreset
    else:
        raise TypeError(f"task must be a latentrl.Task or a shipped task's name, got {type(task).__name__}")
    preset = with_overrides(with_task_run(cls.quick() if quick else cls(), task), fields)
    preset.validate()
    return task.replace(preset.task), preset


def train_latent_policy(
    model: GPLVM,
    task: Task | str = "two_arms",
    *,
    demos: Any = None,
    preset: str = "quick",
    progress: bool = False,
    overrides: Mapping[str, Any] | None = None,
    **fields: Any,
) -> LatentPolicy:
    """Trains the latent TD(0) learner of `task` through the physics sim in the latent space of
    `model`, a GPLVM fitted to postures of the task's robot (columns in its joint order,
    `task.joint_names`).

    `preset` is ``"quick"`` (a short budget) or ``"paper"`` (the full one); the task's `[run]`
    table replaces the paper preset's run settings, `fields` override the result by name
    (``trials=4, episodes=500, seed=1``), `overrides` the task's keys by path
    (``overrides={"learner.alpha": 0.5, "episode.max_steps": 200}``). `demos` (N, D, or a DataFrame whose columns name
    the joints): the postures a ``start = "demo"`` task starts from (default: the model's training postures). The latent box is the bounding
    box of ``model.Z_`` widened by ``latent_margin``. Ctrl-C stops the run with
    `KeyboardInterrupt`.
    """
    from latentrl.experiments.latent_runs import task_learner  # the runner and tqdm: at the first run
    from latentrl.experiments.runner import Setup, episodes_per_trial, run_in_process
    from latentrl.progress import progress_bar

    if preset not in ("quick", "paper"):
        raise ValueError(f"preset must be 'quick' or 'paper', got {preset!r}")
    fit = sorted(k for k in {**fields, **(overrides or {})} if k.removeprefix("run.") in FIT_SETTINGS)
    if fit:
        raise ValueError(f"{', '.join(fit)}: settings of the GPLVM fit, and train_latent_policy trains on the model "
                         "you fitted; fit it so (GPLVM(max_iter=..., spacing='even'), model.evenly_spaced()), or let "
                         "latentrl train fit one")
    check_fitted_gplvm(model)
    task, chosen = _preset_for(task, preset == "quick", {**fields, **(overrides or {})})
    check_model_joints(model, task.joint_names, f"model for {task.name}")
    model = copy.copy(model)  # the run's encoder maps the loop's states; yours keeps its own
    use_encoder(model, chosen.encoder, "the model", api=True)
    chosen = dataclasses.replace(chosen, gplvm_max_iter=model.max_iter, latent_spacing=model.spacing)  # the fit that ran
    starts = model.X_train_ if demos is None else task.postures_of(demos)
    low, high = latent_box(model.Z_, chosen.latent_margin)
    if isinstance(chosen, TrainPreset):  # a Task of yours (not a shipped experiment): derive what it leaves open
        from latentrl.derive import applied, derive

        task = applied(task, derive(task, model, low, high, starts, set(task.given)))
    learner = task_learner(
        task, model, (low, high), starts, episodes=chosen.episodes, seed=chosen.seed, test_episodes=chosen.test_episodes
    )
    built = Setup(learners={"latent": learner})
    with progress_bar(total=chosen.trials * episodes_per_trial(chosen), unit="ep", desc="episodes", disable=not progress) as bar:
        *_, result = next(iter(run_in_process(built, [("latent", 0, chosen.trials)], bar.update)))
    return LatentPolicy(
        task=task, model=model, demos=starts, latent_low=low, latent_high=high, weights=np.asarray(result["weights"]),
        preset=chosen, record={k: np.asarray(result[k]) for k in RECORD},
    )



# --- the run and its figures ------------------------------------------------------------------


def run_training(run: TrainRun, out_dir: Path | str, *, progress: bool = True) -> dict[str, Any]:
    """Runs (or continues) the training into `out_dir` with the one runner, writes its policy
    (`policy.npz`) and draws its figures; without matplotlib (the `[plot]` extra) everything but
    the figures, with a warning saying how to draw them later."""
    from latentrl.experiments.runner import run_rl

    return run_rl(run, out_dir, setup=setup, figures=_policy_and_figures, progress=progress)


def _policy_and_figures(run: TrainRun, arrays: Mapping[str, np.ndarray], run_dir: Path, out: Path) -> None:
    """`policy.npz` (`save_policy`), then the `figures`: a disk that fills while they are drawn
    keeps the policy (it was written after them, so `report` and `rollout` found none). Without
    matplotlib, a warning how to draw them later instead (`train` refused to start without it,
    where the README trains after installing only the recording extras)."""
    try:
        save_policy(run, run_dir)
    except OSError as err:
        raise type(err)(err.errno, f"{err.strerror or err}; the same latentrl train command with --resume "
                                   "writes it once there is room") from err
    try:
        import matplotlib.pyplot  # noqa: F401  (the figures' [plot] extra)
    except ModuleNotFoundError as err:
        if err.name != "matplotlib":
            raise
        warnings.warn(f"no figures: they need matplotlib; pip install 'latentrl[plot]', then latentrl plot {run_dir} "
                      "draws them", stacklevel=2)
        return
    figures(run, arrays, run_dir, out)


def figures(run: TrainRun, arrays: Mapping[str, np.ndarray], run_dir: Path, out: Path) -> None:
    """`returns.png` (mean ± s.d. over trials, running mean) and, with d = 2, `value_before.png`,
    `value_after.png` (trial 1), PNG + PDF."""
    import matplotlib.pyplot as plt

    from latentrl.plots import latent_value_panel, learning_curves, save_figure

    task, _, model = fitted(run, run_dir)
    learner = task.to_dict()["learner"]
    given = ", ".join(f"{key}={value}" for key, value in run.task.items())  # the run's task flags
    named = task.name + (f" ({given[:60]}{'…' if len(given) > 60 else ''})" if given else "")
    fig, ax = plt.subplots(figsize=(6, 4))
    learning_curves(ax, {"latent": arrays["latent"]}, window=max(1, min(100, run.episodes // 5)))
    ax.set_title(f"{named}: return per training episode", fontsize=9)
    save_figure(fig, out, "returns")
    if model.n_components_ != 2 or "latent_weights" not in arrays:
        return
    low, high = latent_box(model.Z_, run.latent_margin)
    trials = len(arrays["latent_weights"])
    for name, weights, title in (
            ("value_before", None, "V before learning (the initial weight w₀)"),
            ("value_after", np.asarray(arrays["latent_weights"])[0],
             f"V after learning: trial 0 of {trials}, the policy act() uses (its own colour scale)")):
        fig, ax = plt.subplots(figsize=(6, 5))
        latent_value_panel(ax, weights, low, high, model, learner=learner)
        ax.set_title(f"{named}:\n{title}", fontsize=9)
        save_figure(fig, out, name)
    if "latent_mean_state" in arrays:
        failures(arrays, named, low, high, model, learner, out)


def failures(arrays: Mapping[str, np.ndarray], name: str, low: np.ndarray, high: np.ndarray, model: Any,
             learner: Mapping[str, Any], out: Path) -> None:
    """`failures.png`: trial 0's V after learning with, for each episode of the last fifth of the
    episodes it ran that never came within the reach radius, its mean latent state, coloured by how it
    ended (where in the latent space episodes fail)."""
    import matplotlib.pyplot as plt

    from latentrl.plots import latent_value_panel, save_figure

    trial = 0
    ran = int((np.asarray(arrays["latent_end"])[trial] >= 0).sum())  # a stopped trial ran fewer than its budget
    fifth = max(1, ran // 5)
    last = slice(ran - fifth, ran)
    means = np.asarray(arrays["latent_mean_state"])[trial, last]
    ends = np.asarray(arrays["latent_end"])[trial, last]
    failed = ~np.asarray(arrays["latent_reached"], dtype=bool)[trial, last] & np.isfinite(means).all(axis=1)
    fig, ax = plt.subplots(figsize=(6, 5))
    latent_value_panel(ax, np.asarray(arrays["latent_weights"])[trial], low, high, model, learner=learner)
    for code, reason in enumerate(end_reasons()):
        mine = failed & (ends == code)
        if mine.any():
            ax.plot(means[mine, 0], means[mine, 1], "x", ms=5, color=f"C{code}", label=f"failed: {reason} ({mine.sum()})")
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2)  # below: the markers stay visible
    ax.set_title(f"{name}: the last {fifth} training episodes of trial {trial}: {failed.sum()} never reached the "
                 "target,\nmarked at each one's mean latent state by how it ended", fontsize=9)
    save_figure(fig, out, "failures")
