//! The arrays of a set of trials by name: what every trial runner returns (to Python, to a
//! results file), laid out here once. Episodes a trial did not run are padded: NaN returns,
//! end code -1, NaN rows.

use crate::episode::EpisodeRecord;
use crate::learner::Learner;
use crate::trials::{TrialOptions, TrialResult};

/// One named result: an array of `shape` (row-major), a scalar count, or nothing.
#[derive(Debug, Clone, PartialEq)]
pub enum ResultArray {
    /// Floats of the shape.
    F64(Vec<f64>, Vec<usize>),
    /// Small integers (end codes, -1 for none) of the shape.
    I8(Vec<i8>, Vec<usize>),
    /// Small unsigned integers (rule codes) of the shape.
    U8(Vec<u8>, Vec<usize>),
    /// Integers of the shape.
    I64(Vec<i64>, Vec<usize>),
    /// Flags of the shape.
    Bool(Vec<bool>, Vec<usize>),
    /// A count.
    Count(usize),
    /// Not kept (the weights unless asked for).
    None,
}

/// The arrays of `results` (trials of `template` run with `options`, paths of `row` values a
/// row), in this order: `returns, ends, steps, reached, passed` (T, E) and the same five of
/// the test episodes prefixed `test_` (T, K); `trajectories` (T, R, max_steps + 1, row) and
/// `test_trajectories`; `test_starts` (T, K, row); `mean_states` (T, E, learner dim);
/// `finished`, `trials` (T,); `weights` (T, M) or none; `learner_low`, `learner_high`,
/// `spacing` (d,); `n_actions`, `n_centres`.
pub fn trial_arrays(
    results: &[TrialResult],
    template: &Learner,
    options: &TrialOptions,
    row: usize,
) -> Vec<(String, ResultArray)> {
    let t = results.len();
    let mut out = Vec::new();
    episode_arrays(&mut out, "", results, options.episodes, |r| &r.episodes);
    episode_arrays(&mut out, "test_", results, options.test_episodes, |r| &r.tests);
    let rows = template.rules().max_steps + 1;
    let mut paths = |name: &str, n: usize, of: fn(&TrialResult) -> &[Vec<f64>]| {
        let mut traj = vec![f64::NAN; t * n * rows * row];
        for (i, r) in results.iter().enumerate() {
            for (j, path) in of(r).iter().enumerate() {
                let start = (i * n + j) * rows * row;
                let len = path.len().min(rows * row);
                traj[start..start + len].copy_from_slice(&path[..len]);
            }
        }
        out.push((name.to_string(), ResultArray::F64(traj, vec![t, n, rows, row])));
    };
    paths("trajectories", options.record_episodes.len(), |r| &r.trajectories);
    paths("test_trajectories", options.record_test_episodes.len(), |r| {
        &r.test_trajectories
    });
    let mut per_episode = |name: &str, n: usize, width: usize, of: fn(&TrialResult) -> &[f64]| {
        let mut values = vec![f64::NAN; t * n * width];
        for (i, r) in results.iter().enumerate() {
            let len = of(r).len().min(n * width);
            values[i * n * width..i * n * width + len].copy_from_slice(&of(r)[..len]);
        }
        out.push((name.to_string(), ResultArray::F64(values, vec![t, n, width])));
    };
    per_episode("test_starts", options.test_episodes, row, |r| &r.test_starts);
    per_episode("mean_states", options.episodes, template.grid().dim(), |r| {
        &r.mean_states
    });
    let finished = results.iter().map(|r| r.finished).collect();
    out.push(("finished".into(), ResultArray::Bool(finished, vec![t])));
    let trials = results.iter().map(|r| r.trial as i64).collect();
    out.push(("trials".into(), ResultArray::I64(trials, vec![t])));
    let m = template.weights().len();
    let weights = if options.keep_weights {
        let w = results
            .iter()
            .flat_map(|r| r.weights.as_deref().unwrap_or(&[]))
            .copied();
        ResultArray::F64(w.collect(), vec![t, m])
    } else {
        ResultArray::None
    };
    out.push(("weights".into(), weights));
    let grid = template.grid();
    let d = grid.dim();
    out.push(("learner_low".into(), ResultArray::F64(grid.low().to_vec(), vec![d])));
    out.push(("learner_high".into(), ResultArray::F64(grid.high().to_vec(), vec![d])));
    out.push(("spacing".into(), ResultArray::F64(grid.spacing().to_vec(), vec![d])));
    out.push(("n_actions".into(), ResultArray::Count(template.n_actions())));
    out.push(("n_centres".into(), ResultArray::Count(m)));
    out
}

/// `{prefix}returns`, `ends`, `steps`, `reached`, `passed` (T, n) of the records `of(trial)`.
fn episode_arrays(
    out: &mut Vec<(String, ResultArray)>,
    prefix: &str,
    results: &[TrialResult],
    n: usize,
    of: fn(&TrialResult) -> &[EpisodeRecord],
) {
    let t = results.len();
    let mut returns = vec![f64::NAN; t * n];
    let mut ends = vec![-1i8; t * n];
    let mut steps = vec![0i64; t * n];
    let mut reached = vec![false; t * n];
    let mut passed = vec![false; t * n];
    for (i, r) in results.iter().enumerate() {
        for (e, rec) in of(r).iter().enumerate() {
            let k = i * n + e;
            returns[k] = rec.ret;
            ends[k] = rec.end.code() as i8;
            steps[k] = rec.steps as i64;
            reached[k] = rec.reached;
            passed[k] = rec.passed;
        }
    }
    let shape = vec![t, n];
    out.push((format!("{prefix}returns"), ResultArray::F64(returns, shape.clone())));
    out.push((format!("{prefix}ends"), ResultArray::I8(ends, shape.clone())));
    out.push((format!("{prefix}steps"), ResultArray::I64(steps, shape.clone())));
    out.push((format!("{prefix}reached"), ResultArray::Bool(reached, shape.clone())));
    out.push((format!("{prefix}passed"), ResultArray::Bool(passed, shape)));
}
