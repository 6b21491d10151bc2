"""What the latent-space experiments' setups share: the GPLVM fit and its latent box (a run's
own, read back from its directory: `RunFolder`), which episodes keep their paths, and the
native trial runner bound to a task, a GPLVM and its latent
box."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from latentrl import _native
from latentrl.run_settings import latent_box
from latentrl.results import gplvm_info
from latentrl.experiments.run_folder import RunFolder
from latentrl.experiments.runner import RunTrials, Setup
from latentrl.gplvm import GPLVM
from latentrl.task import Task


@dataclass(frozen=True)
class Fitted:
    """The demonstrations, the GPLVM (d = 2) fitted to them and the latent box of the learner."""

    demos: NDArray[np.float64]
    model: GPLVM
    low: NDArray[np.float64]
    high: NDArray[np.float64]

    @classmethod
    def of(cls, demos: NDArray[np.float64], *, seed: int, max_iter: int, margin: float, encoder: str,
           spacing: str) -> Fitted:
        """The fit of `demos` (deterministic in `seed`) and its box with `margin` per side; `spacing`
        the run's `latent_spacing` ("auto" derives nothing here: the fit's points)."""
        model = GPLVM(n_components=2, max_iter=max_iter, random_state=seed, encoder=encoder,
                      spacing="fit" if spacing == "auto" else spacing).fit(demos)
        return cls.of_model(model, margin)

    @classmethod
    def of_model(cls, model: GPLVM, margin: float) -> Fitted:
        """A fitted `model`, its training postures as the demos and its box with `margin`."""
        low, high = latent_box(model.Z_, margin)
        return cls(model.X_train_, model, low, high)


def run_fit(run: RunFolder | Path | str | None, margin: float, refit: Callable[[], Fitted]) -> Fitted:
    """The fit of the run in directory `run`: the GPLVM its trials learnt in, read from its
    `MODEL_FILE` (`RunFolder.model`), so its figures, replays and resumes use that latent space
    on any machine (a refit on another CPU or BLAS can land elsewhere: docs/robustness.md).
    `refit()` without a run, or before the run's first save; for a run saved before models were
    kept, `refit()` checked against the fit results.json records (`RunFolder.check_fit`)."""
    folder = run if isinstance(run, RunFolder) or run is None else RunFolder(run)
    if folder is None or not folder.holds_run():
        return refit()
    saved = folder.model()
    fitted = Fitted.of_model(saved, margin) if saved is not None else refit()
    folder.check_fit(fitted.model, kept=saved is not None)
    return fitted


def recorded_episodes(episodes: int) -> list[int]:
    """Training episodes whose paths are kept: three during learning (Fig. 4b), the last three
    (4c)."""
    during = [0, episodes // 10, episodes // 2]
    after = list(range(max(episodes - 3, 0), episodes))
    return sorted(set(during + after))


def recorded_tests(test_episodes: int) -> list[int]:
    """Frozen test episodes whose paths are kept (Fig. 6c, 7d, 8): the first ten."""
    return list(range(min(10, test_episodes)))


def task_learner(
    task: Task,
    model: GPLVM,
    box: tuple[NDArray[np.float64], NDArray[np.float64]],
    demos: NDArray[np.float64],
    *,
    episodes: int,
    seed: int,
    test_episodes: int = 0,
) -> RunTrials:
    """`_native.run_task_trials` on `task`, decoding and encoding with `model` in the latent
    `box` (low, high), starting "demo" episodes from `demos`, with the recorded episodes, the
    effectors at every test start (`test_start_hands`) and the final weights."""
    low, high = box
    run = partial(
        _native.run_task_trials,
        task._native,
        decoder=model.decoder_,
        encoder=model.loop_encoder_,
        latent_low=low,
        latent_high=high,
        demos=np.ascontiguousarray(demos, dtype=np.float64),
        episodes=episodes,
        base_seed=seed,
        record_episodes=recorded_episodes(episodes),
        test_episodes=test_episodes,
        record_test_episodes=recorded_tests(test_episodes),
        return_weights=True,
    )
    effectors = task.row_slices()["effectors"]

    def with_start_hands(**kwargs: Any) -> dict[str, Any]:
        """The native result plus `test_start_hands`: the effectors of every test start."""
        out = run(**kwargs)
        out["test_start_hands"] = out.pop("test_starts")[..., effectors]
        return out

    return with_start_hands


def latent_setup(
    preset: Any,
    task: Task,
    model: GPLVM,
    box: tuple[NDArray[np.float64], NDArray[np.float64]],
    demos: NDArray[np.float64],
) -> Setup:
    """The setup of a latent experiment on a task: its one learner and what results.json
    records of the fit, the box, the recorded episodes and the effective task."""
    low, high = box
    learner = task_learner(
        task, model, box, demos, episodes=preset.episodes, seed=preset.seed, test_episodes=preset.test_episodes
    )
    info = {
        "gplvm": gplvm_info(model),
        "latent_box": {"low": low, "high": high},
        "demo_latent": model.Z_,
        "recorded_episodes": recorded_episodes(preset.episodes),
        "recorded_test_episodes": recorded_tests(preset.test_episodes),
        "task": task.to_dict(),
    }
    return Setup(learners={"latent": learner}, info=info, model=model)
