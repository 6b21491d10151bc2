//! [`World`]: a URDF robot in a rapier3d world, PD-servoed, stepped in RL steps.
//!
//! One RL step (docs/method.md §RL loop, step 4) is: [`World::set_targets`] (the decoded posture),
//! [`World::step_rl`] (`substeps` physics steps of `dt`), then read the reached posture
//! ([`World::joint_positions`]), effector positions ([`World::frame_position`]) and
//! contacts (`obstacles.rs`).
//!
//! Postures and targets are indexed in URDF joint order (actuated joints only); names
//! map to indices with [`World::joint_index`]. rapier computes in f32; every value
//! crossing this API is f64.

use latent_core::CoreError;
use nalgebra::Isometry3;
use rapier3d::prelude::{ColliderBuilder, ColliderHandle, PhysicsWorld, Real, RigidBodyHandle, SharedShape, Vector};

use crate::error::{Result, SimError, check_finite};
use crate::pd::{PdGains, drive, retarget};
use crate::pose::to_pose;
use crate::shapes::Obstacle;
use crate::urdf::{JointSlot, LoadOptions, RootMode, UrdfModel};

mod config;
mod filter;
mod readout;
mod snapshot;
pub use config::{JointServo, PhysicsConfig, ServoConfig, WorldConfig};
pub use readout::{Frame, POSE_WIDTH, POSITION_WIDTH};
pub use snapshot::WorldSnapshot;

/// An obstacle in the world and its collider.
#[derive(Debug, Clone)]
pub(crate) struct ObstacleEntry {
    pub spec: Obstacle,
    pub collider: ColliderHandle,
}

/// A URDF robot in a rapier world with PD servos on every actuated joint.
pub struct World {
    pub(crate) world: PhysicsWorld,
    pub(crate) model: UrdfModel,
    pub(crate) config: WorldConfig,
    pub(crate) slots: Vec<JointSlot>,
    pub(crate) gains: Vec<PdGains>,
    /// The mimic joints' slots and servo gains, in the order of [`UrdfModel::mimics`].
    pub(crate) mimic_slots: Vec<JointSlot>,
    pub(crate) mimic_gains: Vec<PdGains>,
    pub(crate) targets: Vec<f64>,
    pub(crate) frames: Vec<Option<(RigidBodyHandle, Isometry3<f64>)>>,
    pub(crate) link_colliders: Vec<(usize, ColliderHandle)>,
    pub(crate) root: RigidBodyHandle,
    pub(crate) ground: Option<ColliderHandle>,
    pub(crate) obstacles: Vec<ObstacleEntry>,
    pub(crate) time: f64,
    filter: filter::PairFilter,
}

impl std::fmt::Display for World {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (robot, joints, dt) = (self.model.name(), self.num_joints(), self.rl_dt());
        write!(f, "Sim(robot={robot:?}, joints={joints}, dt={dt})")
    }
}

impl World {
    /// The world of the robot in `source` (URDF XML or a file's path,
    /// [`UrdfModel::from_xml_or_file`]) loaded with `options`: [`World::new`].
    pub fn from_urdf(source: &std::path::Path, options: LoadOptions, config: WorldConfig) -> Result<Self> {
        Self::new(UrdfModel::from_xml_or_file(source, options)?, config)
    }

    /// Builds the world: every joint at zero (clamped into its limits), servos holding
    /// that posture, optional floor. Fails on a configuration value that breaks its rule or a
    /// per-joint servo naming no actuated joint.
    pub fn new(model: UrdfModel, config: WorldConfig) -> Result<Self> {
        config.validate()?;
        if let Some(name) = config.servo.joints.keys().find(|n| !model.is_servoed(n)) {
            return Err(SimError::UnknownJoint {
                name: format!("servo.joints.{name}"),
                known: model.servoed_names().join(", "),
            });
        }
        let physics = &config.physics;
        let mut world = PhysicsWorld::new();
        let [gx, gy, gz] = physics.gravity;
        world.gravity = Vector::new(gx as Real, gy as Real, gz as Real);
        world.integration_parameters.dt = physics.dt as Real;
        world.integration_parameters.num_solver_iterations = physics.solver_iterations;
        world.integration_parameters.num_internal_pgs_iterations = physics.pgs_iterations;
        let robot = model.insert(&mut world, config.root, physics.self_collisions)?;
        let ground = config.floor.map(|z| {
            let plane =
                ColliderBuilder::new(SharedShape::halfspace(Vector::Z)).translation(Vector::new(0.0, 0.0, z as Real));
            world.colliders.insert(plane)
        });
        let mut gains = Vec::with_capacity(model.joints().len());
        for (info, slot) in model.joints().iter().zip(&robot.slots) {
            gains.push(config.servo.gains(&info.name, info.effort));
            if let Some((mb, _)) = world.multibody_joints.get_mut(slot.handle) {
                mb.damping_mut()[slot.dof] = info.damping.unwrap_or(physics.joint_damping) as Real;
                mb.frictions_mut()[slot.dof] = info.friction.unwrap_or(0.0) as Real;
            }
        }
        let mut ignored = Vec::with_capacity(physics.ignore_collisions.len());
        for (i, pair) in physics.ignore_collisions.iter().enumerate() {
            let mut at = [0; 2];
            for (k, name) in pair.iter().enumerate() {
                at[k] = model.link_index(name).map_err(|_| SimError::UnknownLink {
                    name: format!("physics.ignore_collisions[{i}][{k}] = {name:?}"),
                    known: model.link_names().join(", "),
                })?;
            }
            ignored.push((at[0], at[1]));
        }
        let filter = filter::PairFilter::new(&ignored, &robot.colliders, &mut world.colliders);
        let mimic_gains: Vec<PdGains> = model
            .mimics()
            .iter()
            .map(|m| config.servo.gains(&m.joint.name, m.joint.effort))
            .collect();
        let n = model.joints().len();
        let start: Vec<f64> = model.joints().iter().map(|j| 0.0_f64.clamp(j.lower, j.upper)).collect();
        let mut sim = Self {
            world,
            model,
            config,
            slots: robot.slots,
            gains,
            mimic_slots: robot.mimic_slots,
            mimic_gains,
            targets: vec![0.0; n],
            frames: robot.frames,
            link_colliders: robot.colliders,
            root: robot.root,
            ground,
            obstacles: Vec::new(),
            time: 0.0,
            filter,
        };
        sim.reset(&start)?;
        Ok(sim)
    }

    /// Loads a URDF file ([`UrdfModel::from_file`]) and builds the world.
    pub fn from_urdf_file(path: impl AsRef<std::path::Path>, config: WorldConfig) -> Result<Self> {
        Self::new(UrdfModel::from_file(path)?, config)
    }

    /// The robot description.
    pub fn model(&self) -> &UrdfModel {
        &self.model
    }

    /// The configuration the world was built with.
    pub fn config(&self) -> &WorldConfig {
        &self.config
    }

    /// Number of actuated joints (the length of postures and targets).
    pub fn num_joints(&self) -> usize {
        self.slots.len()
    }

    /// Index of the actuated joint `name` in postures and targets.
    pub fn joint_index(&self, name: &str) -> Result<usize> {
        self.model.joint_index(name)
    }

    /// Simulated time since the last reset (s).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Duration of one RL step, `dt · substeps` (s).
    pub fn rl_dt(&self) -> f64 {
        self.config.rl_dt()
    }

    fn check_posture(&self, what: &'static str, values: &[f64]) -> Result<()> {
        if values.len() != self.slots.len() {
            let expected = format!("({},)", self.slots.len());
            return Err(SimError::Input(CoreError::Shape {
                what,
                expected,
                got: format!("({},)", values.len()),
            }));
        }
        check_finite(what, values)
    }

    /// Teleports the robot to `posture` at rest (fixed root) and aims the servos at it.
    ///
    /// Multibody joints start at zero; this sets their coordinates (to exactly `q` as f32,
    /// whatever they were), zeroes every velocity, runs forward kinematics and moves the
    /// bodies (contact queries see the new posture at once).
    /// Fails on a wrong length, a non-finite value or a value outside the joint limits.
    pub fn reset(&mut self, posture: &[f64]) -> Result<()> {
        let base = self.base_pose();
        self.reset_with_base(posture, &base)
    }

    /// [`World::reset`] that also places a floating root at `base` (ignored when fixed).
    pub fn reset_with_base(&mut self, posture: &[f64], base: &Isometry3<f64>) -> Result<()> {
        self.check_posture("posture", posture)?;
        for (info, &q) in self.model.joints().iter().zip(posture) {
            if q < info.lower || q > info.upper {
                return Err(SimError::InvalidJointParameter {
                    joint: info.name.clone(),
                    name: "position",
                    value: q,
                    reason: format!("outside the joint limits [{}, {}]", info.lower, info.upper),
                });
            }
        }
        self.teleport(posture, base);
        Ok(())
    }

    /// Puts the robot at a posture it reached (a recorded path row, to draw it): as
    /// [`World::reset_with_base`], but a joint may lie past its limit, as joints driven into
    /// their stops do (by a few mrad).
    pub fn place(&mut self, posture: &[f64], base: &Isometry3<f64>) -> Result<()> {
        self.check_posture("posture", posture)?;
        self.teleport(posture, base);
        Ok(())
    }

    fn teleport(&mut self, posture: &[f64], base: &Isometry3<f64>) {
        let floating = self.config.root == RootMode::Floating;
        if floating && let Some(rb) = self.world.bodies.get_mut(self.root) {
            rb.set_position(to_pose(base), true);
        }
        let coupled: Vec<f64> = self
            .model
            .mimics()
            .iter()
            .map(|m| m.follow(posture[m.leader]))
            .collect();
        let all_slots = self.slots.iter().chain(&self.mimic_slots);
        for (slot, &q) in all_slots.clone().zip(posture.iter().chain(&coupled)) {
            if let Some((mb, _)) = self.world.multibody_joints.get_mut(slot.handle)
                && let Some(link) = mb.link_mut(slot.link_id)
            {
                // Back to exactly 0 (x + (−x) = 0 in IEEE), then to exactly q: the coordinate is
                // `q as f32` whatever the posture before, so a reset does not depend on history.
                let current = link.joint.coords()[slot.axis as usize];
                link.joint.apply_displacement(&[-current]);
                link.joint.apply_displacement(&[q as Real]);
            }
        }
        for slot in &self.slots {
            if let Some((mb, _)) = self.world.multibody_joints.get_mut(slot.handle) {
                mb.generalized_velocity_mut().fill(0.0);
                mb.forward_kinematics(&self.world.bodies, floating);
                mb.update_rigid_bodies(&mut self.world.bodies, true);
            }
        }
        for (_, rb) in self.world.bodies.iter_mut() {
            rb.set_linvel(Vector::ZERO, true);
            rb.set_angvel(Vector::ZERO, true);
        }
        let all_gains = self.gains.iter().chain(&self.mimic_gains);
        for ((slot, &q), gains) in all_slots.zip(posture.iter().chain(&coupled)).zip(all_gains) {
            if let Some((mb, _)) = self.world.multibody_joints.get_mut(slot.handle)
                && let Some(link) = mb.link_mut(slot.link_id)
            {
                drive(&mut link.joint.data, slot.axis, q, gains);
            }
        }
        self.targets.copy_from_slice(posture);
        self.time = 0.0;
    }

    /// Sets every servo target (URDF joint order), clamped to the joint limits.
    pub fn set_targets(&mut self, targets: &[f64]) -> Result<()> {
        self.check_posture("targets", targets)?;
        for (i, &t) in targets.iter().enumerate() {
            self.write_target(i, t);
        }
        Ok(())
    }

    /// Sets the servo target of one joint by name, clamped to its limits.
    pub fn set_target(&mut self, joint: &str, target: f64) -> Result<()> {
        let i = self.model.joint_index(joint)?;
        check_finite("target", &[target])?;
        self.write_target(i, target);
        Ok(())
    }

    fn write_target(&mut self, i: usize, target: f64) {
        let info = &self.model.joints()[i];
        let t = target.clamp(info.lower, info.upper);
        self.targets[i] = t;
        let slot = self.slots[i];
        if let Some((mb, _)) = self.world.multibody_joints.get_mut(slot.handle)
            && let Some(link) = mb.link_mut(slot.link_id)
        {
            retarget(&mut link.joint.data, slot.axis, t);
        }
    }

    /// The current servo targets (after clamping).
    pub fn targets(&self) -> &[f64] {
        &self.targets
    }

    /// The gains of joint `i`.
    pub fn gains(&self, i: usize) -> Option<&PdGains> {
        self.gains.get(i)
    }

    /// Replaces the servo gains (and torque cap) of joint `joint` (by name).
    pub fn set_gains(&mut self, joint: &str, gains: PdGains) -> Result<()> {
        let i = self.model.joint_index(joint)?;
        gains.validate(joint)?;
        self.gains[i] = gains;
        let slot = self.slots[i];
        if let Some((mb, _)) = self.world.multibody_joints.get_mut(slot.handle)
            && let Some(link) = mb.link_mut(slot.link_id)
        {
            drive(&mut link.joint.data, slot.axis, self.targets[i], &gains);
        }
        Ok(())
    }

    /// Advances the world by `n` physics steps of `dt`; before each, the mimic joints' servos
    /// are aimed at their leaders' positions.
    pub fn step(&mut self, n: usize) {
        for _ in 0..n {
            self.couple_mimics();
            if self.filter.is_empty() {
                self.world.step();
            } else {
                self.world.step_with_events(&self.filter, &());
            }
        }
        self.time += n as f64 * self.config.physics.dt;
    }

    /// Aims each mimic joint's servo at `multiplier · q_leader + offset` of its leader now.
    fn couple_mimics(&mut self) {
        for (m, slot) in self.model.mimics().iter().zip(&self.mimic_slots) {
            let q = self.coordinate(&self.slots[m.leader]);
            if let Some((mb, _)) = self.world.multibody_joints.get_mut(slot.handle)
                && let Some(link) = mb.link_mut(slot.link_id)
            {
                retarget(&mut link.joint.data, slot.axis, m.follow(q));
            }
        }
    }

    /// Advances the world by one RL step (`substeps` physics steps).
    pub fn step_rl(&mut self) {
        self.step(self.config.physics.substeps);
    }

    /// Advances the world by `n` physics steps, or by one RL step ([`World::step_rl`]) if none.
    pub fn advance(&mut self, n: Option<usize>) {
        self.step(n.unwrap_or(self.config.physics.substeps));
    }
}
