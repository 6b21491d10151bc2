"""Evenly spaced latent points (`GPLVM(spacing="even")`, `latentrl train`'s default).

The GPLVM's likelihood may pack demonstrations that differ little into a dense cluster: on the
robot zoo's iiwa-style arm the nearest-neighbour distances of the fitted latent points span a
factor of 23 (0.2 % to 4.4 % of the box), and the cluster is where the target is. One latent step
length cannot both land in such a region and cross the box within an episode (examples/zoo/README.md).
The rule here undoes the clustering along each latent axis: the points keep their order along
the axis and its range but move to evenly spaced positions (their ranks), and the kernel's θ is
fitted again with the points held there. The decoder then still passes near every demonstration
(with more noise θ3: the map is smoother than the fit's), and a step covers about as many
demonstrations anywhere in the box. docs/encoders.md §Latent spacing.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from numpy.typing import NDArray

from latentrl._nll_fit import NllFit, minimise_nll

SPACINGS = ("fit", "even")
"""`GPLVM.spacing`: the likelihood's own latent points, or the same points evenly spaced."""


def even_ranks(latent: NDArray[np.float64], points: NDArray[np.float64]) -> NDArray[np.float64]:
    """`points` (M, d) moved by the map that sends each of `latent`'s (N, d) coordinates along
    each axis to its rank's place among N evenly spaced values over the axis's range:
    piecewise linear and increasing between the sorted coordinates, constant beyond them."""
    out = np.empty_like(points)
    for j in range(latent.shape[1]):
        order = np.sort(latent[:, j])
        out[:, j] = np.interp(points[:, j], order, np.linspace(order[0], order[-1], len(order)))
    return out


def evenly_spaced(fit: NllFit, centred: NDArray[np.float64], *, noise_floor: float, max_iter: int,
                  tol: float) -> NllFit:
    """`fit`'s latent points (and inducing inputs) moved by `even_ranks` and θ refitted to the
    centred postures with them fixed; `n_iter` counts both fits, `converged` holds if both did."""
    latent = even_ranks(fit.latent, fit.latent)
    inducing = None if fit.inducing is None else even_ranks(fit.latent, fit.inducing)
    refit = minimise_nll(latent, centred, fit.log_theta, fit_latent=False, latent_prior=False,
                         noise_floor=noise_floor, max_iter=max_iter, tol=tol, inducing=inducing)
    message = refit.message if fit.converged else fit.message
    return dataclasses.replace(refit, latent=latent, inducing=inducing, n_iter=fit.n_iter + refit.n_iter,
                               converged=fit.converged and refit.converged, message=message)
