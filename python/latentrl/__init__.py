"""latentrl: reinforcement learning in the latent space of demonstrated postures."""

from latentrl._base import NotFittedError
from latentrl._native import (
    GpMap,
    InternalError,
    InvalidInputError,
    LatentrlError,
    NumericalError,
    __version__,
)
from latentrl.demos import Demonstrations, load_demos, save_demos
from latentrl.gplvm import GPLVM
from latentrl.pca import PCA
from latentrl.task import Task
from latentrl.train import LatentPolicy, train_latent_policy

import latentrl.envs  # noqa: E402, F401  (registers the Gymnasium environments, as ale_py does)

__all__ = [
    "GPLVM",
    "PCA",
    "Task",
    "Demonstrations",
    "GpMap",
    "LatentPolicy",
    "InternalError",
    "InvalidInputError",
    "LatentrlError",
    "NotFittedError",
    "NumericalError",
    "__version__",
    "load_demos",
    "save_demos",
    "train_latent_policy",
]
