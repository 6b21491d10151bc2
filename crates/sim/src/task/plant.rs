//! [`TaskPlant`]: any [`Task`] as a [`Plant`] for RL in a latent space (docs/method.md §RL loop,
//! steps 4–5).
//!
//! One step: the decoded posture becomes the servo targets (clamped to the joint limits), the
//! world advances one RL step (`physics.substeps × physics.dt`), the joint positions are read
//! back (the **reached** posture) and the effector positions from their link frames. Then, on
//! the reached state, in this order: an obstacle touched (code 1), a fall (code 4), a
//! constraint broken (code 3) end the episode with `reward + penalty` (with
//! `episode.check_rules = "physics_step"`, also when one held after any physics step of it);
//! the reward is `exp(−θ ‖(h − h*)/ℓ‖²)` over the effector positions h. Otherwise, with
//! `target.hold_steps` set, the step that makes that many in a row within the reach radius
//! ends it as a success (code 6, no penalty, not terminal). The same rules
//! refuse a start at [`Plant::reset`], with a posture outside the joint limits (code 2) and, with a fall rule,
//! a centre of mass outside the support (`fall.min_start_margin`) as well.
//!
//! Resets: a fixed-root robot is reset in place (every coordinate set exactly); a floating
//! robot, or one among solid obstacles, gets a fresh world per episode (the world as built,
//! restored from a snapshot) and stands with its first sole flat on the floor — rapier keeps
//! warm-start contact impulses across a teleport, so a reset in place would make an episode
//! depend on the one before.

use std::sync::Arc;

use latent_core::{EndReason, Plant, StepOutcome};
use nalgebra::{Point3, Vector3};
use rand::{Rng, RngExt};

use super::{ConstraintKind, ObstacleTest, RuleCheck, Task, TestStart};
use crate::error::{Result, SimError};
use crate::fall::{FallCriteria, GROUND_CLEARANCE, reset_on_ground, stand_upright, support_margin};
use crate::shapes::{Obstacle, ObstacleShape};
use crate::urdf::RootMode;
use crate::world::{Frame, POSE_WIDTH, POSITION_WIDTH, World, WorldSnapshot};

/// A resolved constraint: the frames it reads and its test.
#[derive(Debug, Clone)]
struct Constraint {
    kind: ConstraintKind,
    frames: Vec<Frame>,
    value: f64,
    offset: [f64; 3],
    tolerance: f64,
    axis: Vector3<f64>,
    direction: Vector3<f64>,
    max_angle: f64,
    coordinate: usize,
    min: f64,
    max: f64,
}

/// The robot of a [`Task`] in its world, as a [`Plant`].
pub struct TaskPlant {
    task: Arc<Task>,
    world: World,
    effector_frames: Vec<Frame>,
    /// The frame h and h* are measured from (`target.relative_to`), if any.
    target_origin: Option<Frame>,
    constraints: Vec<Constraint>,
    /// Effector-tested boxes: lower and upper corners.
    point_boxes: Vec<([f64; 3], [f64; 3])>,
    target: Vec<f64>,
    effectors: Vec<f64>,
    fall: Option<FallCriteria>,
    /// The world as built, restored at every reset when episodes need a fresh world.
    pristine: Option<WorldSnapshot>,
    home: Vec<f64>,
    started_below: bool,
    went_above: bool,
    /// RL steps in a row, up to now, with the effectors within the reach radius.
    held: usize,
}

impl TaskPlant {
    /// The task's robot in a fresh world, standing (or reset) at its home posture: the
    /// demonstration `episode.start_demo` of `demos` (rows of the robot's joints) if given,
    /// else every joint at 0 clamped into its limits. A "demo" start needs `demos`.
    pub fn new(task: Arc<Task>, demos: Option<&[Vec<f64>]>) -> Result<Self> {
        let config = task.config();
        let n = task.model().joints().len();
        let start = &config.episode;
        let home = match demos {
            Some(rows) => {
                if let Some((i, row)) = rows.iter().enumerate().find(|(_, r)| r.len() != n) {
                    return Err(task.error(format!(
                        "demonstration {i} has {} values, the robot {n} actuated joints",
                        row.len()
                    )));
                }
                rows.get(start.start_demo).cloned().ok_or_else(|| {
                    task.error(format!(
                        "episode.start_demo = {} is not a row of the {} demonstrations",
                        start.start_demo,
                        rows.len()
                    ))
                })?
            }
            None if start.start == super::StartRule::Demo => {
                return Err(task.error("episode.start = \"demo\" needs the demonstrations"));
            }
            None => neutral_posture(&task),
        };
        let rebuild = config.root == RootMode::Floating
            || config
                .obstacles
                .iter()
                .any(|o| !o.sensor && o.test == ObstacleTest::Links);
        let world = Self::fresh_world(&task)?;
        let pristine = rebuild.then(|| world.snapshot());
        let effector_frames = config
            .effectors
            .iter()
            .map(|e| world.frame(e, [0.0; 3]))
            .collect::<Result<Vec<_>>>()?;
        let target_origin = config
            .target
            .relative_to
            .as_ref()
            .map(|l| world.frame(l, [0.0; 3]))
            .transpose()?;
        let constraints = config
            .constraints
            .iter()
            .map(|c| {
                let frames = match &c.link {
                    Some(l) => vec![world.frame(l, [0.0; 3])?],
                    None => c
                        .links
                        .iter()
                        .map(|l| world.frame(l, [0.0; 3]))
                        .collect::<Result<Vec<_>>>()?,
                };
                let unit = |v: Option<[f64; 3]>| Vector3::from(v.unwrap_or([0.0, 0.0, 1.0])).normalize();
                Ok(Constraint {
                    kind: c.kind,
                    frames,
                    value: c.value.unwrap_or(0.0),
                    offset: c.offset.unwrap_or([0.0; 3]),
                    tolerance: c.tolerance.unwrap_or(0.0),
                    axis: unit(c.axis),
                    direction: unit(c.direction),
                    max_angle: c.max_angle.unwrap_or(0.0),
                    coordinate: c.coordinate.map_or(2, |a| a.index()),
                    min: c.min.unwrap_or(f64::NEG_INFINITY),
                    max: c.max.unwrap_or(f64::INFINITY),
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let point_boxes = config
            .obstacles
            .iter()
            .filter(|o| o.test == ObstacleTest::Effectors)
            .map(|o| o.corners())
            .collect();
        let mut plant = Self {
            world,
            effector_frames,
            target_origin,
            constraints,
            point_boxes,
            target: config.target.position.iter().flatten().copied().collect(),
            effectors: vec![0.0; 3 * config.effectors.len()],
            fall: task.fall_criteria(),
            task: Arc::clone(&task),
            pristine,
            home,
            started_below: false,
            went_above: false,
            held: 0,
        };
        if let Some(fall) = &plant.fall {
            plant.world.fall_status(fall)?;
        }
        let home = plant.home.clone();
        if let Err(err) = plant.stand(&home) {
            // The home posture's fault only where the robot stands at a neutral one; no episode
            // starts there unless `episode.start = "demo"`, so then the robot stands at that one
            // (and the demos finding of `latentrl check` names the row).
            let neutral = neutral_posture(&task);
            if demos.is_none() || plant.stand(&neutral).is_err() {
                return Err(err);
            }
            if start.start == super::StartRule::Demo {
                return Err(SimError::HomePosture {
                    row: start.start_demo,
                    source: Box::new(err),
                });
            }
            plant.home = neutral;
        }
        Ok(plant)
    }

    /// A fresh world of the task with its link-tested obstacles.
    fn fresh_world(task: &Task) -> Result<World> {
        let mut world = World::new(task.model().clone(), task.world_config())?;
        for o in task.config().obstacles.iter().filter(|o| o.test == ObstacleTest::Links) {
            let (center, half_extents) = o.center_half_extents();
            world.add_obstacle(Obstacle {
                name: o.name.clone(),
                shape: ObstacleShape::Box { half_extents },
                pose: nalgebra::Isometry3::translation(center[0], center[1], center[2]),
                sensor: o.sensor,
            })?;
        }
        Ok(world)
    }

    /// Puts the robot at `posture`: in place (fixed root), or in a fresh world standing on
    /// the floor (floating root, solid obstacles), and sets the fall test's base height.
    fn stand(&mut self, posture: &[f64]) -> Result<()> {
        if let Some(pristine) = &self.pristine {
            self.world.restore(pristine);
        }
        let config = self.task.config();
        match (&mut self.fall, config.floor.as_ref(), config.fall.as_ref()) {
            (Some(fall), Some(floor), Some(rule)) => {
                reset_on_ground(
                    &mut self.world,
                    posture,
                    &fall.soles[0],
                    floor.height,
                    GROUND_CLEARANCE,
                    rule.stance,
                )?;
                let base = self.world.base_pose().translation.z;
                fall.min_base_height = floor.height + rule.base_height_fraction * (base - floor.height);
            }
            (None, Some(floor), None) if config.root == RootMode::Floating => {
                // No sole to stand on: the robot's lowest point rests on the floor (the base at
                // the origin had put a quadruped's feet 30 cm into it).
                stand_upright(&mut self.world, posture, floor.height, GROUND_CLEARANCE, [0.0, 0.0])?;
            }
            _ => self.world.reset(posture)?,
        }
        self.read_effectors();
        Ok(())
    }

    /// The task.
    pub fn task(&self) -> &Task {
        &self.task
    }

    /// The world of the current episode (read-only: poses, contacts, time).
    pub fn world(&self) -> &World {
        &self.world
    }

    /// The effector positions `(x, y, z)` per effector, flat.
    pub fn effectors(&self) -> &[f64] {
        &self.effectors
    }

    /// The home posture: the start demonstration, or every joint at 0 within its limits
    /// (without demonstrations, or where the robot cannot take that one and no episode starts
    /// from it).
    pub fn home(&self) -> &[f64] {
        &self.home
    }

    fn read_effectors(&mut self) {
        for (out, frame) in self.effectors.chunks_exact_mut(3).zip(&self.effector_frames) {
            out.copy_from_slice(&self.world.frame_position(frame));
        }
    }

    /// Where h and h* are measured from now: `target.relative_to`'s origin, or the world's.
    fn target_origin_position(&self) -> [f64; 3] {
        self.target_origin
            .as_ref()
            .map_or([0.0; 3], |f| self.world.frame_position(f))
    }

    /// ‖h − h*‖², h measured from `target.relative_to`'s origin if set.
    fn squared_distance(&self) -> f64 {
        let origin = self.target_origin_position();
        self.effectors
            .chunks_exact(3)
            .zip(self.target.chunks_exact(3))
            .flat_map(|(h, t)| (0..3).map(move |k| h[k] - origin[k] - t[k]))
            .map(|e| e * e)
            .sum()
    }

    /// The target h* in the world now, one row of [`POSITION_WIDTH`] per effector: `target.position`, moved with
    /// `target.relative_to`'s origin if set (what figures and videos draw).
    pub fn target_position(&self) -> Vec<f64> {
        let origin = self.target_origin_position();
        self.target
            .chunks_exact(POSITION_WIDTH)
            .flat_map(|t| (0..POSITION_WIDTH).map(move |k| t[k] + origin[k]))
            .collect()
    }

    /// Each posture of `postures` (D × M, one per column) put at rest: the code of the rule it
    /// breaks (0: none; 1 obstacle, 2 outside the joint limits, 3 drop, 4 fall), the effector
    /// positions and the target's in the world (3E each; they differ by posture if
    /// `target.relative_to` is set).
    pub fn classify(&mut self, postures: &nalgebra::DMatrix<f64>) -> Result<Classified> {
        let d = self.posture_dim();
        if postures.nrows() != d {
            return Err(latent_core::CoreError::Shape {
                what: "postures",
                expected: format!("(M, {d})"),
                got: format!("({}, {})", postures.ncols(), postures.nrows()),
            }
            .into());
        }
        let (m, e) = (postures.ncols(), self.effectors().len());
        let (mut codes, mut effectors, mut targets) = (Vec::with_capacity(m), Vec::new(), Vec::new());
        for q in postures.column_iter() {
            let q: Vec<f64> = q.iter().copied().collect();
            codes.push(self.reset(&q).map_or(0, |e| e.code() as i8));
            effectors.extend_from_slice(self.effectors());
            targets.extend(self.target_position());
        }
        Ok(Classified {
            codes,
            effectors: nalgebra::DMatrix::from_vec(e, m, effectors),
            targets: nalgebra::DMatrix::from_vec(e, m, targets),
        })
    }

    /// [`Plant::step`] towards a caller's `target` (D,), its length checked: the outcome and
    /// the reached posture.
    pub fn step_checked(&mut self, target: &[f64]) -> Result<(StepOutcome, Vec<f64>)> {
        let d = self.posture_dim();
        if target.len() != d {
            return Err(latent_core::CoreError::Shape {
                what: "target",
                expected: format!("({d},)"),
                got: format!("({},)", target.len()),
            }
            .into());
        }
        let mut reached = vec![0.0; d];
        let outcome = self.step(target, &mut reached);
        Ok((outcome, reached))
    }

    /// `R(h) = exp(−θ ‖(h − h*)/ℓ‖²)` (paper Eq. 12 with a length unit ℓ) now.
    pub fn reward(&self) -> f64 {
        let target = &self.task.config().target;
        (-target.theta * self.squared_distance() / (target.width * target.width)).exp()
    }

    /// RMS per-effector distance to the target now.
    pub fn rms_distance(&self) -> f64 {
        (self.squared_distance() / self.effector_frames.len() as f64).sqrt()
    }

    fn broken(&self, c: &Constraint) -> bool {
        let p = |i: usize| Point3::from(self.world.frame_position(&c.frames[i]));
        match c.kind {
            ConstraintKind::Distance => {
                let (a, b) = (p(0), p(1));
                let d = (0..3).map(|k| (b[k] - a[k]).powi(2)).sum::<f64>().sqrt();
                (d - c.value).abs() > c.tolerance
            }
            ConstraintKind::Offset => {
                let (a, b) = (p(0), p(1));
                let e = [0, 1, 2].map(|k| b[k] - a[k] - c.offset[k]);
                e[0].hypot(e[1]).hypot(e[2]) > c.tolerance
            }
            ConstraintKind::Orientation => {
                let axis = self.world.frame_pose(&c.frames[0]).rotation * c.axis;
                axis.dot(&c.direction).clamp(-1.0, 1.0).acos() > c.max_angle
            }
            ConstraintKind::Plane => {
                let v = p(0)[c.coordinate];
                !(c.min..=c.max).contains(&v)
            }
        }
    }

    /// Each constraint's error now, the quantity its tolerance bounds: distance `‖p_b − p_a‖ −
    /// value` (signed, m), offset `‖(p_b − p_a) − offset‖` (m), orientation the angle (rad), plane
    /// the distance outside [min, max] (m; 0 inside).
    pub fn constraint_errors(&self) -> Vec<f64> {
        self.constraints
            .iter()
            .map(|c| {
                let p = |i: usize| Point3::from(self.world.frame_position(&c.frames[i]));
                match c.kind {
                    ConstraintKind::Distance => (p(1) - p(0)).norm() - c.value,
                    ConstraintKind::Offset => {
                        let (a, b) = (p(0), p(1));
                        let e = [0, 1, 2].map(|k| b[k] - a[k] - c.offset[k]);
                        e[0].hypot(e[1]).hypot(e[2])
                    }
                    ConstraintKind::Orientation => {
                        let axis = self.world.frame_pose(&c.frames[0]).rotation * c.axis;
                        axis.dot(&c.direction).clamp(-1.0, 1.0).acos()
                    }
                    ConstraintKind::Plane => {
                        let v = p(0)[c.coordinate];
                        (c.min - v).max(v - c.max).max(0.0)
                    }
                }
            })
            .collect()
    }

    /// The static support margin now (m; the fall rule's soles): how far inside the support
    /// polygon the centre of mass lies, negative outside.
    pub fn support_margin(&self) -> Result<f64> {
        let fall = self
            .fall
            .as_ref()
            .ok_or_else(|| self.task.error("the support margin needs a [fall] table (its soles)"))?;
        support_margin(&self.world, &fall.soles)
    }

    /// The whole robot's centre of mass now (m), from the URDF inertials.
    pub fn center_of_mass(&self) -> Result<[f64; 3]> {
        let c = crate::fall::center_of_mass(&self.world)?;
        Ok([c.x, c.y, c.z])
    }

    /// [`TaskPlant::place`] with the base pose as a recorded row's [`POSE_WIDTH`] values
    /// (position, quaternion x, y, z, w): the link poses there ([`World::link_pose_rows`]).
    pub fn pose_links(&mut self, posture: &[f64], base: &[f64; POSE_WIDTH]) -> Result<Vec<f64>> {
        let b = base;
        let rotation = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(b[6], b[3], b[4], b[5]));
        let pose = nalgebra::Isometry3::from_parts(nalgebra::Translation3::new(b[0], b[1], b[2]), rotation);
        self.place(posture, &pose)?;
        Ok(self.world.link_pose_rows())
    }

    /// Teleports the robot to `posture` with its base at `base` (a floating root; ignored for a
    /// fixed one), e.g. to draw a recorded path; the next episode starts with a reset anyway.
    pub fn place(&mut self, posture: &[f64], base: &nalgebra::Isometry3<f64>) -> Result<()> {
        self.world.place(posture, base)?;
        self.read_effectors();
        Ok(())
    }

    fn in_point_box(&self) -> bool {
        self.effectors.chunks_exact(3).any(|h| {
            self.point_boxes
                .iter()
                .any(|(lo, hi)| (0..3).all(|k| (lo[k]..=hi[k]).contains(&h[k])))
        })
    }

    /// Why the current state ends an episode, if it does: an obstacle touched, a fall, then a
    /// constraint broken (module docs).
    pub fn violation(&self) -> Option<EndReason> {
        if self.in_point_box() || self.world.any_obstacle_contact() {
            return Some(EndReason::Obstacle);
        }
        // The sole links were checked when the plant was built.
        if let Some(fall) = &self.fall
            && self.world.fall_status(fall).is_ok_and(|s| s.fell)
        {
            return Some(EndReason::Fall);
        }
        self.constraints
            .iter()
            .any(|c| self.broken(c))
            .then_some(EndReason::Drop)
    }

    /// Counts the steps in a row within the reach radius; a success once `target.hold_steps`
    /// (if set) are.
    fn success(&mut self) -> Option<EndReason> {
        let hold = self.task.config().target.hold_steps;
        self.held = if self.reached_target() { self.held + 1 } else { 0 };
        (hold > 0 && self.held >= hold).then_some(EndReason::Success)
    }

    fn all_effectors(&self, test: impl Fn(f64) -> bool) -> bool {
        let axis = self.task.config().waypoint.as_ref().map_or(1, |w| w.axis.index());
        self.effectors.chunks_exact(3).all(|h| test(h[axis]))
    }
}

/// Every joint at 0, clamped into its limits: the home posture without demonstrations.
fn neutral_posture(task: &Task) -> Vec<f64> {
    task.model()
        .joints()
        .iter()
        .map(|j| 0.0_f64.clamp(j.lower, j.upper))
        .collect()
}

impl Plant for TaskPlant {
    fn posture_dim(&self) -> usize {
        self.world.num_joints()
    }

    fn task_dim(&self) -> usize {
        self.task.row_len()
    }

    /// The home posture plus uniform noise of ±`episode.start_noise` per joint, clamped to the limits.
    fn sample_start<R: Rng + ?Sized>(&mut self, rng: &mut R, posture: &mut [f64]) {
        let noise = self.task.config().episode.start_noise;
        for ((q, home), info) in posture.iter_mut().zip(&self.home).zip(self.task.model().joints()) {
            let dq = if noise > 0.0 {
                rng.random_range(-noise..=noise)
            } else {
                0.0
            };
            *q = (home + dq).clamp(info.lower, info.upper);
        }
    }

    fn reset(&mut self, posture: &[f64]) -> Option<EndReason> {
        if self.stand(posture).is_err() {
            // Outside the joint limits (or not finite): not a posture of this robot.
            return Some(EndReason::BoxExit);
        }
        if let Some(w) = &self.task.config().waypoint {
            let below = w.below;
            self.started_below = self.all_effectors(|v| v < below);
        }
        self.went_above = false;
        self.held = 0;
        if let Some(end) = self.violation() {
            return Some(end);
        }
        match (&self.fall, self.task.config().fall.as_ref()) {
            (Some(fall), Some(rule)) => {
                let margin = support_margin(&self.world, &fall.soles).unwrap_or(f64::NEG_INFINITY);
                (margin < rule.min_start_margin).then_some(EndReason::Fall)
            }
            _ => None,
        }
    }

    fn step(&mut self, target: &[f64], reached: &mut [f64]) -> StepOutcome {
        let penalty = self.task.config().episode.penalty;
        if self.world.set_targets(target).is_err() {
            // A non-finite target (the learner never sends one): end as a box exit.
            self.world.joint_positions_into(reached);
            return StepOutcome {
                reward: penalty,
                end: Some(EndReason::BoxExit),
            };
        }
        let mut end = None;
        match self.task.config().episode.check_rules {
            RuleCheck::RlStep => self.world.step_rl(),
            RuleCheck::PhysicsStep => {
                // Every physics step but the last; the last is checked below, as in RlStep.
                for _ in 1..self.task.config().physics.substeps {
                    self.world.step(1);
                    if end.is_none() {
                        self.read_effectors();
                        end = self.violation();
                    }
                }
                self.world.step(1);
            }
        }
        self.world.joint_positions_into(reached);
        self.read_effectors();
        if let Some(w) = &self.task.config().waypoint {
            let above = w.above;
            self.went_above |= self.all_effectors(|v| v > above);
        }
        let end = end.or_else(|| self.violation());
        let reward = self.reward() + if end.is_some() { penalty } else { 0.0 };
        let end = end.or_else(|| self.success());
        StepOutcome { reward, end }
    }

    /// Effectors (x, y, z each), the base position and quaternion (x, y, z, w), the joints.
    fn task_position(&self, out: &mut [f64]) {
        let e = self.effectors.len();
        out[..e].copy_from_slice(&self.effectors);
        let base = self.world.base_pose();
        let t = base.translation.vector;
        let q = base.rotation.quaternion();
        out[e..e + 7].copy_from_slice(&[t.x, t.y, t.z, q.i, q.j, q.k, q.w]);
        self.world.joint_positions_into(&mut out[e + 7..]);
    }

    fn reached_target(&self) -> bool {
        self.rms_distance() <= self.task.config().target.reach_radius
    }

    fn passed(&self) -> bool {
        self.started_below && self.went_above
    }

    fn admits_test_start(&self) -> bool {
        self.task.config().episode.test_start == TestStart::Any || self.started_below
    }
}

/// What [`TaskPlant::classify`] finds, posture by posture.
#[derive(Debug, Clone, PartialEq)]
pub struct Classified {
    /// The code of the rule each posture breaks at rest (0: none).
    pub codes: Vec<i8>,
    /// The effector positions, one posture per column (3E × M).
    pub effectors: nalgebra::DMatrix<f64>,
    /// The target in the world, one posture per column (3E × M).
    pub targets: nalgebra::DMatrix<f64>,
}
