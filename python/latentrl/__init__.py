"""latentrl: reinforcement learning in the latent space of demonstrated postures."""

from latentrl._native import GpMap, InvalidInputError, LatentrlError, NumericalError, __version__

__all__ = ["GpMap", "InvalidInputError", "LatentrlError", "NumericalError", "__version__"]
