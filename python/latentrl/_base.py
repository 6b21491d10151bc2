"""Shared machinery of the estimators: parameters, persistence, atomic writes and the
L-BFGS fit of a GP's marginal likelihood (used by the GPLVM and the GP encoder)."""

from __future__ import annotations

import inspect
import json
import os
import uuid
import zipfile
import zlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any, ClassVar

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import minimize
from scipy.spatial.distance import pdist

from latentrl._native import LatentrlError, gplvm_nll_grad

#: Version of the NPZ layout written by `Estimator.save`; `load` refuses any other.
FORMAT_VERSION = 1

PathLike = str | os.PathLike[str]

#: Fitted attribute → (dtype kind, shape); see `Estimator`.
SavedSpec = dict[str, tuple[str, tuple[str | int, ...]]]


class NotFittedError(LatentrlError, AttributeError):
    """An estimator used before `fit`: a ValueError and an AttributeError, as in scikit-learn."""


def atomic_write(path: PathLike, write: Callable[[IO[bytes]], None]) -> None:
    """Calls `write` on a temporary file beside `path` (creating missing parent directories),
    flushes it to disk, then renames it over `path`, so an interrupted write never leaves a
    half-written file. A process killed mid-write leaves only `.{name}.<hex>.tmp` behind."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
    try:
        with open(tmp, "xb") as fh:
            write(fh)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def read_npz(path: PathLike) -> dict[str, NDArray[Any]]:
    """Every array of the NPZ file at `path`, read eagerly without pickles; a file that
    is not a readable NPZ is a ValueError."""
    with open(path, "rb") as fh:
        try:
            npz = np.load(fh, allow_pickle=False)
            if not isinstance(npz, np.lib.npyio.NpzFile):
                raise ValueError("it holds a single array, not an NPZ archive")
            with npz:
                return {key: npz[key] for key in npz.files}
        except (OSError, ValueError, EOFError, zipfile.BadZipFile, zlib.error) as err:
            raise ValueError(f"not a readable NPZ file (corrupt or truncated?): {err}") from err


class Estimator:
    """scikit-learn's estimator contract without depending on it: `__init__` only stores
    its parameters; `get_params`/`set_params`, `__repr__`, pickling and NPZ save/load.

    Subclasses list in `_saved` every fitted attribute that `save` writes, mapped to its
    dtype kind and shape: an int is an exact size, ``"d"`` is `n_components`, ``"D"`` is
    `n_features_in_`, any other symbol (``"N"``) must agree across arrays. `_build` derives
    the rest of the fitted state from those attributes after `fit` and after `load`.
    """

    _saved: ClassVar[SavedSpec] = {}

    @classmethod
    def _param_names(cls) -> list[str]:
        params = inspect.signature(cls.__init__).parameters.values()
        return [p.name for p in params if p.name != "self"]

    def get_params(self, deep: bool = True) -> dict[str, Any]:
        """The constructor's parameters as a dict."""
        return {name: getattr(self, name) for name in self._param_names()}

    def set_params(self, **params: Any) -> Estimator:
        """Sets constructor parameters; returns self."""
        valid = self._param_names()
        for name, value in params.items():
            if name not in valid:
                raise ValueError(
                    f"invalid parameter {name!r} for {type(self).__name__}; valid: {valid}"
                )
            setattr(self, name, value)
        return self

    def __repr__(self) -> str:
        defaults = inspect.signature(type(self).__init__).parameters
        changed = [f"{k}={v!r}" for k, v in self.get_params().items() if v != defaults[k].default]
        return f"{type(self).__name__}({', '.join(changed)})"

    def _build(self) -> None:
        """Derives the fitted state that is not saved (native maps, aliases)."""

    def _check_fitted(self) -> None:
        if not all(hasattr(self, name) for name in self._saved):
            raise NotFittedError(f"this {type(self).__name__} is not fitted yet: call fit(X) first")

    def _fitted_state(self) -> dict[str, Any]:
        return {name: getattr(self, name) for name in self._saved}

    def _restore(self, state: dict[str, Any]) -> None:
        """Sets the saved attributes after checking them against `_saved`, then `_build`s."""
        sizes = {"d": self.n_components}  # type: ignore[attr-defined]
        if "n_features_in_" in state:
            sizes["D"] = int(state["n_features_in_"])
        for name, (kind, shape) in self._saved.items():
            if name not in state:
                raise ValueError(f"missing fitted attribute {name!r}")
            value = np.asarray(state[name])
            if value.dtype.kind != kind or value.ndim != len(shape):
                raise ValueError(
                    f"{name}: expected a {len(shape)}-D array of kind {kind!r}, "
                    f"got dtype {value.dtype} shape {value.shape}"
                )
            for symbol, size in zip(shape, value.shape):
                expected = symbol if isinstance(symbol, int) else sizes.setdefault(symbol, size)
                if size != expected:
                    raise ValueError(f"{name}: axis {symbol} has size {size}, expected {expected}")
            setattr(self, name, value.item() if value.ndim == 0 else value)
        self._build()

    def __getstate__(self) -> dict[str, Any]:
        state = {"params": self.get_params()}
        if all(hasattr(self, name) for name in self._saved):
            state["fitted"] = self._fitted_state()
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.set_params(**state["params"])
        if "fitted" in state:
            self._restore(state["fitted"])

    def save(self, path: PathLike) -> None:
        """Writes the parameters and fitted state to an NPZ file at `path` (atomically)."""
        self._check_fitted()
        try:
            params = json.dumps(self.get_params())
        except TypeError as err:
            raise ValueError(
                f"cannot save {self!r}: its parameters must be plain numbers or strings ({err})"
            ) from err
        arrays: dict[str, Any] = {
            "format": np.array(f"latentrl.{type(self).__name__}"),
            "format_version": np.array(FORMAT_VERSION),
            "params": np.array(params),
            **{name: np.asarray(value) for name, value in self._fitted_state().items()},
        }
        atomic_write(path, lambda fh: np.savez(fh, **arrays))

    @classmethod
    def load(cls, path: PathLike) -> Any:
        """Reads an estimator written by `save`. A corrupt, truncated or mismatched file is a
        ValueError saying what is wrong."""
        try:
            arrays = read_npz(path)
        except ValueError as err:
            raise ValueError(f"{path}: {err}") from err
        expected = f"latentrl.{cls.__name__}"
        found = str(arrays["format"]) if "format" in arrays else None
        if found != expected:
            raise ValueError(f"{path}: holds {found or 'no latentrl model'}, expected {expected}")
        version = arrays.get("format_version")
        if (
            version is None
            or version.ndim != 0
            or version.dtype.kind != "i"
            or int(version) != FORMAT_VERSION
        ):
            raise ValueError(
                f"{path}: format version {version} is not supported "
                f"(this latentrl reads {FORMAT_VERSION})"
            )
        try:
            estimator = cls(**json.loads(str(arrays["params"])))
            estimator._restore(arrays)
        except (KeyError, TypeError, ValueError) as err:
            raise ValueError(f"{path}: inconsistent {expected} file: {err}") from err
        return estimator


def initial_log_theta(
    inputs: NDArray[np.float64], centred: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Starting log θ for a GP from `inputs` (N, q) to `centred` outputs (N, p): θ1 the mean
    output variance, θ2 the median squared distance between inputs, θ3 = θ1 / 100
    (1 where a scale is zero)."""
    variance = float(np.mean(centred**2)) or 1.0
    lengthscale_sq = float(np.median(pdist(inputs, "sqeuclidean"))) or 1.0
    # Clamped at the smallest normal float: data of scale 1e-161 underflows θ3 to 0.
    return np.log(np.maximum([variance, lengthscale_sq, variance / 100], np.finfo(np.float64).tiny))


@dataclass(frozen=True)
class NllFit:
    """Result of `minimise_nll`."""

    latent: NDArray[np.float64]
    log_theta: NDArray[np.float64]
    nll: float
    n_iter: int
    converged: bool
    message: str
    jitter: float


def minimise_nll(
    latent: NDArray[np.float64],
    data: NDArray[np.float64],
    log_theta: NDArray[np.float64],
    *,
    fit_latent: bool,
    latent_prior: bool,
    noise_floor: float,
    max_iter: int,
    tol: float,
) -> NllFit:
    """Minimises the GP negative log marginal likelihood (paper Eq. 1, 3) of centred `data`
    (N, D) given inputs `latent` (N, d) with L-BFGS-B and the analytic gradient: over
    `log θ`, and over the inputs too if `fit_latent` (the GPLVM). θ3 is bounded below by
    `noise_floor`; `latent_prior` adds ½‖Z‖². Stops when the relative decrease of the
    objective or the largest projected gradient falls below `tol`, or after `max_iter`
    iterations (then `converged` is False)."""
    n, d = latent.shape

    def split(params: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        return (params[:-3].reshape(n, d) if fit_latent else latent), params[-3:]

    def objective(params: NDArray[np.float64]) -> tuple[float, NDArray[np.float64]]:
        z, lt = split(params)
        nll, grad_z, grad_lt, _ = gplvm_nll_grad(z, data, lt)
        grad = np.concatenate([grad_z.ravel(), grad_lt]) if fit_latent else grad_lt
        if latent_prior:
            nll += 0.5 * float(np.sum(z * z))
            if fit_latent:
                grad[:-3] += z.ravel()
        return nll, grad

    floor = np.log(noise_floor)
    x0 = np.concatenate(
        [latent.ravel() if fit_latent else [], log_theta[:2], [max(log_theta[2], floor)]]
    )
    bounds = [(None, None)] * (x0.size - 1) + [(floor, None)]
    res = minimize(
        objective,
        x0,
        jac=True,
        method="L-BFGS-B",
        bounds=bounds,
        options={"maxiter": max_iter, "ftol": tol, "gtol": tol},
    )
    z, lt = split(res.x)
    jitter = gplvm_nll_grad(z, data, lt)[3]
    return NllFit(
        np.array(z),
        np.array(lt),
        float(res.fun),
        int(res.nit),
        res.status == 0,
        str(res.message),
        jitter,
    )
