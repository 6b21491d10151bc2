//! Bounded limited-memory BFGS (projected L-BFGS) for small problems: the iterative
//! projection's searches over a latent box ([`crate::projection`]). Deterministic (fixed
//! iteration and line-search caps, no randomness) and allocation-free once its
//! [`LbfgsScratch`] exists.
//!
//! Its stopping rules are SciPy L-BFGS-B's defaults (`maxcor`, `ftol`, `gtol`, `maxls`), so it
//! stops where SciPy does on the same smooth problem; its steps are not L-BFGS-B's (no
//! generalised Cauchy point; a backtracking Armijo search along the projected path instead of
//! the Moré–Thuente search), so the two agree on the minimum found, not on the path to it.

use nalgebra::{DMatrix, DVector};

/// Correction pairs kept (SciPy's `maxcor`).
pub const MEMORY: usize = 10;
/// Stop when the objective's relative decrease falls to this (SciPy's `ftol`: factr 1e7 × ε).
pub const FTOL: f64 = 1e7 * f64::EPSILON;
/// Stop when the projected gradient's largest component falls to this (SciPy's `gtol`).
pub const GTOL: f64 = 1e-5;
/// Backtracking steps per line search before giving up (SciPy's `maxls`).
pub const MAX_LINE_SEARCH: usize = 20;
/// Sufficient decrease constant of the Armijo test (SciPy's `ftol` of its line search).
const ARMIJO: f64 = 1e-3;

/// Buffers of [`minimise`] for problems of one dimension.
#[derive(Debug, Clone)]
pub struct LbfgsScratch {
    s: DMatrix<f64>,
    y: DMatrix<f64>,
    rho: [f64; MEMORY],
    alpha: [f64; MEMORY],
    grad: DVector<f64>,
    dir: DVector<f64>,
    trial: DVector<f64>,
    trial_grad: DVector<f64>,
}

impl LbfgsScratch {
    /// Buffers for problems in `n` variables.
    pub fn new(n: usize) -> Self {
        Self {
            s: DMatrix::zeros(n, MEMORY),
            y: DMatrix::zeros(n, MEMORY),
            rho: [0.0; MEMORY],
            alpha: [0.0; MEMORY],
            grad: DVector::zeros(n),
            dir: DVector::zeros(n),
            trial: DVector::zeros(n),
            trial_grad: DVector::zeros(n),
        }
    }
}

/// Whether coordinate `i` may move: not held at a bound by a gradient pushing outwards.
fn free(x: f64, g: f64, low: f64, high: f64) -> bool {
    !((x <= low && g > 0.0) || (x >= high && g < 0.0))
}

/// Minimises `f` over the box `[low, high]` starting from `x` (projected into the box first),
/// in place, for at most `max_iter` iterations; `f(x, grad)` returns the value at `x` and
/// writes its gradient into `grad`. Returns the value at the final `x`. Stops on a projected
/// gradient below [`GTOL`], a relative decrease below [`FTOL`], a failed line search or a
/// non-finite value (then `x` is the last point with a finite one, or the start).
pub fn minimise(
    mut f: impl FnMut(&[f64], &mut [f64]) -> f64,
    x: &mut [f64],
    low: &[f64],
    high: &[f64],
    max_iter: usize,
    s: &mut LbfgsScratch,
) -> f64 {
    let n = x.len();
    debug_assert_eq!(s.grad.len(), n);
    for i in 0..n {
        x[i] = x[i].clamp(low[i], high[i]);
    }
    let mut fx = f(x, s.grad.as_mut_slice());
    let (mut stored, mut newest) = (0usize, 0usize);
    for _ in 0..max_iter {
        if !fx.is_finite() {
            break;
        }
        let projected = (0..n)
            .map(|i| ((x[i] - s.grad[i]).clamp(low[i], high[i]) - x[i]).abs())
            .fold(0.0, f64::max);
        if projected <= GTOL {
            break;
        }
        direction(x, low, high, stored, newest, s);
        let mut slope = s.dir.dot(&s.grad);
        if slope.is_nan() || slope >= 0.0 {
            // The quasi-Newton direction does not descend: restart from steepest descent.
            stored = 0;
            direction(x, low, high, 0, newest, s);
            slope = s.dir.dot(&s.grad);
            if slope.is_nan() || slope >= 0.0 {
                break;
            }
        }
        let mut step = if stored == 0 {
            (1.0 / s.dir.norm()).min(1.0)
        } else {
            1.0
        };
        let mut accepted = None;
        for _ in 0..MAX_LINE_SEARCH {
            for i in 0..n {
                s.trial[i] = (x[i] + step * s.dir[i]).clamp(low[i], high[i]);
            }
            let ft = f(s.trial.as_slice(), s.trial_grad.as_mut_slice());
            let decrease: f64 = (0..n).map(|i| s.grad[i] * (s.trial[i] - x[i])).sum();
            if ft <= fx + ARMIJO * decrease {
                accepted = Some(ft);
                break;
            }
            step *= 0.5;
        }
        let Some(ft) = accepted else { break };
        let slot = if stored == 0 { newest } else { (newest + 1) % MEMORY };
        for (i, xi) in x.iter().enumerate() {
            s.s[(i, slot)] = s.trial[i] - xi;
            s.y[(i, slot)] = s.trial_grad[i] - s.grad[i];
        }
        let sy = s.s.column(slot).dot(&s.y.column(slot));
        if sy > f64::EPSILON * s.y.column(slot).norm_squared() {
            s.rho[slot] = 1.0 / sy;
            newest = slot;
            stored = (stored + 1).min(MEMORY);
        }
        let relative = (fx - ft) / fx.abs().max(ft.abs()).max(1.0);
        x.copy_from_slice(s.trial.as_slice());
        s.grad.copy_from(&s.trial_grad);
        fx = ft;
        if relative <= FTOL {
            break;
        }
    }
    fx
}

/// `s.dir = −H g` over the free coordinates (zero on the others) by the two-loop recursion
/// over the `stored` newest correction pairs ending at slot `newest`.
fn direction(x: &[f64], low: &[f64], high: &[f64], stored: usize, newest: usize, s: &mut LbfgsScratch) {
    let n = x.len();
    for i in 0..n {
        s.dir[i] = if free(x[i], s.grad[i], low[i], high[i]) {
            s.grad[i]
        } else {
            0.0
        };
    }
    let slot = |k: usize| (newest + MEMORY - k) % MEMORY;
    for k in 0..stored {
        let j = slot(k);
        s.alpha[j] = s.rho[j] * s.s.column(j).dot(&s.dir);
        s.dir.axpy(-s.alpha[j], &s.y.column(j), 1.0);
    }
    if stored > 0 {
        let y = s.y.column(newest);
        s.dir *= s.s.column(newest).dot(&y) / y.norm_squared();
    }
    for k in (0..stored).rev() {
        let j = slot(k);
        let beta = s.rho[j] * s.y.column(j).dot(&s.dir);
        s.dir.axpy(s.alpha[j] - beta, &s.s.column(j), 1.0);
    }
    for i in 0..n {
        s.dir[i] = if free(x[i], s.grad[i], low[i], high[i]) {
            -s.dir[i]
        } else {
            0.0
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rosenbrock's function and its gradient.
    fn rosenbrock(x: &[f64], g: &mut [f64]) -> f64 {
        let (a, b) = (x[0], x[1]);
        g[0] = -2.0 * (1.0 - a) - 400.0 * a * (b - a * a);
        g[1] = 200.0 * (b - a * a);
        (1.0 - a).powi(2) + 100.0 * (b - a * a).powi(2)
    }

    #[test]
    fn finds_the_unconstrained_minimum() {
        let mut x = [-1.2, 1.0];
        let f = minimise(
            rosenbrock,
            &mut x,
            &[-5.0; 2],
            &[5.0; 2],
            500,
            &mut LbfgsScratch::new(2),
        );
        assert!(f < 1e-9, "f = {f}");
        assert!((x[0] - 1.0).abs() < 1e-4 && (x[1] - 1.0).abs() < 1e-4, "{x:?}");
    }

    #[test]
    fn stops_on_the_active_bound() {
        // Minimum of Rosenbrock with b ≤ 0.5 and a ≤ 0.6: a KKT point on a bound.
        let mut x = [0.0, 0.0];
        minimise(
            rosenbrock,
            &mut x,
            &[-2.0; 2],
            &[0.6, 0.5],
            500,
            &mut LbfgsScratch::new(2),
        );
        assert_eq!(x[0], 0.6, "{x:?}");
        assert!((x[1] - 0.36).abs() < 1e-4, "{x:?}");
    }

    #[test]
    fn respects_the_iteration_cap_and_is_deterministic() {
        let run = || {
            let mut x = [-1.2, 1.0];
            let mut calls = 0;
            let f = |x: &[f64], g: &mut [f64]| {
                calls += 1;
                rosenbrock(x, g)
            };
            minimise(f, &mut x, &[-5.0; 2], &[5.0; 2], 3, &mut LbfgsScratch::new(2));
            (x, calls)
        };
        let (x, calls) = run();
        assert!(calls <= 1 + 3 * MAX_LINE_SEARCH, "{calls} evaluations");
        assert_eq!(run().0, x);
    }
}
