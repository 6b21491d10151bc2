//! The back-constrained GPLVM (Lawrence & Quiñonero-Candela 2006): the latent points are a
//! smooth function of the data, `Z = A K_b` with `K_b[m, n] = exp(−‖y_m − y_n‖² / (2 β))`, and
//! the weights `A` (d×N) and `log β` are optimised with `log θ` through the same NLL (Eq. 1).
//! A new posture `y` encodes as `A k_b(Y, y)`: one kernel evaluation, and the training postures
//! encode exactly to the fitted latent points ([`encoder`]).

use nalgebra::DMatrix;

use crate::error::{CoreError, Result, check_finite};
use crate::gp::GpMap;
use crate::gplvm::nll_grad;
use crate::kernel::SeKernel;

/// White noise of the back-constraint kernel: only its variance uses it (the encoder's mean is
/// exactly `A k_b`); it keeps that kernel matrix factorisable for the variance.
pub const BACK_CONSTRAINT_NOISE: f64 = 1e-8;

/// `L(A, θ, β)` and its gradient with respect to `A`, `log θ` and `log β`.
#[derive(Debug, Clone)]
pub struct BackConstrainedGrad {
    /// The GPLVM negative log-likelihood at `Z = A K_b`.
    pub nll: f64,
    /// `∂L/∂A`, d×N like the weights.
    pub grad_weights: DMatrix<f64>,
    /// `∂L/∂ log θ`.
    pub grad_log_theta: [f64; 3],
    /// `∂L/∂ log β`.
    pub grad_log_beta: f64,
    /// The latent points `Z = A K_b` (d×N).
    pub latent: DMatrix<f64>,
    /// Jitter added to the GPLVM's `K` (0 if none).
    pub jitter: f64,
}

/// The back-constraint kernel of squared length-scale `beta` (signal variance 1).
pub fn kernel(beta: f64) -> Result<SeKernel> {
    SeKernel::new([1.0, beta, BACK_CONSTRAINT_NOISE])
}

/// `K_b` (N×N, no noise on the diagonal) of the postures `data` (D×N, one per column).
fn matrix(data: &DMatrix<f64>, k: &SeKernel) -> DMatrix<f64> {
    let n = data.ncols();
    DMatrix::from_fn(n, n, |i, j| k.se(data.column(i).as_slice(), data.column(j).as_slice()))
}

/// Evaluates the back-constrained GPLVM objective: weights `weights` (d×N), centred postures
/// `centred` (D×N, the data of the likelihood and the inputs of the back-constraint), GPLVM
/// kernel `exp(log_theta)`, back-constraint squared length-scale `exp(log_beta)`.
///
/// Chain rule through `Z = A K_b`: `∂L/∂A = (∂L/∂Z) K_b` and `∂L/∂ log β = Σ (∂L/∂Z) ⊙ (A ∂K_b/∂ log β)`
/// with `∂K_b[m, n]/∂ log β = K_b[m, n] ‖y_m − y_n‖² / (2 β)`.
pub fn nll_grad_back_constrained(
    weights: &DMatrix<f64>,
    centred: &DMatrix<f64>,
    log_theta: [f64; 3],
    log_beta: f64,
) -> Result<BackConstrainedGrad> {
    if weights.ncols() != centred.ncols() {
        return Err(CoreError::Shape {
            what: "back-constraint weights",
            expected: format!("({}, d)", centred.ncols()),
            got: format!("({}, {})", weights.ncols(), weights.nrows()),
        });
    }
    check_finite("back-constraint weights", weights.as_slice())?;
    check_finite("log beta", &[log_beta])?;
    let k = kernel(log_beta.exp())?;
    let kb = matrix(centred, &k);
    let latent = weights * &kb;
    let inner = nll_grad(&latent, centred, log_theta)?;
    let grad_weights = &inner.grad_latent * &kb;
    let n = centred.ncols();
    let dkb = DMatrix::from_fn(n, n, |i, j| {
        let r2: f64 = centred
            .column(i)
            .iter()
            .zip(centred.column(j).iter())
            .map(|(a, b)| (a - b).powi(2))
            .sum();
        kb[(i, j)] * r2 / (2.0 * k.lengthscale_sq)
    });
    let grad_log_beta = inner.grad_latent.component_mul(&(weights * dkb)).sum();
    let finite = grad_weights.iter().all(|v| v.is_finite()) && grad_log_beta.is_finite();
    if !finite {
        return Err(CoreError::Overflow {
            what: "the back-constrained GPLVM gradient",
        });
    }
    Ok(BackConstrainedGrad {
        nll: inner.nll,
        grad_weights,
        grad_log_theta: inner.grad_log_theta,
        grad_log_beta,
        latent,
        jitter: inner.jitter,
    })
}

/// The encoder posture → latent of a back-constrained fit: the map `y ↦ A k_b(Y, y)` (its mean
/// at a training posture is that posture's latent point, to rounding).
pub fn encoder(centred: DMatrix<f64>, weights: DMatrix<f64>, log_beta: f64) -> Result<GpMap> {
    GpMap::from_weights(centred, weights, kernel(log_beta.exp())?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn problem() -> (DMatrix<f64>, DMatrix<f64>, [f64; 3], f64) {
        let n = 7;
        let centred = DMatrix::from_fn(3, n, |i, j| ((i * 5 + j * 3) as f64 * 0.37).sin());
        let weights = DMatrix::from_fn(2, n, |i, j| ((i * 11 + j * 7) as f64 * 0.23).cos() * 0.4);
        (
            weights,
            centred,
            [0.3_f64.ln(), 0.8_f64.ln(), 0.05_f64.ln()],
            0.6_f64.ln(),
        )
    }

    #[test]
    fn gradient_matches_central_differences() {
        let (a, y, lt, lb) = problem();
        let g = nll_grad_back_constrained(&a, &y, lt, lb).unwrap();
        let f = |a: &DMatrix<f64>, lt: [f64; 3], lb: f64| nll_grad_back_constrained(a, &y, lt, lb).unwrap().nll;
        let h = 1e-6;
        for idx in 0..a.len() {
            let (mut up, mut down) = (a.clone(), a.clone());
            up[idx] += h;
            down[idx] -= h;
            let fd = (f(&up, lt, lb) - f(&down, lt, lb)) / (2.0 * h);
            assert!(
                (fd - g.grad_weights[idx]).abs() < 1e-6 * (1.0 + fd.abs()),
                "A[{idx}]: {fd} vs {}",
                g.grad_weights[idx]
            );
        }
        let fd = (f(&a, lt, lb + h) - f(&a, lt, lb - h)) / (2.0 * h);
        assert!(
            (fd - g.grad_log_beta).abs() < 1e-6 * (1.0 + fd.abs()),
            "log beta: {fd} vs {}",
            g.grad_log_beta
        );
        for t in 0..3 {
            let (mut up, mut down) = (lt, lt);
            up[t] += h;
            down[t] -= h;
            let fd = (f(&a, up, lb) - f(&a, down, lb)) / (2.0 * h);
            assert!(
                (fd - g.grad_log_theta[t]).abs() < 1e-6 * (1.0 + fd.abs()),
                "log theta{t}: {fd}"
            );
        }
    }

    #[test]
    fn training_postures_encode_to_their_latent_points() {
        let (a, y, lt, lb) = problem();
        let g = nll_grad_back_constrained(&a, &y, lt, lb).unwrap();
        let map = encoder(y.clone(), a, lb).unwrap();
        let encoded = map.predict_mean(&y).unwrap();
        assert!((encoded - &g.latent).abs().max() < 1e-12);
    }

    #[test]
    fn mismatched_weights_are_a_shape_error() {
        let (a, y, lt, lb) = problem();
        let short = a.columns(0, 5).into_owned();
        assert!(matches!(
            nll_grad_back_constrained(&short, &y, lt, lb),
            Err(CoreError::Shape { .. })
        ));
    }
}
