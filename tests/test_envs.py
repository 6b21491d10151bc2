"""Gymnasium environments: the env checker on every registered id and on the latent wrapper,
episode endings as SPEC §4 specifies, determinism given a seed, rendering."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from latentrl import GPLVM, PCA
from latentrl._native import arms_ik
from latentrl.datasets import arm_postures, bimanual_pairs
from latentrl.envs import BimanualReachEnv, LatentSpaceWrapper, TwoArmsEnv

IDS = sorted(env_id for env_id in gym.registry if env_id.startswith("latentrl/"))


def test_both_tasks_are_registered():
    assert IDS == ["latentrl/BimanualReach-v0", "latentrl/TwoArms-v0"]


@pytest.mark.parametrize("env_id", IDS)
def test_check_env(env_id):
    env = gym.make(env_id, render_mode="rgb_array")
    check_env(env.unwrapped)
    frame = env.unwrapped.render()
    assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3
    assert env.unwrapped.dt == pytest.approx(0.05)
    env.close()


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
    np.testing.assert_array_equal(obs[:4], env.posture)
    np.testing.assert_allclose(obs[4:6] + [0.1, 0.0], obs[6:], atol=1e-4)


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
    np.testing.assert_allclose(env.unwrapped.sim.targets(), target, atol=1e-12)
    np.testing.assert_allclose(z2, arms_gplvm.transform(env.unwrapped.posture[None])[0])


def test_latent_wrapper_refuses_box_exits_and_uncertain_targets(arms_gplvm):
    env = LatentSpaceWrapper(TwoArmsEnv(), arms_gplvm, latent_box=([-10, -10], [10, 10]))
    env.reset(seed=0)
    env.z = np.array([9.99, 0.0])
    _, reward, terminated, _, info = env.step(env.action_space.high)
    assert terminated and reward == -1.0 and info["end_reason"] == "box_exit"
    gated = LatentSpaceWrapper(TwoArmsEnv(), arms_gplvm, variance_threshold=1e-12)
    gated.reset(seed=0)
    before = gated.unwrapped.sim.time
    _, reward, terminated, _, info = gated.step(np.zeros(2))
    assert terminated and reward == -1.0 and info["end_reason"] == "gated"
    assert gated.unwrapped.sim.time == before  # no plant step


def test_bad_arguments():
    with pytest.raises(ValueError, match="drop_tolerance"):
        BimanualReachEnv(drop_tolerance=0.0)
    with pytest.raises(ValueError, match="render_mode"):
        TwoArmsEnv(render_mode="human")
    with pytest.raises(ValueError, match="options\\['posture'\\]"):
        BimanualReachEnv().reset(options={"posture": [0.0, 1.0]})
    pca3 = PCA().fit(np.random.default_rng(0).normal(size=(10, 3)))
    with pytest.raises(ValueError, match="postures of 4 values"):
        LatentSpaceWrapper(BimanualReachEnv(), pca3)
    pca = PCA().fit(bimanual_pairs(20, np.random.default_rng(0)))
    with pytest.raises(ValueError, match="predict_variance"):
        LatentSpaceWrapper(BimanualReachEnv(), pca, variance_threshold=0.1)
