//! The iterative projection (paper Sec. III-B; docs/method.md §Encoding, map 2): a posture `x` is
//! encoded as `argmax_z log N(x | μ(z), σ²(z) I)` under the GPLVM decoder (Eq. 4), with the
//! analytic gradients of μ and σ² with respect to z (SE kernel, Eq. 2).
//!
//! As `latentrl.inverse.Projection` (SciPy L-BFGS-B, the independent reference): started from
//! the latent point of the nearest training posture; two stages, the squared reconstruction
//! error `½‖x − μ(z)‖²` first and then the density from there (started on the density,
//! the search leaves the data at once: where σ² is tiny a small residual costs more than
//! moving to where σ² is large); inside the bounding box of the latent points widened by
//! `margin` of its extent per side; the best of start and both stages by density is kept.
//! The minimiser is [`crate::lbfgs`] (SciPy's stopping rules, not its steps).

use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

use crate::error::{CoreError, Result, check_finite};
use crate::gp::GpMap;
use crate::lbfgs::{LbfgsScratch, minimise};

/// Settings of a [`Projection`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProjectionConfig {
    /// L-BFGS iteration cap of each of the two stages (as the Python reference's `max_iter`).
    pub max_iter: usize,
    /// The search box is the latent points' bounding box widened by this share of its extent
    /// per side (as the Python reference's `margin`).
    pub margin: f64,
    /// After a move, search from the commanded latent point instead
    /// ([`Self::encode_near_into`]'s tracking mode): the reconstruction error only, so a
    /// posture the plant tracked encodes to the point that commanded it.
    pub tracking: bool,
}

impl ProjectionConfig {
    /// 200 iterations per stage, a margin of 0.5, no tracking.
    pub const DEFAULT: Self = Self {
        max_iter: 200,
        margin: 0.5,
        tracking: false,
    };
}

impl Default for ProjectionConfig {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// The iterative-projection encoder posture → latent of a GPLVM decoder.
#[derive(Debug, Clone)]
pub struct Projection {
    decoder: GpMap,
    /// The training postures (D×N), the decoder's outputs, for the nearest-posture start.
    postures: DMatrix<f64>,
    low: Vec<f64>,
    high: Vec<f64>,
    max_iter: usize,
    tracking: bool,
}

/// Buffers of the decoder's value and gradients at one latent point.
#[derive(Debug, Clone)]
struct DecodeScratch {
    kstar: DVector<f64>,
    solved: DVector<f64>,
    spare: DVector<f64>,
    /// `∂k*/∂z` (N×d).
    dk: DMatrix<f64>,
    mean: DVector<f64>,
    /// `∂μ/∂z` (D×d).
    jac: DMatrix<f64>,
    residual: DVector<f64>,
    d_variance: DVector<f64>,
}

/// Reusable buffers of [`Projection::encode_into`]: an encoding allocates nothing.
#[derive(Debug, Clone)]
pub struct ProjectionScratch {
    decode: DecodeScratch,
    lbfgs: LbfgsScratch,
    reconstructed: Vec<f64>,
    densest: Vec<f64>,
}

impl Projection {
    /// The projection under `decoder` (latent d → posture D), fitted to `postures` (D×N, one
    /// training posture per column, in the order of the decoder's latent points).
    pub fn new(decoder: &GpMap, postures: DMatrix<f64>, config: ProjectionConfig) -> Result<Self> {
        let (n, joints) = (decoder.len(), decoder.output_dim());
        if postures.ncols() != n || postures.nrows() != joints {
            return Err(CoreError::Shape {
                what: "postures (the decoder's training outputs)",
                expected: format!("({n}, {joints})"),
                got: format!("({}, {})", postures.ncols(), postures.nrows()),
            });
        }
        check_finite("postures", postures.as_slice())?;
        if config.max_iter == 0 {
            return Err(CoreError::InvalidParameter {
                name: "max_iter",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        if !(config.margin.is_finite() && config.margin >= 0.0) {
            return Err(CoreError::InvalidParameter {
                name: "margin",
                value: config.margin,
                reason: "must be finite and >= 0",
            });
        }
        let latent = &decoder.inputs;
        let (low, high): (Vec<f64>, Vec<f64>) = latent
            .row_iter()
            .map(|row| {
                let (lo, hi) = (row.min(), row.max());
                let pad = config.margin * (hi - lo);
                (lo - pad, hi + pad)
            })
            .unzip();
        Ok(Self {
            decoder: decoder.clone(),
            postures,
            low,
            high,
            max_iter: config.max_iter,
            tracking: config.tracking,
        })
    }

    /// Posture dimension D (the decoder's output).
    pub fn posture_dim(&self) -> usize {
        self.decoder.output_dim()
    }

    /// Latent dimension d (the decoder's input).
    pub fn latent_dim(&self) -> usize {
        self.decoder.input_dim()
    }

    /// The search box's lower and upper corners (d each).
    pub fn bounds(&self) -> (&[f64], &[f64]) {
        (&self.low, &self.high)
    }

    /// Fresh buffers for [`Self::encode_into`].
    pub fn scratch(&self) -> ProjectionScratch {
        let (n, d, joints) = (self.decoder.len(), self.decoder.input_dim(), self.decoder.output_dim());
        ProjectionScratch {
            decode: DecodeScratch {
                kstar: DVector::zeros(n),
                solved: DVector::zeros(n),
                spare: DVector::zeros(n),
                dk: DMatrix::zeros(n, d),
                mean: DVector::zeros(joints),
                jac: DMatrix::zeros(joints, d),
                residual: DVector::zeros(joints),
                d_variance: DVector::zeros(d),
            },
            lbfgs: LbfgsScratch::new(d),
            reconstructed: vec![0.0; d],
            densest: vec![0.0; d],
        }
    }

    /// [`CoreError`] unless `posture` has the decoder's output dimension and is finite.
    pub fn check_posture(&self, posture: &[f64]) -> Result<()> {
        if posture.len() != self.decoder.output_dim() {
            return Err(CoreError::Shape {
                what: "posture",
                expected: format!("({},)", self.decoder.output_dim()),
                got: format!("({},)", posture.len()),
            });
        }
        check_finite("posture", posture)
    }

    /// Latent points (d×M) of the postures that are the columns of `postures` (D×M), in
    /// parallel; [`CoreError::Overflow`] if a search overflows float64 (postures of extreme
    /// scale), as the Python reference's `NumericalError`.
    pub fn encode(&self, postures: &DMatrix<f64>) -> Result<DMatrix<f64>> {
        if postures.nrows() != self.decoder.output_dim() {
            return Err(CoreError::Shape {
                what: "postures",
                expected: format!("(M, {})", self.decoder.output_dim()),
                got: format!("({}, {})", postures.ncols(), postures.nrows()),
            });
        }
        check_finite("postures", postures.as_slice())?;
        let d = self.decoder.input_dim();
        let mut latent = DMatrix::zeros(d, postures.ncols());
        latent.as_mut_slice().par_chunks_mut(d).enumerate().for_each_init(
            || self.scratch(),
            |s, (j, z)| self.encode_into(postures.column(j).as_slice(), z, s),
        );
        if !latent.iter().all(|v| v.is_finite()) {
            return Err(CoreError::Overflow {
                what: "the projection encoder's latent points",
            });
        }
        Ok(latent)
    }

    /// The latent point (d) of one caller's `posture` (D), checked ([`Self::check_posture`]).
    pub fn encode_one(&self, posture: &[f64]) -> Result<Vec<f64>> {
        self.check_posture(posture)?;
        let mut z = vec![0.0; self.latent_dim()];
        self.encode_into(posture, &mut z, &mut self.scratch());
        Ok(z)
    }

    /// Encodes one `posture` (length D) into `z` (length d): nearest-posture start, the two
    /// stages, the best of the three by density. Allocation-free; lengths and finiteness are
    /// the caller's contract ([`Self::check_posture`]).
    pub fn encode_into(&self, posture: &[f64], z: &mut [f64], s: &mut ProjectionScratch) {
        debug_assert_eq!(posture.len(), self.decoder.output_dim());
        debug_assert_eq!(z.len(), self.decoder.input_dim());
        let nearest = self
            .postures
            .column_iter()
            .map(|p| p.iter().zip(posture).map(|(a, b)| (a - b) * (a - b)).sum::<f64>())
            .enumerate()
            .fold(
                (0, f64::INFINITY),
                |best, (j, r2)| if r2 < best.1 { (j, r2) } else { best },
            );
        z.copy_from_slice(self.decoder.inputs.column(nearest.0).as_slice());
        let (decode, lbfgs) = (&mut s.decode, &mut s.lbfgs);
        let mut best = self.neg_log_density(z, posture, None, decode);
        s.reconstructed.copy_from_slice(z);
        let (low, high) = (&self.low, &self.high);
        let recon = |z: &[f64], g: &mut [f64]| self.reconstruction_error(z, posture, g, decode);
        minimise(recon, &mut s.reconstructed, low, high, self.max_iter, lbfgs);
        s.densest.copy_from_slice(&s.reconstructed);
        let density = |z: &[f64], g: &mut [f64]| self.neg_log_density(z, posture, Some(g), decode);
        let densest = minimise(density, &mut s.densest, low, high, self.max_iter, lbfgs);
        let reconstructed = self.neg_log_density(&s.reconstructed, posture, None, decode);
        // The first of the smallest wins, as Python's `min` over (start, stage 1, stage 2).
        if reconstructed < best {
            best = reconstructed;
            z.copy_from_slice(&s.reconstructed);
        }
        if densest < best {
            z.copy_from_slice(&s.densest);
        }
    }

    /// Encodes `posture` reached after commanding the latent point `near`: in tracking mode
    /// ([`ProjectionConfig::tracking`]) the reconstruction error `½‖x − μ(z)‖²` minimised from
    /// `near` (clamped to the search box), so a tracked posture keeps its commanded point and
    /// a disturbed one moves to the nearest latent point that reconstructs it, never to a far
    /// demo's; otherwise [`Self::encode_into`]. Allocation-free, the same contract.
    pub fn encode_near_into(&self, posture: &[f64], near: &[f64], z: &mut [f64], s: &mut ProjectionScratch) {
        if !self.tracking {
            return self.encode_into(posture, z, s);
        }
        debug_assert_eq!(near.len(), z.len());
        for (k, v) in s.reconstructed.iter_mut().enumerate() {
            *v = near[k].clamp(self.low[k], self.high[k]);
        }
        let decode = &mut s.decode;
        let recon = |z: &[f64], g: &mut [f64]| self.reconstruction_error(z, posture, g, decode);
        minimise(
            recon,
            &mut s.reconstructed,
            &self.low,
            &self.high,
            self.max_iter,
            &mut s.lbfgs,
        );
        z.copy_from_slice(&s.reconstructed);
    }

    /// `−log N(x | μ(z), σ²(z) I)` (Eq. 4's mean and variance), and its gradient with respect to
    /// `z` into `grad` if given.
    fn neg_log_density(&self, z: &[f64], x: &[f64], grad: Option<&mut [f64]>, s: &mut DecodeScratch) -> f64 {
        let variance = self.decode(z, s, true);
        s.residual.copy_from_slice(x);
        s.residual -= &s.mean;
        let sq = s.residual.norm_squared();
        let joints = x.len() as f64;
        if let Some(grad) = grad {
            // ½D/σ² − ½sq/σ⁴ without forming σ⁴, which overflows for σ² > 1e154.
            let dv = (0.5 / variance) * (joints - sq / variance);
            for (k, g) in grad.iter_mut().enumerate() {
                *g = dv * s.d_variance[k] - s.jac.column(k).dot(&s.residual) / variance;
            }
        }
        0.5 * joints * (2.0 * std::f64::consts::PI * variance).ln() + 0.5 * sq / variance
    }

    /// `½‖x − μ(z)‖²` and its gradient with respect to `z` into `grad`.
    fn reconstruction_error(&self, z: &[f64], x: &[f64], grad: &mut [f64], s: &mut DecodeScratch) -> f64 {
        self.decode(z, s, false);
        s.residual.copy_from_slice(x);
        s.residual -= &s.mean;
        for (k, g) in grad.iter_mut().enumerate() {
            *g = -s.jac.column(k).dot(&s.residual);
        }
        0.5 * s.residual.norm_squared()
    }

    /// Eq. 4 at `z` with gradients: the mean into `s.mean`, its Jacobian `αᵀ ∂k*/∂z` into
    /// `s.jac`; with `with_variance`, returns `σ² = k(z, z) − k*ᵀMk*` (`M = K⁻¹`, or a sparse
    /// map's; unclamped, as the reference) and writes `∂σ²/∂z = −2 (Mk*)ᵀ ∂k*/∂z` into
    /// `s.d_variance` (else returns 0).
    /// `∂k*_i/∂z = −k*_i (z − z_i) / θ2` (Eq. 2).
    fn decode(&self, z: &[f64], s: &mut DecodeScratch, with_variance: bool) -> f64 {
        let map = &self.decoder;
        let lengthscale_sq = map.kernel.lengthscale_sq;
        for (i, point) in map.inputs.column_iter().enumerate() {
            let k = map.kernel.se(z, point.as_slice());
            s.kstar[i] = k;
            for (dim, (zk, pk)) in z.iter().zip(point.iter()).enumerate() {
                s.dk[(i, dim)] = -k * (zk - pk) / lengthscale_sq;
            }
        }
        s.mean.copy_from(&map.mean);
        s.mean.gemv(1.0, &map.alpha_t, &s.kstar, 1.0);
        s.jac.gemm(1.0, &map.alpha_t, &s.dk, 0.0);
        if !with_variance {
            return 0.0;
        }
        let variance = map.kernel.prior_variance() - map.explained(&s.kstar, &mut s.solved, &mut s.spare, true);
        s.d_variance.gemv_tr(-2.0, &s.dk, &s.solved, 0.0);
        variance
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::SeKernel;

    /// A decoder of a 2-D latent curve into 3 joints, and its postures.
    fn toy() -> (GpMap, DMatrix<f64>) {
        let latent = DMatrix::from_fn(2, 15, |i, j| {
            let t = j as f64 / 14.0 * 3.0 - 1.5;
            if i == 0 { t } else { 0.5 * (2.0 * t).sin() }
        });
        let postures = DMatrix::from_fn(3, 15, |i, j| {
            let (a, b) = (latent[(0, j)], latent[(1, j)]);
            [a.cos() + b, a.sin() * b, a + 0.3 * b * b][i]
        });
        let kernel = SeKernel::new([1.2, 0.6, 1e-4]).unwrap();
        (GpMap::new(latent, postures.clone(), kernel).unwrap(), postures)
    }

    fn projection() -> (Projection, DMatrix<f64>) {
        let (decoder, postures) = toy();
        (
            Projection::new(&decoder, postures.clone(), ProjectionConfig::default()).unwrap(),
            postures,
        )
    }

    #[test]
    fn encode_one_checks_its_posture_and_agrees_with_the_batch() {
        let (p, postures) = projection();
        let one = p.encode_one(postures.column(3).as_slice()).unwrap();
        let batch = p.encode(&postures.columns(3, 1).into_owned()).unwrap();
        assert_eq!(one, batch.as_slice());
        assert!(matches!(p.encode_one(&[0.0; 2]), Err(CoreError::Shape { .. })));
        assert!(matches!(
            p.encode_one(&[0.0, f64::NAN, 0.0]),
            Err(CoreError::NonFinite { .. })
        ));
    }

    /// Both objectives' gradients against central differences at points on and off the data,
    /// under the exact decoder and under a sparse one (8 of the 15 points as inducing inputs,
    /// whose projection starts from the postures they decode to).
    #[test]
    fn gradients_match_central_differences() {
        let (p, postures) = projection();
        check_gradients(&p, &postures);
        let (exact, _) = toy();
        let inducing = DMatrix::from_fn(2, 8, |i, j| exact.inputs[(i, 2 * j)]);
        let sparse = GpMap::sparse(inducing.clone(), &exact.inputs, &postures, exact.kernel).unwrap();
        let decoded = sparse.predict_mean(&inducing).unwrap();
        check_gradients(
            &Projection::new(&sparse, decoded, ProjectionConfig::default()).unwrap(),
            &postures,
        );
    }

    fn check_gradients(p: &Projection, postures: &DMatrix<f64>) {
        let mut s = p.scratch();
        let x: Vec<f64> = postures.column(6).iter().map(|v| v + 0.05).collect();
        for z in [[0.1, -0.2], [-1.3, 0.4], [2.0, 1.1], [0.0, 0.0]] {
            let (mut g_density, mut g_recon, mut scratch_g) = ([0.0; 2], [0.0; 2], [0.0; 2]);
            p.neg_log_density(&z, &x, Some(&mut g_density), &mut s.decode);
            p.reconstruction_error(&z, &x, &mut g_recon, &mut s.decode);
            let h = 1e-6;
            for k in 0..2 {
                let (mut up, mut down) = (z, z);
                up[k] += h;
                down[k] -= h;
                let fd = |f: &mut dyn FnMut(&[f64]) -> f64| (f(&up) - f(&down)) / (2.0 * h);
                let density = fd(&mut |z| p.neg_log_density(z, &x, None, &mut s.decode));
                let recon = fd(&mut |z| p.reconstruction_error(z, &x, &mut scratch_g, &mut s.decode));
                let close = |a: f64, b: f64| (a - b).abs() <= 1e-6 * (1.0 + b.abs());
                assert!(
                    close(g_density[k], density),
                    "density ∂{k} at {z:?}: {} vs {density}",
                    g_density[k]
                );
                assert!(
                    close(g_recon[k], recon),
                    "reconstruction ∂{k} at {z:?}: {} vs {recon}",
                    g_recon[k]
                );
            }
        }
    }

    /// The variance and its gradient against the dense formula `k(z,z) − k*ᵀ K⁻¹ k*`.
    #[test]
    fn variance_matches_the_dense_formula() {
        let (p, _) = projection();
        let mut s = p.scratch();
        let z = [0.3, -0.1];
        let variance = p.decode(&z, &mut s.decode, true);
        let map = &p.decoder;
        let kinv = map.kernel.matrix(&map.inputs).try_inverse().unwrap();
        let dense = map.kernel.prior_variance() - (s.decode.kstar.transpose() * &kinv * &s.decode.kstar)[0];
        assert!((variance - dense).abs() < 1e-10, "{variance} vs {dense}");
        let mut mean = vec![0.0; 3];
        let predicted = map.predict_into(&z, &mut mean, &mut map.scratch());
        assert!((variance - predicted).abs() < 1e-12);
        assert_eq!(mean.as_slice(), s.decode.mean.as_slice());
    }

    /// Decoding a latent point on the data's curve, between training points, and projecting it
    /// back recovers it; a training posture encodes at least as densely as its own latent point
    /// (the start is a candidate).
    #[test]
    fn recovers_decoded_points_and_never_loses_to_the_start() {
        let (p, postures) = projection();
        let mut s = p.scratch();
        for t in [0.2f64, -0.7, 1.1] {
            let z = [t, 0.5 * (2.0 * t).sin()];
            let mut x = vec![0.0; 3];
            p.decoder.mean_into(&z, &mut x, &mut p.decoder.scratch());
            let mut back = [0.0; 2];
            p.encode_into(&x, &mut back, &mut s);
            assert!((back[0] - z[0]).hypot(back[1] - z[1]) < 1e-3, "{z:?} → {back:?}");
        }
        for j in 0..postures.ncols() {
            let x = postures.column(j);
            let mut z = [0.0; 2];
            p.encode_into(x.as_slice(), &mut z, &mut s);
            let own = p.decoder.inputs.column(j);
            let density =
                |z: &[f64], s: &mut ProjectionScratch| p.neg_log_density(z, x.as_slice(), None, &mut s.decode);
            assert!(density(&z, &mut s) <= density(own.as_slice(), &mut s));
        }
    }

    /// Tracking mode: a posture decoded at the commanded point encodes back to it exactly (the
    /// search starts at a zero gradient), a slightly disturbed one stays near it, and without
    /// tracking the same call is the nearest-demo projection.
    #[test]
    fn tracking_keeps_the_commanded_point() {
        let (decoder, postures) = toy();
        let tracking = ProjectionConfig {
            tracking: true,
            ..Default::default()
        };
        let p = Projection::new(&decoder, postures.clone(), tracking).unwrap();
        let plain = Projection::new(&decoder, postures, ProjectionConfig::default()).unwrap();
        let (mut s, mut x) = (p.scratch(), vec![0.0; 3]);
        for z in [[0.2, 0.1], [-0.9, -0.4], [1.3, 0.6]] {
            p.decoder.mean_into(&z, &mut x, &mut p.decoder.scratch());
            let mut back = [9.0; 2];
            p.encode_near_into(&x, &z, &mut back, &mut s);
            assert!((back[0] - z[0]).hypot(back[1] - z[1]) < 1e-9, "{z:?} → {back:?}");
            let nudged: Vec<f64> = x.iter().map(|v| v + 1e-3).collect();
            p.encode_near_into(&nudged, &z, &mut back, &mut s);
            assert!((back[0] - z[0]).hypot(back[1] - z[1]) < 0.05, "{z:?} → {back:?}");
            let (mut a, mut b) = ([0.0; 2], [0.0; 2]);
            plain.encode_near_into(&x, &z, &mut a, &mut s);
            plain.encode_into(&x, &mut b, &mut s);
            assert_eq!(a, b);
        }
    }

    #[test]
    fn stays_in_the_box_and_is_deterministic() {
        let (p, _) = projection();
        let far = DMatrix::from_fn(3, 4, |i, j| (i as f64 - 1.0) * 4.0 + j as f64);
        let z = p.encode(&far).unwrap();
        let (low, high) = p.bounds();
        for col in z.column_iter() {
            for k in 0..2 {
                assert!(low[k] <= col[k] && col[k] <= high[k]);
            }
        }
        assert_eq!(p.encode(&far).unwrap(), z);
    }

    #[test]
    fn bad_input_is_an_error() {
        let (decoder, postures) = toy();
        let (p, _) = projection();
        assert!(matches!(
            Projection::new(
                &decoder,
                postures.columns(0, 14).into_owned(),
                ProjectionConfig::default()
            ),
            Err(CoreError::Shape { .. })
        ));
        let zero_iter = ProjectionConfig {
            max_iter: 0,
            ..Default::default()
        };
        assert!(matches!(
            Projection::new(&decoder, postures.clone(), zero_iter),
            Err(CoreError::InvalidParameter { name: "max_iter", .. })
        ));
        assert!(matches!(
            p.check_posture(&[0.0; 2]),
            Err(CoreError::Shape { what: "posture", .. })
        ));
        assert!(matches!(
            p.check_posture(&[0.0, f64::NAN, 0.0]),
            Err(CoreError::NonFinite {
                what: "posture",
                index: 1,
                ..
            })
        ));
        assert!(matches!(p.encode(&DMatrix::zeros(2, 1)), Err(CoreError::Shape { .. })));
        let inf = DMatrix::from_element(3, 1, f64::INFINITY);
        assert!(matches!(p.encode(&inf), Err(CoreError::NonFinite { .. })));
    }
}
