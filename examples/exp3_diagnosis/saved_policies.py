"""What the diagnosis scripts read of a saved Exp 3 run (e.g. `runs/exp3-full`): its preset, the
GPLVM fit its trials learnt in, its task and each trial's learnt policy."""
from pathlib import Path

import numpy as np

from latentrl import _native
from latentrl.saved_runs import saved_run
from latentrl.experiments import exp3


def load(out: Path):
    """(preset, fitted, task, policies): `policies[t]` acts greedily on trial t's learnt weights
    (`_native.LatentPolicy`, what a saved policy does)."""
    _, preset = saved_run(out)
    fitted = exp3.fit(preset, out)
    task = exp3.task_of(preset)
    learner = task.to_dict()["learner"]
    with np.load(out / "returns.npz") as npz:
        weights = npz["latent_weights"]
    policies = [_native.LatentPolicy(learner, list(fitted.low), list(fitted.high), w, fitted.model.decoder_,
                                     fitted.model.loop_encoder_) for w in weights]
    return preset, fitted, task, policies
