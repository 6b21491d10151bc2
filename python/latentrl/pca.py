"""PCA, the linear baseline (docs/method.md §PCA): fit on centred postures by SVD."""

from __future__ import annotations

from typing import Any, ClassVar, Self

import numpy as np
from numpy.typing import NDArray

from latentrl._estimator import Estimator, SavedSpec, column_names
from latentrl._validation import as_matrix, int_at_least


def check_n_components(n_components: Any, X: NDArray[np.float64]) -> int:
    """`n_components` if it is an int with `n_components < n_samples` and `≤ n_features`."""
    n_components = int_at_least("n_components", n_components)
    n_samples, n_features = X.shape
    if n_samples <= n_components:
        raise ValueError(
            f"X: n_samples={n_samples} must be greater than n_components={n_components}"
        )
    if n_features < n_components:
        raise ValueError(f"X: n_features={n_features} must be at least n_components={n_components}")
    return int(n_components)


class PCA(Estimator):
    """Principal component analysis of postures.

    Parameters
    ----------
    n_components : int, default=2
        Dimension d of the latent space.

    Attributes
    ----------
    mean_ : ndarray (D,)
        Mean posture.
    components_ : ndarray (d, D)
        Principal axes, by decreasing variance; each axis's largest entry is positive.
    explained_variance_ : ndarray (d,)
        Variance of the data along each axis (denominator N − 1).
    explained_variance_ratio_ : ndarray (d,)
        Share of the total variance along each axis.
    n_features_in_ : int
        Number of joints D seen in `fit`.
    feature_names_in_ : ndarray (D,) of str objects
        The joint names: the column names of a pandas DataFrame passed to `fit`, if they
        are all strings (not set otherwise).

    Notes
    -----
    A scikit-learn transformer, without depending on scikit-learn: it works in
    `Pipeline`, `clone` and `GridSearchCV`, and passes every check of scikit-learn's
    `parametrize_with_checks` (tests/test_sklearn.py). `X` may be a pandas DataFrame:
    `transform` then wants the columns of `fit` in the same order, and raises a ValueError
    naming the unseen, missing or misplaced ones (it warns if only one of the two had
    column names). `transform` and `inverse_transform` return ndarrays (`transform` a
    DataFrame after `set_output(transform="pandas")`, as in a pipeline set so), the latter's
    columns in the order of `feature_names_in_`; `get_feature_names_out` names the latent
    axes ``pca0``, ``pca1``, …
    """

    _saved: ClassVar[SavedSpec] = {
        "n_features_in_": ("i", ()),
        "mean_": ("f", ("D",)),
        "components_": ("f", ("d", "D")),
        "explained_variance_": ("f", ("d",)),
        "explained_variance_ratio_": ("f", ("d",)),
    }

    def __init__(self, n_components: int = 2) -> None:
        self.n_components = n_components

    def fit(self, X: Any, y: Any = None) -> Self:
        """Fits the principal axes of `X` (N, D), an array or DataFrame; `y` is ignored.
        Returns self."""
        names = column_names(X)
        X = as_matrix("X", X)
        d = check_n_components(self.n_components, X)
        with np.errstate(over="ignore", invalid="ignore"):
            mean = X.mean(axis=0)
            centred = X - mean
            variances = (centred**2).sum(axis=0)
        if not (np.all(np.isfinite(mean)) and np.all(np.isfinite(variances))):
            raise ValueError("X: values too large, their variance overflows float64 (rescale X)")
        self.n_features_in_ = X.shape[1]
        self._set_feature_names(names)
        self.mean_ = mean
        _, s, vt = np.linalg.svd(centred, full_matrices=False)
        axes = vt[:d]
        self.components_ = (
            axes * np.sign(axes[np.arange(d), np.argmax(np.abs(axes), axis=1)])[:, None]
        )
        variances = s**2 / (X.shape[0] - 1)
        self.explained_variance_ = variances[:d]
        total = variances.sum()
        self.explained_variance_ratio_ = (
            self.explained_variance_ / total if total > 0 else np.zeros(d)
        )
        return self

    @property
    def _n_features_out(self) -> int:
        return int(self.components_.shape[0])

    def transform(self, X: Any) -> Any:
        """Latent points (N, d) of postures `X` (N, D), an array or DataFrame: an ndarray, or a
        DataFrame (`set_output`)."""
        return self._output(self._encode(self._check_X(X)), X)

    def _encode(self, X: Any) -> NDArray[np.float64]:
        """`transform` of postures whose columns are those of the fit, unnamed, without the
        warning that they have no names: latentrl's own calls with a task's joints, which
        `check_model_joints` compared with the fit's."""
        self._check_fitted()
        X = as_matrix("X", X, n_cols=self.n_features_in_)
        latent: NDArray[np.float64] = (X - self.mean_) @ self.components_.T
        return latent

    def fit_transform(self, X: Any, y: Any = None) -> Any:
        """`fit(X)`, then `transform(X)`."""
        return self.fit(X).transform(X)

    def inverse_transform(self, Z: Any) -> NDArray[np.float64]:
        """Postures (M, D) reconstructed from latent points `Z` (M, d): an ndarray, its
        columns in the order of `feature_names_in_`."""
        self._check_fitted()
        Z = as_matrix("Z", Z, n_cols=self._n_features_out)
        postures: NDArray[np.float64] = Z @ self.components_ + self.mean_
        return postures
