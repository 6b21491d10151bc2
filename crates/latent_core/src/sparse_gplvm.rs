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

use nalgebra::{Cholesky, DMatrix, Dyn};

use crate::error::{CoreError, Result, check_finite};
use crate::gp::{GpMap, check_gp_size, check_points, check_values};
use crate::gplvm::NllGrad;
use crate::kernel::{SeKernel, factorize};

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
    /// `K_mn` (m×N).
    pub(crate) kmn: DMatrix<f64>,
    /// `L`, the lower Cholesky factor of `K_mm + jitter·I`.
    pub(crate) lower: DMatrix<f64>,
    pub(crate) jitter: f64,
    /// `A = L⁻¹ K_mn` (m×N).
    pub(crate) a: DMatrix<f64>,
    /// `B = I + A Aᵀ/θ3 = L_B L_Bᵀ`.
    pub(crate) b: Cholesky<f64, Dyn>,
    /// `A Y` (m×D).
    pub(crate) ay: DMatrix<f64>,
    /// `B⁻¹ A Y` (m×D).
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

impl Dtc {
    /// The factors at inputs `inputs` (q×N), inducing inputs `inducing` (q×m) and centred
    /// outputs `centred` (D×N).
    pub(crate) fn new(
        inputs: &DMatrix<f64>,
        inducing: &DMatrix<f64>,
        centred: &DMatrix<f64>,
        kernel: SeKernel,
    ) -> Result<Self> {
        check_problem(inputs, inducing, centred, "data")?;
        let kmm = kernel.cross(inducing, inducing);
        let factor = factorize(kmm.clone())?;
        let lower = factor.cholesky.l();
        let kmn = kernel.cross(inducing, inputs);
        let mut a = kmn.clone();
        lower.solve_lower_triangular_mut(&mut a);
        let m = inducing.ncols();
        let mut b = DMatrix::identity(m, m);
        b.gemm(1.0 / kernel.noise, &a, &a.transpose(), 1.0);
        let b = Cholesky::new(b).ok_or(CoreError::NotPositiveDefinite { n: m, jitter: 0.0 })?;
        let ay = &a * centred.transpose();
        let c = b.solve(&ay);
        Ok(Self {
            kernel,
            kmm,
            kmn,
            lower,
            jitter: factor.jitter,
            a,
            b,
            ay,
            c,
        })
    }

    /// `α = (θ3 K_mm + K_mn K_nm)⁻¹ K_mn Y = L⁻ᵀ B⁻¹ A Y/θ3` (m×D): the predictive mean at `x`
    /// is `k(x, U) α`, and `Σ⁻¹ Y = (Y − Aᵀ B⁻¹ A Y/θ3)/θ3` projects onto it (`L⁻ᵀ A Σ⁻¹ Y = α`).
    pub(crate) fn alpha(&self) -> DMatrix<f64> {
        let mut alpha = self.c.clone() / self.kernel.noise;
        self.lower.tr_solve_lower_triangular_mut(&mut alpha);
        alpha
    }
}

/// Evaluates the DTC bound at latent points `latent` (q×N) with inducing inputs `inducing`
/// (q×m) for centred data `centred` (D×N, one posture per column) and kernel `exp(log_theta)`.
///
/// With `G = ∂L/∂Σ = ½(D Σ⁻¹ − Σ⁻¹ Y Yᵀ Σ⁻¹)` and `W = K_mm⁻¹ K_mn`:
/// `∂L/∂K_mn = 2 W G`, `∂L/∂K_mm = −W G Wᵀ`, `∂L/∂θ3 = tr G`, each in O(N m²) from
/// `Σ⁻¹ Aᵀ = Aᵀ B⁻¹/θ3` and `A Aᵀ = θ3 (B − I)`; then the chain rule through the kernel.
pub fn sparse_nll_grad(
    latent: &DMatrix<f64>,
    inducing: &DMatrix<f64>,
    centred: &DMatrix<f64>,
    log_theta: [f64; 3],
) -> Result<SparseNllGrad> {
    check_finite("log theta", &log_theta)?;
    let kernel = SeKernel::new(log_theta.map(f64::exp))?;
    let dtc = Dtc::new(latent, inducing, centred, kernel)?;
    let (n, m, dims) = (latent.ncols(), inducing.ncols(), centred.nrows() as f64);
    let noise = kernel.noise;

    let log_det_b = 2.0 * dtc.b.l_dirty().diagonal().iter().map(|v| v.ln()).sum::<f64>();
    let fit = (centred.norm_squared() - dtc.ay.component_mul(&dtc.c).sum() / noise) / noise;
    let log_2pi = (2.0 * std::f64::consts::PI).ln();
    let nll = 0.5 * dims * (n as f64 * (log_2pi + noise.ln()) + log_det_b) + 0.5 * fit;

    let identity = DMatrix::identity(m, m);
    let mut l_inv = identity.clone();
    dtc.lower.solve_lower_triangular_mut(&mut l_inv);
    let b_inv = dtc.b.solve(&identity);
    let e = &b_inv * &l_inv; // B⁻¹ L⁻¹
    let wv = dtc.alpha(); // W Σ⁻¹ Y
    // (Σ⁻¹ Y)ᵀ, D×N.
    let mut vt = centred.clone();
    vt.gemm(-1.0 / noise, &dtc.c.transpose(), &dtc.a, 1.0);
    vt /= noise;
    // ∂L/∂K_mn = (D/θ3) L⁻ᵀ B⁻¹ A − W Σ⁻¹ Y Yᵀ Σ⁻¹.
    let mut d_kmn = e.tr_mul(&dtc.a) * (dims / noise);
    d_kmn.gemm(-1.0, &wv, &vt, 1.0);
    // ∂L/∂K_mm = −(D/2) L⁻ᵀ (I − B⁻¹) L⁻¹ + ½ (W Σ⁻¹ Y)(W Σ⁻¹ Y)ᵀ.
    let mut d_kmm = l_inv.tr_mul(&(&l_inv - &e)) * (-0.5 * dims);
    d_kmm.gemm(0.5, &wv, &wv.transpose(), 1.0);
    let d_kmm = (&d_kmm + d_kmm.transpose()) * 0.5;
    // tr Σ⁻¹ = (N − m + tr B⁻¹)/θ3.
    let trace_inv = (n as f64 - m as f64 + b_inv.trace()) / noise;
    let d_noise = 0.5 * (dims * trace_inv - vt.norm_squared());

    let cross = kernel.se_grad(inducing, latent, &dtc.kmn, &d_kmn);
    let within = kernel.se_grad(inducing, inducing, &dtc.kmm, &d_kmm);
    let grad_inducing = cross.a + within.a + within.b;
    let grad_log_theta = [
        cross.log_variance + within.log_variance,
        cross.log_lengthscale_sq + within.log_lengthscale_sq,
        noise * d_noise,
    ];
    let finite = nll.is_finite()
        && cross
            .b
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
        grad_latent: cross.b,
        grad_inducing,
        grad_log_theta,
        jitter: dtc.jitter,
    })
}

impl GpMap {
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
    use crate::gplvm::nll_grad;
    use crate::gplvm::tests::problem;

    fn inducing() -> DMatrix<f64> {
        DMatrix::from_row_slice(2, 4, &[-0.8, 0.1, 0.9, 0.3, -0.5, 0.6, -0.2, 0.4])
    }

    /// Central differences of `f` at every entry of `at` against `analytic`.
    fn check_fd(name: &str, at: &DMatrix<f64>, analytic: &DMatrix<f64>, f: impl Fn(&DMatrix<f64>) -> f64) {
        let h = 1e-6;
        for idx in 0..at.len() {
            let (mut plus, mut minus) = (at.clone(), at.clone());
            plus[idx] += h;
            minus[idx] -= h;
            let fd = (f(&plus) - f(&minus)) / (2.0 * h);
            let an = analytic[idx];
            assert!(
                (fd - an).abs() < 1e-5 * (1.0 + an.abs()),
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
