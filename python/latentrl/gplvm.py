"""The GPLVM (Lawrence 2005) as in the paper (docs/method.md §GPLVM): a latent space whose GP map
decodes to the demonstrated postures, with two inverse maps to encode."""

from __future__ import annotations

from dataclasses import replace
from collections.abc import Sequence
from typing import Any, ClassVar, Literal, Self, overload

import numpy as np
from numpy.typing import NDArray

from latentrl._estimator import Estimator, SavedSpec, column_names
from latentrl._nll_fit import NllFit, initial_log_theta, minimise_nll
from latentrl import _native
from latentrl._native import GpMap, gplvm_nll_grad
from latentrl._validation import as_matrix, int_at_least, positive
from latentrl.pca import PCA, check_n_components
from latentrl.spacing import SPACINGS, evenly_spaced
from latentrl.task import encoders, run_default

ENCODERS = encoders()
"""The encoders (the `[run]` table's `encoder` choices; docs/encoders.md)."""

#: Standard deviation of the perturbation of the (unit-scaled) PCA start for each restart.
RESTART_SCALE = 0.5

#: A sparse fit of more postures than this fits the latent points, inducing inputs and θ of this
#: many evenly spaced postures first, then all (docs/method.md §Sparse GPLVM).
SPARSE_FIRST_STAGE = 4096

#: Postures beyond which an exact fit first says what one iteration will cost: it grows as N³
#: (one objective and gradient: 0.27 s at 1 000 postures, 6.3 s at 2 000 on the 2-core machine
#: of docs/performance.md), and a fit runs up to `max_iter` of them without a word.
COSTLY_EXACT_FIT = 1000

#: Postures of the timed objective that cost is extrapolated from (by N³: a lower bound, as
#: larger matrices also leave the CPU's caches).
COST_SAMPLE = 500


class GPLVM(Estimator):
    """Gaussian-process latent variable model with an SE + white-noise kernel (paper Eq. 2).

    `fit` centres the postures, starts Z from PCA (scaled so the first latent axis has unit
    variance) and minimises the negative log-likelihood (Eq. 1, 3) jointly over Z and log θ
    with L-BFGS-B and the analytic gradient of the Rust core. Then it fits the
    out-of-sample GP encoder. With ``encoder="back_constrained"`` it fits Z as a kernel
    regression on the postures instead (docs/encoders.md).

    Parameters
    ----------
    n_components : int or "auto", default=2
        Latent dimension d. "auto" chooses it from the data by automatic relevance: a fit
        with `max_components` dimensions gives each principal axis of its latent points a
        relevance, the inverse squared length scale an ARD kernel would give it (the axis's
        variance over θ2); d is the number of axes whose relevance is at least
        `relevance_threshold` of the largest, and the model is then fitted with that d
        (`relevance_` keeps the evidence; docs/encoders.md).
    max_components : int or None, default=None
        With n_components="auto": the dimension of the first fit, less than the number of
        joints and of postures (None: 5, or one less than the fewer of the two).
    relevance_threshold : float, default=0.1
        With n_components="auto": the least relative relevance of a kept latent axis.
    max_iter : int, default=1000
        L-BFGS-B iteration cap per start. If it is hit, `converged_` is False.
    noise_floor : float, default=1e-6
        Lower bound on θ3, the white-noise variance (units of the postures, squared). On
        noise-free demonstrations the likelihood has no finite optimum (θ3 → 0); the
        floor gives it one. Also the floor of the GP encoder's noise.
    latent_prior : bool, default=False
        Add a unit-Gaussian prior on Z (½‖Z‖² in the objective), as Lawrence's toolbox.
    n_restarts : int, default=0
        Extra starts, each the PCA start plus N(0, 0.5²) noise drawn from `random_state`;
        the fit with the lowest objective is kept.
    random_state : int or None, default=None
        Seed of the restarts' perturbations.
    encoder : {"gp", "projection", "back_constrained", "tracking"}, default="gp"
        Inverse map of `transform`: the out-of-sample GP fitted onto `Z_` after the fit (the
        paper's), the iterative projection, or the back-constraint (Lawrence & Quiñonero-
        Candela 2006): the latent points are fitted as a smooth function of the postures,
        `Z_ = K_b W` (an RBF kernel regression, its weights and length scale optimised with θ
        through the same NLL), so `transform(X_train)` is `Z_` and a new posture encodes with
        one kernel evaluation. "gp" and "projection" fit the same model (either may be
        chosen at `transform`); "back_constrained" fits another (with it, `transform` takes
        "back_constrained" or "projection"). "tracking" fits the "gp" model; the RL loop then
        encodes a reached posture by the projection searched from the latent point the move
        commanded (reconstruction error only), so a posture the plant tracked keeps its point
        (docs/encoders.md); `transform`, which has no commanded point, projects.
    tol : float, default=1e-6
        L-BFGS-B stops when the relative decrease of the objective (ftol; a sparse fit's
        relative to max(|bound|, N·D), docs/method.md §Sparse GPLVM) or the largest projected
        gradient component (gtol) falls below `tol` (scipy's `tol`).
    inducing : int or None, default=None
        None: the exact GPLVM (O(N³) per step, at most `_native.MAX_GP_POINTS` postures). An int
        m (1 ≤ m ≤ N): the sparse GPLVM, the DTC bound through m inducing inputs (docs/method.md
        §Sparse GPLVM; O(N m² + m³) per step, O(N m) memory, no limit on N). The inducing inputs
        start at the latent points of m postures chosen by farthest-point sampling of the start
        latent points (`latentrl.recorded.sampling.farthest_points`: the first, then each time the
        one farthest from those chosen; fewer if fewer are distinct) and are optimised with Z and
        θ. Above `SPARSE_FIRST_STAGE` (4096) postures the fit has two stages: Z, the inducing
        inputs (chosen among them) and θ of 4096 evenly spaced postures, then all latent points
        from where that stage's GP encoder puts them or at their nearest first-stage posture's
        point, whichever start has the lower bound (`max_iter` caps each stage). Decoding is the DTC predictive mean and variance (O(m) and O(m²) per point); the GP
        encoder is a DTC GP through the postures of those m rows; the projection starts from the
        inducing input whose decoded posture is nearest. Not with encoder="back_constrained".

    Attributes
    ----------
    Z_ : ndarray (N, d)
        Latent points of the training postures.
    n_components_ : int
        The fitted latent dimension d.
    relevance_ : ndarray (K,)
        Relevance of the principal axes of the latent points, largest first (an ARD
        kernel's inverse squared length scales): of the `max_components` fit with
        n_components="auto" (K = max_components), else of this fit (K = d).
    theta_ : ndarray (3,)
        Kernel parameters θ1 (signal variance), θ2 (squared length-scale), θ3 (noise).
    nll_ : float
        Final objective: Eq. 1 NLL, plus ½‖Z‖² with `latent_prior`.
    log_likelihood_ : float
        −`nll_`.
    n_iter_ : int
        L-BFGS-B iterations of the kept start (of both stages of a two-stage sparse fit).
    converged_ : bool
        False if the kept start stopped at `max_iter`, or on a failed line search (often
        the limit of floating-point precision; see `stop_reason_`).
    stop_reason_ : str
        L-BFGS-B's message for the kept start.
    jitter_ : float
        Jitter added to K's diagonal to factorise it at the optimum (0 if none).
    mean_ : ndarray (D,)
        Mean posture (added back on decoding).
    X_train_ : ndarray (N, D)
        The training postures.
    encoder_theta_ : ndarray (3,)
        θ of the encoder: the out-of-sample GP's, or the back-constraint's (1, β, 1e-8).
    encoder_weights_ : ndarray (N, d)
        The back-constraint's weights W (zeros for the other encoders).
    fitted_encoder_ : {"gp", "back_constrained"}
        Which encoder the fit made (`encoder_`); "projection" fits the "gp" model.
    decoder_ : GpMap
        Z → posture (Eq. 4).
    encoder_ : GpMap
        Posture → Z: the out-of-sample GP encoder, or the back-constraint.
    inducing_ : ndarray (m, d)
        The inducing inputs of a sparse fit ((0, d) for an exact one).
    inducing_index_ : ndarray (m,) of int
        The rows of `X_train_` whose latent points the inducing inputs started at; their
        postures are the GP encoder's inducing inputs.
    projection_ : Projection or latentrl._native.Projection
        Posture → Z by iterative projection (SciPy L-BFGS-B; what `transform` uses); the native
        one for a sparse fit (the SciPy reference is exact, O(N³)).
    native_projection_ : latentrl._native.Projection
        The same iterative projection in Rust, the one the RL loop runs (docs/encoders.md:
        how closely the two agree).
    loop_encoder_ : GpMap or latentrl._native.Projection
        The posture → Z map of the native RL loop, by the `encoder` parameter: `encoder_`,
        `native_projection_` for "projection", its tracking mode for "tracking".
    n_features_in_ : int
        Number of joints D.
    feature_names_in_ : ndarray (D,) of str objects
        The joint names: the column names of a pandas DataFrame passed to `fit`, if they
        are all strings (not set otherwise); `latentrl fit` records the demo file's. A latent
        run refuses a model whose names are not its task's joints in order (`check_model_joints`).

    Notes
    -----
    A scikit-learn transformer, without depending on scikit-learn: it works in
    `Pipeline`, `clone` and `GridSearchCV`, and passes scikit-learn's
    `parametrize_with_checks` (tests/test_sklearn.py) but for two checks that may fail by
    design, `check_transformer_general` and `check_transformer_data_not_an_array`: they
    want `fit_transform(X)` to equal `transform(X)` within 1e-2, but `fit_transform`
    returns the fitted latent points `Z_` while `transform` encodes with the GP encoder, a
    smooth regression onto `Z_` that only approximates them (how closely depends on the
    data and on where L-BFGS leaves `Z_`). With ``encoder="back_constrained"`` every check
    passes: `transform(X_train)` is `Z_` (docs/encoders.md).
    `X` may be a pandas DataFrame: `transform` then wants the columns of `fit` in the same
    order, and raises a ValueError naming the unseen, missing or misplaced ones (it warns
    if only one of the two had column names). `transform`, `inverse_transform` and
    `predict_variance` return ndarrays (`transform` and `fit_transform` DataFrames after
    `set_output(transform="pandas")`), `inverse_transform`'s columns in the order of
    `feature_names_in_`; `get_feature_names_out` names the latent axes ``gplvm0``, …
    """

    _saved: ClassVar[SavedSpec] = {
        "n_features_in_": ("i", ()),
        "mean_": ("f", ("D",)),
        "X_train_": ("f", ("N", "D")),
        "Z_": ("f", ("N", "d")),
        "theta_": ("f", (3,)),
        "encoder_theta_": ("f", (3,)),
        "encoder_weights_": ("f", ("N", "d")),
        "relevance_": ("f", ("K",)),
        "inducing_": ("f", ("M", "d")),
        "inducing_index_": ("i", ("M",)),
        "nll_": ("f", ()),
        "n_iter_": ("i", ()),
        "converged_": ("b", ()),
        "stop_reason_": ("U", ()),
        "jitter_": ("f", ()),
    }

    def __init__(
        self,
        n_components: int | str = 2,
        max_iter: int = run_default("gplvm_max_iter"),
        noise_floor: float = 1e-6,
        latent_prior: bool = False,
        n_restarts: int = 0,
        random_state: int | None = None,
        encoder: str = run_default("encoder"),
        tol: float = 1e-6,
        max_components: int | None = None,
        relevance_threshold: float = 0.1,
        inducing: int | None = None,
        spacing: str = "fit",
    ) -> None:
        self.n_components = n_components
        self.max_components = max_components
        self.relevance_threshold = relevance_threshold
        self.max_iter = max_iter
        self.noise_floor = noise_floor
        self.latent_prior = latent_prior
        self.n_restarts = n_restarts
        self.random_state = random_state
        self.encoder = encoder
        self.tol = tol
        self.inducing = inducing
        self.spacing = spacing

    def fit(self, X: Any, y: Any = None) -> Self:
        """Fits the latent points and kernel to postures `X` (N, D), an array or DataFrame;
        `y` is ignored. Returns self."""
        names = column_names(X)
        X = as_matrix("X", X)
        if isinstance(self.n_components, str):
            if self.n_components != "auto":
                raise ValueError(f"n_components must be an int >= 1 or 'auto', got {self.n_components!r}")
            return self._fit_auto(X, names)
        return self._fit(X, names)

    def _fit(self, X: NDArray[np.float64], names: Any, unspaced: Any = None) -> Self:
        """`fit` with d = `n_components`; with `unspaced` (the best unspaced fit of a GPLVM with
        the same parameters, but its spacing, to the same `X`), that fit instead of fitting again."""
        d = check_n_components(self.n_components, X)
        inducing = self._check_inducing(len(X))
        if inducing is None and len(X) > _native.MAX_GP_POINTS:
            raise ValueError(f"X: {len(X)} postures, more than the {_native.MAX_GP_POINTS} an exact GPLVM fit takes "
                             f"(its N × N kernel matrix would need {len(X) ** 2 * 8 / 2**30:.1f} GiB); fit the sparse "
                             "GPLVM with inducing=M (e.g. GPLVM(inducing=256), `latentrl fit --inducing 256`), or keep "
                             "fewer postures (load_demos(..., max_postures=N), --max-postures N)")
        if not np.ptp(X, axis=0).any():
            raise ValueError(f"X: all {len(X)} postures are identical; a GPLVM needs postures that differ")
        max_iter = int_at_least("max_iter", self.max_iter, 1)
        n_restarts = int_at_least("n_restarts", self.n_restarts, 0)
        noise_floor = positive("noise_floor", self.noise_floor)
        tol = positive("tol", self.tol)
        self._check_encoder(self.encoder)

        if inducing is None and len(X) > COSTLY_EXACT_FIT:
            _warn_of_cost(X, d, max_iter)
        pca = PCA(d).fit(X)
        start = pca._encode(X) / (np.sqrt(pca.explained_variance_[0]) or 1.0)
        centred = X - pca.mean_
        log_theta = initial_log_theta(start, centred)
        rng = np.random.default_rng(self.random_state)
        starts = [start] + [
            start + RESTART_SCALE * rng.standard_normal(start.shape) for _ in range(n_restarts)
        ]
        # SciPy (L-BFGS-B, the encoders' factorisations) loads at a fit, not at `import latentrl`.
        from latentrl.back_constraint import minimise_back_constrained
        from latentrl.inverse import fit_gp_encoder

        back_constrained = self.encoder == "back_constrained"
        if back_constrained and inducing is not None:
            raise ValueError("inducing: the back-constrained GPLVM is fitted exactly; use inducing=None "
                             "or another encoder")
        if self.spacing not in SPACINGS:
            raise ValueError(f"spacing must be one of {', '.join(map(repr, SPACINGS))}, got {self.spacing!r}")
        if back_constrained and self.spacing != "fit":
            raise ValueError("spacing: the back-constrained latent points are a function of X and cannot be "
                             "moved; use spacing='fit' or another encoder")
        if back_constrained and self.latent_prior:
            raise ValueError("latent_prior: the back-constrained latent points are a function of X, "
                             "not free points with a prior; use latent_prior=False")
        from latentrl.recorded.sampling import farthest_points

        rows = sparse_first_stage(len(X))
        chosen = np.zeros(0, dtype=np.intp) if inducing is None else rows[farthest_points(start[rows], inducing)]
        options: dict[str, Any] = {"latent_prior": bool(self.latent_prior), "noise_floor": noise_floor,
                                   "max_iter": max_iter, "tol": tol}
        fits: list[Any] = [unspaced] if unspaced is not None else [
            minimise_back_constrained(z0, centred, log_theta, noise_floor=noise_floor, max_iter=max_iter, tol=tol)
            if back_constrained else
            minimise_nll(z0, centred, log_theta, fit_latent=True, **options) if inducing is None else
            minimise_sparse(z0, centred, log_theta, rows, chosen, **options)
            for z0 in starts
        ]
        best = unspaced = min(fits, key=lambda fit: fit.nll)
        if self.spacing == "even":
            best = evenly_spaced(best, centred, noise_floor=noise_floor, max_iter=max_iter, tol=tol)

        self.n_features_in_ = X.shape[1]
        self._set_feature_names(names)
        self.mean_ = pca.mean_
        self.X_train_ = X.copy()
        # The likelihood's own points, for `evenly_spaced` while these parameters and X hold (not saved).
        self._unspaced = (self.get_params(), self.X_train_, unspaced)
        self.Z_ = best.latent
        self.theta_ = np.exp(best.log_theta)
        self.nll_ = best.nll
        self.n_iter_ = best.n_iter
        self.converged_ = best.converged
        self.stop_reason_ = best.message
        self.jitter_ = best.jitter
        self.inducing_index_ = chosen
        self.inducing_ = np.zeros((0, start.shape[1])) if inducing is None else best.inducing
        if back_constrained:
            self.encoder_weights_ = best.weights
            encoder = GpMap.back_constraint(X, best.weights, best.log_beta)
            self.Z_ = encoder.predict_mean(X)  # K_b W of the raw postures: what transform gives
        else:
            self.encoder_weights_ = np.zeros_like(self.Z_)
            encoder = fit_gp_encoder(X, self.Z_, noise_floor=noise_floor, max_iter=max_iter, tol=tol,
                                     inducing=X[chosen] if inducing is not None else None)
        self.encoder_theta_ = np.array(encoder.theta)
        self.relevance_ = latent_relevance(self.Z_, self.theta_)
        self._build()
        return self

    def evenly_spaced(self) -> GPLVM:
        """This fit with `spacing="even"`: the same as `GPLVM(spacing="even", ...)` with these
        parameters fitted to `X_train_`, to the bit, but from this fit's latent points where this
        process made it (only θ and the encoder are fitted again; docs/encoders.md §Latent spacing)."""
        self._check_fitted()
        if self.spacing != "fit":
            raise ValueError(f"evenly_spaced: this GPLVM's spacing is already {self.spacing!r}")
        twin = GPLVM(**{**self.get_params(), "spacing": "even"})
        names = getattr(self, "feature_names_in_", None)
        if isinstance(twin.n_components, str):  # "auto" chooses d on evenly spaced fits
            return twin._fit_auto(self.X_train_, names)
        params, X, unspaced = getattr(self, "_unspaced", (None, None, None))
        same = params == self.get_params() and X is self.X_train_
        return twin._fit(self.X_train_, names, unspaced if same else None)

    def _fit_auto(self, X: NDArray[np.float64], names: Any) -> Self:
        """n_components="auto": the `max_components` fit's relevances choose d, then the fit
        with d (module doc of `n_components`)."""
        n, joints = X.shape
        if n < 3:
            raise ValueError(f"n_components='auto' needs at least 3 postures to compare latent axes, got {n}")
        k = min(5, joints - 1, n - 1) if self.max_components is None else int_at_least("max_components", self.max_components, 1)
        if k >= joints or k >= n:
            raise ValueError(f"max_components must be less than the number of joints ({joints}) and of postures "
                             f"({n}), got {k}")
        threshold = positive("relevance_threshold", self.relevance_threshold)
        if threshold > 1:
            raise ValueError(f"relevance_threshold must be in (0, 1], got {threshold!r}")
        params = {**self.get_params(), "max_components": k}
        widest = GPLVM(**{**params, "n_components": k}).fit(X)
        relevance = widest.relevance_
        d = int(np.sum(relevance >= threshold * relevance[0]))
        chosen = widest if d == k else GPLVM(**{**params, "n_components": d}).fit(X)
        self._restore({**chosen._fitted_state(), "relevance_": relevance})
        self._set_feature_names(names)
        return self

    def _check_inducing(self, n: int) -> int | None:
        """The `inducing` parameter for N = `n` postures: None, or an int in [1, n]."""
        m = self.inducing
        if m is None:
            return None
        if isinstance(m, bool) or not isinstance(m, int | np.integer) or not 1 <= m <= n:
            raise ValueError(f"inducing must be None (the exact GPLVM) or an int m with 1 <= m <= the number of "
                             f"postures ({n}), got {m!r}")
        return int(m)

    def _build(self) -> None:
        self.log_likelihood_ = -self.nll_
        sparse = len(self.inducing_) > 0
        self.decoder_ = GpMap(self.Z_, self.X_train_, self.theta_, inducing=self.inducing_ if sparse else None)
        if self.fitted_encoder_ == "back_constrained":
            log_beta = float(np.log(self.encoder_theta_[1]))
            self.encoder_ = GpMap.back_constraint(self.X_train_, self.encoder_weights_, log_beta)
        else:
            inducing_postures = self.X_train_[self.inducing_index_] if sparse else None
            self.encoder_ = GpMap(self.X_train_, self.Z_, self.encoder_theta_, inducing=inducing_postures)
        from latentrl.inverse import Projection

        # A sparse decoder's points are the inducing inputs: the projection starts from the one
        # whose decoded posture is nearest (the SciPy reference would be the exact O(N³) GP).
        self._projection_postures = self.decoder_.predict_mean(self.inducing_) if sparse else self.X_train_
        self.native_projection_ = _native.Projection(self.decoder_, self._projection_postures)
        self.projection_: Projection | _native.Projection = (
            self.native_projection_ if sparse
            else Projection(self.Z_, self.X_train_, self.theta_, self.decoder_.jitter)
        )

    @property
    def loop_encoder_(self) -> GpMap | _native.Projection:
        """The posture → Z map of the native RL loop, by the `encoder` parameter: `encoder_`,
        `native_projection_` for "projection", its tracking mode for "tracking"."""
        if self.encoder == "tracking":
            return _native.Projection(self.decoder_, self._projection_postures, tracking=True)
        return self.native_projection_ if self.encoder == "projection" else self.encoder_

    @property
    def fitted_encoder_(self) -> str:
        """Which encoder the fit made: "back_constrained" (its weights are never all zero; the
        other encoders' are) or "gp"."""
        return "back_constrained" if np.any(self.encoder_weights_) else "gp"

    def _restore(self, state: dict[str, Any]) -> None:
        # Files written before the back-constraint have no weights: their encoders had none;
        # files written before n_components="auto" have no relevances: those of their own axes;
        # files written before the sparse GPLVM have no inducing inputs: they are exact.
        # A Z_ or θ of another shape or dtype is left to the checks of `_saved` (issue #38: a 1-D Z_
        # was an IndexError here, a complex one a ComplexWarning).
        Z = np.asarray(state.get("Z_", ()))
        if Z.ndim == 2 and Z.dtype.kind == "f":
            state = {"encoder_weights_": np.zeros_like(Z), "inducing_": np.zeros((0, Z.shape[1])),
                     "inducing_index_": np.zeros(0, dtype=np.intp), **state}
            theta = np.asarray(state.get("theta_", ()))
            if "relevance_" not in state and theta.shape == (3,) and theta.dtype.kind == "f":
                state["relevance_"] = latent_relevance(Z, theta)
        super()._restore(state)

    @staticmethod
    def _check_encoder(method: str) -> None:
        if method not in ENCODERS:
            raise ValueError(f"encoder method must be one of {ENCODERS}, got {method!r}")

    @property
    def _n_features_out(self) -> int:
        return int(self.Z_.shape[1])

    def fit_transform(self, X: Any, y: Any = None) -> Any:
        """`fit(X)`, then the fitted latent points `Z_` (not re-encoded), as `transform` returns them."""
        return self._output(self.fit(X).Z_, X)

    def transform(self, X: Any, method: str | None = None) -> Any:
        """Encodes postures `X` (M, D), an array or DataFrame, to latent points (M, d),
        with the out-of-sample GP (`method="gp"`) or the iterative projection; default: the
        `encoder` parameter. An ndarray, or a DataFrame (`set_output`)."""
        return self._output(self._encode(self._check_X(X), method), X)

    def _encode(self, X: Any, method: str | None = None) -> NDArray[np.float64]:
        """`transform` of postures whose columns are those of the fit, unnamed, without the
        warning that they have no names: latentrl's own calls with a task's joints, which
        `check_model_joints` compared with the fit's."""
        self._check_fitted()
        method = self.encoder if method is None else method
        self._check_encoder(method)
        fitted = self.fitted_encoder_
        if method not in (fitted, "projection", "tracking"):
            raise ValueError(f"method {method!r}: this GPLVM was fitted with the {fitted!r} encoder, "
                             f"so transform takes {fitted!r} or 'projection'")
        X = as_matrix("X", X, n_cols=self.n_features_in_)
        if method in ("projection", "tracking"):
            return self.projection_.encode(X)
        return self.encoder_.predict_mean(X)

    @overload
    def inverse_transform(self, Z: Any, return_variance: Literal[False] = False) -> NDArray[np.float64]: ...
    @overload
    def inverse_transform(
        self, Z: Any, return_variance: Literal[True]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]: ...

    def inverse_transform(
        self, Z: Any, return_variance: bool = False
    ) -> NDArray[np.float64] | tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Decodes latent points `Z` (M, d) to postures (M, D): the GP mean (Eq. 4), an
        ndarray, its columns in the order of `feature_names_in_`. With `return_variance`, also
        the predictive variance σ²(z) (M,) of `predict_variance`, from the same native call."""
        self._check_fitted()
        Z = as_matrix("Z", Z, n_cols=self._n_features_out)
        if return_variance:
            return self.decoder_.predict(Z)
        return self.decoder_.predict_mean(Z)

    def predict_variance(self, Z: Any) -> NDArray[np.float64]:
        """Predictive variance σ²(z) (M,) at latent points `Z` (M, d), θ3 included (Eq. 4)."""
        self._check_fitted()
        return self.decoder_.predict(as_matrix("Z", Z, n_cols=self._n_features_out))[1]


def check_fitted_gplvm(model: Any) -> None:
    """TypeError unless `model` is a fitted GPLVM: the model a latent run (`check`, training) maps with."""
    if not isinstance(model, GPLVM) or not hasattr(model, "decoder_"):
        raise TypeError(f"model must be a fitted latentrl.GPLVM, got {model!r}")


def name_joints(model: Estimator, joint_names: Sequence[str]) -> None:
    """Records on the fitted `model` (GPLVM or PCA) the joints its columns held, as a fit on a
    DataFrame with those columns would (`feature_names_in_`), so that a run, `check` or a policy
    later refuses it for other joints (`check_model_joints`)."""
    names = np.asarray([str(name) for name in joint_names], dtype=object)
    if len(names) != model.n_features_in_:
        raise ValueError(f"{len(names)} joint names for a model of {model.n_features_in_} columns")
    model._set_feature_names(names)


def check_model_joints(model: GPLVM, joint_names: Sequence[str], where: str) -> None:
    """ValueError naming `where` unless the fitted `model` decodes the joints `joint_names` (a
    task's, in its order): as many columns and, if the fit recorded its columns' names
    (`feature_names_in_`), those names in that order. A model is never reordered: its latent space
    was fitted to its columns as they were."""
    joints = [str(name) for name in joint_names]
    names = [str(name) for name in getattr(model, "feature_names_in_", ())]
    if model.n_features_in_ == len(joints) and names in ([], joints):
        return
    fitted = f"fitted to {model.n_features_in_} joints" + (f" {names}" if names else "")
    if sorted(names) == sorted(joints):
        raise ValueError(f"{where}: fitted to the task's joints in another order, {names}; the task's joints are "
                         f"{joints}: fit it again to postures in that order (a demo file's columns in that order, "
                         "a DataFrame's df[list(task.joint_names)]), or train without it (train fits one)")
    raise ValueError(f"{where}: {fitted}, not to the task's {len(joints)} joints {joints}")


def sparse_first_stage(n: int) -> NDArray[np.intp]:
    """The postures of a sparse fit's first stage: all `n`, or `SPARSE_FIRST_STAGE` evenly spaced
    ones (the first, the last and every (n − 1)/(SPARSE_FIRST_STAGE − 1)-th between)."""
    if n <= SPARSE_FIRST_STAGE:
        return np.arange(n)
    return np.linspace(0, n - 1, SPARSE_FIRST_STAGE).round().astype(np.intp)


def minimise_sparse(start: NDArray[np.float64], centred: NDArray[np.float64], log_theta: NDArray[np.float64],
                    rows: NDArray[np.intp], chosen: NDArray[np.intp], **options: Any) -> NllFit:
    """The sparse GPLVM's fit from latent points `start` (N, d) of `centred` postures (N, D): the
    DTC bound minimised over the latent points of `rows`, the inducing inputs (starting at the
    latent points of the rows `chosen`, a subset of `rows`) and θ; then, if `rows` are not all,
    over every latent point from `second_stage_start`, and the first stage's inducing inputs and
    θ. `options` are `minimise_nll`'s; `max_iter` caps each stage, and `n_iter` counts both."""
    first = minimise_nll(start[rows], centred[rows], log_theta, fit_latent=True, inducing=start[chosen], **options)
    if len(rows) == len(start):
        return first
    latent = second_stage_start(first, centred, rows, chosen, options)
    second = minimise_nll(latent, centred, first.log_theta, fit_latent=True, inducing=first.inducing, **options)
    return replace(second, n_iter=first.n_iter + second.n_iter)


def second_stage_start(first: NllFit, centred: NDArray[np.float64], rows: NDArray[np.intp],
                       chosen: NDArray[np.intp], options: dict[str, Any]) -> NDArray[np.float64]:
    """Where the second stage starts every latent point, the first stage's `rows` at their fitted
    points: the lower bound (under the first stage's U and θ) of two starts. Each posture where
    the first stage's out-of-sample GP (a DTC GP from the rows' postures to their latent points,
    through the `chosen` postures) encodes it, or at the latent point of its nearest first-stage
    posture. The GP's start is near the optimum where the postures lie on a smooth d-dimensional
    manifold; on recorded trajectories (docs/demos.md) it started 30× higher than the nearest
    posture's, and the second stage then spent 230 of its 100 000-point iterations climbing down."""
    from scipy.spatial import cKDTree

    from latentrl.inverse import fit_gp_encoder

    encoder = fit_gp_encoder(centred[rows], first.latent, noise_floor=options["noise_floor"],
                             max_iter=options["max_iter"], tol=options["tol"], inducing=centred[chosen])
    encoded = encoder.predict_mean(centred)
    nearest = first.latent[cKDTree(centred[rows]).query(centred)[1]]
    for latent in (encoded, nearest):
        latent[rows] = first.latent

    def bound(latent: NDArray[np.float64]) -> float:
        return float(gplvm_nll_grad(latent, centred, first.log_theta, inducing=first.inducing)[0])

    return min((encoded, nearest), key=bound)


def latent_relevance(Z: NDArray[np.float64], theta: NDArray[np.float64]) -> NDArray[np.float64]:
    """The principal axes' relevances of latent points `Z` (N, d) under kernel θ, largest
    first: each axis's variance over θ2, the inverse squared length scale an ARD kernel on
    unit-variance axes would have (the SE kernel is isotropic, so only the spread of Z along
    an axis tells how much the fit uses it)."""
    spread = np.linalg.eigvalsh(np.atleast_2d(np.cov(Z, rowvar=False)))
    relevance: NDArray[np.float64] = np.sort(np.maximum(spread, 0.0))[::-1] / theta[1]
    return relevance


def _warn_of_cost(X: NDArray[np.float64], d: int, max_iter: int) -> None:
    """A UserWarning of what an exact fit of `X` costs per iteration here (timed on `COST_SAMPLE`
    of its postures, extrapolated by N³) and how to spend less, before the fit begins."""
    import time
    import warnings

    sample = X[:COST_SAMPLE] - X[:COST_SAMPLE].mean(axis=0)
    began = time.perf_counter()
    gplvm_nll_grad(np.random.default_rng(0).standard_normal((len(sample), d)), sample, np.zeros(3))
    each = (time.perf_counter() - began) * (len(X) / len(sample)) ** 3
    warnings.warn(f"X: {len(X)} postures: each iteration of an exact GPLVM fit costs at least {each:.2g} s here "
                  f"(it grows as N³), for up to {max_iter} iterations; keep fewer postures (load_demos(..., "
                  "max_postures=1000), --max-postures 1000: farthest-point sampling keeps each motion's extremes) "
                  "or fit the sparse GPLVM (GPLVM(inducing=256), `latentrl fit --inducing 256`, then --model)",
                  stacklevel=3)
