//! A fitted GP regression map (paper Eq. 4): the GPLVM decoder (latent → posture) and the
//! out-of-sample encoder (posture → latent) are both a [`GpMap`], and so is the sparse GPLVM's
//! DTC decoder (`GpMap::sparse`, in [`crate::sparse_gplvm`]): its inputs are the inducing inputs.
//!
//! Points are the columns of a matrix: a NumPy `(N, q)` C-ordered array read as
//! column-major `q×N` is exactly that, with no copy.

use nalgebra::{DMatrix, DVector, DVectorViewMut};
use rayon::prelude::*;

use crate::error::{CoreError, Result, check_finite};
use crate::kernel::{SeKernel, factorize};

/// Predictive mean and variance of a GP fitted to (inputs, outputs), everything that can be
/// pre-computed done once: the Cholesky factor `L` of `K` and `α = K⁻¹ (Y − mean)`. The mean at
/// `x` is `k(x, inputs) α + mean`, the variance `k(x, x) − k*ᵀ M k*` with `M = K⁻¹`, or for a
/// sparse (DTC) map `M = K_mm⁻¹ − (K_mm + K_mn K_nm/θ3)⁻¹` over its inducing inputs.
#[derive(Debug, Clone)]
pub struct GpMap {
    pub(crate) kernel: SeKernel,
    /// Training inputs (q×N).
    pub(crate) inputs: DMatrix<f64>,
    /// `αᵀ` (p×N), so the mean is one matrix–vector product.
    pub(crate) alpha_t: DMatrix<f64>,
    /// Cholesky factor of `K` (jitter included; `K_mm`'s for a sparse map).
    pub(crate) lower: DMatrix<f64>,
    /// A sparse map's Cholesky factor of `K_mm + K_mn K_nm/θ3`, whose inverse `M` subtracts.
    pub(crate) projected: Option<DMatrix<f64>>,
    /// Output mean (p).
    pub(crate) mean: DVector<f64>,
    pub(crate) jitter: f64,
}

/// The most points a GP map or the GPLVM objective takes: its dense N×N kernel matrix is then
/// 2 GiB. Larger inputs are refused before any allocation (they would abort the process).
pub const MAX_GP_POINTS: usize = 16_384;

/// [`CoreError::TooLarge`] unless `n` points fit under [`MAX_GP_POINTS`].
pub(crate) fn check_gp_size(what: &'static str, n: usize) -> Result<()> {
    if n > MAX_GP_POINTS {
        return Err(CoreError::TooLarge {
            what,
            size: n,
            limit: MAX_GP_POINTS,
            gib: (n as f64).powi(2) * 8.0 / (1u64 << 30) as f64,
        });
    }
    Ok(())
}

/// The training inputs (q×N) and per-point values (p×N, called `what`) of a map: not empty, at
/// most [`MAX_GP_POINTS`], one value column per input, all finite.
fn check_training(inputs: &DMatrix<f64>, values: &DMatrix<f64>, what: &'static str) -> Result<()> {
    check_gp_size("inputs", inputs.ncols())?;
    check_values(inputs, values, what)
}

/// [`check_training`] without the size limit (a sparse map's training set has none).
pub(crate) fn check_values(inputs: &DMatrix<f64>, values: &DMatrix<f64>, what: &'static str) -> Result<()> {
    let n = inputs.ncols();
    if n == 0 || inputs.nrows() == 0 {
        return Err(CoreError::Empty { what: "inputs" });
    }
    if values.ncols() != n || values.nrows() == 0 {
        return Err(CoreError::Shape {
            what,
            expected: format!("({n}, p) with p >= 1"),
            got: format!("({}, {})", values.ncols(), values.nrows()),
        });
    }
    check_finite("inputs", inputs.as_slice())?;
    check_finite(what, values.as_slice())
}

/// [`CoreError`] unless `points` (dim×M, named `what`) are of dimension `dim` and finite.
pub(crate) fn check_points(what: &'static str, points: &DMatrix<f64>, dim: usize) -> Result<()> {
    if points.nrows() != dim {
        return Err(CoreError::Shape {
            what,
            expected: format!("(M, {dim})"),
            got: format!("({}, {})", points.ncols(), points.nrows()),
        });
    }
    check_finite(what, points.as_slice())
}

/// Reusable buffers for [`GpMap::predict_into`], so a prediction allocates nothing.
#[derive(Debug, Clone)]
pub struct PredictScratch {
    kstar: DVector<f64>,
    solved: DVector<f64>,
    spare: DVector<f64>,
}

/// `‖L⁻¹ v‖²` for a lower-triangular `L`, with `L⁻¹ v` left in `out`, or `L⁻ᵀ L⁻¹ v` if `back`.
fn solve_norm(lower: &DMatrix<f64>, v: &DVector<f64>, out: &mut DVector<f64>, back: bool) -> f64 {
    out.copy_from(v);
    lower.solve_lower_triangular_mut(out);
    let norm = out.norm_squared();
    if back {
        lower.tr_solve_lower_triangular_mut(out);
    }
    norm
}

impl GpMap {
    /// Fits the map: `inputs` is q×N, `outputs` p×N (one point per column). Outputs are
    /// centred here and the mean is added back on prediction.
    pub fn new(inputs: DMatrix<f64>, outputs: DMatrix<f64>, kernel: SeKernel) -> Result<Self> {
        check_training(&inputs, &outputs, "outputs")?;
        let n = inputs.ncols();
        let mean = outputs.column_mean();
        let centred_t = (&outputs - &mean * DMatrix::from_element(1, n, 1.0)).transpose();
        let factor = factorize(kernel.matrix(&inputs))?;
        let alpha_t = factor.cholesky.solve(&centred_t).transpose();
        // Finite inputs of extreme scale (outputs ~1e107 over a noise ~1e-202) overflow here,
        // and every prediction would be NaN: found by fuzzing.
        if !mean.iter().chain(alpha_t.iter()).all(|v| v.is_finite()) {
            return Err(CoreError::Overflow {
                what: "the GP weights K⁻¹(outputs − mean)",
            });
        }
        Ok(Self {
            kernel,
            inputs,
            alpha_t,
            lower: factor.cholesky.l(),
            projected: None,
            mean,
            jitter: factor.jitter,
        })
    }

    /// A kernel regression with given weights: the mean at `x` is `weights · k(inputs, x)`
    /// (`weights` p×N, no output mean), the variance that of a GP on `inputs` with `kernel`.
    /// The back-constrained GPLVM's encoder ([`crate::back_constraint::encoder`]).
    pub fn from_weights(inputs: DMatrix<f64>, weights: DMatrix<f64>, kernel: SeKernel) -> Result<Self> {
        check_training(&inputs, &weights, "weights")?;
        let factor = factorize(kernel.matrix(&inputs))?;
        Ok(Self {
            kernel,
            mean: DVector::zeros(weights.nrows()),
            alpha_t: weights,
            inputs,
            lower: factor.cholesky.l(),
            projected: None,
            jitter: factor.jitter,
        })
    }

    /// `k*ᵀ M k*`, the prior variance the inputs explain at a point whose `k*` is `kstar`; with
    /// `weights`, leaves `M k*` in `solved` (the variance's gradient is `−2 (M k*)ᵀ ∂k*/∂x`).
    /// `solved` and `spare` are buffers of the inputs' length.
    pub(crate) fn explained(
        &self,
        kstar: &DVector<f64>,
        solved: &mut DVector<f64>,
        spare: &mut DVector<f64>,
        weights: bool,
    ) -> f64 {
        let mut explained = solve_norm(&self.lower, kstar, solved, weights);
        if let Some(projected) = &self.projected {
            explained -= solve_norm(projected, kstar, spare, weights);
            if weights {
                *solved -= &*spare;
            }
        }
        explained
    }

    /// Mean (p,) and variance at one point `x` (q,), checked: its length, finite values in and
    /// out.
    pub fn predict_one(&self, x: &[f64]) -> Result<(Vec<f64>, f64)> {
        crate::error::check_vector("x", x, self.input_dim())?;
        let mut mean = vec![0.0; self.output_dim()];
        let variance = self.predict_into(x, &mut mean, &mut self.scratch());
        check_prediction(&mean)?;
        Ok((mean, variance))
    }

    /// Input dimension q.
    pub fn input_dim(&self) -> usize {
        self.inputs.nrows()
    }

    /// Output dimension p.
    pub fn output_dim(&self) -> usize {
        self.alpha_t.nrows()
    }

    /// The training inputs, q×N (one point per column): a GPLVM decoder's are the demos' latent
    /// points (a sparse one's, its inducing inputs).
    pub fn inputs(&self) -> &DMatrix<f64> {
        &self.inputs
    }

    /// Number of training points N.
    pub fn len(&self) -> usize {
        self.inputs.ncols()
    }

    /// Always false: a map is never fitted to no points.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The kernel it was fitted with.
    pub fn kernel(&self) -> SeKernel {
        self.kernel
    }

    /// Jitter that had to be added to `K`'s diagonal to factorise it (0 if none).
    pub fn jitter(&self) -> f64 {
        self.jitter
    }

    /// Fresh buffers for [`Self::predict_into`].
    pub fn scratch(&self) -> PredictScratch {
        PredictScratch {
            kstar: DVector::zeros(self.len()),
            solved: DVector::zeros(self.len()),
            spare: DVector::zeros(self.len()),
        }
    }

    /// Eq. 4 at one point `x` (length q): writes the mean `k*ᵀ K⁻¹ Y + mean` into `mean_out`
    /// (length p) and returns the variance `k(x, x) − k*ᵀ K⁻¹ k*` (white noise included,
    /// the same in every output dimension). Allocation-free; lengths are the caller's
    /// contract (checked in debug builds).
    pub fn predict_into(&self, x: &[f64], mean_out: &mut [f64], scratch: &mut PredictScratch) -> f64 {
        self.mean_into(x, mean_out, scratch);
        let explained = self.explained(&scratch.kstar, &mut scratch.solved, &mut scratch.spare, false);
        (self.kernel.prior_variance() - explained).max(0.0)
    }

    /// The mean half of [`Self::predict_into`]: `O(N (q + p))`, leaves `k*` in `scratch`.
    pub fn mean_into(&self, x: &[f64], mean_out: &mut [f64], scratch: &mut PredictScratch) {
        debug_assert_eq!(x.len(), self.input_dim());
        debug_assert_eq!(mean_out.len(), self.output_dim());
        for (k, point) in scratch.kstar.iter_mut().zip(self.inputs.column_iter()) {
            *k = self.kernel.se(x, point.as_slice());
        }
        let mut out = DVectorViewMut::from_slice(mean_out, self.output_dim());
        out.copy_from(&self.mean);
        out.gemv(1.0, &self.alpha_t, &scratch.kstar, 1.0);
    }

    /// Checks a batch of query points (q×M) before prediction.
    pub fn check_queries(&self, queries: &DMatrix<f64>) -> Result<()> {
        check_points("query points", queries, self.input_dim())
    }

    /// Means (p×M) and variances (M) at the columns of `queries` (q×M), points in parallel.
    pub fn predict(&self, queries: &DMatrix<f64>) -> Result<(DMatrix<f64>, DVector<f64>)> {
        self.check_queries(queries)?;
        let mut means = DMatrix::zeros(self.output_dim(), queries.ncols());
        let mut variances = DVector::zeros(queries.ncols());
        self.for_each_query(queries, &mut means, Some(variances.as_mut_slice()));
        check_prediction(means.as_slice())?;
        Ok((means, variances))
    }

    /// Means only (p×M), several times cheaper than [`Self::predict`]: no `O(N²)` solve.
    pub fn predict_mean(&self, queries: &DMatrix<f64>) -> Result<DMatrix<f64>> {
        self.check_queries(queries)?;
        let mut means = DMatrix::zeros(self.output_dim(), queries.ncols());
        self.for_each_query(queries, &mut means, None);
        check_prediction(means.as_slice())?;
        Ok(means)
    }

    fn for_each_query(&self, queries: &DMatrix<f64>, means: &mut DMatrix<f64>, variances: Option<&mut [f64]>) {
        let p = self.output_dim();
        match variances {
            Some(variances) => means
                .as_mut_slice()
                .par_chunks_mut(p * BLOCK)
                .zip(variances.par_chunks_mut(BLOCK))
                .enumerate()
                .for_each_init(
                    || (self.scratch(), BlockScratch::default()),
                    |(scratch, block), (b, (means_out, vars_out))| {
                        // Full groups of LANES queries solve together; the rest (all of a batch
                        // of one) one at a time, rather than solve a group of mostly empty lanes.
                        let grouped = vars_out.len() - vars_out.len() % LANES;
                        for (j, mean_out) in means_out.chunks_mut(p).enumerate() {
                            let x = queries.column(b * BLOCK + j);
                            if j < grouped {
                                self.mean_into(x.as_slice(), mean_out, scratch);
                                block.set_kstar(j, &scratch.kstar);
                            } else {
                                vars_out[j] = self.predict_into(x.as_slice(), mean_out, scratch);
                            }
                        }
                        self.block_variances(block, &mut vars_out[..grouped]);
                    },
                ),
            None => means.as_mut_slice().par_chunks_mut(p).enumerate().for_each_init(
                || self.scratch(),
                |scratch, (j, mean_out)| self.mean_into(queries.column(j).as_slice(), mean_out, scratch),
            ),
        }
    }

    /// The variances of a block of queries whose `k*` are in `block`: [`Self::predict_into`]'s to
    /// the bit, each solve run over `LANES` queries at once (vectorised, with no chain of
    /// divisions).
    fn block_variances(&self, block: &mut BlockScratch, vars_out: &mut [f64]) {
        let n = self.len();
        for (vars, group) in vars_out.chunks_mut(LANES).zip(block.kstar.chunks_exact_mut(n)) {
            let mut unexplained = [0.0; LANES];
            if let Some(projected) = &self.projected {
                block.spare.copy_from_slice(group);
                solve_norms(projected, &mut block.spare, &mut unexplained);
            }
            let mut explained = [0.0; LANES];
            solve_norms(&self.lower, group, &mut explained);
            // x − 0.0 is x to the bit: an exact map subtracts nothing.
            for ((var, explained), unexplained) in vars.iter_mut().zip(explained).zip(unexplained) {
                *var = (self.kernel.prior_variance() - (explained - unexplained)).max(0.0);
            }
        }
    }
}

/// Queries per block of a batch prediction with variances, a multiple of [`LANES`].
const BLOCK: usize = 64;

/// Queries one solve of [`solve_norms`] runs at once.
const LANES: usize = 16;

/// One value for each of [`LANES`] queries.
type Lanes = [f64; LANES];

/// A block's `k*`s, by groups of [`LANES`] queries (a group's entry i of every query, then entry
/// i + 1), and a buffer of [`GpMap::block_variances`].
#[derive(Debug, Default)]
struct BlockScratch {
    kstar: Vec<Lanes>,
    spare: Vec<Lanes>,
}

impl BlockScratch {
    /// Stores query `j`'s `k*`; query 0 starts a block.
    fn set_kstar(&mut self, j: usize, kstar: &DVector<f64>) {
        let n = kstar.len();
        if j == 0 {
            self.kstar.clear();
            self.kstar.resize(BLOCK / LANES * n, [0.0; LANES]);
            self.spare.resize(n, [0.0; LANES]);
        }
        for (i, k) in kstar.iter().enumerate() {
            self.kstar[j / LANES * n + i][j % LANES] = *k;
        }
    }
}

/// `‖L⁻¹ v‖²` of each of a group's vectors `v`, `L⁻¹ v` left in `group`, with the arithmetic of
/// [`solve_norm`]: nalgebra's forward substitution (each entry's updates added in the same order),
/// then its dot product's eight interleaved sums, so each norm has its bits.
fn solve_norms(lower: &DMatrix<f64>, group: &mut [Lanes], norms: &mut Lanes) {
    let n = lower.nrows();
    let unrolled = n - n % 8;
    let mut sums = [[0.0; LANES]; 8];
    for j in 0..n {
        let mut acc = group[j];
        for (i, solved) in group[..j].iter().enumerate() {
            let l = lower[(j, i)];
            acc.iter_mut().zip(solved).for_each(|(a, s)| *a += -*s * l);
        }
        let diag = lower[(j, j)];
        acc.iter_mut().for_each(|a| *a /= diag);
        if j < unrolled {
            sums[j % 8].iter_mut().zip(&acc).for_each(|(sum, a)| *sum += a * a);
        }
        group[j] = acc;
    }
    for (q, norm) in norms.iter_mut().enumerate() {
        let mut res = 0.0;
        res += sums[0][q] + sums[4][q];
        res += sums[1][q] + sums[5][q];
        res += sums[2][q] + sums[6][q];
        res += sums[3][q] + sums[7][q];
        for entry in &group[unrolled..] {
            res += entry[q] * entry[q];
        }
        *norm = res;
    }
}

/// [`CoreError::Overflow`] if a predicted mean is not finite: finite queries of a map fitted
/// at an extreme scale (θ1 ~1e303 over outputs ~1e230) can overflow `k*ᵀα`; found by fuzzing.
pub fn check_prediction(means: &[f64]) -> Result<()> {
    if means.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(CoreError::Overflow {
            what: "the GP predictive mean",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn toy() -> GpMap {
        let inputs = DMatrix::from_fn(2, 12, |i, j| ((j * 5 + i * 3) % 7) as f64 * 0.4 - 1.0 + 0.01 * j as f64);
        let outputs = DMatrix::from_fn(3, 12, |i, j| (inputs[(0, j)] * (i + 1) as f64).sin() + inputs[(1, j)]);
        GpMap::new(inputs, outputs, SeKernel::new([1.0, 0.5, 1e-4]).unwrap()).unwrap()
    }

    #[test]
    fn dense_formula_agrees() {
        let gp = toy();
        let k = gp.kernel.matrix(&gp.inputs);
        let kinv = k.try_inverse().unwrap();
        let x = [0.3, -0.2];
        let kstar = DVector::from_iterator(
            gp.len(),
            gp.inputs.column_iter().map(|c| gp.kernel.se(&x, c.as_slice())),
        );
        let mut mean = vec![0.0; 3];
        let var = gp.predict_into(&x, &mut mean, &mut gp.scratch());
        let dense_var = gp.kernel.prior_variance() - (kstar.transpose() * &kinv * &kstar)[0];
        assert!((var - dense_var).abs() < 1e-9, "{var} vs {dense_var}");
        let y = gp.alpha_t.clone() * gp.kernel.matrix(&gp.inputs); // recovers centred outputs
        let dense_mean = &y * &kinv * &kstar + &gp.mean;
        for i in 0..3 {
            assert!((mean[i] - dense_mean[i]).abs() < 1e-8);
        }
    }

    #[test]
    fn interpolates_training_points_with_low_variance() {
        let gp = toy();
        let x: Vec<f64> = gp.inputs.column(4).iter().copied().collect();
        let mut mean = vec![0.0; 3];
        let var = gp.predict_into(&x, &mut mean, &mut gp.scratch());
        assert!(var < 2e-4, "variance at a training point {var}");
        let far = gp.predict_into(&[50.0, 50.0], &mut mean, &mut gp.scratch());
        assert!((far - gp.kernel.prior_variance()).abs() < 1e-12);
        assert!((DVector::from_column_slice(&mean) - &gp.mean).norm() < 1e-12);
    }

    #[test]
    fn batch_equals_single() {
        let gp = toy();
        // Three blocks of variances, the last one short.
        let q = DMatrix::from_fn(2, 150, |i, j| (i as f64 - j as f64 * 0.05) * 0.3);
        let (means, vars) = gp.predict(&q).unwrap();
        assert_eq!(gp.predict_mean(&q).unwrap(), means);
        for j in 0..150 {
            let mut m = vec![0.0; 3];
            let v = gp.predict_into(q.column(j).as_slice(), &mut m, &mut gp.scratch());
            assert_eq!(v, vars[j]);
            assert_eq!(m.as_slice(), means.column(j).as_slice());
        }
    }

    #[test]
    fn bad_queries_are_errors() {
        let gp = toy();
        assert!(matches!(
            gp.predict(&DMatrix::zeros(3, 1)),
            Err(CoreError::Shape { .. })
        ));
        let nan = DMatrix::from_element(2, 1, f64::NAN);
        assert!(matches!(gp.predict(&nan), Err(CoreError::NonFinite { .. })));
    }

    /// Fuzzing found outputs ~1e107 with θ ~1e-202 giving NaN predictions.
    #[test]
    fn overflowing_weights_are_an_error_not_nan() {
        let gp = toy();
        let kernel = SeKernel::new([1e-202; 3]).unwrap();
        let fitted = GpMap::new(gp.inputs.clone(), gp.inputs.map(|v| v * 1e107), kernel);
        assert!(matches!(fitted, Err(CoreError::Overflow { .. })));
        assert!(check_prediction(&[1.0, -2.0]).is_ok());
        assert!(matches!(
            check_prediction(&[1.0, f64::NAN]),
            Err(CoreError::Overflow { .. })
        ));
    }
}
