"""What the latent-space experiments' setups share: which episodes keep their paths, the fitted
GPLVM's metadata for the results, and a Rust trial runner bound to one robot and latent box."""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np
from numpy.typing import NDArray

from latentrl.experiments.runner import RunTrials
from latentrl.gplvm import GPLVM


def recorded_episodes(episodes: int) -> list[int]:
    """Training episodes whose paths are kept: three during learning (Fig. 4b), the last three
    (4c)."""
    during = [0, episodes // 10, episodes // 2]
    after = list(range(max(episodes - 3, 0), episodes))
    return sorted(set(during + after))


def recorded_tests(test_episodes: int) -> list[int]:
    """Frozen test episodes whose paths are kept (Fig. 6c, 7d, 8): the first ten."""
    return list(range(min(10, test_episodes)))


def gplvm_info(model: GPLVM) -> dict[str, Any]:
    """The fitted GPLVM's objective, hyper-parameters and convergence, for results.json."""
    return {
        "nll": model.nll_,
        "theta": model.theta_,
        "converged": model.converged_,
        "n_iter": model.n_iter_,
        "encoder_theta": model.encoder_theta_,
    }


def robot_learner(
    run_trials: Callable[..., Any],
    urdf: str,
    preset: Any,
    model: GPLVM,
    box: tuple[NDArray[np.float64], NDArray[np.float64]],
    config: dict[str, Any],
) -> RunTrials:
    """`run_trials` (`_native.run_arms_trials` or `run_lift_trials`) on the robot at `urdf`,
    decoding and encoding with `model` in the latent `box` (low, high), with the preset's
    episodes, seed and frozen test episodes, the recorded episodes and the final weights."""
    low, high = box
    return partial(
        run_trials,
        urdf,
        decoder=model.decoder_,
        encoder=model.encoder_,
        latent_low=low,
        latent_high=high,
        episodes=preset.episodes,
        base_seed=preset.seed,
        config=config,
        record_episodes=recorded_episodes(preset.episodes),
        test_episodes=preset.test_episodes,
        record_test_episodes=recorded_tests(preset.test_episodes),
        return_weights=True,
    )
