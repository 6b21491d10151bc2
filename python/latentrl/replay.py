"""Videos of recorded episodes (`latentrl replay`): the robot drawn from a run's stored path
(base pose and joints per step, through the native kinematics: no physics re-run, so a replay is
exact and cheap) with its collision shapes, obstacles, floor and target, beside the learnt V
over the latent space with the GPLVM variance shading and the latent point moving along its
path (over a 2-D latent space; any other: the robot alone). GIF with Pillow, MP4 with the ffmpeg that imageio-ffmpeg ships: the `[video]` extra."""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from importlib import import_module
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from latentrl._persistence import atomic_path, read_npz
from latentrl.render import VIEWS

#: What `replay` writes, by suffix.
FORMATS = (".gif", ".mp4")

#: The runs that store episode paths: Exp 1's latent learner (the toy's hands), and the robots
#: of Exp 2, Exp 3 and `latentrl train` on any task.
REPLAYABLE = ("exp1", "exp2", "exp3", "train")


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


@dataclass(frozen=True)
class Recorded:
    """One recorded episode and what drawing it needs: the effectors' path (T, E, 3), the
    latent path (T, d) on the learner's V (its final `weights` over the box [`low`, `high`]), and
    either a robot (`scene` and link poses (T, L, 7)) or Exp 1's toy (its plant `toy`)."""

    title: str
    effectors: NDArray[np.float64]
    latent: NDArray[np.float64]
    weights: NDArray[np.float64]
    low: NDArray[np.float64]
    high: NDArray[np.float64]
    model: Any
    learner: dict[str, Any]
    scene: Any = None
    poses: NDArray[np.float64] | None = None
    toy: dict[str, Any] | None = None

    @property
    def value_map(self) -> bool:
        """Whether V and the latent path are drawn: over a 2-D latent space only."""
        return bool(self.latent.shape[1] == 2)


def recorded(experiment: str, preset: Any, run_dir: Path, rows: NDArray[np.float64], weights: NDArray[np.float64],
             title: str, view: str | None = None) -> Recorded:
    """The episode of stored `rows` of the run of `experiment` in `run_dir`, with the GPLVM saved
    there (`latent_runs.run_fit`), the robot seen in `view` (`render.view_axes`)."""
    if experiment == "exp1":
        from latentrl.experiments import exp1

        fitted = exp1.fit(preset, run_dir)
        plant, learner = exp1.configs(preset)
        hands = np.concatenate([rows.reshape(len(rows), 2, 2), np.zeros((len(rows), 2, 1))], axis=2)
        return Recorded(title, hands, fitted.model._encode(rows), weights, fitted.low, fitted.high, fitted.model,
                        learner, toy=plant)
    task, model, (low, high) = run_setup(experiment, preset, run_dir)
    return robot_episode(task, model, low, high, rows, weights, title, view)


def robot_episode(task: Any, model: Any, low: NDArray[np.float64], high: NDArray[np.float64],
                  rows: NDArray[np.float64], weights: NDArray[np.float64], title: str,
                  view: str | None = None, demos: NDArray[np.float64] | None = None) -> Recorded:
    """The episode of stored path `rows` of `task`'s robot (its plant built with `demos`) in the
    latent box [`low`, `high`] of `model`, on the V of `weights`, seen in `view`."""
    from latentrl.render import Scene

    slices = task.row_slices()
    joints = rows[:, slices["joints"]]
    base = rows[:, np.r_[slices["base_position"], slices["base_quaternion"]]]
    plant = task.plant(demos)
    poses = np.stack([np.asarray(plant.pose_links(b, q)) for b, q in zip(base, joints)])
    plant.pose_links(base[0], joints[0])
    scene = Scene.of(task, plant, poses[..., :3].reshape(-1, 3), view)  # the target where it stands at the start
    if getattr(model, "encoder", None) == "tracking":  # its states came from the commanded points, which no file keeps
        title += "\nlatent path: each reached posture projected anew, not the states the tracking encoder gave"
    return Recorded(f"{task.name}: {title}", rows[:, slices["effectors"]].reshape(len(rows), -1, 3),
                    model._encode(joints), weights, low, high, model, scene.config["learner"], scene=scene,
                    poses=poses)


def render_frames(episode: Recorded, size: tuple[int, int] = (960, 480), max_frames: int = 400) -> NDArray[np.uint8]:
    """RGB frames (T, height, width, 3) of `iter_frames`, all in memory."""
    return np.stack(list(iter_frames(episode, size, max_frames)))


def iter_frames(episode: Recorded, size: tuple[int, int] = (960, 480), max_frames: int = 400) -> Iterator[NDArray[np.uint8]]:
    """RGB frames (height, width, 3), one at a time: the robot (or Exp 1's hands) at each stored
    step (left) and V over the latent box with the latent path so far (right; a latent space
    that is not 2-D: the robot alone, `Recorded.value_map`). What does not move is drawn once; each frame restores it and draws the moving artists on it
    (matplotlib's blitting)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from latentrl.plots import latent_value_panel
    from latentrl.render import RobotArtists, draw_backdrop, draw_toy_backdrop, scene_limits, view_subplot

    fig = Figure(figsize=(size[0] / 100, size[1] / 100), dpi=100)
    canvas = FigureCanvasAgg(fig)
    left = view_subplot(fig, VIEWS["top"] if episode.poses is None else episode.scene.view, 1,
                        2 if episode.value_map else 1, 1)
    tracers: list[Any] = []
    if episode.value_map:
        value = fig.add_subplot(1, 2, 2)
        latent_value_panel(value, episode.weights, episode.low, episode.high, episode.model, learner=episode.learner,
                           grid=60)
        tracers = [value.plot([], [], "-", color="w", lw=1.5, animated=True)[0],
                   value.plot([], [], "o", color="r", ms=6, animated=True)[0]]
    label = left.set_title("", fontsize=8)
    label.set_animated(True)
    if episode.poses is not None:
        scene = episode.scene
        draw_backdrop(left, scene, scene_limits(scene, episode.poses[..., :3].reshape(-1, 3)))  # one view for the episode
        robot = RobotArtists.of(left, scene, animated=True)
        moving = [*robot.artists, *tracers, label]

        def move(step: int) -> None:
            robot.update(episode.poses[step])  # type: ignore[index]
    else:
        draw_toy_backdrop(left, episode.toy)  # type: ignore[arg-type]
        hands, = left.plot([], [], "o-", color="C0", lw=3, animated=True)
        paths = [left.plot([], [], "-", color="C0", lw=0.8, animated=True)[0] for _ in range(2)]
        moving = [hands, *paths, *tracers, label]

        def move(step: int) -> None:
            now = episode.effectors[step]
            hands.set_data(now[:, 0], now[:, 1])
            for hand, path in enumerate(paths):
                path.set_data(episode.effectors[: step + 1, hand, 0], episode.effectors[: step + 1, hand, 1])

    fig.suptitle(episode.title, fontsize=9)
    fig.subplots_adjust(left=0.08, right=0.95, bottom=0.14, top=0.86, wspace=0.3)
    canvas.draw()  # type: ignore[no-untyped-call]
    background = canvas.copy_from_bbox(fig.bbox)  # type: ignore[no-untyped-call]
    steps = len(episode.latent)
    for step in frame_steps(steps, max_frames):
        canvas.restore_region(background)  # type: ignore[no-untyped-call]
        move(step)
        label.set_text(f"step {step} of {steps - 1}")
        if tracers:
            tracers[0].set_data(episode.latent[: step + 1, 0], episode.latent[: step + 1, 1])
            tracers[1].set_data([episode.latent[step, 0]], [episode.latent[step, 1]])
        for artist in moving:
            fig.draw_artist(artist)
        yield np.asarray(canvas.buffer_rgba())[..., :3].copy()  # type: ignore[no-untyped-call]


def frame_steps(steps: int, max_frames: int) -> NDArray[np.int64]:
    """The stored steps drawn as frames: all `steps`, or `max_frames` of them evenly spread."""
    return np.unique(np.linspace(0, steps - 1, min(steps, max_frames)).round().astype(np.int64))


def write_video(frames: Iterable[NDArray[np.uint8]], out: Path, fps: int) -> None:
    """Writes `frames` (at least one) to `out` (GIF or MP4 by suffix) as they come, through a
    temporary file, so a failed or interrupted write leaves nothing half-written. Memory stays
    bounded: an MP4's frames stream to ffmpeg (imageio's writer; at their size, an odd side
    padded by one pixel, as H.264 needs even ones), a GIF keeps each frame
    quantised to its 256-colour palette (Pillow, one byte per pixel) until it is saved. A write
    that fails (a full disk) is an OSError naming `out` (`atomic_path`, issue #38)."""
    with atomic_path(out) as temp:
        if out.suffix.lower() == ".gif":
            from PIL import Image

            images = (Image.fromarray(frame).quantize(256) for frame in frames)
            first = next(images)  # Pillow takes the rest as they come
            first.save(temp, format="GIF", save_all=True, append_images=images, duration=1000 / fps, loop=0)
            return
        import imageio.v2 as imageio

        # H.264 in yuv420p needs even sides; imageio's default would resize every frame to a
        # multiple of 16 (322 wide became 336): an odd side gets one edge pixel instead.
        writer = imageio.get_writer(temp, format="FFMPEG", fps=fps, macro_block_size=1)
        with writer:  # streams each frame to ffmpeg's stdin
            for frame in frames:
                writer.append_data(np.pad(frame, ((0, frame.shape[0] % 2), (0, frame.shape[1] % 2), (0, 0)), mode="edge"))


def run_setup(experiment: str, preset: Any, run_dir: Path) -> tuple[Any, Any, tuple[NDArray[np.float64], NDArray[np.float64]]]:
    """The task, the GPLVM and the latent box of the run in `run_dir`, as it was trained (its
    saved GPLVM: `latent_runs.run_fit`)."""
    if experiment == "train":
        from latentrl.run_settings import latent_box
        from latentrl.experiments.training import fitted

        task, _, model = fitted(preset, run_dir)
        return task, model, latent_box(model.Z_, preset.latent_margin)
    module = import_module(f"latentrl.experiments.{experiment}")
    fit = module.fit(preset, run_dir)
    return module.task_of(preset), fit.model, (fit.low, fit.high)


#: The arrays of returns.npz a replay reads, and their axes.
REPLAY_ARRAYS = {"latent": ("trials", "episodes"), "latent_paths": ("trials", "episodes", "steps", "values"),
                 "latent_test_paths": ("trials", "tests", "steps", "values"), "latent_weights": ("trials", "weights")}


def check_replay_arrays(path: Path, arrays: dict[str, NDArray[Any]]) -> None:
    """ValueError naming `path` and the array unless each array a replay reads (`REPLAY_ARRAYS`,
    where present; `latent` always) is real-valued with its axes and one row per trial (issue #38:
    a flattened array was an IndexError, strings a TypeError)."""
    if "latent" not in arrays:
        raise ValueError(f"{path}: no array 'latent' (not the returns.npz of a latent run)")
    trials = None
    for key, axes in REPLAY_ARRAYS.items():
        if key not in arrays:
            continue
        value = arrays[key]
        if value.dtype.kind not in "fiu" or value.ndim != len(axes):
            raise ValueError(f"{path}: {key}: expected real numbers of shape ({', '.join(axes)}), got {value.dtype} "
                             f"of shape {value.shape}")
        trials = len(value) if trials is None else trials
        if len(value) != trials:
            raise ValueError(f"{path}: {key} has {len(value)} trials, 'latent' {trials}")


def check_rollout_meta(path: Path, meta: dict[str, Any]) -> None:
    """ValueError naming `path` unless the fields of rollout.json a replay reads have their types:
    `trials` a list of trial indices, `policy` (and `policy_from_out` where present) a path
    (issue #38: a list as a path was a TypeError)."""
    trials = meta.get("trials")
    if not isinstance(trials, list) or not all(type(t) is int and t >= 0 for t in trials):
        raise ValueError(f"{path}: trials must be a list of trial indices, got {trials!r:.80}")
    if "policy" not in meta and "policy_from_out" not in meta:
        raise ValueError(f"{path}: names no policy (neither policy nor policy_from_out)")
    for key in ("policy", "policy_from_out"):
        if key in meta and not (isinstance(meta[key], str) and meta[key] and "\0" not in meta[key]):
            raise ValueError(f"{path}: {key} must be the path of a policy.npz, got {meta[key]!r:.80}")


def rollout_episode(out: Path, policy: str, trial: int, episode: int, view: str | None = None) -> Recorded:
    """Episode `episode` of trial `trial` of the `policy` ("greedy", "softmax", "random") rollout
    that `latentrl rollout` wrote into `out`, with the saved policy it names."""
    from latentrl.results import read_json
    from latentrl.train import POLICIES, LatentPolicy

    meta = read_json(out / "rollout.json")
    check_rollout_meta(out / "rollout.json", meta)
    if policy not in POLICIES or policy not in meta:
        ran = [p for p in POLICIES if p in meta]
        raise ValueError(f"--policy {policy}: the rollout in {out} ran {', '.join(ran)}")
    trials = list(meta["trials"])
    if trial not in trials:
        raise ValueError(f"--trial {trial}: the rollout in {out} ran trials {trials}")
    moved = out / meta.get("policy_from_out", "")  # the rollout and its run moved together
    saved = LatentPolicy.load(moved if moved.is_file() or "policy" not in meta else Path(meta["policy"]))
    key, where = f"{policy}_paths", out / "rollout.npz"
    try:
        arrays = read_npz(where, keys=[key])
    except ValueError as err:
        raise ValueError(f"{where}: {err}") from None
    # Issue #38: a missing array was a KeyError, another shape an IndexError, NaN paths "need at least one array".
    if key not in arrays:
        raise ValueError(f"{where}: no array {key!r} (the rollout ran {', '.join(p for p in POLICIES if p in meta)})")
    if arrays[key].dtype.kind != "f" or arrays[key].ndim != 4 or len(arrays[key]) != len(trials):
        raise ValueError(f"{where}: {key}: expected floats of shape (trials {len(trials)}, episodes, steps, values), "
                         f"got {arrays[key].dtype} of shape {arrays[key].shape}")
    paths = arrays[key][trials.index(trial)]
    if not 0 <= episode < len(paths):
        raise ValueError(f"--episode {episode}: the rollout recorded episodes 0..{len(paths) - 1}")
    rows = paths[episode][np.isfinite(paths[episode]).all(axis=1)]
    if len(rows) == 0:
        raise ValueError(f"{where}: {key}: episode {episode} of trial {trial} has no finite stored step")
    title = f"{policy} rollout episode {episode} of trial {trial}"
    return robot_episode(saved.task, saved.model, saved.latent_low, saved.latent_high, rows, saved.weights[trial],
                         title, view, saved.demos)


def replay(run_dir: Path, experiment: str, preset: Any, out: Path | None = None, *, rerun: Path | None = None,
           trial: int = 0, episode: int | None = None, test: int | None = None, fps: int = 20, width: int = 960,
           max_frames: int = 400, view: str | None = None) -> str:
    """Renders one recorded episode of the run in `run_dir` (`experiment` "exp1", "exp2", "exp3"
    or "train", its saved `preset`) to the video `out` and/or the Rerun recording `rerun`;
    returns what was rendered. Every argument is checked before drawing."""
    from latentrl.experiments.run_folder import RunFolder

    if experiment not in REPLAYABLE:
        raise ValueError(f"{run_dir}: a run of {experiment}; replay draws runs of {', '.join(REPLAYABLE[:-1])} "
                         "and latentrl train")
    if (episode is None) == (test is None):
        raise ValueError("give one of --episode E (a recorded training episode) or --test T (a frozen test episode)")
    check_request(out, rerun, fps, width, max_frames, view)
    folder = RunFolder(run_dir)
    arrays = folder.arrays()  # its errors name the file
    check_replay_arrays(folder.arrays_path, arrays)
    try:
        rows, what = episode_path(arrays, trial, episode, test, preset.episodes)
    except ValueError as err:  # the request, or the arrays (issue #38: name the file they are in)
        raise ValueError(f"{folder.arrays_path}: {err}") from None
    weights = arrays.get("latent_weights")
    if weights is None:
        raise ValueError(f"{run_dir}: the run kept no learnt weights to draw V from")
    weights = np.asarray(weights)[trial]
    if not np.isfinite(weights).all():  # issue #38: V would be drawn from NaN without a word
        raise ValueError(f"{folder.arrays_path}: latent_weights of trial {trial} holds NaN or infinite values (the "
                         "trial did not finish, or the file was edited)")
    drawn = recorded(experiment, preset, run_dir, rows, weights, what, view)
    return render(drawn, out, rerun, fps=fps, width=width, max_frames=max_frames)


def check_request(out: Path | None, rerun: Path | None, fps: int, width: int, max_frames: int,
                  view: str | None) -> None:
    """ValueError naming the first flag of a replay request that cannot be drawn or written."""
    if out is None and rerun is None:
        raise ValueError("give --out FILE.gif|FILE.mp4, --rerun FILE.rrd or both")
    for flag, value, least in (("--fps", fps, 1), ("--width", width, 200), ("--max-frames", max_frames, 2)):
        if value < least:
            raise ValueError(f"{flag} must be at least {least}, got {value}")
    if view is not None and view not in VIEWS:
        raise ValueError(f"--view must be one of {', '.join(VIEWS)}, got {view!r}")
    if out is not None:
        check_output(out)
    if rerun is not None:
        from latentrl.rerun_log import check_rerun_output

        check_rerun_output(rerun)


def render(drawn: Recorded, out: Path | None, rerun: Path | None, *, fps: int = 20, width: int = 960,
           max_frames: int = 400) -> str:
    """Writes the episode `drawn` to the video `out` and/or the Rerun recording `rerun`; returns
    what was written."""
    done = []
    if out is not None:
        write_video(iter_frames(drawn, size=(width, width // 2), max_frames=max_frames), out, fps)
        done.append(f"{len(frame_steps(len(drawn.latent), max_frames))} frames in {out}")
    if rerun is not None:
        from latentrl.rerun_log import write_rerun

        write_rerun(drawn, rerun)
        done.append(f"a Rerun recording of {len(drawn.latent)} steps in {rerun}")
    alone = "" if drawn.value_map else (f" (the robot alone: V is drawn over a 2-D latent space, this one is "
                                        f"{drawn.latent.shape[1]}-D)")
    return f"{drawn.title}: {' and '.join(done)}{alone}"
