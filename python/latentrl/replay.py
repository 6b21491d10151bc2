"""Videos of recorded episodes (`latentrl replay`): the robot drawn from a run's stored path
(base pose and joints per step, through the native kinematics: no physics re-run, so a replay is
exact and cheap) with its collision shapes, obstacles, floor and target, beside the learnt V
over the latent space with the GPLVM variance shading and the latent point moving along its
path. GIF with Pillow, MP4 with the ffmpeg that imageio-ffmpeg ships: the `[video]` extra."""

from __future__ import annotations

import os
from importlib import import_module
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

#: What `replay` writes, by suffix.
FORMATS = (".gif", ".mp4")

#: The runs that store robot paths: Exp 2, Exp 3 and `latentrl train` on any task (Exp 1's toy
#: stores hand positions only).
REPLAYABLE = ("exp2", "exp3", "train")


def episode_path(arrays: dict[str, NDArray[Any]], trial: int, episode: int | None, test: int | None,
                 episodes: int) -> tuple[NDArray[np.float64], str]:
    """The stored rows of one recorded episode (finite rows only) and what it is."""
    from latentrl.experiments.latent_runs import recorded_episodes

    trials = arrays["latent"].shape[0]
    if not 0 <= trial < trials:
        raise ValueError(f"--trial {trial}: the run has trials 0..{trials - 1}")
    if test is not None:
        paths = arrays.get("latent_test_paths")
        if paths is None or paths.shape[1] == 0:
            raise ValueError("--test: the run recorded no frozen test episodes (run it with test_episodes > 0)")
        if not 0 <= test < paths.shape[1]:
            raise ValueError(f"--test {test}: the run recorded test episodes 0..{paths.shape[1] - 1}")
        rows, what = paths[trial, test], f"frozen test episode {test} of trial {trial}"
    else:
        paths = arrays.get("latent_paths")
        recorded = recorded_episodes(episodes)[: 0 if paths is None else paths.shape[1]]
        if episode not in recorded:
            raise ValueError(f"--episode {episode}: the run recorded training episodes {recorded}")
        rows = paths[trial, recorded.index(episode)]  # type: ignore[index]
        what = f"training episode {episode} of trial {trial}"
    rows = rows[np.isfinite(rows).all(axis=1)]
    if len(rows) == 0:
        raise ValueError(f"{what}: no stored steps")
    return rows, what


def check_output(out: Path) -> None:
    """`out` is a GIF or MP4 name whose writer is installed; else a ValueError saying what to do."""
    if out.suffix.lower() not in FORMATS:
        raise ValueError(f"--out {out}: write a .gif or an .mp4")
    try:
        import imageio.v3  # noqa: F401
        if out.suffix.lower() == ".mp4":
            import imageio_ffmpeg  # noqa: F401
    except ImportError:
        raise ValueError("videos need imageio and imageio-ffmpeg: pip install 'latentrl[video]'") from None


def render_frames(task: Any, model: Any, box: tuple[NDArray[np.float64], NDArray[np.float64]],
                  weights: NDArray[np.float64], rows: NDArray[np.float64], title: str,
                  size: tuple[int, int] = (960, 480), max_frames: int = 400) -> NDArray[np.uint8]:
    """RGB frames (T, height, width, 3): the robot at each stored row (left) and V over the
    latent box with the path of the encoded postures (right)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from latentrl.plots import latent_value_panel
    from latentrl.render import Scene, draw_scene, view_limits

    slices = task.row_slices()
    base = rows[:, np.r_[slices["base_position"], slices["base_quaternion"]]]
    joints = rows[:, slices["joints"]]
    latent = model.transform(joints)
    plant = task.plant()
    poses = [np.asarray(plant.pose_links(b, q)) for b, q in zip(base, joints)]
    scene = Scene.of(task)
    every = np.vstack([p[:, :3] for p in poses])[:, list(scene.view)]
    limits = view_limits(every[np.isfinite(every).all(axis=1)])  # one view for the whole episode

    fig = Figure(figsize=(size[0] / 100, size[1] / 100), dpi=100)
    FigureCanvasAgg(fig)
    robot, value = fig.add_subplot(1, 2, 1, aspect="equal"), fig.add_subplot(1, 2, 2)
    latent_value_panel(value, weights, box[0], box[1], model, learner=scene.config["learner"], grid=60)
    trace, = value.plot([], [], "-", color="w", lw=1.5)
    point, = value.plot([], [], "o", color="r", ms=6)
    fig.suptitle(title, fontsize=9)
    fig.subplots_adjust(left=0.08, right=0.95, bottom=0.14, top=0.86, wspace=0.3)
    picks = np.unique(np.linspace(0, len(rows) - 1, min(len(rows), max_frames)).round().astype(int))
    frames = []
    for step in picks:
        robot.cla()
        draw_scene(robot, scene, poses[step], limits)
        robot.set_title(f"step {step} of {len(rows) - 1}", fontsize=8)
        trace.set_data(latent[: step + 1, 0], latent[: step + 1, 1])
        point.set_data([latent[step, 0]], [latent[step, 1]])
        fig.canvas.draw()
        frames.append(np.asarray(fig.canvas.buffer_rgba())[..., :3].copy())  # type: ignore[attr-defined]
    return np.stack(frames)


def write_video(frames: NDArray[np.uint8], out: Path, fps: int) -> None:
    """Writes `frames` to `out` (GIF or MP4 by suffix) through a temporary file, so a failed or
    interrupted write leaves nothing half-written."""
    import imageio.v3 as iio

    temp = out.with_name(f".{out.stem}.{os.getpid()}.tmp{out.suffix}")
    try:
        if out.suffix.lower() == ".gif":
            iio.imwrite(temp, frames, duration=1000 / fps, loop=0)
        else:
            iio.imwrite(temp, frames, fps=fps)
        temp.replace(out)
    finally:
        temp.unlink(missing_ok=True)


def run_setup(experiment: str, preset: Any) -> tuple[Any, Any, tuple[NDArray[np.float64], NDArray[np.float64]]]:
    """The task, the GPLVM and the latent box of a run, as it was trained (the fit is
    deterministic in the saved preset)."""
    if experiment == "train":
        from latentrl.experiments.presets import latent_box
        from latentrl.experiments.training import fitted

        task, _, model = fitted(preset)
        return task, model, latent_box(model.Z_, preset.latent_margin)
    module = import_module(f"latentrl.experiments.{experiment}")
    fit = module.fit(preset)
    return module.task_of(preset), fit.model, (fit.low, fit.high)


def replay(run_dir: Path, experiment: str, preset: Any, out: Path, *, trial: int = 0,
           episode: int | None = None, test: int | None = None, fps: int = 20, width: int = 960,
           max_frames: int = 400) -> str:
    """Renders one recorded episode of the run in `run_dir` (`experiment` "exp2", "exp3" or
    "train", its saved `preset`) to `out`; returns what was rendered. Every argument is checked
    before drawing."""
    from latentrl.experiments.runner import load_arrays

    if experiment not in REPLAYABLE:
        raise ValueError(f"{run_dir}: a run of {experiment}; replay draws robot runs (exp2, exp3, latentrl train)")
    if (episode is None) == (test is None):
        raise ValueError("give one of --episode E (a recorded training episode) or --test T (a frozen test episode)")
    for flag, value, least in (("--fps", fps, 1), ("--width", width, 200), ("--max-frames", max_frames, 2)):
        if value < least:
            raise ValueError(f"{flag} must be at least {least}, got {value}")
    check_output(out)
    arrays = load_arrays(run_dir)
    rows, what = episode_path(arrays, trial, episode, test, preset.episodes)
    weights = arrays.get("latent_weights")
    if weights is None:
        raise ValueError(f"{run_dir}: the run kept no learnt weights to draw V from")
    task, model, box = run_setup(experiment, preset)
    frames = render_frames(task, model, box, np.asarray(weights)[trial], rows, f"{task.name}: {what}",
                           size=(width, width // 2), max_frames=max_frames)
    write_video(frames, out, fps)
    return f"{what}: {len(frames)} frames"
