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

__all__ = [
    "GPLVM",
    "PCA",
    "Demonstrations",
    "GpMap",
    "InternalError",
    "InvalidInputError",
    "LatentrlError",
    "NotFittedError",
    "NumericalError",
    "__version__",
    "load_demos",
    "save_demos",
]
