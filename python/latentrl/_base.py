"""Shared machinery of the estimators: parameters, input and column-name checks, the
scikit-learn protocol, persistence, atomic writes and the L-BFGS fit of a GP's marginal
likelihood (used by the GPLVM and the GP encoder)."""

from __future__ import annotations

import contextlib
import inspect
import json
import os
import struct
import tokenize
import uuid
import warnings
import zipfile
import zlib
from collections.abc import Callable, Collection, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any, ClassVar, Self

import numpy as np
from numpy.typing import NDArray

from latentrl._files import open_regular
from latentrl._native import LatentrlError, gplvm_nll_grad
from latentrl._validation import as_matrix

#: Version of the NPZ layout written by `Estimator.save`; `load` refuses any other.
FORMAT_VERSION = 1

PathLike = str | os.PathLike[str]

#: Fitted attribute → (dtype kind, shape); see `Estimator`.
SavedSpec = dict[str, tuple[str, tuple[str | int, ...]]]


class NotFittedError(LatentrlError, AttributeError):
    """An estimator used before `fit`: a ValueError and an AttributeError, as in scikit-learn."""


@contextlib.contextmanager
def naming_os_errors(path: Path) -> Iterator[None]:
    """An OSError raised inside (a full disk, a read-only folder) names `path`, unless it already
    does: `cannot write PATH: No space left on device` (issue #38)."""
    try:
        yield
    except OSError as err:
        if str(path) in str(err):
            raise
        raise type(err)(err.errno, f"cannot write {path}: {err.strerror or err}") from err


def atomic_write(path: PathLike, write: Callable[[IO[bytes]], object]) -> None:
    """Calls `write` (its result is ignored) on a temporary file beside `path` (creating
    missing parent directories), flushes it to disk, then renames it over `path`, so an
    interrupted write never leaves a half-written file. A process killed mid-write leaves
    only `.{name}.<hex>.tmp` behind. An OSError names `path` (`naming_os_errors`)."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
    try:
        with naming_os_errors(path):
            path.parent.mkdir(parents=True, exist_ok=True)
            with open(tmp, "xb") as fh:
                write(fh)
                fh.flush()
                os.fsync(fh.fileno())
            os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


@contextlib.contextmanager
def atomic_path(path: PathLike) -> Iterator[Path]:
    """A temporary file name beside `path` that keeps its suffix (for writers that take a name
    and choose the format by it: imageio, rerun), renamed over `path` when the block ends and
    removed if it raises, so such a writer never leaves a half-written `path`; an OSError in the
    block names `path` (`naming_os_errors`)."""
    path = Path(path)
    tmp = path.with_name(f".{path.stem}.{uuid.uuid4().hex}.tmp{path.suffix}")
    try:
        with naming_os_errors(path):
            yield tmp
            os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


MAX_NPZ_BYTES = 2**30
"""The most bytes an NPZ file read by latentrl (a model, a run's returns) may have, and the most
bytes of arrays it may unpack to."""


class _TooLarge(ValueError):
    """An NPZ archive refused for its size, not for being corrupt."""


def _check_npz_sizes(fh: IO[bytes]) -> None:
    """Refuses, before anything is unpacked, an archive that would unpack to more than
    MAX_NPZ_BYTES (a zip bomb) or a member whose header declares more data than the member
    holds (an array of 10¹² elements in a small file)."""
    with zipfile.ZipFile(fh) as archive:
        members = archive.infolist()
        total = sum(m.file_size for m in members)
        if total > MAX_NPZ_BYTES:
            raise _TooLarge(f"it unpacks to {total} bytes, more than the {MAX_NPZ_BYTES} latentrl reads")
        for member in members:
            with archive.open(member) as item:
                version = np.lib.format.read_magic(item)
                read_header = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
                shape, _, dtype = read_header(item)
                declared = int(np.prod(shape, dtype=object)) * dtype.itemsize
                if declared > member.file_size:
                    raise _TooLarge(f"{member.filename}: its header declares {declared} bytes of data, the "
                                    f"member holds {member.file_size}")


def read_npz(path: PathLike, keys: Collection[str] | None = None) -> dict[str, NDArray[Any]]:
    """Every array of the NPZ file at `path` (those named in `keys` if given), read eagerly
    without pickles; a file that is not a regular file of at most MAX_NPZ_BYTES
    (`latentrl._files`) or not a readable NPZ is a ValueError."""
    with open_regular(path, MAX_NPZ_BYTES, "an NPZ file") as fh:
        magic = fh.read(6)
        if magic.startswith(b"\x93NUMPY"):
            raise ValueError("not a readable NPZ file: it holds a single array (.npy), not an NPZ archive")
        if not magic.startswith(b"PK\x03\x04"):
            raise ValueError("not a readable NPZ file: it has no zip archive header (latentrl writes models and results as .npz)")
        fh.seek(0)
        try:
            _check_npz_sizes(fh)
            fh.seek(0)
            npz = np.load(fh, allow_pickle=False)
            if not isinstance(npz, np.lib.npyio.NpzFile):
                raise ValueError("it holds a single array, not an NPZ archive")
            with npz:
                return {key: npz[key] for key in npz.files if keys is None or key in keys}
        except _TooLarge as err:
            raise ValueError(f"refused NPZ file: {err}") from None
        # Issue #38: a flipped byte can also name an unknown compression method (NotImplementedError),
        # spoil an array header (tokenize's TokenError, SyntaxError) or a zip record (struct.error).
        except (OSError, ValueError, EOFError, zipfile.BadZipFile, zlib.error, NotImplementedError, SyntaxError,
                tokenize.TokenError, struct.error) as err:
            raise ValueError(f"not a readable NPZ file (corrupt or truncated?): {err}") from err


def column_names(X: Any) -> NDArray[np.object_] | None:
    """The column names of a DataFrame `X` (pandas, or anything with ``columns``) as an
    object array, if they are all strings; None for other inputs and for non-string names
    (pandas' default 0, 1, …), as scikit-learn. Mixed string and other names: TypeError."""
    columns = getattr(X, "columns", None)
    if columns is None or isinstance(X, np.ndarray):
        return None
    names = np.asarray(list(columns), dtype=object)
    is_str = [isinstance(name, str) for name in names]
    if not any(is_str):
        return None
    if not all(is_str):
        types = sorted({type(name).__name__ for name in names})
        raise TypeError(
            f"X: column names must all be strings to be recorded, got types {types}; "
            "convert them (X.columns = X.columns.astype(str))"
        )
    return names


def check_feature_names(estimator: Any, names: NDArray[np.object_] | None) -> None:
    """Compares the column names `names` of a transform's input with the
    `feature_names_in_` that `estimator` was fitted with: a ValueError listing the unseen,
    the missing, or (same set) the expected order; a UserWarning if only one side has names.
    The first line is scikit-learn's, which its checks match."""
    fitted = getattr(estimator, "feature_names_in_", None)
    cls = type(estimator).__name__
    if names is None or fitted is None:
        if names is not None:
            warnings.warn(
                f"X has feature names, but {cls} was fitted without feature names", stacklevel=4
            )
        elif fitted is not None:
            warnings.warn(
                f"X does not have valid feature names, but {cls} was fitted with feature names",
                stacklevel=4,
            )
        return
    if len(names) == len(fitted) and np.all(names == fitted):
        return
    unseen = sorted(set(names) - set(fitted))
    missing = sorted(set(fitted) - set(names))
    message = "The feature names should match those that were passed during fit.\n"
    if unseen:
        message += "Feature names unseen at fit time:\n" + "".join(f"- {n}\n" for n in unseen)
    if missing:
        message += "Feature names seen at fit time, yet now missing:\n" + "".join(
            f"- {n}\n" for n in missing
        )
    if not unseen and not missing:
        message += "Feature names must be in the same order as they were in fit.\n"
    message += f"{cls} was fitted with the columns {list(fitted)}; X has {list(names)}"
    raise ValueError(message)


class Estimator:
    """scikit-learn's estimator contract without depending on it: `__init__` only stores
    its parameters; `get_params`/`set_params`, `__repr__`, pickling and NPZ save/load; the
    input checks of `fit` and `transform`, column names of pandas DataFrames
    (`feature_names_in_`), `get_feature_names_out`, and the hooks scikit-learn's tools look
    for (`__sklearn_tags__`, `__sklearn_is_fitted__`), so that `clone`, `Pipeline` and
    `GridSearchCV` take it as one of theirs.

    Subclasses list in `_saved` every fitted attribute that `save` writes, mapped to its
    dtype kind and shape: an int is an exact size, ``"d"`` is `n_components`, ``"D"`` is
    `n_features_in_`, any other symbol (``"N"``) must agree across arrays. `_build` derives
    the rest of the fitted state from those attributes after `fit` and after `load`.
    `feature_names_in_`, set only when `fit` saw column names, is saved and pickled too.
    """

    _saved: ClassVar[SavedSpec] = {}

    #: Fitted attributes (see `fit`); declared for type checkers.
    n_components: int | str
    n_features_in_: int
    feature_names_in_: NDArray[np.object_]

    def fit(self, X: Any, y: Any = None) -> Self:
        """Fits the model to postures `X` (N, D); returns self."""
        raise NotImplementedError

    def transform(self, X: Any) -> NDArray[np.float64]:
        """Latent points (M, d) of postures `X` (M, D)."""
        raise NotImplementedError

    def fit_transform(self, X: Any, y: Any = None) -> NDArray[np.float64]:
        """Latent points (N, d) of the postures `X` (N, D) it is fitted to."""
        raise NotImplementedError

    def inverse_transform(self, Z: Any) -> NDArray[np.float64]:
        """Postures (M, D) decoded from latent points `Z` (M, d)."""
        raise NotImplementedError

    @property
    def _n_features_out(self) -> int:
        """Latent dimension of the fitted model."""
        raise NotImplementedError

    @property
    def n_components_(self) -> int:
        """The fitted latent dimension d (`n_components`, or what "auto" chose)."""
        self._check_fitted()
        return self._n_features_out

    @classmethod
    def _param_names(cls) -> list[str]:
        params = inspect.signature(cls.__init__).parameters.values()
        return [p.name for p in params if p.name != "self"]

    def get_params(self, deep: bool = True) -> dict[str, Any]:
        """The constructor's parameters as a dict."""
        return {name: getattr(self, name) for name in self._param_names()}

    def set_params(self, **params: Any) -> Self:
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

    def __sklearn_is_fitted__(self) -> bool:
        """Whether `fit` (or `load`) has set the fitted state (scikit-learn's hook)."""
        return all(hasattr(self, name) for name in self._saved)

    def __sklearn_tags__(self) -> Any:
        """scikit-learn's tags: an unsupervised transformer of dense float64 matrices
        without NaN. Only scikit-learn calls this, so it is imported here, not by latentrl."""
        from sklearn.utils import InputTags, Tags, TargetTags, TransformerTags

        return Tags(
            estimator_type=None,
            target_tags=TargetTags(required=False),
            transformer_tags=TransformerTags(preserves_dtype=["float64"]),
            input_tags=InputTags(two_d_array=True, sparse=False, allow_nan=False),
        )

    def _check_fitted(self) -> None:
        if not self.__sklearn_is_fitted__():
            raise NotFittedError(f"this {type(self).__name__} is not fitted yet: call fit(X) first")

    def _check_X(self, X: Any) -> NDArray[np.float64]:
        """Postures `X` for a fitted model, as a float64 matrix: a DataFrame's columns must
        be `feature_names_in_` in the same order (a ValueError naming the unseen, missing
        or misplaced ones); a UserWarning if only one of `fit` and `X` had column names (as
        scikit-learn); then `n_features_in_` columns."""
        self._check_fitted()
        check_feature_names(self, column_names(X))
        matrix = as_matrix("X", X)
        if matrix.shape[1] != self.n_features_in_:
            raise ValueError(
                f"X has {matrix.shape[1]} features, but {type(self).__name__} is expecting "
                f"{self.n_features_in_} features as input (got shape {matrix.shape})"
            )
        return matrix

    def _set_feature_names(self, names: NDArray[np.object_] | None) -> None:
        """Records the column names `fit` saw, or forgets those of an earlier fit."""
        if names is not None:
            self.feature_names_in_ = names
        elif hasattr(self, "feature_names_in_"):
            del self.feature_names_in_

    def get_feature_names_out(self, input_features: Any = None) -> NDArray[np.object_]:
        """Names of the latent axes, ``"<class>0"``, ``"<class>1"``, … (``pca0``,
        ``gplvm1``), as scikit-learn names the outputs of its decompositions.
        `input_features`, if given, must be `feature_names_in_` (or any D names if `fit`
        saw none)."""
        self._check_fitted()
        if input_features is not None:
            given = np.asarray(input_features, dtype=object)
            fitted = getattr(self, "feature_names_in_", None)
            if fitted is not None and not np.array_equal(given, fitted):
                raise ValueError(
                    "input_features is not equal to feature_names_in_: "
                    f"{list(given)} != {list(fitted)}"
                )
            if given.ndim != 1 or len(given) != self.n_features_in_:
                raise ValueError(
                    "input_features should have length equal to number of features "
                    f"({self.n_features_in_}), got {len(given)}"
                )
        prefix = type(self).__name__.lower()
        return np.array([f"{prefix}{i}" for i in range(self._n_features_out)], dtype=object)

    def _fitted_state(self) -> dict[str, Any]:
        state = {name: getattr(self, name) for name in self._saved}
        if hasattr(self, "feature_names_in_"):
            state["feature_names_in_"] = self.feature_names_in_
        return state

    def _restore(self, state: dict[str, Any]) -> None:
        """Sets the saved attributes after checking them against `_saved`, then `_build`s."""
        # "d" is n_components, or for n_components="auto" what the saved latent points have.
        sizes = {"d": self.n_components} if isinstance(self.n_components, int) else {}
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
        names = state.get("feature_names_in_")
        if names is not None:
            names = np.asarray(names, dtype=object)
            if names.shape != (sizes["D"],) or not all(isinstance(n, str) for n in names):
                raise ValueError(
                    f"feature_names_in_: expected {sizes['D']} strings, got {names!r}"
                )
        self._set_feature_names(names)
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
        """Writes the parameters and fitted state to an NPZ file at `path` (atomically; the name
        must end in .npz, the format it holds)."""
        if not str(path).endswith(".npz"):
            raise ValueError(f"{path}: a model is saved as NPZ; give a file name ending in .npz")
        arrays = self._arrays()
        atomic_write(path, lambda fh: np.savez(fh, **arrays))

    def _arrays(self) -> dict[str, Any]:
        """The arrays `save` writes: format, version, parameters (JSON), fitted state."""
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
        if "feature_names_in_" in arrays:  # strings, not objects: `load` reads no pickles
            arrays["feature_names_in_"] = arrays["feature_names_in_"].astype(str)
        return arrays

    @classmethod
    def load(cls, path: PathLike) -> Self:
        """Reads an estimator written by `save`. A corrupt, truncated or mismatched file is a
        ValueError saying what is wrong."""
        try:
            arrays = read_npz(path)
        except ValueError as err:
            raise ValueError(f"{path}: {err}") from err
        return cls._from_arrays(arrays, str(path))

    @classmethod
    def _from_arrays(cls, arrays: dict[str, Any], path: str) -> Self:
        """The estimator of `_arrays`' output; `path` names it in errors."""
        expected = f"latentrl.{cls.__name__}"
        check_format(arrays, expected, path)
        try:
            estimator = cls(**json.loads(str(arrays["params"])))
            estimator._restore(arrays)
        except (KeyError, TypeError, ValueError, OverflowError) as err:  # OverflowError: an infinite size
            raise ValueError(f"{path}: inconsistent {expected} file: {err}") from err
        return estimator


def check_format(arrays: Mapping[str, Any], expected: str, path: str) -> None:
    """ValueError naming `path` unless `arrays` (a saved file's) hold the format `expected` (e.g.
    "latentrl.GPLVM") at this latentrl's `FORMAT_VERSION`."""
    found = str(arrays["format"]) if "format" in arrays else None
    if found != expected:
        raise ValueError(f"{path}: holds {found or 'no latentrl file'}, expected {expected}")
    version = arrays.get("format_version")
    if version is None or version.ndim != 0 or version.dtype.kind != "i" or int(version) != FORMAT_VERSION:
        shown = "missing" if version is None else f"{version.tolist()!r} ({version.dtype})"
        raise ValueError(f"{path}: format_version {shown} is not supported (this latentrl reads the integer "
                         f"{FORMAT_VERSION})")


#: The largest |log θ| a sparse fit evaluates: e^±700 is still a finite, non-zero float.
MAX_LOG_THETA = 700.0

#: The most inputs whose pairwise distances `initial_log_theta` takes the median of.
MEDIAN_SAMPLE = 4096


def initial_log_theta(
    inputs: NDArray[np.float64], centred: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Starting log θ for a GP from `inputs` (N, q) to `centred` outputs (N, p): θ1 the mean
    output variance, θ2 the median squared distance between inputs (between `MEDIAN_SAMPLE`
    evenly spaced ones when N is larger: pdist of N points takes N²/2 floats), θ3 = θ1 / 100
    (1 where a scale is zero)."""
    from scipy.spatial.distance import pdist  # SciPy loads at a fit, not at `import latentrl`

    variance = float(np.mean(centred**2)) or 1.0
    sample = inputs[np.linspace(0, len(inputs) - 1, MEDIAN_SAMPLE).astype(np.intp)] if len(inputs) > MEDIAN_SAMPLE else inputs
    lengthscale_sq = float(np.median(pdist(sample, "sqeuclidean"))) or 1.0
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
    inducing: NDArray[np.float64] | None = None


def lbfgs(objective: Callable[[NDArray[np.float64]], tuple[float, NDArray[np.float64]]], x0: NDArray[np.float64],
          bounds: Sequence[tuple[float | None, float | None]], *, max_iter: int, tol: float) -> Any:
    """scipy's L-BFGS-B on `objective` (value and gradient), stopping when the relative decrease
    of the objective or the largest projected gradient falls below `tol`, or after `max_iter`
    iterations: the one optimiser call of every likelihood fit here."""
    from scipy.optimize import minimize

    return minimize(objective, x0, jac=True, method="L-BFGS-B", bounds=bounds,
                    options={"maxiter": max_iter, "ftol": tol, "gtol": tol})


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
    inducing: NDArray[np.float64] | None = None,
) -> NllFit:
    """Minimises the GP negative log marginal likelihood (paper Eq. 1, 3) of centred `data`
    (N, D) given inputs `latent` (N, d) with L-BFGS-B and the analytic gradient: over
    `log θ`, and over the inputs too if `fit_latent` (the GPLVM). θ3 is bounded below by
    `noise_floor`; `latent_prior` adds ½‖Z‖². Stops when the relative decrease of the
    objective or the largest projected gradient falls below `tol`, or after `max_iter`
    iterations (then `converged` is False). With `inducing` (m, d) the objective is the sparse
    (DTC) bound through those inducing inputs (docs/method.md §Sparse GPLVM), optimised with the
    inputs if `fit_latent` (else held fixed)."""
    n, d = latent.shape
    # The points L-BFGS moves: the latent points, then the inducing inputs (the native
    # gradient's row order); the data term alone with fixed inputs.
    moved = np.vstack([latent, inducing]) if inducing is not None else latent

    def split(params: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        return (params[:-3].reshape(moved.shape) if fit_latent else moved), params[-3:]

    def evaluate(params: NDArray[np.float64]) -> tuple[float, NDArray[np.float64], NDArray[np.float64], float]:
        points, lt = split(params)
        if inducing is None:
            return gplvm_nll_grad(points, data, lt)
        return gplvm_nll_grad(points[:n], data, lt, inducing=points[n:])

    def objective(params: NDArray[np.float64]) -> tuple[float, NDArray[np.float64]]:
        if inducing is not None and np.max(np.abs(params[-3:])) > MAX_LOG_THETA:
            # The sparse bound's gradient grows with N: on 100k frames L-BFGS-B's line search
            # tried log θ2 = −1254 (θ2 underflows to 0). A huge value makes it step back.
            return 1e300, np.zeros_like(params)
        nll, grad_points, grad_lt, _ = evaluate(params)
        grad = np.concatenate([grad_points.ravel(), grad_lt]) if fit_latent else grad_lt
        if latent_prior:
            z = split(params)[0][:n]
            nll += 0.5 * float(np.sum(z * z))
            if fit_latent:
                grad[: n * d] += z.ravel()
        return nll, grad

    floor = np.log(noise_floor)
    x0 = np.concatenate(
        [moved.ravel() if fit_latent else [], log_theta[:2], [max(log_theta[2], floor)]]
    )
    bounds = [(None, None)] * (x0.size - 1) + [(floor, None)]
    if inducing is None:
        res = lbfgs(objective, x0, bounds, max_iter=max_iter, tol=tol)
    else:
        # L-BFGS-B's vector operations call BLAS, which OpenBLAS splits over spinning threads from
        # ~10⁴ variables: on 200k variables (100k postures) and 2 busy cores that cost 30–50× the
        # optimiser's own work (measured), and the split's rounding changes with the thread count.
        from threadpoolctl import threadpool_limits

        with threadpool_limits(limits=1, user_api="blas"):
            res = lbfgs(objective, x0, bounds, max_iter=max_iter, tol=tol)
    points, lt = split(res.x)
    return NllFit(
        np.array(points[:n]),
        np.array(lt),
        float(res.fun),
        int(res.nit),
        res.status == 0,
        str(res.message),
        evaluate(res.x)[3],
        None if inducing is None else np.array(points[n:]),
    )
