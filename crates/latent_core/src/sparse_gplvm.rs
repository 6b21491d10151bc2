//! The sparse GPLVM's objective: the DTC ("projected process") bound of Lawrence (2007) with
//! inducing inputs (docs/method.md §Sparse GPLVM). The N×N kernel matrix of the exact GPLVM
//! ([`crate::gplvm`]) is replaced by its projection through m inducing inputs `U`,
//! `Q = K_nm K_mm⁻¹ K_mn`, so the data covariance is `Σ = Q + θ3 I` and
//!
//! `L(Z, U, θ) = (D/2) log|Σ| + ½ tr(Σ⁻¹ Y Yᵀ) + (N D/2) log 2π`
//!
//! costs O(N m² + m³) time and O(N m) memory (`K` here is the smooth part of the kernel; θ3 is
//! the noise of the data only). With `U = Z` it is the exact GPLVM's NLL.
//!
//! With `K_mm + jitter = L Lᵀ`, `A = L⁻¹ K_mn` and `B = I + A Aᵀ/θ3 = L_B L_Bᵀ`:
//! `log|Σ| = N log θ3 + log|B|` and `Σ⁻¹ = (I − Aᵀ B⁻¹ A/θ3)/θ3` (Woodbury), never formed.
//! Everything over the N points is two passes over fixed blocks of [`CHUNK`] columns of `K_mn`,
//! in parallel (rayon); the blocks' partial sums are added in block order, so the result has
//! the same bits on any number of threads.

use std::ops::Range;

use nalgebra::{Cholesky, DMatrix, DMatrixView, DMatrixViewMut, DVector, Dyn};
use rayon::prelude::*;

use crate::error::{CoreError, Result, check_finite};
use crate::gp::{GpMap, check_gp_size, check_points, check_values};
use crate::gplvm::{NllGrad, nll_grad};
use crate::kernel::{SeKernel, factorize};

/// Points (columns of `K_mn`) per block of the passes over the data. Fixed: the partial sums,
/// and the order they are added in, depend on N only, not on the thread count.
pub const CHUNK: usize = 128;

/// The blocks of `0..n` of [`CHUNK`] points.
fn chunks(n: usize) -> impl Iterator<Item = Range<usize>> {
    (0..n.div_ceil(CHUNK)).map(move |c| c * CHUNK..((c + 1) * CHUNK).min(n))
}

/// `map` over the blocks of `0..n` in parallel, `add` of their results in block order: at most
/// `group` results wait at a time (each may hold an m×m partial sum).
fn in_blocks<T: Send>(n: usize, group: usize, map: impl Fn(Range<usize>) -> T + Sync, mut add: impl FnMut(T)) {
    let blocks: Vec<Range<usize>> = chunks(n).collect();
    for batch in blocks.chunks(group.max(1)) {
        let results: Vec<T> = batch.par_iter().map(|r| map(r.clone())).collect();
        results.into_iter().for_each(&mut add);
    }
}

/// How many blocks of partial m×m sums may wait at once: 32, fewer for large m (≤ 64 MiB).
fn group_size(m: usize) -> usize {
    ((8 << 20) / (m * m).max(1)).clamp(1, 32)
}

/// `L(Z, U, θ)` and its gradient with respect to `Z`, `U` and `log θ`.
#[derive(Debug, Clone)]
pub struct SparseNllGrad {
    /// The DTC negative log marginal likelihood.
    pub nll: f64,
    /// `∂L/∂Z`, q×N like the latent points.
    pub grad_latent: DMatrix<f64>,
    /// `∂L/∂U`, q×m like the inducing inputs.
    pub grad_inducing: DMatrix<f64>,
    /// `∂L/∂ log θ` for `θ1, θ2, θ3`.
    pub grad_log_theta: [f64; 3],
    /// Jitter added to `K_mm` to factorise it (0 if none).
    pub jitter: f64,
}

impl SparseNllGrad {
    /// As an [`NllGrad`] whose gradient of the points is `[∂L/∂Z  ∂L/∂U]` (q×(N+m)): the
    /// points an optimiser moves together, latent points first.
    pub fn stacked(self) -> NllGrad {
        let (n, m) = (self.grad_latent.ncols(), self.grad_inducing.ncols());
        let mut grad_latent = self.grad_latent.resize_horizontally(n + m, 0.0);
        grad_latent.columns_mut(n, m).copy_from(&self.grad_inducing);
        NllGrad {
            nll: self.nll,
            grad_latent,
            grad_log_theta: self.grad_log_theta,
            jitter: self.jitter,
        }
    }
}

/// The factors of the DTC model that the bound, its gradient and the sparse map share.
pub(crate) struct Dtc {
    pub(crate) kernel: SeKernel,
    /// `K_mm` (smooth part, m×m).
    pub(crate) kmm: DMatrix<f64>,
    /// `K_mn` in blocks of [`CHUNK`] columns (m×c each), block `b` the points `b·CHUNK..`.
    pub(crate) kmn: Vec<DMatrix<f64>>,
    /// `A = L⁻¹ K_mn` in the same blocks.
    pub(crate) a: Vec<DMatrix<f64>>,
    /// `L`, the lower Cholesky factor of `K_mm + jitter·I`.
    pub(crate) lower: DMatrix<f64>,
    pub(crate) jitter: f64,
    /// `B = I + L⁻¹ K_mn K_nm L⁻ᵀ/θ3 = L_B L_Bᵀ`.
    pub(crate) b: Cholesky<f64, Dyn>,
    /// `B⁻¹ L⁻¹ K_mn Y` (m×D).
    pub(crate) c: DMatrix<f64>,
}

/// [`CoreError`] unless `inputs` (q×N), `inducing` (q×m) and `values` (p×N, called `what`) are
/// non-empty, agree in shape, are finite, and `K_mm` fits under [`crate::gp::MAX_GP_POINTS`].
pub(crate) fn check_problem(
    inputs: &DMatrix<f64>,
    inducing: &DMatrix<f64>,
    values: &DMatrix<f64>,
    what: &'static str,
) -> Result<()> {
    check_values(inputs, values, what)?;
    if inducing.ncols() == 0 {
        return Err(CoreError::Empty {
            what: "inducing inputs",
        });
    }
    check_gp_size("inducing inputs", inducing.ncols())?;
    check_points("inducing inputs", inducing, inputs.nrows())
}

/// `k(u_i, x_j)` (smooth part) for the inducing inputs `inducing` (q×m) and the points
/// `range` of `inputs` (q×N): m×c.
fn cross_block(kernel: &SeKernel, inducing: &DMatrix<f64>, inputs: &DMatrix<f64>, range: Range<usize>) -> DMatrix<f64> {
    let mut k = DMatrix::zeros(inducing.ncols(), range.len());
    for (mut col, j) in k.column_iter_mut().zip(range) {
        let x = inputs.column(j);
        for (v, u) in col.iter_mut().zip(inducing.column_iter()) {
            *v = kernel.se(u.as_slice(), x.as_slice());
        }
    }
    k
}

/// Rows of the diagonal blocks [`solve_lower`] substitutes in; it multiplies the rest.
const SUBSTITUTED: usize = 8;

/// `b ← L⁻¹ b` for lower-triangular `lower` (m×m), `b` m×c: forward substitution, blocked as
/// LAPACK's `dtrsm` (halves recursively: solve the top, subtract `L₂₁ X₁` from the bottom by one
/// matrix product, solve the bottom), as backward-stable as plain substitution and several times
/// faster at m = 64 (the products run in `matrixmultiply`'s kernels).
fn solve_lower(lower: DMatrixView<'_, f64>, mut b: DMatrixViewMut<'_, f64>) {
    let m = lower.nrows();
    if m <= SUBSTITUTED {
        lower.solve_lower_triangular_mut(&mut b);
        return;
    }
    let h = m / 2;
    let (mut top, mut bottom) = b.rows_range_pair_mut(0..h, h..m);
    solve_lower(lower.view((0, 0), (h, h)), top.as_view_mut());
    bottom.gemm(-1.0, &lower.view((h, 0), (m - h, h)), &top, 1.0);
    solve_lower(lower.view((h, h), (m - h, m - h)), bottom);
}

impl Dtc {
    /// The factors at inputs `inputs` (q×N), inducing inputs `inducing` (q×m) and centred
    /// outputs `centred` (D×N): one pass over the points for `K_mn`, `A Aᵀ` and `A Y`
    /// (O(N m (m + D)), `A` a block at a time), then O(m³).
    pub(crate) fn new(
        inputs: &DMatrix<f64>,
        inducing: &DMatrix<f64>,
        centred: &DMatrix<f64>,
        kernel: SeKernel,
    ) -> Result<Self> {
        check_problem(inputs, inducing, centred, "data")?;
        let (n, m) = (inputs.ncols(), inducing.ncols());
        let kmm = kernel.cross(inducing, inducing);
        let factor = factorize(kmm.clone())?;
        let lower = factor.cholesky.l();
        let mut kmn = Vec::with_capacity(n.div_ceil(CHUNK));
        let mut a_blocks = Vec::with_capacity(n.div_ceil(CHUNK));
        let mut s = DMatrix::zeros(m, m);
        let mut ay = DMatrix::zeros(m, centred.nrows());
        in_blocks(
            n,
            group_size(m),
            |range| {
                let k = cross_block(&kernel, inducing, inputs, range.clone());
                // A = L⁻¹ K_mn over the block, by substitution: K_mm is ill-conditioned (inducing
                // inputs closer than the length scale), and L⁻¹ K_mn K_nm L⁻ᵀ formed from the
                // product, or A from an explicit L⁻¹, loses the gradient to rounding.
                let mut a = k.clone();
                solve_lower(lower.as_view(), a.as_view_mut());
                let s = &a * a.transpose();
                let ay = &a * centred.columns(range.start, range.len()).transpose();
                (k, a, s, ay)
            },
            |(k, a, block_s, block_ay)| {
                s += block_s;
                ay += block_ay;
                kmn.push(k);
                a_blocks.push(a);
            },
        );
        let mut b = (&s + s.transpose()) * (0.5 / kernel.noise);
        for i in 0..m {
            b[(i, i)] += 1.0;
        }
        let b = Cholesky::new(b).ok_or(CoreError::NotPositiveDefinite { n: m, jitter: 0.0 })?;
        let mut c = ay;
        b.solve_mut(&mut c);
        Ok(Self {
            kernel,
            kmm,
            kmn,
            a: a_blocks,
            lower,
            jitter: factor.jitter,
            b,
            c,
        })
    }

    /// `α = (θ3 K_mm + K_mn K_nm)⁻¹ K_mn Y = L⁻ᵀ B⁻¹ L⁻¹ K_mn Y/θ3` (m×D): the predictive mean at
    /// `x` is `k(x, U) α`, and `Σ⁻¹ Y = (Y − K_nm α)/θ3`, the residual of that mean at the data
    /// over the noise.
    pub(crate) fn alpha(&self) -> DMatrix<f64> {
        let mut alpha = self.c.clone() / self.kernel.noise;
        self.lower.tr_solve_lower_triangular_mut(&mut alpha);
        alpha
    }
}

/// One block's share of the second pass of [`sparse_nll_grad`].
struct BlockSums {
    /// `Σ_j g_ij z_jᵀ` (m×q), `g_ij = ∂L/∂K_ij · K_ij`.
    weighted: DMatrix<f64>,
    /// `Σ_j g_ij` (m).
    total: DVector<f64>,
    /// `Σ_ij g_ij` and `Σ_j (Σ_i g_ij) ‖z_j‖² − 2 z_j · Σ_i g_ij u_i`.
    log_variance: f64,
    log_lengthscale_sq: f64,
    /// `tr(Yᵀ Σ⁻¹ Y)` and `‖Σ⁻¹ Y‖²` over the block.
    fit: f64,
    residual: f64,
}

/// Evaluates the DTC bound at latent points `latent` (q×N) with inducing inputs `inducing`
/// (q×m) for centred data `centred` (D×N, one posture per column) and kernel `exp(log_theta)`.
///
/// With `G = ∂L/∂Σ = ½(D Σ⁻¹ − Σ⁻¹ Y Yᵀ Σ⁻¹)` and `W = K_mm⁻¹ K_mn`:
/// `∂L/∂K_mn = 2 W G = P K_mn − α (Σ⁻¹ Y)ᵀ` with `P = (D/θ3) L⁻ᵀ B⁻¹ L⁻¹`,
/// The GPLVM objective at `latent` (d×N) for `centred` data (D×N): the exact one
/// ([`nll_grad`]), or with `inducing` (d×m) the sparse bound, its gradient that of the points
/// then of the inducing inputs ([`SparseNllGrad::stacked`]).
pub fn gplvm_objective(
    latent: &DMatrix<f64>,
    centred: &DMatrix<f64>,
    log_theta: [f64; 3],
    inducing: Option<&DMatrix<f64>>,
) -> Result<NllGrad> {
    match inducing {
        None => nll_grad(latent, centred, log_theta),
        Some(u) => sparse_nll_grad(latent, u, centred, log_theta).map(SparseNllGrad::stacked),
    }
}

/// `∂L/∂K_mm = −W G Wᵀ = −(D/2) L⁻ᵀ (I − B⁻¹) L⁻¹ + ½ α αᵀ` and `∂L/∂θ3 = tr G`. The second pass
/// over the points forms `∂L/∂K_mn` a block at a time (one m×m by m×c product) and carries it
/// through the kernel at once: O(N m (m + q + D)) time, O(N m) memory (`K_mn`).
pub fn sparse_nll_grad(
    latent: &DMatrix<f64>,
    inducing: &DMatrix<f64>,
    centred: &DMatrix<f64>,
    log_theta: [f64; 3],
) -> Result<SparseNllGrad> {
    check_finite("log theta", &log_theta)?;
    let kernel = SeKernel::new(log_theta.map(f64::exp))?;
    let dtc = Dtc::new(latent, inducing, centred, kernel)?;
    let (n, m, q) = (latent.ncols(), inducing.ncols(), latent.nrows());
    let dims = centred.nrows() as f64;
    let (noise, ell) = (kernel.noise, kernel.lengthscale_sq);

    let identity = DMatrix::identity(m, m);
    let mut l_inv = identity.clone();
    dtc.lower.solve_lower_triangular_mut(&mut l_inv);
    let b_inv = dtc.b.solve(&identity);
    let e = &b_inv * &l_inv; // B⁻¹ L⁻¹
    let alpha = dtc.alpha(); // W Σ⁻¹ Y
    let alpha_t = alpha.transpose();
    let e_t = e.transpose() * (dims / noise);
    let weights = &dtc.c / noise; // B⁻¹ A Y/θ3
    // ∂L/∂K_mm = −(D/2) L⁻ᵀ (I − B⁻¹) L⁻¹ + ½ α αᵀ.
    let mut d_kmm = l_inv.tr_mul(&(&l_inv - &e)) * (-0.5 * dims);
    d_kmm.gemm(0.5, &alpha, &alpha_t, 1.0);
    let d_kmm = (&d_kmm + d_kmm.transpose()) * 0.5;

    let inducing_t = inducing.transpose();
    let mut grad_latent = DMatrix::zeros(q, n);
    let starts: Vec<usize> = chunks(n).map(|r| r.start).collect();
    let sums: Vec<BlockSums> = grad_latent
        .as_mut_slice()
        .par_chunks_mut(q * CHUNK)
        .zip(dtc.kmn.par_iter())
        .zip(dtc.a.par_iter())
        .zip(starts.par_iter())
        .map(|(((grad, k), a), &start)| {
            let c = k.ncols();
            let y = centred.columns(start, c);
            let z = latent.columns(start, c);
            // Σ⁻¹ Y over the block: (Y − Aᵀ B⁻¹ A Y/θ3)/θ3, D×c.
            let mut v = y.clone_owned();
            for (mut v_col, a_col) in v.column_iter_mut().zip(a.column_iter()) {
                for (out, c_col) in v_col.iter_mut().zip(weights.column_iter()) {
                    *out = (*out - c_col.dot(&a_col)) / noise;
                }
            }
            // ∂L/∂K = (D/θ3) L⁻ᵀ B⁻¹ A − α (Σ⁻¹ Y)ᵀ; g_ij = ∂L/∂K_ij · K_ij over the block, m×c.
            let mut g = &e_t * a;
            g.gemm(-1.0, &alpha, &v, 1.0);
            g.component_mul_assign(k);
            // ∂L/∂z_j = Σ_i g_ij (u_i − z_j)/θ2 = (t_j − w_j z_j)/θ2 with t_j = Σ_i g_ij u_i,
            // w_j = Σ_i g_ij; and Σ_ij g_ij ‖u_i − z_j‖² = Σ_i (Σ_j g_ij) ‖u_i‖² (added once all
            // blocks are in) + Σ_j (w_j ‖z_j‖² − 2 z_j·t_j).
            let mut log_variance = 0.0;
            let mut log_lengthscale_sq = 0.0;
            let mut toward = vec![0.0; q];
            for ((g_col, z_col), grad_j) in g.column_iter().zip(z.column_iter()).zip(grad.chunks_exact_mut(q)) {
                let weight = g_col.sum();
                for (t, u_row) in toward.iter_mut().zip(inducing_t.column_iter()) {
                    *t = u_row.dot(&g_col);
                }
                let mut dot = 0.0;
                for ((out, t), z) in grad_j.iter_mut().zip(&toward).zip(z_col.iter()) {
                    *out = (t - weight * z) / ell;
                    dot += z * t;
                }
                log_variance += weight;
                log_lengthscale_sq += weight * z_col.norm_squared() - 2.0 * dot;
            }
            BlockSums {
                weighted: &g * z.transpose(),
                total: g.column_sum(),
                log_variance,
                log_lengthscale_sq,
                fit: y.dot(&v),
                residual: v.norm_squared(),
            }
        })
        .collect();

    let mut cross_u = DMatrix::zeros(m, q);
    let mut total = DVector::zeros(m);
    let mut log_variance = 0.0;
    let mut log_lengthscale_sq = 0.0;
    let (mut fit, mut residual) = (0.0, 0.0);
    for s in &sums {
        cross_u += &s.weighted;
        total += &s.total;
        log_variance += s.log_variance;
        log_lengthscale_sq += s.log_lengthscale_sq;
        fit += s.fit;
        residual += s.residual;
    }
    // ∂L/∂u_i through K_mn: Σ_j g_ij (z_j − u_i)/θ2.
    for (i, t) in total.iter().enumerate() {
        for a in 0..q {
            cross_u[(i, a)] -= t * inducing[(a, i)];
        }
        log_lengthscale_sq += t * inducing.column(i).norm_squared();
    }
    cross_u /= ell;

    let log_det_b = 2.0 * dtc.b.l_dirty().diagonal().iter().map(|v| v.ln()).sum::<f64>();
    let log_2pi = (2.0 * std::f64::consts::PI).ln();
    let nll = 0.5 * dims * (n as f64 * (log_2pi + noise.ln()) + log_det_b) + 0.5 * fit;
    // tr Σ⁻¹ = (N − m + tr B⁻¹)/θ3.
    let trace_inv = (n as f64 - m as f64 + b_inv.trace()) / noise;
    let d_noise = 0.5 * (dims * trace_inv - residual);

    let within = kernel.se_grad(inducing, inducing, &dtc.kmm, &d_kmm);
    let grad_inducing = cross_u.transpose() + within.a + within.b;
    let grad_log_theta = [
        log_variance + within.log_variance,
        log_lengthscale_sq / (2.0 * ell) + within.log_lengthscale_sq,
        noise * d_noise,
    ];
    let finite = nll.is_finite()
        && grad_latent
            .iter()
            .chain(&grad_inducing)
            .chain(&grad_log_theta)
            .all(|v| v.is_finite());
    if !finite {
        return Err(CoreError::Overflow {
            what: "the sparse GPLVM objective or its gradient",
        });
    }
    Ok(SparseNllGrad {
        nll,
        grad_latent,
        grad_inducing,
        grad_log_theta,
        jitter: dtc.jitter,
    })
}

impl GpMap {
    /// The exact map ([`Self::new`]), or the sparse one through `inducing` ([`Self::sparse`]).
    pub fn fit(
        inputs: DMatrix<f64>,
        outputs: DMatrix<f64>,
        kernel: SeKernel,
        inducing: Option<DMatrix<f64>>,
    ) -> Result<Self> {
        match inducing {
            Some(u) => Self::sparse(u, &inputs, &outputs, kernel),
            None => Self::new(inputs, outputs, kernel),
        }
    }

    /// The sparse GPLVM's decoder, the DTC predictive distribution of a GP trained on `inputs`
    /// (q×N) and `outputs` (p×N) through the inducing inputs `inducing` (q×m), which become the
    /// map's inputs: mean `k(x, U) α + mean` with `α = (θ3 K_mm + K_mn K_nm)⁻¹ K_mn (Y − mean)`,
    /// variance `k(x, x) − k*ᵀ (K_mm⁻¹ − (K_mm + K_mn K_nm/θ3)⁻¹) k*`. O(N m² + m³) to build,
    /// then O(m) per mean and O(m²) per variance; with `U = inputs` it is [`Self::new`].
    pub fn sparse(
        inducing: DMatrix<f64>,
        inputs: &DMatrix<f64>,
        outputs: &DMatrix<f64>,
        kernel: SeKernel,
    ) -> Result<Self> {
        check_problem(inputs, &inducing, outputs, "outputs")?;
        let mean = outputs.column_mean();
        let centred = outputs - &mean * DMatrix::from_element(1, inputs.ncols(), 1.0);
        let dtc = Dtc::new(inputs, &inducing, &centred, kernel)?;
        let alpha_t = dtc.alpha().transpose();
        if !mean.iter().chain(alpha_t.iter()).all(|v| v.is_finite()) {
            return Err(CoreError::Overflow {
                what: "the sparse GP weights",
            });
        }
        Ok(Self {
            kernel,
            inputs: inducing,
            alpha_t,
            projected: Some(&dtc.lower * dtc.b.l()),
            lower: dtc.lower,
            mean,
            jitter: dtc.jitter,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gplvm::tests::problem;

    fn inducing() -> DMatrix<f64> {
        DMatrix::from_row_slice(2, 4, &[-0.8, 0.1, 0.9, 0.3, -0.5, 0.6, -0.2, 0.4])
    }

    #[test]
    fn fit_is_the_exact_map_without_inducing_inputs_and_the_sparse_one_with() {
        let (latent, data, lt) = problem();
        let kernel = SeKernel::new(lt.map(f64::exp)).unwrap();
        let exact = GpMap::new(latent.clone(), data.clone(), kernel).unwrap();
        let sparse = GpMap::sparse(inducing(), &latent, &data, kernel).unwrap();
        let fitted = |u| {
            GpMap::fit(latent.clone(), data.clone(), kernel, u)
                .unwrap()
                .predict_mean(&latent)
                .unwrap()
        };
        assert_eq!(fitted(None), exact.predict_mean(&latent).unwrap());
        assert_eq!(fitted(Some(inducing())), sparse.predict_mean(&latent).unwrap());
    }

    #[test]
    fn the_objective_is_exact_without_inducing_inputs_and_stacked_with() {
        let (latent, data, lt) = problem();
        let (exact, objective) = (
            nll_grad(&latent, &data, lt).unwrap(),
            gplvm_objective(&latent, &data, lt, None),
        );
        assert_eq!(
            (objective.as_ref().unwrap().nll, &objective.unwrap().grad_latent),
            (exact.nll, &exact.grad_latent)
        );
        let sparse = sparse_nll_grad(&latent, &inducing(), &data, lt).unwrap();
        let stacked = gplvm_objective(&latent, &data, lt, Some(&inducing())).unwrap();
        assert_eq!(
            (stacked.nll, stacked.grad_latent.shape()),
            (sparse.nll, (2, latent.ncols() + 4))
        );
        assert_eq!(stacked.grad_latent.columns(latent.ncols(), 4), sparse.grad_inducing);
    }

    /// Central differences of `f` at every entry of `at` against `analytic`.
    fn check_fd(name: &str, at: &DMatrix<f64>, analytic: &DMatrix<f64>, f: impl Fn(&DMatrix<f64>) -> f64) {
        check_fd_at(name, at, analytic, 1e-6, 1e-5, f);
    }

    /// [`check_fd`] with step `h` and tolerance `tol` (relative to 1 + |analytic|).
    fn check_fd_at(
        name: &str,
        at: &DMatrix<f64>,
        analytic: &DMatrix<f64>,
        h: f64,
        tol: f64,
        f: impl Fn(&DMatrix<f64>) -> f64,
    ) {
        for idx in 0..at.len() {
            let (mut plus, mut minus) = (at.clone(), at.clone());
            plus[idx] += h;
            minus[idx] -= h;
            let fd = (f(&plus) - f(&minus)) / (2.0 * h);
            let an = analytic[idx];
            assert!(
                (fd - an).abs() < tol * (1.0 + an.abs()),
                "{name}[{idx}]: fd {fd} analytic {an}"
            );
        }
    }

    #[test]
    fn gradient_matches_central_differences() {
        let (latent, data, lt) = problem();
        let u = inducing();
        let r = sparse_nll_grad(&latent, &u, &data, lt).unwrap();
        let nll = |z: &DMatrix<f64>, u: &DMatrix<f64>, lt| sparse_nll_grad(z, u, &data, lt).unwrap().nll;
        check_fd("z", &latent, &r.grad_latent, |z| nll(z, &u, lt));
        check_fd("u", &u, &r.grad_inducing, |u| nll(&latent, u, lt));
        let log_theta = DMatrix::from_column_slice(3, 1, &lt);
        let grad = DMatrix::from_column_slice(3, 1, &r.grad_log_theta);
        check_fd("log theta", &log_theta, &grad, |lt| {
            nll(&latent, &u, [lt[0], lt[1], lt[2]])
        });
    }

    /// With the inducing inputs at the latent points, `Q = K` and the bound is the exact NLL;
    /// moving both together moves it as the exact GPLVM's gradient says.
    #[test]
    fn inducing_at_the_latent_points_is_the_exact_gplvm() {
        let (latent, data, lt) = problem();
        let sparse = sparse_nll_grad(&latent, &latent, &data, lt).unwrap();
        let exact = nll_grad(&latent, &data, lt).unwrap();
        assert_eq!(sparse.jitter, 0.0);
        assert!(
            (sparse.nll - exact.nll).abs() <= 1e-8 * exact.nll.abs(),
            "{} vs {}",
            sparse.nll,
            exact.nll
        );
        let together = &sparse.grad_latent + &sparse.grad_inducing;
        assert!((together - &exact.grad_latent).amax() <= 1e-6 * (1.0 + exact.grad_latent.amax()));
        for p in 0..3 {
            assert!(
                (sparse.grad_log_theta[p] - exact.grad_log_theta[p]).abs()
                    <= 1e-6 * (1.0 + exact.grad_log_theta[p].abs())
            );
        }
    }

    /// The sparse map at `U = Z` predicts as the exact GP; with fewer inducing inputs its mean
    /// and variance are the DTC formulas `σ⁻² k*ᵀ (K_mm + σ⁻² K_mn K_nm)⁻¹ K_mn Y` and
    /// `k** + σ² − k*ᵀ K_mm⁻¹ k* + k*ᵀ (K_mm + σ⁻² K_mn K_nm)⁻¹ k*`.
    #[test]
    fn sparse_map_predicts_the_dtc_formulas() {
        let (latent, data, lt) = problem();
        let kernel = SeKernel::new(lt.map(f64::exp)).unwrap();
        let queries = DMatrix::from_fn(2, 5, |i, j| (i as f64 - j as f64) * 0.35 + 0.1);
        let exact = GpMap::new(latent.clone(), data.clone(), kernel).unwrap();
        let at_latent = GpMap::sparse(latent.clone(), &latent, &data, kernel).unwrap();
        let (me, ve) = exact.predict(&queries).unwrap();
        let (ms, vs) = at_latent.predict(&queries).unwrap();
        assert!((me - ms).amax() < 1e-8 && (ve - vs).amax() < 1e-8);

        let u = inducing();
        let map = GpMap::sparse(u.clone(), &latent, &data, kernel).unwrap();
        assert_eq!(map.len(), 4);
        let (means, vars) = map.predict(&queries).unwrap();
        // A batch's variances, solved in groups of points (40: two groups and 8 one at a time),
        // are the single point's to the bit.
        let many = DMatrix::from_fn(2, 40, |i, j| (i as f64 - j as f64 * 0.1) * 0.35);
        let (many_means, many_vars) = map.predict(&many).unwrap();
        for (j, var) in many_vars.iter().enumerate() {
            let mut mean = vec![0.0; data.nrows()];
            let one = map.predict_into(many.column(j).as_slice(), &mut mean, &mut map.scratch());
            assert_eq!((one, mean.as_slice()), (*var, many_means.column(j).as_slice()));
        }
        let noise = kernel.noise;
        let kmm = kernel.cross(&u, &u);
        let kmn = kernel.cross(&u, &latent);
        let big = &kmm + &kmn * kmn.transpose() / noise;
        let big_inv = big.try_inverse().unwrap();
        let kmm_inv = kmm.try_inverse().unwrap();
        let offset = data.column_mean();
        for j in 0..queries.ncols() {
            let ks = kernel.cross(&u, &queries.columns(j, 1).into_owned());
            let mean = (&data * kmn.transpose() * &big_inv * &ks) / noise + &offset;
            assert!((mean - means.column(j)).amax() < 1e-8);
            let var = kernel.prior_variance() - (ks.transpose() * (&kmm_inv - &big_inv) * &ks)[0];
            assert!((var - vars[j]).abs() < 1e-8, "{var} vs {}", vars[j]);
        }
    }

    /// 400 latent points in [−1.5, 1.5]² (four blocks of [`CHUNK`]), data of a smooth map, and
    /// every tenth point an inducing input: 40 inputs about 0.47 apart under a length scale of 1
    /// (`K_mm`'s condition number 8e6; it factorises without jitter, which would make the bound
    /// jump under a small step).
    fn blocks_problem() -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>, [f64; 3]) {
        let n = 400;
        let latent = DMatrix::from_fn(2, n, |i, j| {
            ((j * (7 + 6 * i)) % 97) as f64 / 97.0 * 3.0 - 1.5 + 1e-3 * j as f64 / n as f64
        });
        let mut data = DMatrix::from_fn(3, n, |i, j| {
            (latent[(0, j)] * (i + 1) as f64).sin() + 0.3 * latent[(1, j)] * latent[(0, j)] * i as f64
        });
        let mean = data.column_mean();
        for mut c in data.column_iter_mut() {
            c -= &mean;
        }
        let inducing = DMatrix::from_fn(2, n / 10, |i, j| latent[(i, 10 * j)]);
        (latent, data, inducing, [0.5f64.ln(), 0.0, 1e-4f64.ln()])
    }

    /// The gradient where `∂L/∂U` through `K_mn` and through `K_mm` nearly cancel: `A = L⁻¹ K_mn`
    /// by substitution keeps it; an explicit `L⁻¹` (or `L⁻¹ K_mn K_nm L⁻ᵀ` from the product) made
    /// `∂L/∂U` of a 1000-posture fit's start 0.03 where it is 1e-5, and L-BFGS stopped after 4
    /// iterations. The bound itself is only good to ~1e-8 here, hence steps of 1e-4.
    #[test]
    fn gradient_holds_with_blocks_problem() {
        let (latent, data, u, lt) = blocks_problem();
        let r = sparse_nll_grad(&latent, &u, &data, lt).unwrap();
        let nll = |z: &DMatrix<f64>, u: &DMatrix<f64>, lt| sparse_nll_grad(z, u, &data, lt).unwrap().nll;
        check_fd_at("u", &u, &r.grad_inducing, 1e-4, 1e-4, |u| nll(&latent, u, lt));
        let some = latent.columns(0, 6).into_owned();
        check_fd_at("z", &some, &r.grad_latent.columns(0, 6).into_owned(), 1e-4, 1e-4, |z| {
            let mut all = latent.clone();
            all.columns_mut(0, 6).copy_from(z);
            nll(&all, &u, lt)
        });
        let log_theta = DMatrix::from_column_slice(3, 1, &lt);
        let grad = DMatrix::from_column_slice(3, 1, &r.grad_log_theta);
        check_fd_at("log theta", &log_theta, &grad, 1e-4, 1e-4, |lt| {
            nll(&latent, &u, [lt[0], lt[1], lt[2]])
        });
    }

    /// The blocks' partial sums are added in block order: the same bits on 1 to 8 threads, for
    /// the bound, its gradient and the sparse map.
    #[test]
    fn same_bits_on_any_thread_count() {
        let (latent, data, u, lt) = blocks_problem();
        let kernel = SeKernel::new(lt.map(f64::exp)).unwrap();
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let r = sparse_nll_grad(&latent, &u, &data, lt).unwrap();
                let map = GpMap::sparse(u.clone(), &latent, &data, kernel).unwrap();
                let (mean, var) = map.predict(&latent).unwrap();
                (
                    r.nll.to_bits(),
                    r.grad_latent,
                    r.grad_inducing,
                    r.grad_log_theta.map(f64::to_bits),
                    mean,
                    var,
                )
            })
        };
        let one = run(1);
        for threads in [2, 3, 8] {
            assert!(run(threads) == one, "{threads} threads");
        }
    }

    #[test]
    fn bad_shapes_and_values_are_errors() {
        let (latent, data, lt) = problem();
        let u = inducing();
        let short = data.columns(0, 5).into_owned();
        assert!(matches!(
            sparse_nll_grad(&latent, &u, &short, lt),
            Err(CoreError::Shape { .. })
        ));
        let wrong_dim = DMatrix::zeros(3, 4);
        assert!(matches!(
            sparse_nll_grad(&latent, &wrong_dim, &data, lt),
            Err(CoreError::Shape { .. })
        ));
        assert!(matches!(
            sparse_nll_grad(&latent, &DMatrix::zeros(2, 0), &data, lt),
            Err(CoreError::Empty { .. })
        ));
        let mut nan = u.clone();
        nan[3] = f64::NAN;
        assert!(matches!(
            sparse_nll_grad(&latent, &nan, &data, lt),
            Err(CoreError::NonFinite { .. })
        ));
        assert!(matches!(
            sparse_nll_grad(&latent, &u, &data, [0.0, f64::NAN, 0.0]),
            Err(CoreError::NonFinite { .. })
        ));
        assert!(matches!(
            GpMap::sparse(u.clone(), &latent, &short, SeKernel::new([1.0; 3]).unwrap()),
            Err(CoreError::Shape { .. })
        ));
        assert!(matches!(
            sparse_nll_grad(&latent, &u, &(&data * 1e200), lt),
            Err(CoreError::Overflow { .. })
        ));
    }
}
