"""What the latent-space experiments' setups share: the GPLVM fit and its latent box (a run's
own, read back from its directory), which episodes keep their paths, the fitted GPLVM's
metadata for the results, and the native trial runner bound to a task, a GPLVM and its latent
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
from latentrl.experiments.presets import latent_box
from latentrl.experiments.results import as_saved, read_results
from latentrl.experiments.runner import MODEL_FILE, RunTrials, Setup
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
    def of(cls, demos: NDArray[np.float64], *, seed: int, max_iter: int, margin: float, encoder: str) -> Fitted:
        """The fit of `demos` (deterministic in `seed`) and its box with `margin` per side."""
        model = GPLVM(n_components=2, max_iter=max_iter, random_state=seed, encoder=encoder).fit(demos)
        return cls.of_model(model, margin)

    @classmethod
    def of_model(cls, model: GPLVM, margin: float) -> Fitted:
        """A fitted `model`, its training postures as the demos and its box with `margin`."""
        low, high = latent_box(model.Z_, margin)
        return cls(model.X_train_, model, low, high)


def run_fit(run: Path | str | None, margin: float, refit: Callable[[], Fitted]) -> Fitted:
    """The fit of the run in directory `run`: the GPLVM its trials learnt in, read from
    `MODEL_FILE`, so its figures, replays and resumes use that latent space on any machine (a
    refit on another CPU or BLAS can land elsewhere: docs/robustness.md). `refit()` without a
    run, or before the run's first save; for a run saved before models were kept, `refit()`
    checked against the fit results.json records."""
    meta_path = None if run is None else Path(run) / "results.json"
    if meta_path is None or not meta_path.exists():
        return refit()
    model_path = meta_path.parent / MODEL_FILE
    kept = model_path.exists()
    fitted = Fitted.of_model(GPLVM.load(model_path), margin) if kept else refit()
    saved, now = read_results(meta_path).get("setup", {}).get("gplvm"), as_saved(gplvm_info(fitted.model))
    if saved is not None and saved != now:
        source = f"{model_path} (nll {now['nll']})" if kept else (
            f"the GPLVM refitted on this machine (nll {now['nll']}; the run has no {MODEL_FILE}, and another CPU "
            "or BLAS can fit another latent space)")
        raise ValueError(f"{source} is not the one the saved trials used (nll {saved.get('nll')}, "
                         f"{meta_path}); refusing to mix them: restore the run's files, or start a new run with --out")
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


def gplvm_info(model: GPLVM) -> dict[str, Any]:
    """The fitted GPLVM's objective, hyper-parameters and convergence, for results.json."""
    return {
        "nll": model.nll_,
        "theta": model.theta_,
        "converged": model.converged_,
        "n_iter": model.n_iter_,
        "encoder": model.fitted_encoder_,
        "encoder_theta": model.encoder_theta_,
    }


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
