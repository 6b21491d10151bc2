//! When a training trial has stopped improving (ours, not the paper's: its trials ran a fixed
//! number of episodes). The episodes are cut into windows of [`StopRule::window`]; a window
//! improves if it reached the target in more episodes than any window before it, or its mean
//! return beats the best window's by more than [`RETURN_GAIN`] of the best's magnitude (at
//! least 1). After [`StopRule::patience`] windows in a row without improvement the trial stops:
//! the episode budget is a ceiling.

use crate::episode::EpisodeRecord;

/// The share of the best window's mean return (or of 1, if larger) a window must add to count
/// as an improvement: noise in the mean return must not keep a trial running.
pub const RETURN_GAIN: f64 = 0.01;

/// A stopping rule: windows of `window` episodes, stop after `patience` of them in a row
/// without improvement (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StopRule {
    /// Episodes per window (≥ 1).
    pub window: usize,
    /// Windows without improvement before the trial stops (≥ 1).
    pub patience: usize,
}

/// A trial's progress under a [`StopRule`], episode by episode.
#[derive(Debug, Clone)]
pub struct Plateau {
    rule: StopRule,
    best_return: f64,
    best_reached: usize,
    sum: f64,
    reached: usize,
    count: usize,
    stale: usize,
}

impl Plateau {
    /// A fresh trial under `rule`.
    pub fn new(rule: StopRule) -> Self {
        Self {
            rule,
            best_return: f64::NEG_INFINITY,
            best_reached: 0,
            sum: 0.0,
            reached: 0,
            count: 0,
            stale: 0,
        }
    }

    /// Adds the episode `record`; true once the trial should stop (at the end of a window).
    pub fn record(&mut self, record: &EpisodeRecord) -> bool {
        self.sum += record.ret;
        self.reached += usize::from(record.reached);
        self.count += 1;
        if self.count < self.rule.window.max(1) {
            return false;
        }
        let mean = self.sum / self.count as f64;
        let gain = RETURN_GAIN * self.best_return.abs().max(1.0);
        let better_return = !self.best_return.is_finite() || mean > self.best_return + gain;
        let better_reach = self.reached > self.best_reached;
        if better_return || better_reach {
            self.stale = 0;
        } else {
            self.stale += 1;
        }
        self.best_return = self.best_return.max(mean);
        self.best_reached = self.best_reached.max(self.reached);
        (self.sum, self.reached, self.count) = (0.0, 0, 0);
        self.stale >= self.rule.patience
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::EndReason;

    fn episode(ret: f64, reached: bool) -> EpisodeRecord {
        EpisodeRecord {
            ret,
            end: EndReason::TimeOut,
            steps: 1,
            reached,
            passed: false,
        }
    }

    /// Episodes after which the rule stops, or None within `n`.
    fn stops_after(rule: StopRule, n: usize, of: impl Fn(usize) -> EpisodeRecord) -> Option<usize> {
        let mut p = Plateau::new(rule);
        (0..n).find(|&e| p.record(&of(e))).map(|e| e + 1)
    }

    #[test]
    fn a_flat_trial_stops_after_patience_windows_past_the_first() {
        let rule = StopRule {
            window: 10,
            patience: 3,
        };
        assert_eq!(stops_after(rule, 1000, |_| episode(5.0, false)), Some(40));
    }

    #[test]
    fn a_rising_return_or_reach_rate_keeps_it_running() {
        let rule = StopRule {
            window: 10,
            patience: 5,
        };
        assert_eq!(stops_after(rule, 1000, |e| episode(e as f64, false)), None);
        // Returns flat; one more episode of each window reaches the target every 5 windows
        // until episode 500, none after: it stops 5 windows after the last rise.
        let reach = |e: usize| episode(1.0, e < 500 && e % 10 < e / 50);
        assert_eq!(stops_after(rule, 1000, reach), Some(510));
    }

    #[test]
    fn noise_within_the_gain_is_no_improvement() {
        let rule = StopRule { window: 4, patience: 2 };
        let wobble = |e: usize| episode(100.0 + 0.5 * ((e / 4) % 2) as f64, false);
        assert_eq!(stops_after(rule, 1000, wobble), Some(12));
    }
}
