"""Plain-NumPy reference versions of the GP maths (dense, with `np.linalg`): the SE kernel
(paper Eq. 2), GP prediction (Eq. 4) and the GPLVM objective and gradient (Eq. 1, 3), the
normalised RBF features, the TD(0) step, a learner's value function over its latent grid and the
two planar arms' forward kinematics. Tests check the Rust core against them; benches use them as
the baseline."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from latentrl._validation import as_matrix
from latentrl.datasets import LINKS, OFFSET, SHOULDERS

Array = NDArray[np.float64]


def se_kernel(a: Array, b: Array, theta: Array) -> Array:
    """`θ1 exp(−‖a_i − b_j‖² / (2 θ2))` between the rows of `a` (N, q) and `b` (M, q): (N, M)."""
    r2 = np.sum((a[:, None, :] - b[None, :, :]) ** 2, axis=-1)
    k: Array = theta[0] * np.exp(-0.5 * r2 / theta[1])
    return k


def kernel_matrix(points: Array, theta: Array) -> Array:
    """`K` of Eq. 2 over the rows of `points`: SE part plus `θ3 I`."""
    k: Array = se_kernel(points, points, theta) + theta[2] * np.eye(len(points))
    return k


def gp_predict(inputs: Array, outputs: Array, theta: Array, queries: Array) -> tuple[Array, Array]:
    """Eq. 4: means (M, p) and variances (M,) at `queries` of the GP fitted to (inputs, outputs),
    outputs centred and the mean added back, variance including θ3."""
    mean = outputs.mean(axis=0)
    k_inv = np.linalg.inv(kernel_matrix(inputs, theta))
    k_star = se_kernel(queries, inputs, theta)
    means = k_star @ k_inv @ (outputs - mean) + mean
    variances = theta[0] + theta[2] - np.einsum("mi,ij,mj->m", k_star, k_inv, k_star)
    return means, variances


def gplvm_nll_grad(latent: Array, centred: Array, log_theta: Array) -> tuple[float, Array, Array]:
    """Eq. 1/3: `L = (D/2) log|K| + ½ tr(K⁻¹ Y Yᵀ) + (N D/2) log 2π` and its gradient with
    respect to `latent` (N, d) and `log θ` (3,), through `∂L/∂K = ½(D K⁻¹ − K⁻¹ Y Yᵀ K⁻¹)`."""
    theta = np.exp(log_theta)
    n, dims = centred.shape
    k = kernel_matrix(latent, theta)
    k_inv = np.linalg.inv(k)
    log_det = np.linalg.slogdet(k)[1]
    yyt = centred @ centred.T
    nll = 0.5 * dims * log_det + 0.5 * np.trace(k_inv @ yyt) + 0.5 * n * dims * np.log(2 * np.pi)
    g = 0.5 * (dims * k_inv - k_inv @ yyt @ k_inv)
    k_se = se_kernel(latent, latent, theta)
    diff = latent[:, None, :] - latent[None, :, :]
    r2 = np.sum(diff**2, axis=-1)
    grad_latent = -2.0 / theta[1] * np.einsum("ij,ijk->ik", g * k_se, diff)
    grad_log_theta = np.array(
        [np.sum(g * k_se), np.sum(g * k_se * r2) / (2 * theta[1]), theta[2] * np.trace(g)]
    )
    return float(nll), grad_latent, grad_log_theta


def rbf_centres(low: Array, high: Array, per_dim: int) -> tuple[Array, Array]:
    """Centres (per_dim^d, d) of a regular grid over the box [low, high], corners included,
    and the grid spacing (d,)."""
    axes = [np.linspace(lo, hi, per_dim) for lo, hi in zip(low, high)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, len(low))
    return grid, (np.asarray(high) - np.asarray(low)) / (per_dim - 1)


def rbf_features(state: Array, centres: Array, sigma: Array) -> Array:
    """Dense normalised RBFs `b_i = φ_i / Σ_j φ_j`, `φ_i = exp(−½ Σ_k ((s_k − c_ik)/σ_k)²)`."""
    phi = np.exp(-0.5 * np.sum(((state - centres) / sigma) ** 2, axis=-1))
    features: Array = phi / phi.sum()
    return features


def td0_update(weights: Array, b: Array, reward: float, v_next: float, alpha: float, gamma: float) -> float:
    """Eq. 7–9 in place: `δ = r + γ V(s') − V(s)`, `w += α δ b(s)`; `v_next` = 0 if terminal."""
    delta = reward + gamma * v_next - weights @ b
    weights += alpha * delta * b
    return float(delta)


def value_function(
    weights: NDArray[np.float64],
    low: NDArray[np.float64],
    high: NDArray[np.float64],
    points: NDArray[np.float64],
    *,
    width: float = 1.0,
    cutoff: float | None = 3.0,
) -> NDArray[np.float64]:
    """V(z) = Σ w_i b_i(z) at `points` (M, d) with normalised RBFs on the learner's grid of
    `weights.size ** (1/d)` centres per dimension, flat index with dimension 0 fastest (as the
    Rust grid), σ_k = `width` × spacing_k; with `cutoff` (in σ) only centres within it count, as
    the learner's sparse features (None: dense). Points more than `cutoff` σ from every centre are
    not handled (the learner falls back to the nearest centre)."""
    d = points.shape[1]
    n = int(round(weights.size ** (1.0 / d)))
    axes = [np.linspace(lo, hi, n) for lo, hi in zip(low, high)]
    mesh = np.meshgrid(*axes[::-1], indexing="ij")  # last axis slowest → dimension 0 fastest
    centres = np.stack(mesh[::-1], axis=-1).reshape(-1, d)
    sigma = width * (np.asarray(high) - np.asarray(low)) / (n - 1)
    d2 = (((points[:, None, :] - centres[None, :, :]) / sigma) ** 2).sum(axis=-1)
    phi = np.exp(-0.5 * d2)
    if cutoff is not None:
        phi = np.where(d2 <= cutoff**2, phi, 0.0)
    values: NDArray[np.float64] = (phi @ weights) / phi.sum(axis=1)
    return values


def arms_forward(postures: NDArray[np.float64], *, elbows: bool = False) -> NDArray[np.float64]:
    """NumPy forward kinematics: hands (N, 4) `[x_L, y_L, x_R, y_R]` of postures (N, 4)
    `[q1_L, q2_L, q1_R, q2_R]` — `q1` from the +x axis, `q2` relative to the upper arm. With
    `elbows=True`, the elbow positions (N, 4) instead."""
    q = as_matrix("postures", postures, n_cols=4)
    l1, l2 = LINKS
    out = np.empty_like(q)
    for arm in (0, 1):
        q1, q12 = q[:, 2 * arm], q[:, 2 * arm] + q[:, 2 * arm + 1]
        ex = SHOULDERS[arm, 0] + l1 * np.cos(q1)
        ey = SHOULDERS[arm, 1] + l1 * np.sin(q1)
        if elbows:
            out[:, 2 * arm], out[:, 2 * arm + 1] = ex, ey
        else:
            out[:, 2 * arm], out[:, 2 * arm + 1] = ex + l2 * np.cos(q12), ey + l2 * np.sin(q12)
    return out


def grip_error(hands: NDArray[np.float64], test: str = "distance") -> NDArray[np.float64]:
    """NumPy grip error (N,) of hands (N, 4): `"distance"` `| ‖hand_R − hand_L‖ − ‖OFFSET‖ |`,
    `"vector"` `‖(hand_R − hand_L) − OFFSET‖`."""
    hands = as_matrix("hands", hands, n_cols=4)
    diff = hands[:, 2:] - hands[:, :2]
    error: NDArray[np.float64]
    if test == "distance":
        error = np.abs(np.linalg.norm(diff, axis=1) - np.linalg.norm(OFFSET))
    else:
        error = np.linalg.norm(diff - OFFSET, axis=1)
    return error
