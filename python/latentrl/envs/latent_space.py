"""`LatentSpaceWrapper`: RL in the latent space of a fitted `PCA` or `GPLVM` over any of the
environments (docs/method.md §RL loop)."""

from __future__ import annotations

from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from latentrl import _native, run_settings
from latentrl.envs.contract import Obs, checked_action
from latentrl.gplvm import check_model_joints
from latentrl.task import end_reasons, run_default


class LatentSpaceWrapper(gym.Wrapper[Obs, Obs, Obs, Obs], gym.utils.RecordConstructorArgs):
    """RL in the latent space of a fitted `PCA` or `GPLVM` (docs/method.md §RL loop, paper Fig. 3).

    The observation is the encoded reached posture `z = g(x̃)` (`model.transform`), clipped
    into the latent box. An action is a latent delta `u` (clipped to the action space); the
    target `z + u` is refused as the learner refuses it (`latent_core::refused`: outside the
    latent box, `"box_exit"`; with `variance_threshold`, a GPLVM variance above it, `"variance_gate"`
    — docs/method.md §RL loop step 2, §Variance gating): no plant step, the wrapped task's penalty,
    terminated. Otherwise it is decoded (`model.inverse_transform`) and handed to the wrapped
    environment as the delta `x̂ − o` from its `action_origin` `o`, which it clips to its own action
    space.

    The model's columns are the wrapped robot's joints: a model fitted to a DataFrame (its
    `feature_names_in_`) must name a task's joints in `joint_names` order (else a ValueError
    naming both lists: a latent space is never reordered). An action that is not d finite
    numbers is a ValueError naming it.

    `latent_box` = (low, high), each (d,); default: the bounding box of the GPLVM's latent
    points `Z_` widened by the `[run]` table's default `latent_margin` per side (10 %;
    docs/method.md §RL loop), or ± 3 s.d. (`explained_variance_`) for
    PCA. `max_step`: the largest latent delta per dimension; default 0.02 × the box width
    (about 0.4 RBF spacings of a 20-per-dimension grid).
    """

    def __init__(
        self,
        env: gym.Env[Obs, Obs],
        model: Any,
        variance_threshold: float | None = None,
        *,
        latent_box: tuple[Any, Any] | None = None,
        max_step: float | None = None,
    ) -> None:
        gym.utils.RecordConstructorArgs.__init__(
            self, model=model, variance_threshold=variance_threshold, latent_box=latent_box, max_step=max_step,
        )
        gym.Wrapper.__init__(self, env)
        posture = np.asarray(env.unwrapped.posture)  # type: ignore[attr-defined]
        if getattr(model, "n_features_in_", None) != posture.shape[0]:
            raise ValueError(
                f"model must be fitted to postures of {posture.shape[0]} values, "
                f"got n_features_in_={getattr(model, 'n_features_in_', None)!r}"
            )
        joints = getattr(env.unwrapped, "joint_names", None)
        if joints is not None:  # a task's robot: a model that named its columns has its joints in its order
            check_model_joints(model, joints, "model")
        if variance_threshold is not None:
            if not hasattr(model, "predict_variance"):
                raise ValueError("variance_threshold needs a model with predict_variance (GPLVM)")
            if not (np.isfinite(variance_threshold) and variance_threshold > 0):
                raise ValueError(f"variance_threshold must be > 0, got {variance_threshold!r}")
        d = int(model.n_components_)
        if latent_box is None:
            if hasattr(model, "Z_"):
                low, high = run_settings.latent_box(np.asarray(model.Z_), run_default("latent_margin"))
            else:
                sd = np.sqrt(np.asarray(model.explained_variance_))
                low, high = -3 * sd, 3 * sd
        else:
            low, high = (np.asarray(b, dtype=np.float64) for b in latent_box)
        if low.shape != (d,) or high.shape != (d,) or not np.all(high > low):
            raise ValueError(f"latent_box must be (low, high) of shape ({d},) with high > low")
        step = 0.02 * (high - low) if max_step is None else np.full(d, max_step, dtype=np.float64)
        if not np.all(np.isfinite(step) & (step > 0)):
            raise ValueError(f"max_step must be finite and > 0, got {max_step!r}")
        self.model = model
        task = getattr(env.unwrapped, "task", None)
        config = task.to_dict()["episode"] if task is not None else getattr(env.unwrapped, "config", {})
        self.penalty = float(config.get("penalty", -1.0))
        """The penalty of a refused target: the wrapped task's."""
        self.variance_threshold = variance_threshold
        self.latent_low, self.latent_high, self.max_step = low, high, step
        self.action_space = spaces.Box(-step, step, (d,), np.float64)
        self.observation_space = spaces.Box(low, high, (d,), np.float64)
        self.z = np.zeros(d)

    def _encode(self) -> Obs:
        posture = np.asarray(self.env.unwrapped.posture)  # type: ignore[attr-defined]
        encode = getattr(self.model, "_encode", self.model.transform)  # ours: columns checked above, no name warning
        z = np.asarray(encode(posture[None])[0], dtype=np.float64)
        return np.clip(z, self.latent_low, self.latent_high)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Obs, dict[str, Any]]:
        """Resets the wrapped env and returns the encoded latent point of its posture."""
        _, info = self.env.reset(seed=seed, options=options)
        self.z = self._encode()
        return self.z.copy(), info

    def step(self, action: Obs) -> tuple[Obs, SupportsFloat, bool, bool, dict[str, Any]]:
        """Moves the latent point by `action` (clipped to ±`max_step`), decodes it and steps
        the wrapped env towards that posture; a refused target ends the episode with the
        penalty instead (``end_reason`` ``"box_exit"`` / ``"variance_gate"``)."""
        u = np.clip(checked_action(action, len(self.max_step)), -self.max_step, self.max_step)
        target_z = self.z + u
        variance = None
        if self.variance_threshold is not None:  # a GPLVM: mean and variance in one native call
            decoded, variances = self.model.inverse_transform(target_z[None], return_variance=True)
            variance = float(variances[0])
        else:
            decoded = self.model.inverse_transform(target_z[None])
        refused = _native.latent_refusal(
            list(target_z), list(self.latent_low), list(self.latent_high), variance, self.variance_threshold
        )
        if refused is not None:
            return self.z.copy(), self.penalty, True, False, {"end_reason": end_reasons()[refused]}
        target = decoded[0]
        origin = np.asarray(self.env.unwrapped.action_origin)  # type: ignore[attr-defined]
        _, reward, terminated, truncated, info = self.env.step(target - origin)
        self.z = self._encode()
        return self.z.copy(), reward, terminated, truncated, info

