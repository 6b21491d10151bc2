"""Gymnasium environments: the env checker on every registered id and on the latent wrapper,
episode endings as docs/method.md §Reward and endings specifies, determinism given a seed,
rendering."""

import warnings

import gymnasium as gym
import numpy as np
import pandas as pd
import pytest
from gymnasium.utils.env_checker import check_env

from latentrl import GPLVM, PCA, Task, load_demos
from latentrl._native import arms_ik
from latentrl.datasets import arm_postures, bimanual_pairs
from latentrl.envs import BimanualReachEnv, LatentSpaceWrapper, TaskEnv, shipped_demos
from latentrl.experiments.exp3 import demos_path
from latentrl.run_settings import latent_box
from latentrl.task import run_default

IDS = sorted(env_id for env_id in gym.registry if env_id.startswith("latentrl/"))


def TwoArmsEnv(**kwargs):
    """Experiment 2's arms: the environment of `latentrl/TwoArms-v0` (no time limit)."""
    return TaskEnv("two_arms", **kwargs)


def HumanoidLiftEnv(**kwargs):
    """Experiment 3's humanoid: the environment of `latentrl/HumanoidLift-v0` (no time limit)."""
    return TaskEnv("humanoid_lift", **kwargs)


class CountingPlant:
    """The native plant, counting its steps (everything else passes through)."""

    def __init__(self, plant):
        self.plant, self.steps = plant, 0

    def step(self, target):
        self.steps += 1
        return self.plant.step(target)

    def __getattr__(self, name):
        return getattr(self.plant, name)


def test_every_task_is_registered():
    assert IDS == ["latentrl/BimanualReach-v0", "latentrl/HumanoidLift-v0", "latentrl/TwoArms-v0"]
    for env_id, name in (("latentrl/TwoArms-v0", "two_arms"), ("latentrl/HumanoidLift-v0", "humanoid_lift")):
        env = gym.make(env_id)
        assert isinstance(env.unwrapped, TaskEnv) and env.unwrapped.task.name == name
        assert env.spec.max_episode_steps == Task.shipped(name).to_dict()["episode"]["max_steps"]
        env.close()


@pytest.mark.parametrize("env_id", IDS)
def test_check_env(env_id):
    env = gym.make(env_id, render_mode="rgb_array")
    check_env(env.unwrapped)
    frame = env.unwrapped.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3
    assert env.unwrapped.dt == pytest.approx(0.05)
    env.close()


def test_rgb_array_frames_take_a_view():
    """Issue #41: a TaskEnv's frames in the view it is given (here the humanoid, side by default,
    from the top and in 3-D), the same size; a view that does not exist is refused up front."""
    frames = {}
    for view in (None, "top", "3d"):
        env = gym.make("latentrl/HumanoidLift-v0", render_mode="rgb_array", view=view)
        env.reset(seed=0)
        frames[view] = env.unwrapped.render()
        env.close()
    assert frames[None].shape == frames["top"].shape == frames["3d"].shape
    assert (frames[None] != frames["top"]).any() and (frames["top"] != frames["3d"]).any()
    with pytest.raises(ValueError, match="view must be one of top, side, front, 3d, got 'iso'"):
        TaskEnv("two_arms", view="iso")


@pytest.mark.parametrize("env_id", IDS)
def test_same_seed_same_episode(env_id):
    def rollout():
        env = gym.make(env_id)
        env.action_space.seed(3)
        obs, _ = env.reset(seed=7)
        out = [obs]
        for _ in range(5):
            obs, reward, *_ = env.step(0.01 * env.action_space.sample())
            out += [obs, [reward]]
        return np.concatenate(out)

    np.testing.assert_array_equal(rollout(), rollout())


def test_bimanual_drop_and_obstacle():
    env = BimanualReachEnv()
    env.reset(seed=0)
    _, reward, terminated, truncated, info = env.step(np.array([0.05, 0.0, -0.05, 0.0]))
    assert not terminated  # grip error 0.1: at the tolerance, still held
    _, reward, terminated, _, info = env.step(np.array([0.05, 0.0, 0.0, 0.0]))
    assert terminated and info["end_reason"] == "drop" and -1 < reward < 0
    env.reset(options={"posture": [0.28, 0.5, 0.38, 0.5]})
    _, reward, terminated, _, info = env.step(np.array([0.021, 0.0, 0.021, 0.0]))
    assert terminated and info["end_reason"] == "obstacle" and reward < 0
    env.reset(options={"posture": [1.45, 0.0, 1.49, 0.0]})
    *_, terminated, _, info = env.step(np.array([0.0, 0.0, 0.02, 0.0]))
    assert terminated and info["end_reason"] == "box_exit"


def test_bimanual_reward_at_the_target():
    env = BimanualReachEnv()
    env.reset(options={"posture": [0.0, 0.0, 0.1, 0.0]})
    _, reward, terminated, _, info = env.step(np.zeros(4))
    assert reward == pytest.approx(1.0) and not terminated and info["reached"]


def test_two_arms_episode_ends():
    env = TwoArmsEnv()
    env.reset(seed=0)
    _, reward, terminated, *_ = env.step(np.zeros(4))
    assert not terminated and 0 < reward < 1
    _, reward, terminated, _, info = env.step(np.array([0.05, 0.0, 0.0, 0.0]))
    assert terminated and info["end_reason"] == "drop" and reward < 0

    below = arms_ik(np.array([[0.1, 0.28, 0.2, 0.28]]))[0]
    env.reset(options={"posture": below})
    up = arms_ik(np.array([[0.1, 0.32, 0.2, 0.32]]))[0]
    _, reward, terminated, _, info = env.step(up - env.posture)
    assert terminated and info["end_reason"] == "obstacle" and reward < 0


def test_two_arms_observation_is_posture_then_hands():
    env = TwoArmsEnv()
    obs, _ = env.reset(seed=1)
    assert obs.shape == (4 + 6,)
    np.testing.assert_array_equal(obs[:4], env.posture)
    np.testing.assert_array_equal(obs[4:], env.effectors())
    np.testing.assert_allclose(obs[4:7] + [0.1, 0.0, 0.0], obs[7:10], atol=1e-4)
    np.testing.assert_allclose(obs[[6, 9]], 0.0, atol=1e-5)  # planar in z = 0


def test_humanoid_holds_still_then_drops_or_falls():
    env = HumanoidLiftEnv()
    base = env.task.row_slices()["base_position"]
    grip = env.task.to_dict()["constraints"][0]
    assert grip["kind"] == "distance" and grip["value"] == 0.10
    obs, _ = env.reset(seed=0)
    assert obs.shape == (25,) and np.array_equal(obs[:19], env.posture)
    start_base = env.plant.row()[base]
    for _ in range(20):  # 1 s of zero actions: the targets hold, the robot stands
        obs, reward, terminated, truncated, info = env.step(np.zeros(19))
        assert not terminated and not truncated and 0 < reward < 1
    assert np.linalg.norm(env.plant.row()[base] - start_base) < 0.02
    hands = np.linalg.norm(obs[22:25] - obs[19:22])
    assert abs(hands - grip["value"]) < 0.005
    assert env.plant.constraint_errors()[0] == pytest.approx(hands - grip["value"], abs=1e-9)
    # Opening both shoulders, step after step, spreads the hands: the object drops.
    j = env.joint_names
    spread = np.zeros(19)
    spread[j.index("l_shoulder_roll")], spread[j.index("r_shoulder_roll")] = 0.1, -0.1
    env.reset(seed=0)
    for _ in range(5):
        _, reward, terminated, _, info = env.step(spread)
        if terminated:
            break
    assert terminated and info["end_reason"] == "drop" and reward < 0
    # Tipping both ankles forward, step after step, topples the robot; the grip holds.
    tip = np.zeros(19)
    tip[j.index("l_ankle_pitch")] = tip[j.index("r_ankle_pitch")] = 0.1
    env.reset(seed=0)
    for _ in range(40):
        _, reward, terminated, _, info = env.step(tip)
        if terminated:
            break
    assert terminated and info["end_reason"] == "fall" and reward < 0


def test_humanoid_reward_peaks_at_the_highest_demonstrated_hands():
    # Without the block (the straight-arm demos 0-2 touch it, so they may not start an episode).
    lift = Task.shipped("humanoid_lift")
    env = TaskEnv(lift.replace({"obstacles": []}), shipped_demos("humanoid_lift"))
    demos = load_demos(demos_path(), expected_joints=env.joint_names).postures
    with pytest.raises(ValueError, match="breaks a rule of the task: obstacle"):
        TaskEnv(lift).reset(options={"posture": demos[0]})
    rewards = []
    for pose in demos:
        env.reset(options={"posture": pose})
        _, reward, *_ = env.step(np.zeros(19))
        rewards.append(reward)
    assert max(rewards) > 0.8 and min(rewards) < 0.2, rewards


@pytest.mark.filterwarnings("ignore:.*different from the unwrapped")
def test_latent_wrapper_on_the_humanoid_passes_check_env():
    task = Task.shipped("humanoid_lift")
    demos = load_demos(demos_path(), expected_joints=task.joint_names).postures
    model = GPLVM(max_iter=100, random_state=0).fit(demos)
    wrapped = LatentSpaceWrapper(gym.make("latentrl/HumanoidLift-v0"), model)
    check_env(wrapped)
    z, _ = wrapped.reset(seed=0)
    u = 0.5 * wrapped.action_space.high
    wrapped.step(u)
    # The servo targets are the decoded latent target (clipped to the joint limits).
    target = model.inverse_transform((z + u)[None])[0]
    np.testing.assert_allclose(wrapped.unwrapped.plant.targets(), np.clip(target, task.lower, task.upper), atol=1e-9)


@pytest.fixture(scope="module")
def arms_gplvm():
    return GPLVM(max_iter=50, random_state=0).fit(arm_postures(40, np.random.default_rng(0)))


@pytest.mark.filterwarnings("ignore:.*different from the unwrapped")
def test_latent_wrapper_passes_check_env(arms_gplvm):
    pca = PCA().fit(bimanual_pairs(50, np.random.default_rng(1)))
    for wrapped in (
        LatentSpaceWrapper(gym.make("latentrl/BimanualReach-v0"), pca),
        LatentSpaceWrapper(gym.make("latentrl/TwoArms-v0"), arms_gplvm, variance_threshold=1.0),
    ):
        check_env(wrapped)
        assert wrapped.observation_space.shape == wrapped.action_space.shape == (2,)


def test_latent_wrapper_steps_through_the_decoder(arms_gplvm):
    env = LatentSpaceWrapper(TwoArmsEnv(), arms_gplvm)
    z, _ = env.reset(seed=2)
    u = np.array([env.action_space.high[0] / 2, 0.0])
    z2, reward, terminated, _, info = env.step(u)
    target = arms_gplvm.inverse_transform((z + u)[None])[0]
    assert not terminated and info["end_reason"] is None
    np.testing.assert_allclose(env.unwrapped.plant.targets(), target, atol=1e-12)
    np.testing.assert_allclose(z2, arms_gplvm.transform(env.unwrapped.posture[None])[0])


def test_the_default_latent_box_is_the_runs_box(arms_gplvm):
    """A GPLVM's default box is a latent RL run's (`run_settings.latent_box` at the `[run]` table's
    margin): the bounding box of Z_ widened by 10 % of its width per side, to the bit."""
    env = LatentSpaceWrapper(TwoArmsEnv(), arms_gplvm)
    z = arms_gplvm.Z_
    low, high = latent_box(z, run_default("latent_margin"))
    width = z.max(axis=0) - z.min(axis=0)
    assert run_default("latent_margin") == 0.1
    np.testing.assert_array_equal(env.latent_low, low)
    np.testing.assert_array_equal(env.latent_high, high)
    np.testing.assert_array_equal(low, z.min(axis=0) - 0.1 * width)
    np.testing.assert_array_equal(high, z.max(axis=0) + 0.1 * width)


def test_latent_wrapper_refuses_box_exits_and_uncertain_targets(arms_gplvm):
    env = LatentSpaceWrapper(TwoArmsEnv(), arms_gplvm, latent_box=([-10, -10], [10, 10]))
    env.reset(seed=0)
    env.z = np.array([9.99, 0.0])
    _, reward, terminated, _, info = env.step(env.action_space.high)
    assert terminated and reward == -1.0 and info["end_reason"] == "box_exit"
    gated = LatentSpaceWrapper(TwoArmsEnv(), arms_gplvm, variance_threshold=1e-12)
    gated.reset(seed=0)
    plant = gated.unwrapped.plant = CountingPlant(gated.unwrapped.plant)
    before = plant.joint_positions(), plant.targets()
    _, reward, terminated, _, info = gated.step(np.zeros(2))
    assert terminated and reward == -1.0 and info["end_reason"] == "variance_gate"
    assert plant.steps == 0  # no plant step
    np.testing.assert_array_equal(plant.joint_positions(), before[0])
    np.testing.assert_array_equal(plant.targets(), before[1])


def test_the_wrapper_penalty_is_the_tasks():
    env = LatentSpaceWrapper(
        TaskEnv(Task.shipped("two_arms").replace({"episode.penalty": -3.0}), shipped_demos("two_arms")),
        PCA().fit(arm_postures(20, np.random.default_rng(0))),
        latent_box=([-1e-9, -1e-9], [1e-9, 1e-9]),
    )
    env.reset(seed=0)
    _, reward, terminated, _, info = env.step(env.action_space.high)
    assert terminated and reward == -3.0 and info["end_reason"] == "box_exit"


def test_the_wrapper_names_an_action_that_is_not_d_finite_numbers(arms_gplvm):
    """It was an internal "Z: non-finite" message, a NumPy broadcast error, or one value applied
    to both axes."""
    env = LatentSpaceWrapper(TwoArmsEnv(), arms_gplvm)
    env.reset(seed=0)
    for action in (np.array([np.nan, 0.0]), np.zeros(3), np.zeros(1)):
        with pytest.raises(ValueError, match="action: expected 2 finite numbers"):
            env.step(action)


def test_the_wrapper_takes_a_named_model_in_the_tasks_joint_order():
    """A model fitted to a DataFrame encodes the robot's postures without a warning per step; one
    whose columns are the joints in another order is refused (it was taken, reading the joints
    wrongly)."""
    names = list(Task.shipped("two_arms").joint_names)
    frame = pd.DataFrame(arm_postures(40, np.random.default_rng(0)), columns=names)
    env = LatentSpaceWrapper(TwoArmsEnv(), GPLVM(max_iter=50, random_state=0).fit(frame))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        env.reset(seed=0)
        env.step(np.zeros(2))
    with pytest.raises(ValueError, match=r"model: fitted to the task's joints in another order, \['right_elbow'"):
        LatentSpaceWrapper(TwoArmsEnv(), GPLVM(max_iter=50, random_state=0).fit(frame[names[::-1]]))


def test_a_task_env_matches_demo_columns_to_the_joints_by_name():
    names = list(Task.shipped("two_arms").joint_names)
    frame = pd.DataFrame(shipped_demos("two_arms"), columns=names)
    starts = [TaskEnv("two_arms", demos=demos).reset(seed=0)[0] for demos in (frame, frame[names[::-1]])]
    np.testing.assert_array_equal(*starts)
    with pytest.raises(ValueError, match="knee"):
        TaskEnv("two_arms", demos=frame.rename(columns={names[0]: "knee"}))


def test_bad_arguments():
    with pytest.raises(ValueError, match="drop_tolerance"):
        BimanualReachEnv(drop_tolerance=0.0)
    with pytest.raises(ValueError, match="render_mode"):
        TwoArmsEnv(render_mode="human")
    with pytest.raises(ValueError, match="max_step"):
        TwoArmsEnv(max_step=0.0)
    with pytest.raises(ValueError, match="options\\['posture'\\]"):
        BimanualReachEnv().reset(options={"posture": [0.0, 1.0]})
    with pytest.raises(ValueError, match="expected 19 finite values"):
        HumanoidLiftEnv().reset(options={"posture": np.zeros(4)})
    with pytest.raises(ValueError, match="breaks a rule of the task: box_exit"):  # outside the joint limits
        TwoArmsEnv().reset(options={"posture": np.full(4, 100.0)})
    with pytest.raises(ValueError, match="start_noise"):
        TaskEnv(Task.shipped("humanoid_lift").replace({"episode.start_noise": -0.1}))
    with pytest.raises(ValueError, match="no shipped task 'three_arms'"):
        TaskEnv("three_arms")
    pca3 = PCA().fit(np.random.default_rng(0).normal(size=(10, 3)))
    with pytest.raises(ValueError, match="postures of 4 values"):
        LatentSpaceWrapper(BimanualReachEnv(), pca3)
    pca = PCA().fit(bimanual_pairs(20, np.random.default_rng(0)))
    with pytest.raises(ValueError, match="predict_variance"):
        LatentSpaceWrapper(BimanualReachEnv(), pca, variance_threshold=0.1)


# moviepy's writer leaves its ffmpeg pipe to the garbage collector (a ResourceWarning of theirs).
@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
@pytest.mark.parametrize("env_id", IDS)
def test_record_video_writes_an_episode_of_every_env(env_id, tmp_path):
    """Gymnasium's RecordVideo (moviepy) records `rgb_array` frames of every latentrl env: an
    episode of 3 steps becomes an MP4 of its 4 frames (the reset's and each step's)."""
    pytest.importorskip("moviepy")
    iio = pytest.importorskip("imageio.v3")
    from gymnasium.wrappers import RecordVideo

    env = RecordVideo(gym.make(env_id, render_mode="rgb_array", max_episode_steps=3), str(tmp_path / "videos"),
                      episode_trigger=lambda episode: True, disable_logger=True)
    env.reset(seed=0)
    done = False
    while not done:
        _, _, terminated, truncated, _ = env.step(np.zeros(env.action_space.shape))
        done = terminated or truncated
    env.close()
    videos = sorted((tmp_path / "videos").glob("*.mp4"))
    assert len(videos) == 1
    frames = iio.imread(videos[0])
    assert frames.shape[0] == 4 and frames.shape[3] == 3
    assert frames.std() > 0  # a picture, not a blank frame


def test_a_success_truncates_and_does_not_terminate():
    """Issue #41: with `target.hold_steps` an episode held at the target ends as a success,
    which Gymnasium's API calls truncated (over, but not a terminal state: bootstrap it)."""
    task = Task.shipped("two_arms").replace({"target.reach_radius": 100.0, "target.hold_steps": 2})
    env = TaskEnv(task, demos=shipped_demos("two_arms"))
    env.reset(seed=0)
    zero = np.zeros(env.action_space.shape)
    _, _, terminated, truncated, info = env.step(zero)
    assert not terminated and not truncated and info == {"end_reason": None, "reached": True}
    _, _, terminated, truncated, info = env.step(zero)
    assert not terminated and truncated and info == {"end_reason": "success", "reached": True}


def test_the_time_limit_recipe_for_a_direct_task_env_is_what_a_registered_id_is():
    """`TaskEnv(task)` built directly has no time limit (Gymnasium's convention); its docstring's
    TimeLimit recipe truncates where `gym.make` of the registered id does."""
    task = Task.shipped("two_arms").replace({"episode.max_steps": 3})
    demos = shipped_demos("two_arms")
    made = gym.make("latentrl/TwoArms-v0", task=task, demos=demos, max_episode_steps=3)
    wrapped = gym.wrappers.TimeLimit(TaskEnv(task, demos), task.to_dict()["episode"]["max_steps"])
    for env in (made, wrapped):
        env.reset(seed=0)
        ends = [env.step(np.zeros(env.action_space.shape, np.float32))[2:4] for _ in range(3)]
        assert ends == [(False, False), (False, False), (False, True)]
    assert gym.spec("latentrl/TwoArms-v0").max_episode_steps == Task.shipped("two_arms").to_dict()["episode"]["max_steps"]
