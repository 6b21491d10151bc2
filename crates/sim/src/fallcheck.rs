//! The fall check (docs/method.md §Experiment 3, paper Fig. 7a): drive a free-floating robot
//! standing on the floor through a sequence of joint targets and report, per segment, whether it
//! fell ([`crate::fall`]), its smallest support margin and its grip error (the distance between
//! the two hand frames minus the object's width).

use latent_core::CoreError;
use nalgebra::DMatrix;

use crate::error::{Result, SimError, check_finite};
use crate::fall::{FallCriteria, FallStatus, GROUND_CLEARANCE, reset_on_ground, support_margin};
use crate::task::{ConstraintKind, Task};
use crate::world::World;

/// What the fall check measures and for how long it holds each target.
#[derive(Debug, Clone, PartialEq)]
pub struct FallCheckConfig {
    /// Time each target of the sequence is held (s); rounded up to whole physics steps.
    pub hold: f64,
    /// The sole links (box collision shapes); their corners make the support polygon, the
    /// first stands flat at the start.
    pub soles: Vec<String>,
    /// The two hand frames whose distance is the grip.
    pub hands: [String; 2],
    /// Width of the held object (m): the demonstrated hand distance. Default 0.10.
    pub grip_width: f64,
    /// The fall test. Default: sole tilt 20°, base height half its start value (set by
    /// [`run_fall_check`] from the start posture when `min_base_height` is ≤ 0).
    pub fall: FallCriteria,
    /// Evaluate the fall test, margin and grip every this many physics steps. Default 4.
    pub check_every: usize,
}

impl FallCheckConfig {
    /// The check of a task with a fall rule (its soles and tilt) and a distance constraint
    /// (its two links are the hands, its value the grip width), holding each target `hold` s.
    pub fn for_task(task: &Task, hold: f64) -> Result<Self> {
        let config = task.config();
        let failed = |reason: &str| task.error(reason);
        let rule = config
            .fall
            .as_ref()
            .ok_or_else(|| failed("the fall check needs a [fall] table"))?;
        let grip = config
            .constraints
            .iter()
            .find(|c| c.kind == ConstraintKind::Distance)
            .ok_or_else(|| failed("the fall check needs a distance constraint (the grip)"))?;
        Ok(Self {
            hold,
            soles: rule.soles.clone(),
            hands: [grip.links[0].clone(), grip.links[1].clone()],
            grip_width: grip.value.unwrap_or(0.0),
            fall: FallCriteria {
                min_base_height: 0.0,
                max_sole_tilt: rule.max_tilt,
                soles: rule.soles.clone(),
            },
            check_every: 4,
        })
    }
}

/// What happened while one target of the sequence was held.
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentReport {
    /// The robot met the fall test at some check of this segment (or an earlier one).
    pub fell: bool,
    /// Smallest support margin over the segment's checks (m; negative = outside).
    pub min_margin: f64,
    /// Support margin at the end of the segment (m).
    pub final_margin: f64,
    /// Hand distance minus the grip width at the end of the segment (m).
    pub grip_error: f64,
    /// Largest |hand distance − grip width| over the segment's checks (m).
    pub max_grip_error: f64,
    /// The fall status at the end of the segment.
    pub status: FallStatus,
    /// Time since the check's start (s) of the first check that met the fall test, in this
    /// segment or an earlier one; `None` while the robot stands.
    pub fall_time: Option<f64>,
}

/// The fall check: resets the robot at `start` standing on the ground, then holds each
/// of `targets` for `config.hold` seconds, reporting one [`SegmentReport`] per target.
///
/// Once the robot has fallen every later segment reports `fell` too (it stays down).
/// When `config.fall.min_base_height` is ≤ 0 it is set to half the base height at the
/// start posture. Fails on wrong lengths, non-finite values, postures outside the joint
/// limits (targets are clamped), unknown links or a non-positive hold.
pub fn run_fall_check(
    sim: &mut World,
    start: &[f64],
    targets: &[Vec<f64>],
    config: &FallCheckConfig,
) -> Result<Vec<SegmentReport>> {
    run_fall_check_observed(sim, start, targets, config, |_, _| {})
}

/// The names of [`SegmentReport::row`]'s columns.
pub const REPORT_COLUMNS: [&str; 7] = [
    "fell",
    "min_margin",
    "final_margin",
    "grip_error",
    "max_grip_error",
    "base_height",
    "fall_time",
];

/// Columns of a recorded frame before the joint positions: time (s), fell (0/1), base
/// position (m), base quaternion (x, y, z, w).
pub const FRAME_HEAD: usize = 9;

impl SegmentReport {
    /// The report as numbers, in [`REPORT_COLUMNS`] order: fell (0/1), margins (m), grip
    /// errors (m), base height (m), time of the fall (s; NaN while standing).
    pub fn row(&self) -> [f64; 7] {
        [
            f64::from(u8::from(self.fell)),
            self.min_margin,
            self.final_margin,
            self.grip_error,
            self.max_grip_error,
            self.status.base_height,
            self.fall_time.unwrap_or(f64::NAN),
        ]
    }
}

/// A task's fall check: a report per target and the frames recorded.
#[derive(Debug, Clone, PartialEq)]
pub struct TaskFallCheck {
    /// One report per target.
    pub reports: Vec<SegmentReport>,
    /// One frame per column: [`FRAME_HEAD`] values, then the joint positions.
    pub frames: DMatrix<f64>,
}

impl TaskFallCheck {
    /// The reports as a [`REPORT_COLUMNS`] × M matrix, one [`SegmentReport::row`] per column.
    pub fn table(&self) -> DMatrix<f64> {
        let rows = self.reports.iter().flat_map(SegmentReport::row);
        DMatrix::from_iterator(REPORT_COLUMNS.len(), self.reports.len(), rows)
    }
}

/// The fall check of `task` ([`FallCheckConfig::for_task`]) in its world: stand at `start`
/// (D,), hold each column of `targets` (D × M) for `hold` s. Returns the reports and the
/// frames recorded at `record_times` (s), each at the first check at or after it.
pub fn run_task_fall_check(
    task: &Task,
    start: &[f64],
    targets: &DMatrix<f64>,
    hold: f64,
    record_times: &[f64],
) -> Result<TaskFallCheck> {
    if let Some(bad) = record_times.iter().find(|t| !(t.is_finite() && **t >= 0.0)) {
        return Err(CoreError::Argument(format!("record_times: expected finite times ≥ 0 s, got {bad}")).into());
    }
    if targets.nrows() != start.len() {
        return Err(CoreError::Shape {
            what: "targets",
            expected: format!("(M, {})", start.len()),
            got: format!("({}, {})", targets.ncols(), targets.nrows()),
        }
        .into());
    }
    let rows: Vec<Vec<f64>> = targets.column_iter().map(|c| c.iter().copied().collect()).collect();
    let config = FallCheckConfig::for_task(task, hold)?;
    let world = task.world_config();
    let dt = world.physics.dt;
    let mut pending: Vec<f64> = record_times.iter().map(|t| (t / dt).round()).collect();
    pending.sort_by(|a, b| b.total_cmp(a));
    let mut frames: Vec<f64> = Vec::new();
    let mut sim = World::new(task.model().clone(), world)?;
    let reports = run_fall_check_observed(&mut sim, start, &rows, &config, |sim, fell| {
        let done = (sim.time() / dt).round();
        while pending.last().is_some_and(|&step| done >= step) {
            pending.pop();
            let base = sim.base_pose();
            frames.extend([sim.time(), f64::from(u8::from(fell))]);
            frames.extend(base.translation.vector.iter());
            frames.extend(base.rotation.coords.iter());
            frames.extend(sim.joint_positions());
        }
    })?;
    let width = FRAME_HEAD + start.len();
    let frames = DMatrix::from_vec(width, frames.len() / width, frames);
    Ok(TaskFallCheck { reports, frames })
}

/// [`run_fall_check`] that also calls `observe(sim, fell)` after the reset and after every
/// check (every `config.check_every` physics steps; `sim.time()` is the time since the start),
/// e.g. to record the robot's poses for a picture.
pub fn run_fall_check_observed(
    sim: &mut World,
    start: &[f64],
    targets: &[Vec<f64>],
    config: &FallCheckConfig,
    mut observe: impl FnMut(&World, bool),
) -> Result<Vec<SegmentReport>> {
    check_finite("hold", &[config.hold, config.grip_width])?;
    if config.hold <= 0.0 || config.check_every == 0 {
        return Err(SimError::Input(CoreError::InvalidParameter {
            name: "hold",
            value: config.hold,
            reason: "hold must be > 0 and check_every ≥ 1",
        }));
    }
    let ground = sim.config.floor.unwrap_or(0.0);
    reset_on_ground(sim, start, &config.soles[0], ground, GROUND_CLEARANCE, None)?;
    let mut fall = config.fall.clone();
    if fall.min_base_height <= 0.0 {
        fall.min_base_height = ground + 0.5 * (sim.base_pose().translation.z - ground);
    }
    let hands = [
        sim.frame(&config.hands[0], [0.0; 3])?,
        sim.frame(&config.hands[1], [0.0; 3])?,
    ];
    let grip = |sim: &World| {
        let (a, b) = (sim.frame_position(&hands[0]), sim.frame_position(&hands[1]));
        let d = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
        d - config.grip_width
    };
    let steps = (config.hold / sim.config.physics.dt).ceil() as usize;
    let mut fall_time = None;
    let mut out = Vec::with_capacity(targets.len());
    observe(sim, false);
    for target in targets {
        sim.set_targets(target)?;
        let mut min_margin = f64::INFINITY;
        let mut max_grip = 0.0_f64;
        let mut done = 0;
        while done < steps {
            let n = config.check_every.min(steps - done);
            sim.step(n);
            done += n;
            let margin = support_margin(sim, &config.soles)?;
            min_margin = min_margin.min(margin);
            max_grip = max_grip.max(grip(sim).abs());
            if fall_time.is_none() && sim.fall_status(&fall)?.fell {
                fall_time = Some(sim.time());
            }
            observe(sim, fall_time.is_some());
        }
        let status = sim.fall_status(&fall)?;
        out.push(SegmentReport {
            fell: fall_time.is_some(),
            min_margin,
            final_margin: support_margin(sim, &config.soles)?,
            grip_error: grip(sim),
            max_grip_error: max_grip,
            status,
            fall_time,
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_holds_one_report_per_column_in_report_column_order() {
        let report = |fell: bool, fall_time: Option<f64>| SegmentReport {
            fell,
            min_margin: 0.01,
            final_margin: 0.02,
            grip_error: 0.003,
            max_grip_error: 0.004,
            status: FallStatus {
                fell,
                base_height: 0.3,
                sole_tilt: 0.0,
                ground_contact: None,
            },
            fall_time,
        };
        let check = TaskFallCheck {
            reports: vec![report(false, None), report(true, Some(1.5))],
            frames: DMatrix::zeros(FRAME_HEAD, 0),
        };
        let table = check.table();
        assert_eq!(table.shape(), (REPORT_COLUMNS.len(), 2));
        let fall_time = REPORT_COLUMNS.iter().position(|c| *c == "fall_time").unwrap();
        assert!(table[(fall_time, 0)].is_nan() && table[(fall_time, 1)] == 1.5);
        assert_eq!((table[(0, 0)], table[(0, 1)]), (0.0, 1.0));
        assert_eq!(table[(5, 1)], 0.3);
    }
}
