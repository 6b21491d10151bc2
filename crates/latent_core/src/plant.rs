//! The plant interface: what the learner asks of a system it controls (a kinematic toy,
//! simulated arms, a humanoid), and how an episode can end.

use rand::Rng;

/// How an episode ended; the codes are those of `returns.npz` (docs/method.md §Results layout) and
/// the names those of results files and Python (`END_REASONS`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum EndReason {
    /// 0 `timeout`: ran for `max_steps` without a penalty (also "not ended" inside a step).
    TimeOut = 0,
    /// 1 `obstacle`: the effectors (or links) hit an obstacle.
    Obstacle = 1,
    /// 2 `box_exit`: the learner's state left its box, or the plant left its own state box.
    BoxExit = 2,
    /// 3 `drop`: a constraint was broken (the held object dropped).
    Drop = 3,
    /// 4 `fall`: the robot fell.
    Fall = 4,
    /// 5 `variance_gate`: variance gating (docs/method.md §Variance gating) refused a decoded target;
    /// ours.
    VarianceGate = 5,
    /// 6 `success`: the plant's own success rule held (a task's `target.hold_steps`: within
    /// the reach radius that many steps running). The episode ends but the state is not
    /// terminal: its last update bootstraps, as a time-out's does, so V keeps valuing the
    /// target (a terminal success would teach the learner to avoid finishing).
    Success = 6,
}

impl EndReason {
    /// Every reason, in code order.
    pub const ALL: [EndReason; 7] = [
        Self::TimeOut,
        Self::Obstacle,
        Self::BoxExit,
        Self::Drop,
        Self::Fall,
        Self::VarianceGate,
        Self::Success,
    ];

    /// The numeric code (0 time-out, 1 obstacle, 2 box exit, 3 drop, 4 fall, 5 variance gate,
    /// 6 success).
    pub fn code(self) -> u8 {
        self as u8
    }

    /// The reason for a code, if it is one.
    pub fn from_code(code: u8) -> Option<Self> {
        Self::ALL.get(code as usize).copied()
    }

    /// The name in results files and Python.
    pub fn name(self) -> &'static str {
        match self {
            Self::TimeOut => "timeout",
            Self::Obstacle => "obstacle",
            Self::BoxExit => "box_exit",
            Self::Drop => "drop",
            Self::Fall => "fall",
            Self::VarianceGate => "variance_gate",
            Self::Success => "success",
        }
    }

    /// Whether the state it ends in is terminal (its update does not bootstrap): every ending
    /// but a time-out and a success.
    pub fn is_terminal(self) -> bool {
        !matches!(self, Self::TimeOut | Self::Success)
    }
}

/// What one plant step reports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepOutcome {
    /// Reward of the reached state (Eq. 12), the plant's penalty already added if it ended.
    pub reward: f64,
    /// `Some(reason)` if this step ended the episode (a terminal transition unless
    /// [`EndReason::is_terminal`] says otherwise).
    pub end: Option<EndReason>,
}

/// A system to control: a kinematic toy, simulated arms, a humanoid.
pub trait Plant {
    /// Posture dimension D (joint angles, or hand coordinates for the toy).
    fn posture_dim(&self) -> usize;

    /// Dimension of the task-space row recorded in trajectories (e.g. 4 for two planar hands).
    fn task_dim(&self) -> usize;

    /// Draws a start posture from the plant's own start distribution into `posture`.
    fn sample_start<R: Rng + ?Sized>(&mut self, rng: &mut R, posture: &mut [f64]);

    /// Puts the plant at `posture`. Returns `Some(reason)` if that posture is not an
    /// admissible start (e.g. inside an obstacle or with the object dropped).
    fn reset(&mut self, posture: &[f64]) -> Option<EndReason>;

    /// Tracks `target` for one RL time step, writes the reached posture into `reached`
    /// and reports the reward and whether the episode ended.
    fn step(&mut self, target: &[f64], reached: &mut [f64]) -> StepOutcome;

    /// The current task-space row (e.g. both hands) into `out` (`task_dim()` long).
    fn task_position(&self, out: &mut [f64]);

    /// True if the current state counts as "reached the target" (the task's one
    /// definition); plants without one keep the default `false`.
    fn reached_target(&self) -> bool {
        false
    }

    /// True if the episode has, since the last reset, passed the plant's waypoint (e.g.
    /// started below a wall and got above it through a corridor); default `false`.
    fn passed(&self) -> bool {
        false
    }

    /// Checked after an admitted [`Plant::reset`] when the learner is in
    /// [`crate::Phase::Test`]: whether the current state may also start a frozen test episode
    /// (e.g. the hands below the wall they must pass). Default: every admissible start.
    fn admits_test_start(&self) -> bool {
        true
    }

    /// The current task-space row ([`Plant::task_position`]).
    fn task_row(&self) -> Vec<f64> {
        let mut row = vec![0.0; self.task_dim()];
        self.task_position(&mut row);
        row
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A point on a line, drawn uniformly from [0, 1); its row is `(x, 2x)`.
    struct Line(f64);

    impl Plant for Line {
        fn posture_dim(&self) -> usize {
            1
        }
        fn task_dim(&self) -> usize {
            2
        }
        fn sample_start<R: Rng + ?Sized>(&mut self, rng: &mut R, posture: &mut [f64]) {
            posture[0] = (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        }
        fn reset(&mut self, posture: &[f64]) -> Option<EndReason> {
            self.0 = posture[0];
            None
        }
        fn step(&mut self, target: &[f64], reached: &mut [f64]) -> StepOutcome {
            self.0 = target[0];
            reached[0] = target[0];
            StepOutcome { reward: 0.0, end: None }
        }
        fn task_position(&self, out: &mut [f64]) {
            out.copy_from_slice(&[self.0, 2.0 * self.0]);
        }
    }

    #[test]
    fn the_row_is_the_plants() {
        let mut line = Line(0.0);
        line.reset(&[0.25]);
        assert_eq!(line.task_row(), [0.25, 0.5]);
    }

    #[test]
    fn end_codes_and_names_round_trip() {
        for code in 0..7u8 {
            assert_eq!(EndReason::from_code(code).unwrap().code(), code);
        }
        assert!(EndReason::from_code(7).is_none());
        let names: Vec<_> = EndReason::ALL.iter().map(|e| e.name()).collect();
        assert_eq!(
            names,
            [
                "timeout",
                "obstacle",
                "box_exit",
                "drop",
                "fall",
                "variance_gate",
                "success"
            ]
        );
        let terminal: Vec<_> = EndReason::ALL.iter().map(|e| e.is_terminal()).collect();
        assert_eq!(terminal, [false, true, true, true, true, true, false]);
    }
}
