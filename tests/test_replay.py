"""`latentrl replay` (issue #23): a recorded episode of an Exp 1, Exp 2, Exp 3 or train run as a
GIF or MP4, or a Rerun recording, drawn from the stored path; bad requests exit 1 naming the
problem and write nothing."""

import importlib.util
import subprocess
import sys

import numpy as np
import pytest

iio = pytest.importorskip("imageio.v3")

from latentrl.cli import main  # noqa: E402

EXP3 = ["run", "exp3", "--quick", "--trials", "1", "--episodes", "4", "--episode.max-steps", "12",
        "--test-episodes", "2", "--no-progress"]
EXP1 = ["run", "exp1", "--quick", "--trials", "1", "--episodes", "3", "--plant.max-steps", "15", "--no-progress"]
EXP2 = ["run", "exp2", "--quick", "--trials", "1", "--episodes", "2", "--episode.max-steps", "10",
        "--test-episodes", "1", "--fig5-samples", "50", "--gplvm-max-iter", "20", "--no-progress"]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("replay")
    assert main([*EXP3, "--out", str(root / "exp3")]) == 0
    assert main([*EXP2, "--out", str(root / "exp2")]) == 0
    assert main([*EXP1, "--out", str(root / "exp1")]) == 0
    return root


def test_a_test_episode_of_exp3_becomes_a_gif_with_one_frame_per_stored_step(runs):
    steps = int(np.load(runs / "exp3" / "returns.npz")["latent_test_steps"][0, 0])
    out = runs / "lift.gif"
    assert main(["replay", str(runs / "exp3"), "--test", "0", "--out", str(out)]) == 0
    frames = iio.imread(out)
    assert frames.shape == (steps + 1, 480, 960, 3)
    assert not np.array_equal(frames[0], frames[-1])  # the robot and the latent point moved


def test_a_training_episode_of_exp2_becomes_an_mp4(runs):
    out = runs / "arms.mp4"
    assert main(["replay", str(runs / "exp2"), "--episode", "0", "--out", str(out), "--fps", "10"]) == 0
    assert iio.improps(out).shape[1:] == (480, 960, 3)


@pytest.mark.parametrize("width, height", [(322, 161), (320, 160)])
def test_an_mp4_keeps_the_frame_size_asked_for(tmp_path, width, height):
    """imageio resized MP4 frames to a multiple of 16 (`--width 322`: 336 × 176); now they keep
    their size, an odd side padded by one pixel (H.264 needs even sides)."""
    from latentrl.replay import write_video

    frames = [np.full((height, width, 3), 40 * i, np.uint8) for i in range(3)]
    write_video(iter(frames), tmp_path / "v.mp4", fps=5)
    assert iio.improps(tmp_path / "v.mp4").shape[1:] == (height + height % 2, width, 3)


@pytest.mark.parametrize("args, says", [
    (["--test", "5"], "--test 5: the run recorded test episodes 0..1"),
    (["--episode", "7"], "--episode 7: the run recorded training episodes [0, 1, 2, 3]"),
    (["--test", "0", "--trial", "3"], "--trial 3: the run has trials 0..0"),
    (["--test", "0", "--fps", "0"], "--fps must be at least 1"),
])
def test_bad_requests_exit_1_and_write_nothing(runs, tmp_path, capsys, args, says):
    out = tmp_path / "bad.gif"
    assert main(["replay", str(runs / "exp3"), *args, "--out", str(out)]) == 1
    assert says in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_a_suffix_it_cannot_write_and_a_missing_extra_are_named(runs, tmp_path):
    err = subprocess.run([sys.executable, "-m", "latentrl", "replay", str(runs / "exp3"), "--test", "0",
                          "--out", str(tmp_path / "x.avi")], capture_output=True, text=True)
    assert err.returncode == 1 and "write a .gif or an .mp4" in err.stderr and "Traceback" not in err.stderr
    code = ("import sys; sys.modules['imageio'] = None; from latentrl.cli import main; "
            f"sys.exit(main(['replay', {str(runs / 'exp3')!r}, '--test', '0', '--out', {str(tmp_path / 'x.gif')!r}]))")
    err = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert err.returncode == 1 and "pip install 'latentrl[video]'" in err.stderr
    assert not (tmp_path / "x.gif").exists()


def test_a_latentrl_train_run_on_a_custom_task_replays(tmp_path):
    from pathlib import Path

    example = Path(__file__).resolve().parents[1] / "examples" / "glass_arm"
    run = tmp_path / "glass"
    assert main(["train", str(example / "glass_arm.toml"), "--demos", str(example / "demos.csv"), "--out", str(run),
                 "--quick", "--trials", "1", "--episodes", "3", "--test-episodes", "1", "--episode.max-steps", "8",
                 "--no-progress"]) == 0
    out = tmp_path / "glass.gif"
    assert main(["replay", str(run), "--test", "0", "--out", str(out)]) == 0
    assert iio.imread(out).shape[1:] == (480, 960, 3)
    # Issue #41: a rollout is saved in a layout replay reads, each policy's episodes.
    rolled = tmp_path / "rolled"
    assert main(["rollout", str(run), "--out", str(rolled), "--episodes", "2", "--no-progress"]) == 0
    for policy in ("greedy", "random"):
        video = tmp_path / f"{policy}.gif"
        assert main(["replay", str(rolled), "--episode", "1", "--policy", policy, "--out", str(video)]) == 0
        with np.load(rolled / "rollout.npz") as npz:
            rows = np.isfinite(npz[f"{policy}_paths"][0, 1]).all(axis=1).sum()
        assert iio.imread(video).shape == (rows, 480, 960, 3)
    # The tracking encoder's states are not stored: the drawn latent path says it is a projection.
    from latentrl.replay import robot_episode
    from latentrl.train import LatentPolicy

    saved = LatentPolicy.load(run / "policy.npz")
    with np.load(rolled / "rollout.npz") as npz:
        path = npz["greedy_paths"][0, 0]
    drawn = robot_episode(saved.task, saved.model, saved.latent_low, saved.latent_high,
                          path[np.isfinite(path).all(axis=1)], saved.weights[0], "t")
    assert saved.model.encoder == "tracking" and "not the states the tracking encoder gave" in drawn.title
    moved = tmp_path / "moved"
    moved.mkdir()
    run.rename(moved / "glass")
    rolled.rename(moved / "rolled")
    rolled = moved / "rolled"
    assert main(["replay", str(rolled), "--episode", "0", "--out", str(tmp_path / "moved.gif")]) == 0
    assert main(["replay", str(rolled), "--episode", "5", "--out", str(tmp_path / "x.gif")]) == 1
    assert not (tmp_path / "x.gif").exists()


def test_a_run_in_a_1d_latent_space_replays_the_robot_alone(tmp_path, capsys):
    """V is drawn over a 2-D latent space: a run with a 1-D model replays without the V panel,
    saying so (it was an IndexError in plots.latent_value_grid; a 3-D model's a shape error)."""
    from pathlib import Path

    example = Path(__file__).resolve().parents[1] / "examples" / "glass_arm"
    model, run = tmp_path / "g1.npz", tmp_path / "run"
    assert main(["fit", str(example / "demos.csv"), "--n-components", "1", "--max-iter", "20", "--out", str(model)]) == 0
    assert main(["train", str(example / "glass_arm.toml"), "--demos", str(example / "demos.csv"), "--model", str(model),
                 "--out", str(run), "--quick", "--trials", "1", "--episodes", "2", "--test-episodes", "1",
                 "--episode.max-steps", "6", "--no-progress"]) == 0
    capsys.readouterr()
    out = tmp_path / "g1.gif"
    assert main(["replay", str(run), "--test", "0", "--out", str(out), "--max-frames", "3"]) == 0
    assert "the robot alone: V is drawn over a 2-D latent space, this one is 1-D" in capsys.readouterr().out
    assert iio.imread(out).shape[1:] == (480, 960, 3)
    if importlib.util.find_spec("rerun") is not None:
        assert main(["replay", str(run), "--test", "0", "--rerun", str(tmp_path / "g1.rrd")]) == 0
        entities = _entities(tmp_path / "g1.rrd")
        assert entities["/world/robot/tree"] > 0 and not any(path.startswith("/latent") for path in entities)


def test_replay_view_3d_draws_the_robot_in_perspective_as_it_moves(runs):
    """Issue #41: `replay --view 3d` writes frames of the 2-D views' size whose robot panel is
    not the side view's and changes over the episode (the 3-D artists move in blitted frames)."""
    videos = {}
    for view in ("3d", "side"):
        out = runs / f"lift-{view}.gif"
        assert main(["replay", str(runs / "exp3"), "--test", "0", "--view", view, "--max-frames", "3",
                     "--out", str(out)]) == 0
        videos[view] = iio.imread(out)
    assert videos["3d"].shape == videos["side"].shape == (3, 480, 960, 3)
    robot = [_robot_blue(frame[:, :480]) for frame in (*videos["3d"], videos["side"][0])]
    assert min(mask.sum() for mask in robot[:3]) > 5000  # every frame's solids (its sticks alone: 1800 pixels)
    assert (robot[0] != robot[3]).sum() > 1000  # not the side view
    assert (robot[0] != robot[2]).sum() > 1000  # the robot moved (not only the step counter above it)


def test_a_training_episode_of_exp1s_latent_learner_becomes_a_gif(runs):
    steps = int(np.load(runs / "exp1" / "returns.npz")["latent_steps"][0, 2])
    out = runs / "toy.gif"
    assert main(["replay", str(runs / "exp1"), "--episode", "2", "--out", str(out), "--width", "640"]) == 0
    frames = iio.imread(out)
    assert frames.shape == (steps + 1, 320, 640, 3)
    assert not np.array_equal(frames[0], frames[-1])


def _entities(path):
    """Rows per entity path of a Rerun recording, read back with rerun-sdk's own reader."""
    from collections import Counter

    from rerun.chunk import RrdReader

    rows = Counter()
    for chunk in RrdReader(path).stream():
        rows[str(chunk.entity_path)] += chunk.num_rows
    return rows


@pytest.mark.parametrize("run, what", [("exp3", ["--test", "0"]), ("exp1", ["--episode", "2"])])
def test_a_rerun_recording_holds_every_step_of_the_robot_hands_and_latent_path(runs, tmp_path, run, what):
    pytest.importorskip("rerun")
    rows = np.load(runs / run / "returns.npz")
    steps = int(rows["latent_test_steps"][0, 0] if what[0] == "--test" else rows["latent_steps"][0, 2]) + 1
    out = tmp_path / "episode.rrd"
    assert main(["replay", str(runs / run), *what, "--rerun", str(out)]) == 0
    entities = _entities(out)
    moving = ["/world/robot/boxes", "/world/robot/capsules", "/world/robot/tree"] if run == "exp3" else ["/world/robot/hands"]
    for path in [*moving, "/world/effectors/0", "/world/effectors/1", "/latent/path", "/latent/point"]:
        assert entities[path] == steps, path
    for path in ["/world/obstacles", "/world/target", "/latent/value", "/latent/demos"]:
        assert entities[path] == 1, path
    assert list(tmp_path.iterdir()) == [out]  # no temporary file left


def test_bad_rerun_requests_are_named(runs, tmp_path, capsys):
    assert main(["replay", str(runs / "exp3"), "--test", "0", "--rerun", str(tmp_path / "x.rec")]) == 1
    assert "--rerun " in capsys.readouterr().err
    assert main(["replay", str(runs / "exp3"), "--test", "0"]) == 1
    assert "give --out FILE.gif|FILE.mp4, --rerun FILE.rrd or both" in capsys.readouterr().err
    code = ("import sys; sys.modules['rerun'] = None; from latentrl.cli import main; "
            f"sys.exit(main(['replay', {str(runs / 'exp3')!r}, '--test', '0', '--rerun', {str(tmp_path / 'x.rrd')!r}]))")
    err = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert err.returncode == 1 and "pip install 'latentrl[viewer]'" in err.stderr
    assert list(tmp_path.iterdir()) == []


def test_every_output_is_checked_first_by_its_flag_and_its_missing_folders_are_made(runs, tmp_path, capsys):
    """A --rerun under a file was named --out; a --rerun in a missing folder was a RuntimeError
    traceback after the work, a --out there an error after rendering every frame."""
    (tmp_path / "afile").write_text("")
    bad = tmp_path / "afile" / "v.rrd"
    assert main(["replay", str(runs / "exp3"), "--test", "0", "--out", str(tmp_path / "v.gif"), "--rerun", str(bad)]) == 1
    assert f"--rerun {bad}: cannot write under {tmp_path / 'afile'}" in capsys.readouterr().err
    assert sorted(tmp_path.iterdir()) == [tmp_path / "afile"]
    out = tmp_path / "new" / "sub" / "v.gif"
    assert main(["replay", str(runs / "exp3"), "--test", "0", "--out", str(out), "--max-frames", "2"]) == 0
    assert out.is_file()
    if importlib.util.find_spec("rerun") is not None:
        rerun = tmp_path / "other" / "sub" / "v.rrd"
        assert main(["replay", str(runs / "exp3"), "--test", "0", "--rerun", str(rerun)]) == 0
        assert rerun.is_file()


def test_a_lifting_arm_is_seen_from_the_side_and_its_height_changes_the_picture():
    """Issue #41: a 3-D arm whose target is above it was drawn top-down (x–y), where a lift does
    not show. The default view keeps the two axes its links and target spread over most; the
    image changes with the effector's height; `view` picks one by name."""
    from pathlib import Path

    from latentrl import Task
    from latentrl.render import VIEWS, draw_task, view_axes

    arm7 = Path(__file__).parent / "robots" / "arm7_description" / "urdf" / "arm7.urdf"
    task = Task.from_dict({"name": "lift", "urdf": str(arm7), "root": "fixed", "effectors": ["tcp"],
                           "target": {"position": [[0.5, 0.0, 0.9]]}})
    plant = task.plant()
    low, high = np.nan_to_num(task.lower, neginf=-1.0), np.nan_to_num(task.upper, posinf=1.0)
    bent = np.clip(np.array([0.0, 0.9, 0.0, -1.5, 0.0, 1.8, 0.0, 0.0, 0.0][: len(low)]), low, high)
    raised = bent.copy()
    raised[1] = np.clip(0.2, low[1], high[1])  # the shoulder lifts the hand
    images, heights = [], []
    for posture in (bent, raised):
        assert plant.reset(posture) is None
        heights.append(float(plant.effectors()[2]))
        poses = np.asarray(plant.link_poses())
        assert 2 in view_axes(task, poses[:, :3], np.asarray(plant.target_position()))
        images.append(draw_task(task, plant, size=200))
    assert abs(heights[1] - heights[0]) > 0.05
    assert not np.array_equal(images[0], images[1])
    assert view_axes(task, np.zeros((1, 3)), np.zeros((1, 3)), "top") == VIEWS["top"] == (0, 1)
    # The arm's links are collision meshes: each is drawn as the outline of the hull it collides with.
    from latentrl.render import shape_outline

    pose_of = dict(zip(task.link_names, np.asarray(plant.link_poses())))
    meshes = [shape for shape in task._native.collision_shapes() if shape["kind"] == "mesh"]
    assert meshes and all(len(shape["points"]) == shape["hull"]["vertices"] for shape in meshes)
    assert all(shape_outline(pose_of[shape["link"]], shape, (0, 2)) is not None for shape in meshes)
    with pytest.raises(ValueError, match="view must be one of top, side, front, 3d, got 'iso'"):
        draw_task(task, plant, view="iso")


def _arm7_lift():
    """The test arm (collision meshes on every link) with its target above the start, and two
    postures whose effector heights differ: bent forward, and lifted at the shoulder."""
    from pathlib import Path

    from latentrl import Task

    arm7 = Path(__file__).parent / "robots" / "arm7_description" / "urdf" / "arm7.urdf"
    task = Task.from_dict({"name": "lift", "urdf": str(arm7), "root": "fixed", "effectors": ["tcp"],
                           "target": {"position": [[0.5, 0.0, 0.9]]}, "floor": {"height": 0.0}})
    low, high = np.nan_to_num(task.lower, neginf=-1.0), np.nan_to_num(task.upper, posinf=1.0)
    bent = np.clip(np.array([0.0, 0.9, 0.0, -1.5, 0.0, 1.8, 0.0, 0.0, 0.0][: len(low)]), low, high)
    raised = bent.copy()
    raised[1] = np.clip(0.2, low[1], high[1])
    return task, (bent, raised)


def _draw_3d(scene, poses, limits):
    """The 3d view of `scene` at link poses `poses` within `limits`, and a function from world
    points to the (row, column) of their pixel in it."""
    from mpl_toolkits.mplot3d import proj3d

    from latentrl.render import _canvas, _pixels, draw_scene

    fig, ax = _canvas(200, scene.view)
    draw_scene(ax, scene, poses, limits)
    image = _pixels(fig)

    def pixel(point):
        x, y, _ = proj3d.proj_transform(*point, ax.get_proj())
        column, up = ax.transData.transform((x, y))
        return image.shape[0] - int(round(up)), int(round(column))

    return image, pixel


def _robot_blue(image):
    """Where `image` (..., 3) has the robot's colour (C0, blue over the light panes): blue well
    above red (the target is green, obstacles, floor, panes and text grey)."""
    return image[..., 2].astype(int) - image[..., 0] > 60


def test_the_3d_view_shows_a_lift_of_the_effector_in_the_drawing_size():
    """Issue #41: in the 3d view (mplot3d, the same image size as the 2-D views) an arm lifting
    its effector toward a target above it is drawn higher: the pixels around the effector change,
    the robot is drawn at its effector in both postures, and the lifted one sits higher."""
    from latentrl.render import VIEWS, Scene, draw_task, scene_limits

    task, postures = _arm7_lift()
    plant = task.plant()
    poses, heights = [], []
    for posture in postures:
        assert plant.reset(posture) is None
        poses.append(np.asarray(plant.link_poses()))
        heights.append(float(plant.effectors()[2]))
    assert heights[1] - heights[0] > 0.05
    assert draw_task(task, plant, size=200, view="3d").shape == draw_task(task, plant, size=200, view="side").shape
    scene = Scene.of(task, plant, np.concatenate(poses)[:, :3], "3d")
    assert scene.view == VIEWS["3d"] == (0, 1, 2)
    limits = scene_limits(scene, np.concatenate(poses)[:, :3])  # one frame for both, as a replay draws
    drawn = [_draw_3d(scene, pose, limits) for pose in poses]
    tcp = task.link_names.index("tcp")
    where = [pixel(pose[tcp, :3]) for (_, pixel), pose in zip(drawn, poses)]
    assert where[1][0] < where[0][0] - 5  # the lifted effector is higher in the picture
    for (image, _), (row, column) in zip(drawn, where):
        assert _robot_blue(image[row - 3: row + 4, column - 3: column + 4]).sum() > 5
    bent, raised = (image.astype(int) for image, _ in drawn)
    for row, column in where:
        window = np.s_[row - 3: row + 4, column - 3: column + 4]
        assert np.abs(bent[window] - raised[window]).sum() > 1000


def test_the_3d_view_draws_a_mesh_link_as_its_hull():
    """Issue #41: a link whose collision shape is a mesh is drawn in the 3d view as the hull the
    physics collides with: without the kinematic tree's sticks, the pixels where the link is
    are the robot's, and they are background when the shape is left out."""
    from dataclasses import replace

    from latentrl.render import Scene, scene_limits, shape_points

    task, (bent, _) = _arm7_lift()
    plant = task.plant()
    assert plant.reset(bent) is None
    poses = np.asarray(plant.link_poses())
    scene = replace(Scene.of(task, plant, poses[:, :3], "3d"), edges=())
    limits = scene_limits(scene, poses[:, :3])
    link4 = [shape for shape in scene.shapes if shape["link"] == "link4"]
    assert [shape["kind"] for shape in link4] == ["mesh"]
    centre = shape_points(poses[task.link_names.index("link4")], link4[0]).mean(axis=0)
    with_mesh, pixel = _draw_3d(scene, poses, limits)
    without, _ = _draw_3d(replace(scene, shapes=tuple(s for s in scene.shapes if s["link"] != "link4")), poses, limits)
    row, column = pixel(centre)
    window = np.s_[row - 2: row + 3, column - 2: column + 3]
    assert _robot_blue(with_mesh[window]).all()
    assert not _robot_blue(without[window]).any()


STREAM = """
import re, sys
from pathlib import Path
import numpy as np
from latentrl.replay import write_video

def frames():
    rng = np.random.default_rng(0)
    for t in range(200):
        frame = np.full((480, 960, 3), t, dtype=np.uint8)
        frame[::7, ::5] = rng.integers(0, 255, size=frame[::7, ::5].shape, dtype=np.uint8)
        yield frame

write_video(frames(), Path(sys.argv[1]), 20)
# VmHWM: this program's own peak (ru_maxrss would keep the forked parent's across exec)
print(int(re.search(r"VmHWM:\\s+(\\d+) kB", open("/proc/self/status").read()).group(1)) // 1024)
"""


@pytest.mark.parametrize("suffix", [".gif", ".mp4"])
def test_a_200_frame_960_wide_clip_streams_in_bounded_memory(tmp_path, suffix):
    """Issue #41: frames are written as they are drawn, so a 200-frame 960 × 480 clip (276 MB of
    RGB frames held at once) peaks below 300 MB (measured 205 MB for the GIF, 88 MB for the MP4):
    GIF frames are kept quantised (1 byte per pixel), MP4 frames stream to ffmpeg."""
    out = tmp_path / f"clip{suffix}"
    done = subprocess.run([sys.executable, "-c", STREAM, str(out)], capture_output=True, text=True, check=True)
    assert int(done.stdout.split()[-1]) < 300
    if suffix == ".gif":
        assert iio.improps(out).shape[0] == 200
    else:  # ffmpeg counts the frames itself (imageio's reader may leave its pipe to the GC)
        import imageio_ffmpeg

        assert imageio_ffmpeg.count_frames_and_secs(str(out))[0] == 200


def test_a_rerun_recording_draws_mesh_links_as_their_hulls(tmp_path):
    """Issue #41: a link whose collision shape is a mesh is drawn in Rerun as the convex hull the
    physics collides with, moving with the link (it was drawn only by its stick)."""
    pytest.importorskip("rerun")
    from pathlib import Path
    from types import SimpleNamespace

    import rerun as rr

    from latentrl import Task
    from latentrl.render import Scene
    from latentrl.rerun_log import _log_robot

    arm7 = Path(__file__).parent / "robots" / "arm7_description" / "urdf" / "arm7.urdf"
    task = Task.from_dict({"name": "arm", "urdf": str(arm7), "root": "fixed", "effectors": ["tcp"],
                           "target": {"position": [[0.5, 0.0, 0.9]]}})
    plant = task.plant()
    poses = []
    for shoulder in (0.0, 0.6):
        posture = np.clip(np.r_[0.0, shoulder, np.zeros(len(task.lower) - 2)], task.lower, task.upper)
        assert plant.reset(posture) is None
        poses.append(np.asarray(plant.link_poses()))
    scene = Scene.of(task, plant, np.concatenate(poses)[:, :3], None)
    hulls = [shape for shape in scene.shapes if shape["kind"] == "mesh"]
    assert hulls
    out = tmp_path / "arm.rrd"
    rec = rr.RecordingStream("test")
    rec.save(out)
    for step in range(2):
        rec.set_time("step", sequence=step)
        _log_robot(rec, SimpleNamespace(scene=scene, poses=np.stack(poses)), step)
    rec.flush()
    rec.disconnect()
    from rerun.chunk import RrdReader

    vertices = [chunk for chunk in RrdReader(out).stream() if str(chunk.entity_path) == "/world/robot/meshes"]
    assert sum(chunk.num_rows for chunk in vertices) == 2
