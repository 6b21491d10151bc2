//! The settings of a latent RL run (a task file's `[run]` table, docs/tasks.md): how many trials
//! of how many episodes, the seed, and how the latent space is made (the GPLVM fit, the encoder
//! of the loop, the latent box). Each is declared once with its doc, default and rule
//! ([`crate::params!`]); an experiment's preset sets its own values (the paper's), a task file's
//! `[run]` overrides them and a flag or an API argument overrides that.
//!
//! They live here, beside the learner, because they know no plant: they size the run and make
//! the latent space the learner acts in.

use crate::params::{ParamError, Params, Rule, join};
use crate::{choice, params};

choice! {
    /// The posture → latent map of the RL loop (docs/encoders.md).
    pub enum Encoder {
        /// The paper's out-of-sample GP onto the fitted latent points.
        Gp = "gp",
        /// The latent point of highest density under the decoder, iterated from the nearest demo.
        Projection = "projection",
        /// The GPLVM fitted with Z = g(X), encoding its demos exactly.
        BackConstrained = "back_constrained",
        /// The projection searched from the latent point the move commanded: a tracked posture
        /// keeps its point.
        Tracking = "tracking",
    }
}

choice! {
    /// Where the GPLVM's latent points sit (docs/encoders.md §Latent spacing).
    pub enum LatentSpacing {
        /// "even" where a run derives its settings (`latentrl train`, `latentrl check`) and the
        /// fit's own points leave no learner step that lands in the target region within half
        /// an episode; else "fit" (always where a run derives nothing, as the paper's).
        Auto = "auto",
        /// Where the likelihood puts them (the paper's).
        Fit = "fit",
        /// Moved to evenly spaced ranks along each latent axis, θ refitted with them held there.
        Even = "even",
    }
}

params! {
    /// The settings of a latent RL run: trials, episodes, seed, GPLVM fit, encoder, latent box.
    pub struct RunConfig {
        /// Independent RL trials.
        trials: usize = 4 => Rule::count(1, 1_000_000),
        /// Training episodes per trial.
        episodes: usize = 1000 => Rule::count(1, 100_000_000),
        /// Base seed, an integer ≥ 0 (a task file holds up to 2⁶³ − 1): demonstrations, GPLVM
        /// fit and every trial's RNG derive from it.
        seed: u64 = 0 => Rule::Any,
        /// Frozen test episodes per trial after training (no TD updates, the task's test
        /// starts); 0 = none.
        test_episodes: usize = 0 => Rule::count(0, 100_000_000),
        /// Posture → latent map of the RL loop: "gp" (the paper's out-of-sample GP onto the
        /// fitted points), "projection" (the latent point of highest density under the decoder,
        /// iterated from the nearest demo), "back_constrained" (the GPLVM fitted with Z = g(X),
        /// encoding its demos exactly) or "tracking" (the projection searched from the latent
        /// point the move commanded: a tracked posture keeps its point; docs/encoders.md).
        encoder: Encoder = Encoder::Gp => Rule::Any,
        /// Latent box = bounding box of the fitted latent points, widened by this share of its
        /// width per side (ours: 10 %).
        latent_margin: f64 = 0.1 => Rule::NonNegative,
        /// L-BFGS iteration cap of the GPLVM fit.
        gplvm_max_iter: usize = 1000 => Rule::count(1, 1_000_000_000),
        /// The GPLVM's latent points: "fit" (where the likelihood puts them, the paper's), "even"
        /// (moved to evenly spaced ranks along each axis, θ refitted) or "auto" ("even" where a
        /// run derives its settings and the fit's points leave no learner step that lands in the
        /// target region within half an episode; docs/encoders.md §Latent spacing).
        latent_spacing: LatentSpacing = LatentSpacing::Auto => Rule::Any,
    }
    check = run_rules;
}

/// Most episode records one run or one runner call may hold (≈ 0.5 GB of per-episode arrays).
pub const MAX_EPISODES: usize = 10_000_000;

/// `trials × (episodes + test_episodes)` episode records if more than [`MAX_EPISODES`] (what one
/// run holds in memory), else None: the rule of a runner's arguments and of a `[run]` table.
pub fn records_over_limit(trials: usize, episodes: usize, test_episodes: usize) -> Option<u128> {
    let records = trials as u128 * (episodes as u128 + test_episodes as u128);
    (records > MAX_EPISODES as u128).then_some(records)
}

/// At most [`MAX_EPISODES`] episode records in one run (what it holds in memory); evenly spaced
/// points are not a back-constrained fit's (a function of the postures).
fn run_rules(run: &RunConfig, path: &str) -> Result<(), ParamError> {
    if run.latent_spacing == LatentSpacing::Even && run.encoder == Encoder::BackConstrained {
        return Err(ParamError::new(
            &join(path, "latent_spacing"),
            "\"even\" moves the latent points, which the back_constrained encoder's fit makes a function \
             of the postures; give \"fit\" or \"auto\" (which keeps them) with it",
        ));
    }
    if let Some(records) = records_over_limit(run.trials, run.episodes, run.test_episodes) {
        return Err(ParamError::new(
            &join(path, "trials"),
            format!(
                "× (episodes + test_episodes) = {records} episodes, more than the {MAX_EPISODES} one run holds in \
                 memory; run fewer trials or episodes"
            ),
        ));
    }
    Ok(())
}

impl RunConfig {
    /// The bounds `[min, max]` of the count `key` (`trials`, `episodes`, …) by its rule above,
    /// None for a key that is no count: a trial runner's arguments obey the same limits.
    pub fn count_bounds(key: &str) -> Option<(u64, u64)> {
        Self::fields()
            .into_iter()
            .find(|f| f.name == key)
            .and_then(|f| match f.rule {
                Rule::Count { min, max } => Some((min, max)),
                _ => None,
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_pass_and_errors_name_the_key() {
        assert!(RunConfig::default().validate().is_ok());
        let bad = |run: RunConfig| run.check_fields("run").unwrap_err().to_string();
        assert_eq!(
            bad(RunConfig {
                trials: 0,
                ..RunConfig::default()
            }),
            "run.trials must be an integer in [1, 1000000], got 0"
        );
        assert_eq!(
            bad(RunConfig {
                latent_margin: -0.5,
                ..RunConfig::default()
            }),
            "run.latent_margin must be a finite number >= 0, got -0.5"
        );
        assert!(
            bad(RunConfig {
                trials: 1000,
                episodes: 100_000,
                ..RunConfig::default()
            })
            .starts_with("run.trials × (episodes + test_episodes) = 100000000 episodes")
        );
        assert!(
            bad(RunConfig {
                latent_spacing: LatentSpacing::Even,
                encoder: Encoder::BackConstrained,
                ..RunConfig::default()
            })
            .starts_with("run.latent_spacing \"even\" moves the latent points")
        );
        let encoder = RunConfig::fields().into_iter().find(|f| f.name == "encoder").unwrap();
        assert_eq!(encoder.kind, "gp | projection | back_constrained | tracking");
    }
}
