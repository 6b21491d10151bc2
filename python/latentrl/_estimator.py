"""The estimators' shared contract (`Estimator`, scikit-learn's without depending on it):
parameters, input and column-name checks, pickling, and NPZ save/load."""

from __future__ import annotations

import inspect
import json
import sys
import warnings
from typing import Any, ClassVar, Self

import numpy as np
from numpy.typing import NDArray

from latentrl._native import LatentrlError
from latentrl._persistence import FORMAT_VERSION, PathLike, atomic_write, check_format, read_npz
from latentrl._validation import as_matrix

#: Fitted attribute → (dtype kind, shape); see `Estimator`.
SavedSpec = dict[str, tuple[str, tuple[str | int, ...]]]


class NotFittedError(LatentrlError, AttributeError):
    """An estimator used before `fit`: a ValueError and an AttributeError, as in scikit-learn."""


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


def _plain_number(value: Any) -> Any:
    """A NumPy scalar (`np.int64(3)`, as GridSearchCV's grids give) as the plain number or
    string it is, for `json.dumps`; anything else is a TypeError."""
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"Object of type {type(value).__name__} is not JSON serializable")


OUTPUTS = ("default", "pandas", "polars")
"""What `set_output(transform=...)` takes, as scikit-learn's."""


class Estimator:
    """scikit-learn's estimator contract without depending on it: `__init__` only stores
    its parameters; `get_params`/`set_params`, `__repr__`, pickling and NPZ save/load; the
    input checks of `fit` and `transform`, column names of pandas DataFrames
    (`feature_names_in_`), `get_feature_names_out`, and the hooks scikit-learn's tools look
    for (`__sklearn_tags__`, `__sklearn_is_fitted__`), so that `clone`, `Pipeline` and
    `GridSearchCV` take it as one of theirs.

    Subclasses list in `_saved` every fitted attribute that `save` writes, mapped to its
    dtype kind and shape: an int is an exact size, ``"D"`` is `n_features_in_`, any other
    symbol (``"d"``, the fitted latent dimension; ``"N"``) must agree across arrays. `_build`
    derives the rest of the fitted state from those attributes after `fit` and after `load`.
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

    def transform(self, X: Any) -> Any:
        """Latent points (M, d) of postures `X` (M, D): an ndarray, or a DataFrame (`set_output`)."""
        raise NotImplementedError

    def fit_transform(self, X: Any, y: Any = None) -> Any:
        """Latent points (N, d) of the postures `X` (N, D) it is fitted to (as `transform`'s)."""
        raise NotImplementedError

    def set_output(self, *, transform: str | None = None) -> Self:
        """scikit-learn's output API (`Pipeline.set_output` calls it): ``"pandas"`` or ``"polars"``
        makes `transform` and `fit_transform` return a DataFrame with the columns
        `get_feature_names_out()` (pandas: the index of a DataFrame given); ``"default"``
        ndarrays, unless scikit-learn is imported and its `transform_output` is set; None
        changes nothing. Kept by pickling and `clone`, not by `save` (a setting, not the fit)."""
        if transform is None:
            return self
        if transform not in OUTPUTS:
            raise ValueError(f"set_output: transform must be one of {list(OUTPUTS)} or None, got {transform!r}")
        self._sklearn_output_config = {"transform": transform}  # the attribute scikit-learn's clone copies
        return self

    def _output(self, latent: NDArray[np.float64], X: Any) -> Any:
        """`latent`, the latent points of postures `X`, in the form `set_output` asked for."""
        how = getattr(self, "_sklearn_output_config", {}).get("transform", "default")
        sklearn = sys.modules.get("sklearn")
        if how == "default" and sklearn is not None:
            how = sklearn.get_config().get("transform_output", "default")
        if how not in ("pandas", "polars"):
            return latent
        columns = [str(name) for name in self.get_feature_names_out()]
        if how == "pandas":
            import pandas as pd

            index = X.index if isinstance(X, pd.DataFrame) else None
            return pd.DataFrame(latent, columns=columns, index=index, copy=False)
        import polars as pl

        return pl.DataFrame(latent, schema=columns, orient="row")

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
        # "d" is what the saved arrays agree on, not `n_components`: `set_params` may have
        # changed that since the fit (as in scikit-learn, the fit stands until the next `fit`).
        sizes: dict[str, int] = {}
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
        state: dict[str, Any] = {"params": self.get_params()}
        if all(hasattr(self, name) for name in self._saved):
            state["fitted"] = self._fitted_state()
        if hasattr(self, "_sklearn_output_config"):
            state["output"] = self._sklearn_output_config["transform"]
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.set_params(**state["params"])
        if "fitted" in state:
            self._restore(state["fitted"])
        self.set_output(transform=state.get("output"))

    def save(self, path: PathLike) -> None:
        """Writes the parameters and fitted state to an NPZ file at `path` (atomically; the name
        must end in .npz, the format it holds). Parameters are saved as JSON: NumPy scalars as
        the plain numbers they are."""
        if not str(path).endswith(".npz"):
            raise ValueError(f"{path}: a model is saved as NPZ; give a file name ending in .npz")
        arrays = self._arrays()
        atomic_write(path, lambda fh: np.savez(fh, **arrays))

    def _arrays(self) -> dict[str, Any]:
        """The arrays `save` writes: format, version, parameters (JSON), fitted state."""
        self._check_fitted()
        try:
            params = json.dumps(self.get_params(), default=_plain_number)
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

