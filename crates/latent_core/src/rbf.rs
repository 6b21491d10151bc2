//! Normalised radial basis features on a regular grid (paper Sec. III-D, the `b(s)` of
//! Eq. 7), evaluated sparsely.
//!
//! `b_i(s) = φ_i(s) / Σ_j φ_j(s)` with `φ_i(s) = exp(−½ Σ_k (s_k − c_ik)² / σ_k²)` and the
//! centres `c_i` on a regular grid of `n` points per dimension spanning a box `[low, high]`
//! (corners included). The width is per dimension, `σ_k = width · h_k` with `h_k` the grid
//! spacing, so on a square box it is the paper's isotropic `‖s − c‖² / (2σ²)` with
//! `σ = width · h` (ours: `width = 1`, σ equal to the spacing).
//!
//! **Sparse evaluation.** Only centres within the cut-off `‖(s − c)/σ‖ ≤ cutoff` (default 3)
//! contribute, and they are found by index arithmetic: per dimension the candidate indices
//! are `⌈t_k − r⌉ ..= ⌊t_k + r⌋` (clamped to the grid) with `t_k = (s_k − low_k)/h_k` and
//! `r = cutoff · width`; the 1-D Gaussian factors are computed once per index and the
//! product is taken over the candidate block: the outer dimensions visit only the indices
//! within the remaining distance budget (`|t_k − i| ≤ width·√(cutoff² − partial)`), and
//! the innermost dimension is one contiguous row of weights, masked branch-free. A 20⁴
//! grid with a 3σ cut-off touches ≈ 360–400 centres instead of 160,000. Normalising over the retained centres only, the sparse features
//! differ from the dense ones by exactly `2m` in L1 norm, `m` being the share of the
//! dense mass `Σ φ` that lies beyond the cut-off (≈ 1 % in 2-D, ≈ 6 % in 4-D for 3σ;
//! ≤ 2e-3 per feature, see the tests).
//!
//! **No centre within the cut-off** (a point more than `cutoff · σ` outside the box in
//! some dimension, or a configured cut-off so large that every retained `φ` underflows to
//! zero): the features fall back to the nearest grid centre (each coordinate clamped to
//! the box and rounded to the nearest index) with `b = 1`. That is the limit of the dense
//! features far outside the box along a coordinate axis direction, and keeps `V(s)`
//! defined (the value of the nearest boundary centre) wherever the policy looks ahead.

use crate::error::{CoreError, Result, check_finite, check_positive};

/// Largest number of centres a grid may have (`n^dim`): 2²⁶ weights are 512 MiB.
pub const MAX_CENTRES: usize = 1 << 26;

/// Configuration of an [`RbfGrid`]; `Default` is the paper's set-up (20 per dimension,
/// σ = spacing) with our 3σ cut-off.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RbfConfig {
    /// Centres per dimension, corners included (paper: 20, i.e. 20² latent, 20⁴ full).
    pub centres_per_dim: usize,
    /// σ as a multiple of the grid spacing in each dimension (ours: 1.0, "σ ≈ spacing").
    pub width: f64,
    /// Cut-off radius in units of σ: centres farther away are left out (ours: 3.0).
    pub cutoff: f64,
}

impl Default for RbfConfig {
    fn default() -> Self {
        Self {
            centres_per_dim: 20,
            width: 1.0,
            cutoff: 3.0,
        }
    }
}

/// The sparse feature vector `b(s)`: the retained centres' flat indices and their values
/// (which sum to 1). Reused between calls, so evaluation allocates nothing once warm.
#[derive(Debug, Clone, Default)]
pub struct SparseFeatures {
    /// Flat centre indices (dimension 0 varies fastest).
    pub indices: Vec<usize>,
    /// `b_i(s)` for each index, normalised to sum to 1.
    pub values: Vec<f64>,
}

impl SparseFeatures {
    /// `wᵀ b(s)` (paper Eq. 7 with these features).
    #[inline]
    pub fn dot(&self, weights: &[f64]) -> f64 {
        self.indices
            .iter()
            .zip(&self.values)
            .map(|(&i, &b)| weights[i] * b)
            .sum()
    }

    /// Number of retained centres.
    pub fn len(&self) -> usize {
        self.indices.len()
    }

    /// True if no centre is stored (only before the first evaluation).
    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }
}

/// Per-call buffers of [`RbfGrid`]: the 1-D candidate ranges and Gaussian factors.
#[derive(Debug, Clone)]
pub struct RbfScratch {
    t: Vec<f64>,
    first: Vec<usize>,
    count: Vec<usize>,
    d2: Vec<f64>,
    phi: Vec<f64>,
}

/// A regular grid of normalised RBF centres over a box (paper Sec. III-D).
#[derive(Debug, Clone)]
pub struct RbfGrid {
    low: Vec<f64>,
    high: Vec<f64>,
    n: usize,
    spacing: Vec<f64>,
    width: f64,
    cutoff: f64,
    /// Candidate indices per dimension and side: `cutoff · width` in index units.
    reach: f64,
    /// Maximum number of candidates per dimension.
    block: usize,
    strides: Vec<usize>,
    len: usize,
}

impl RbfGrid {
    /// A grid over the box `[low, high]` (one entry per dimension, `low < high`).
    pub fn new(low: &[f64], high: &[f64], config: &RbfConfig) -> Result<Self> {
        let dim = low.len();
        if dim == 0 {
            return Err(CoreError::Empty { what: "RBF box" });
        }
        if high.len() != dim {
            return Err(CoreError::Shape {
                what: "RBF box upper corner",
                expected: format!("({dim},)"),
                got: format!("({},)", high.len()),
            });
        }
        check_finite("RBF box lower corner", low)?;
        check_finite("RBF box upper corner", high)?;
        if let Some(k) = (0..dim).find(|&k| high[k] <= low[k]) {
            return Err(CoreError::InvalidParameter {
                name: "RBF box",
                value: high[k] - low[k],
                reason: "every upper corner coordinate must exceed the lower one (width shown)",
            });
        }
        let n = config.centres_per_dim;
        if n < 2 {
            return Err(CoreError::InvalidParameter {
                name: "centres_per_dim",
                value: n as f64,
                reason: "must be at least 2",
            });
        }
        check_positive("rbf width (σ / spacing)", config.width)?;
        check_positive("rbf cutoff (in σ)", config.cutoff)?;
        let len = u32::try_from(dim)
            .ok()
            .and_then(|d| n.checked_pow(d))
            .filter(|&l| l <= MAX_CENTRES)
            .ok_or(CoreError::InvalidParameter {
                name: "centres_per_dim ^ dimension",
                value: (n as f64).powi(dim as i32),
                reason: "the grid would exceed MAX_CENTRES (2^26) centres",
            })?;
        let spacing: Vec<f64> = (0..dim).map(|k| (high[k] - low[k]) / (n - 1) as f64).collect();
        let reach = config.cutoff * config.width;
        let block = (2.0 * reach).floor().min(n as f64) as usize + 1;
        let mut strides = vec![1usize; dim];
        for k in 1..dim {
            strides[k] = strides[k - 1] * n;
        }
        Ok(Self {
            low: low.to_vec(),
            high: high.to_vec(),
            n,
            spacing,
            width: config.width,
            cutoff: config.cutoff,
            reach,
            block,
            strides,
            len,
        })
    }

    /// Dimension of the state space.
    pub fn dim(&self) -> usize {
        self.low.len()
    }

    /// Number of centres `M = n^dim` (the length of the weight vector).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Always false: a grid has at least 2 centres per dimension.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Centres per dimension.
    pub fn centres_per_dim(&self) -> usize {
        self.n
    }

    /// Grid spacing `h_k` per dimension.
    pub fn spacing(&self) -> &[f64] {
        &self.spacing
    }

    /// σ_k = width · h_k per dimension.
    pub fn sigma(&self) -> Vec<f64> {
        self.spacing.iter().map(|h| h * self.width).collect()
    }

    /// Lower corner of the box.
    pub fn low(&self) -> &[f64] {
        &self.low
    }

    /// Upper corner of the box.
    pub fn high(&self) -> &[f64] {
        &self.high
    }

    /// True if `s` lies in the closed box `[low, high]`.
    #[inline]
    pub fn contains(&self, s: &[f64]) -> bool {
        s.iter()
            .zip(&self.low)
            .zip(&self.high)
            .all(|((x, lo), hi)| x >= lo && x <= hi)
    }

    /// Coordinates of centre `index`.
    pub fn centre(&self, index: usize) -> Vec<f64> {
        (0..self.dim())
            .map(|k| self.low[k] + ((index / self.strides[k]) % self.n) as f64 * self.spacing[k])
            .collect()
    }

    /// Fresh buffers for the sparse evaluations.
    pub fn scratch(&self) -> RbfScratch {
        let dim = self.dim();
        RbfScratch {
            t: vec![0.0; dim],
            first: vec![0; dim],
            count: vec![0; dim],
            d2: vec![0.0; dim * self.block],
            phi: vec![0.0; dim * self.block],
        }
    }

    /// Fresh, pre-sized feature storage.
    pub fn features(&self) -> SparseFeatures {
        let cap = self.block.pow(self.dim() as u32).min(self.len);
        SparseFeatures {
            indices: Vec::with_capacity(cap),
            values: Vec::with_capacity(cap),
        }
    }

    /// Sparse `b(s)` into `out` (paper Sec. III-D, normalised RBFs; see the module doc for
    /// the cut-off and the nearest-centre fallback). `s` must have `dim()` finite entries.
    pub fn eval_into(&self, s: &[f64], scratch: &mut RbfScratch, out: &mut SparseFeatures) {
        out.indices.clear();
        out.values.clear();
        let mut sink = FeatureSink { out, total: 0.0 };
        let total = if self.traverse(s, scratch, &mut sink) {
            sink.total
        } else {
            0.0
        };
        if total > 0.0 {
            let inv = 1.0 / total;
            out.values.iter_mut().for_each(|b| *b *= inv);
        } else {
            out.indices.clear();
            out.values.clear();
            out.indices.push(self.nearest(s));
            out.values.push(1.0);
        }
    }

    /// `V(s) = wᵀ b(s)` (paper Eq. 7) without storing the features: the look-ahead's
    /// fast path. `weights` has `len()` entries.
    #[inline]
    pub fn value(&self, weights: &[f64], s: &[f64], scratch: &mut RbfScratch) -> f64 {
        debug_assert_eq!(weights.len(), self.len);
        let mut sink = ValueSink {
            weights,
            acc: 0.0,
            total: 0.0,
        };
        if self.traverse(s, scratch, &mut sink) && sink.total > 0.0 {
            sink.acc / sink.total
        } else {
            weights[self.nearest(s)]
        }
    }

    /// Dense `b(s)` over all `len()` centres, no cut-off: the reference the sparse form is
    /// tested against (slow on large grids).
    pub fn eval_dense(&self, s: &[f64]) -> Vec<f64> {
        let sigma = self.sigma();
        let mut phi: Vec<f64> = (0..self.len)
            .map(|i| {
                let c = self.centre(i);
                let d2: f64 = (0..self.dim()).map(|k| ((s[k] - c[k]) / sigma[k]).powi(2)).sum();
                (-0.5 * d2).exp()
            })
            .collect();
        let total: f64 = phi.iter().sum();
        phi.iter_mut().for_each(|p| *p /= total);
        phi
    }

    /// Hands every centre within the cut-off to `sink`, one contiguous row of dimension 0
    /// at a time (`φ` = row scale × 1-D factor). Returns false if no candidate block exists
    /// (the point is beyond the cut-off of the whole grid in some dimension).
    #[inline]
    fn traverse(&self, s: &[f64], scratch: &mut RbfScratch, sink: &mut impl Sink) -> bool {
        debug_assert_eq!(s.len(), self.dim());
        let dim = self.dim();
        let last = (self.n - 1) as f64;
        let inv_width = 1.0 / self.width;
        for (k, &x) in s.iter().enumerate() {
            let t = (x - self.low[k]) / self.spacing[k];
            let lo = (t - self.reach).ceil().max(0.0);
            let hi = (t + self.reach).floor().min(last);
            if lo > hi {
                return false;
            }
            let (lo, count) = (lo as usize, (hi - lo) as usize + 1);
            scratch.first[k] = lo;
            scratch.count[k] = count;
            scratch.t[k] = t;
            let base = k * self.block;
            for j in 0..count {
                let d = (t - (lo + j) as f64) * inv_width;
                let d2 = d * d;
                scratch.d2[base + j] = d2;
                scratch.phi[base + j] = (-0.5 * d2).exp();
            }
        }
        let limit = self.cutoff * self.cutoff;
        if dim == 1 {
            self.row(0.0, 1.0, 0, limit, scratch, sink);
        } else {
            self.visit(dim - 1, 0.0, 1.0, 0, limit, scratch, sink);
        }
        true
    }

    /// Depth-first product over the candidate block, dimension `k ≥ 1` down to 1; each
    /// level visits only the indices within the remaining budget (see [`Self::range`]), so
    /// nothing is tested and skipped. Dimension 0 is handed over a row at a time.
    #[allow(clippy::too_many_arguments)]
    fn visit(&self, k: usize, d2: f64, phi: f64, index: usize, limit: f64, scratch: &RbfScratch, sink: &mut impl Sink) {
        let base = k * self.block;
        let first = scratch.first[k];
        let (a, b) = self.range(k, d2, limit, scratch);
        for j in a..b {
            let d2k = d2 + scratch.d2[base + j];
            let phik = phi * scratch.phi[base + j];
            let idx = index + (first + j) * self.strides[k];
            if k == 1 {
                self.row(d2k, phik, idx, limit, scratch, sink);
            } else {
                self.visit(k - 1, d2k, phik, idx, limit, scratch, sink);
            }
        }
    }

    /// Local candidate offsets `a..b` of dimension `k` within the remaining budget:
    /// `|t_k − i| ≤ width·√(limit − d2)`.
    #[inline]
    fn range(&self, k: usize, d2: f64, limit: f64, scratch: &RbfScratch) -> (usize, usize) {
        let half = self.width * (limit - d2).max(0.0).sqrt();
        let t = scratch.t[k];
        let first = scratch.first[k] as f64;
        let lo = (t - half).ceil().max(first);
        let hi = (t + half).floor().min(first + (scratch.count[k] - 1) as f64);
        if hi < lo {
            (0, 0)
        } else {
            ((lo - first) as usize, (hi - first) as usize + 1)
        }
    }

    /// The candidates of dimension 0 as one contiguous row; the sink keeps those within
    /// the remaining budget `limit − d2` (branch-free in the value path).
    #[inline]
    fn row(&self, d2: f64, phi: f64, index: usize, limit: f64, scratch: &RbfScratch, sink: &mut impl Sink) {
        let count = scratch.count[0];
        sink.row(
            index + scratch.first[0],
            limit - d2,
            &scratch.d2[..count],
            &scratch.phi[..count],
            phi,
        );
    }

    /// The fallback: flat index of the nearest grid centre.
    #[cold]
    fn nearest(&self, s: &[f64]) -> usize {
        let last = (self.n - 1) as f64;
        (0..self.dim())
            .map(|k| ((s[k] - self.low[k]) / self.spacing[k]).round().clamp(0.0, last) as usize * self.strides[k])
            .sum()
    }

    /// Checks a point before it is evaluated: length `dim()`, finite entries.
    pub fn check_point(&self, what: &'static str, s: &[f64]) -> Result<()> {
        if s.len() != self.dim() {
            return Err(CoreError::Shape {
                what,
                expected: format!("({},)", self.dim()),
                got: format!("({},)", s.len()),
            });
        }
        check_finite(what, s)
    }
}

/// Receives the centres of one traversal, a contiguous row of dimension 0 at a time.
trait Sink {
    /// Candidates `start + j` with squared distance `d2s[j]` (in σ units, dimension 0
    /// only) and factor `factors[j]`: those with `d2s[j] ≤ budget` are within the cut-off,
    /// with `φ = scale · factors[j]`.
    fn row(&mut self, start: usize, budget: f64, d2s: &[f64], factors: &[f64], scale: f64);
}

/// Stores indices and unnormalised `φ`, summing them.
struct FeatureSink<'a> {
    out: &'a mut SparseFeatures,
    total: f64,
}

impl Sink for FeatureSink<'_> {
    #[inline]
    fn row(&mut self, start: usize, budget: f64, d2s: &[f64], factors: &[f64], scale: f64) {
        for (j, (&d2, &g)) in d2s.iter().zip(factors).enumerate() {
            if d2 <= budget {
                let phi = scale * g;
                self.out.indices.push(start + j);
                self.out.values.push(phi);
                self.total += phi;
            }
        }
    }
}

/// Accumulates `Σ w_i φ_i` and `Σ φ_i`.
struct ValueSink<'a> {
    weights: &'a [f64],
    acc: f64,
    total: f64,
}

impl Sink for ValueSink<'_> {
    #[inline]
    fn row(&mut self, start: usize, budget: f64, d2s: &[f64], factors: &[f64], scale: f64) {
        let w = &self.weights[start..start + factors.len()];
        let (mut acc, mut total) = (0.0, 0.0);
        for ((&w, &g), &d2) in w.iter().zip(factors).zip(d2s) {
            let g = if d2 <= budget { g } else { 0.0 };
            acc += w * g;
            total += g;
        }
        self.acc += scale * acc;
        self.total += scale * total;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Compares sparse and dense features at `points` random points of a grid over
    /// `[-0.5, 1.5]^dim`, drawn in the box widened by `margin` spacings on every side.
    /// Returns the largest per-feature difference seen.
    fn compare(dim: usize, n: usize, cutoff: f64, points: usize, margin: f64) -> f64 {
        let config = RbfConfig {
            centres_per_dim: n,
            cutoff,
            ..RbfConfig::default()
        };
        let grid = RbfGrid::new(&vec![-0.5; dim], &vec![1.5; dim], &config).unwrap();
        let pad = margin * grid.spacing()[0];
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let mut scratch = grid.scratch();
        let mut sparse = grid.features();
        let weights: Vec<f64> = (0..grid.len()).map(|_| rng.random::<f64>() * 2.0 - 1.0).collect();
        let mut worst = 0.0f64;
        for _ in 0..points {
            let s: Vec<f64> = (0..dim).map(|_| rng.random_range(-0.5 - pad..1.5 + pad)).collect();
            let dense = grid.eval_dense(&s);
            grid.eval_into(&s, &mut scratch, &mut sparse);
            assert!((sparse.values.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            // Missing mass m: the dense share of the centres left out.
            let mut kept = vec![false; grid.len()];
            sparse.indices.iter().for_each(|&i| kept[i] = true);
            let m: f64 = dense.iter().zip(&kept).filter(|(_, k)| !**k).map(|(b, _)| b).sum();
            let mut full = vec![0.0; grid.len()];
            for (&i, &b) in sparse.indices.iter().zip(&sparse.values) {
                full[i] = b;
            }
            let l1: f64 = full.iter().zip(&dense).map(|(a, b)| (a - b).abs()).sum();
            // Exact identity of the truncated normalisation: ‖b_sparse − b_dense‖₁ = 2m
            // (a kept feature is inflated by exactly b_sparse·m, a dropped one loses b_dense).
            assert!((l1 - 2.0 * m).abs() < 1e-10, "L1 {l1} vs 2m {}", 2.0 * m);
            let max = full.iter().zip(&dense).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            assert!(max <= m + 1e-15);
            worst = worst.max(max);
            // Value: the fast path agrees with the stored features exactly (same sums)...
            let v_fast = grid.value(&weights, &s, &mut scratch);
            assert!((v_fast - sparse.dot(&weights)).abs() < 1e-12);
            // ...and with the dense value up to Σ|Δb|·max|w| ≤ 2m.
            let v_dense: f64 = dense.iter().zip(&weights).map(|(b, w)| b * w).sum();
            assert!((v_fast - v_dense).abs() <= 2.0 * m + 1e-12);
        }
        worst
    }

    // Stated tolerances for the 3σ cut-off. Each kept feature is inflated by b·m, m the
    // dense mass beyond the cut-off (the χ² tail beyond 3²: ≈ 1.1 % in 2-D, 6.1 % in 4-D
    // in the interior, up to ≈ 2.5 % / 7.5 % near and outside the faces, where fewer
    // centres share the normaliser and the features are larger).
    // - Inside the box: max |Δb| < 3e-3 (measured 2.9e-3 in 2-D near a face, 2.0e-3 in
    //   4-D; the peer figures of benches/README.md: ≈ 2e-3).
    // - Up to half a spacing outside (where look-ahead candidates go: steps are 0.2–0.5
    //   spacings): max |Δb| < 1e-2 (the features there reach 0.3–0.4).
    const TOL_INSIDE: f64 = 3e-3;
    const TOL_OUTSIDE: f64 = 1e-2;

    #[test]
    fn sparse_matches_dense_2d() {
        let inside = compare(2, 20, 3.0, 300, 0.0);
        assert!(inside < TOL_INSIDE, "inside: max |Δb| = {inside}");
        let outside = compare(2, 20, 3.0, 300, 0.5);
        assert!(outside < TOL_OUTSIDE, "outside: max |Δb| = {outside}");
        // A wider cut-off converges to the dense features: 5σ leaves ≈ e^(−12.5) of the mass.
        assert!(compare(2, 20, 5.0, 100, 0.5) < 1e-5);
    }

    #[test]
    fn sparse_matches_dense_4d() {
        // 10⁴ centres keep the dense reference fast; the spacing/σ ratio (and so the
        // error) is that of the paper's 20⁴ grid.
        let inside = compare(4, 10, 3.0, 40, 0.0);
        assert!(inside < TOL_INSIDE, "inside: max |Δb| = {inside}");
        let outside = compare(4, 10, 3.0, 40, 0.5);
        assert!(outside < TOL_OUTSIDE, "outside: max |Δb| = {outside}");
    }

    #[test]
    fn touches_a_few_hundred_centres_on_the_20_4_grid() {
        let grid = RbfGrid::new(&[-0.5; 4], &[1.5; 4], &RbfConfig::default()).unwrap();
        assert_eq!(grid.len(), 160_000);
        let mut f = grid.features();
        grid.eval_into(&[0.5, 0.5, 0.6, 0.5], &mut grid.scratch(), &mut f);
        assert!((300..=450).contains(&f.len()), "{} centres", f.len());
        let mut sorted = f.indices.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), f.len(), "each centre once");
    }

    #[test]
    fn far_outside_falls_back_to_the_nearest_centre() {
        let grid = RbfGrid::new(
            &[0.0, 0.0],
            &[1.0, 2.0],
            &RbfConfig {
                centres_per_dim: 5,
                ..Default::default()
            },
        )
        .unwrap();
        let mut f = grid.features();
        grid.eval_into(&[10.0, 1.1], &mut grid.scratch(), &mut f);
        // Nearest centre: x clamped to index 4, y = 1.1 / 0.5 → index 2.
        assert_eq!(f.indices, vec![4 + 2 * 5]);
        assert_eq!(f.values, vec![1.0]);
        assert_eq!(grid.centre(14), vec![1.0, 1.0]);
        let w: Vec<f64> = (0..grid.len()).map(|i| i as f64).collect();
        assert_eq!(grid.value(&w, &[10.0, 1.1], &mut grid.scratch()), 14.0);
    }

    #[test]
    fn bad_configs_are_errors() {
        let c = RbfConfig::default();
        assert!(matches!(RbfGrid::new(&[], &[], &c), Err(CoreError::Empty { .. })));
        assert!(matches!(
            RbfGrid::new(&[0.0], &[0.0], &c),
            Err(CoreError::InvalidParameter { .. })
        ));
        assert!(matches!(
            RbfGrid::new(&[0.0], &[1.0, 2.0], &c),
            Err(CoreError::Shape { .. })
        ));
        assert!(RbfGrid::new(&[0.0], &[f64::NAN], &c).is_err());
        assert!(
            RbfGrid::new(
                &[0.0],
                &[1.0],
                &RbfConfig {
                    centres_per_dim: 1,
                    ..c
                }
            )
            .is_err()
        );
        assert!(RbfGrid::new(&[0.0], &[1.0], &RbfConfig { cutoff: 0.0, ..c }).is_err());
        assert!(RbfGrid::new(&[0.0; 9], &[1.0; 9], &c).is_err(), "20^9 centres");
    }
}
