//! GPLVM negative log-likelihood and its analytic gradient (paper Eq. 1–3).

use nalgebra::DMatrix;

use crate::error::{CoreError, Result, check_finite};
use crate::kernel::{SeKernel, factorize};

/// `L(Z, θ)` and its gradient with respect to `Z` and `log θ`.
#[derive(Debug, Clone)]
pub struct NllGrad {
    /// `(D/2) log|K| + (1/2) tr(K⁻¹ Y Yᵀ) + (N D/2) log 2π`.
    pub nll: f64,
    /// `∂L/∂Z`, d×N like the latent points.
    pub grad_latent: DMatrix<f64>,
    /// `∂L/∂ log θ` for `θ1, θ2, θ3`.
    pub grad_log_theta: [f64; 3],
    /// Jitter added to `K` to factorise it (0 if none); the NLL is that of `K + jitter·I`.
    pub jitter: f64,
}

/// Evaluates the GPLVM objective at latent points `latent` (d×N) for centred data
/// `centred` (D×N, one posture per column) and kernel parameters `exp(log_theta)`.
///
/// Uses `∂L/∂K = ½(D K⁻¹ − K⁻¹ Y Yᵀ K⁻¹)` and the chain rule through Eq. 2.
pub fn nll_grad(latent: &DMatrix<f64>, centred: &DMatrix<f64>, log_theta: [f64; 3]) -> Result<NllGrad> {
    let n = latent.ncols();
    if n == 0 || latent.nrows() == 0 {
        return Err(CoreError::Empty { what: "latent points" });
    }
    crate::gp::check_gp_size("latent points", n)?;
    if centred.ncols() != n || centred.nrows() == 0 {
        return Err(CoreError::Shape {
            what: "data",
            expected: format!("({n}, D) with D >= 1"),
            got: format!("({}, {})", centred.ncols(), centred.nrows()),
        });
    }
    check_finite("latent points", latent.as_slice())?;
    check_finite("data", centred.as_slice())?;
    check_finite("log theta", &log_theta)?;
    let kernel = SeKernel::new(log_theta.map(f64::exp))?;
    let dims = centred.nrows() as f64;

    let k = kernel.matrix(latent);
    let factor = factorize(k.clone())?;
    let chol = &factor.cholesky;
    let y = centred.transpose(); // N×D
    let a = chol.solve(&y); // K⁻¹ Y
    let log_det: f64 = 2.0 * chol.l_dirty().diagonal().iter().map(|v| v.ln()).sum::<f64>();
    let fit: f64 = y.component_mul(&a).sum();
    let nll = 0.5 * dims * log_det + 0.5 * fit + 0.5 * (n as f64) * dims * (2.0 * std::f64::consts::PI).ln();

    // G = ∂L/∂K = ½(D K⁻¹ − A Aᵀ), symmetric.
    let mut g = factor.inverse() * (0.5 * dims);
    g.gemm(-0.5, &a, &a.transpose(), 1.0);

    // K = se(Z, Z) + θ3 I: the smooth part carries Z, θ1, θ2; the noise only θ3.
    let mut se = k;
    se.fill_diagonal(kernel.variance);
    let through_se = kernel.se_grad(latent, latent, &se, &g);
    let grad_latent = through_se.a + through_se.b;
    let grad_log_theta = [
        through_se.log_variance,
        through_se.log_lengthscale_sq,
        kernel.noise * g.trace(),
    ];
    let finite = nll.is_finite() && grad_latent.iter().chain(&grad_log_theta).all(|v| v.is_finite());
    if !finite {
        return Err(CoreError::Overflow {
            what: "the GPLVM objective or its gradient",
        });
    }
    Ok(NllGrad {
        nll,
        grad_latent,
        grad_log_theta,
        jitter: factor.jitter,
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Ten 2-D latent points and 3-D centred data of a smooth map, and a kernel.
    pub(crate) fn problem() -> (DMatrix<f64>, DMatrix<f64>, [f64; 3]) {
        let n = 10;
        let latent = DMatrix::from_fn(2, n, |i, j| ((j * 7 + i * 3) % 11) as f64 / 5.0 - 1.0 + 0.03 * i as f64);
        let mut data = DMatrix::from_fn(3, n, |i, j| {
            (latent[(0, j)] * (i + 1) as f64).cos() + latent[(1, j)] * i as f64
        });
        let mean = data.column_mean();
        for mut c in data.column_iter_mut() {
            c -= &mean;
        }
        (latent, data, [0.2f64.ln(), 0.7f64.ln(), 0.05f64.ln()])
    }

    #[test]
    fn gradient_matches_central_differences() {
        let (latent, data, lt) = problem();
        let r = nll_grad(&latent, &data, lt).unwrap();
        let h = 1e-6;
        for idx in 0..latent.len() {
            let (mut plus, mut minus) = (latent.clone(), latent.clone());
            plus[idx] += h;
            minus[idx] -= h;
            let fd = (nll_grad(&plus, &data, lt).unwrap().nll - nll_grad(&minus, &data, lt).unwrap().nll) / (2.0 * h);
            let an = r.grad_latent[idx];
            assert!(
                (fd - an).abs() < 1e-5 * (1.0 + an.abs()),
                "z[{idx}]: fd {fd} analytic {an}"
            );
        }
        for p in 0..3 {
            let (mut plus, mut minus) = (lt, lt);
            plus[p] += h;
            minus[p] -= h;
            let fd = (nll_grad(&latent, &data, plus).unwrap().nll - nll_grad(&latent, &data, minus).unwrap().nll)
                / (2.0 * h);
            let an = r.grad_log_theta[p];
            assert!(
                (fd - an).abs() < 1e-5 * (1.0 + an.abs()),
                "log theta{}: fd {fd} analytic {an}",
                p + 1
            );
        }
    }

    #[test]
    fn nll_matches_dense_formula() {
        let (latent, data, lt) = problem();
        let k = SeKernel::new(lt.map(f64::exp)).unwrap().matrix(&latent);
        let y = data.transpose();
        let (n, d) = (y.nrows() as f64, y.ncols() as f64);
        let dense = 0.5 * d * k.determinant().ln()
            + 0.5 * (k.clone().try_inverse().unwrap() * &y * y.transpose()).trace()
            + 0.5 * n * d * (2.0 * std::f64::consts::PI).ln();
        let r = nll_grad(&latent, &data, lt).unwrap();
        assert!(
            (r.nll - dense).abs() < 1e-9 * dense.abs().max(1.0),
            "{} vs {dense}",
            r.nll
        );
    }

    #[test]
    fn mismatched_shapes_are_errors() {
        let (latent, data, lt) = problem();
        let short = data.columns(0, 5).into_owned();
        assert!(matches!(nll_grad(&latent, &short, lt), Err(CoreError::Shape { .. })));
        assert!(matches!(
            nll_grad(&latent, &data, [0.0, f64::NAN, 0.0]),
            Err(CoreError::NonFinite { .. })
        ));
    }

    /// Fuzzing found data of scale 1e200 giving an infinite NLL and NaN gradients.
    #[test]
    fn overflowing_scale_is_an_error_not_nan() {
        let (latent, data, lt) = problem();
        let huge = &data * 1e200;
        assert!(matches!(nll_grad(&latent, &huge, lt), Err(CoreError::Overflow { .. })));
        assert!(nll_grad(&latent, &(&data * 1e100), lt).is_ok());
    }
}
