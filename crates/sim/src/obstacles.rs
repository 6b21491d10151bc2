//! Static obstacles and contact queries (SPEC §3: touching an obstacle ⇒ −1, terminate;
//! §4.3: a fall ends the episode).
//!
//! Every query is an exact shape-distance test (parry) at the **current** body poses,
//! not a read of rapier's narrow phase: the narrow phase is only refreshed inside a
//! physics step, so after a reset it would report the contacts of the previous
//! episode, and refreshing it by hand (`PhysicsWorld::detect_collisions`) swallows the
//! pending body changes of the next step (measured on 0.36.1: a robot queried that way
//! before its first step is never simulated). A link "touches" an obstacle when their
//! shapes are within [`crate::SimOptions::contact_margin`] (solid obstacles stop the
//! robot a hair short of penetration, so a margin of 0 would miss resting contact).
//! Distances are exact for spheres; parry's GJK reads capsule–box gaps ≈ 0.4 mm long
//! (measured), so the effective margin against boxes is ≈ 0.6 mm at the default 1 mm.

use latent_core::CoreError;
use nalgebra::Isometry3;
use rapier3d::math::Rot3;
use rapier3d::parry::query::distance;
use rapier3d::prelude::{ColliderBuilder, ColliderHandle, Pose, Real, SharedShape, Vector};

use crate::error::{Result, SimError, check_finite};
use crate::plant::PhysicsSim;

/// Shape of a static obstacle, in its own frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ObstacleShape {
    /// Box with these half-extents along x, y, z (m).
    Box {
        /// Half-extents (m), all > 0.
        half_extents: [f64; 3],
    },
    /// Sphere (m).
    Sphere {
        /// Radius (m), > 0.
        radius: f64,
    },
    /// Capsule: the segment `a`–`b` swept by a sphere of `radius` (m).
    Capsule {
        /// First end of the segment.
        a: [f64; 3],
        /// Second end of the segment.
        b: [f64; 3],
        /// Radius (m), > 0.
        radius: f64,
    },
}

/// A static obstacle: a shape placed in the world.
#[derive(Debug, Clone, PartialEq)]
pub struct Obstacle {
    /// Name for reports (need not be unique).
    pub name: String,
    /// The shape.
    pub shape: ObstacleShape,
    /// Pose of the shape's frame in the world.
    pub pose: Isometry3<f64>,
    /// `true`: a sensor the robot passes through (still reported by the queries);
    /// `false`: a solid wall the robot collides with.
    pub sensor: bool,
}

/// Index of an obstacle, in the order of [`PhysicsSim::add_obstacle`] calls.
pub type ObstacleId = usize;

/// One link touching one obstacle.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Contact {
    /// URDF name of the link.
    pub link: String,
    /// The obstacle.
    pub obstacle: ObstacleId,
}

/// An obstacle in the world and its collider.
#[derive(Debug, Clone)]
pub(crate) struct ObstacleEntry {
    pub spec: Obstacle,
    pub collider: ColliderHandle,
}

/// An f64 isometry narrowed to a rapier (glam, f32) pose.
pub(crate) fn to_pose(iso: &Isometry3<f64>) -> Pose {
    let t = iso.translation.vector;
    let q = iso.rotation.quaternion();
    let rotation = Rot3::from_xyzw(q.i as Real, q.j as Real, q.k as Real, q.w as Real).normalize();
    Pose::from_parts(Vector::new(t.x as Real, t.y as Real, t.z as Real), rotation)
}

fn vector(v: [f64; 3]) -> Vector {
    Vector::new(v[0] as Real, v[1] as Real, v[2] as Real)
}

impl ObstacleShape {
    fn build(&self) -> Result<SharedShape> {
        let bad = |name, value| {
            SimError::Input(CoreError::InvalidParameter {
                name,
                value,
                reason: "must be finite and > 0",
            })
        };
        let positive = |name, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(v as Real)
            } else {
                Err(bad(name, v))
            }
        };
        Ok(match *self {
            ObstacleShape::Box {
                half_extents: [x, y, z],
            } => SharedShape::cuboid(
                positive("half_extents.x", x)?,
                positive("half_extents.y", y)?,
                positive("half_extents.z", z)?,
            ),
            ObstacleShape::Sphere { radius } => SharedShape::ball(positive("radius", radius)?),
            ObstacleShape::Capsule { a, b, radius } => {
                check_finite("capsule end a", &a)?;
                check_finite("capsule end b", &b)?;
                SharedShape::capsule(vector(a), vector(b), positive("radius", radius)?)
            }
        })
    }
}

impl PhysicsSim {
    /// Adds a static obstacle; returns its id. Contacts are known after the next step.
    pub fn add_obstacle(&mut self, obstacle: Obstacle) -> Result<ObstacleId> {
        let shape = obstacle.shape.build()?;
        let t = obstacle.pose.translation.vector;
        check_finite("obstacle position", &[t.x, t.y, t.z])?;
        let builder = ColliderBuilder::new(shape)
            .position(to_pose(&obstacle.pose))
            .sensor(obstacle.sensor);
        let collider = self.world.colliders.insert(builder);
        self.obstacles.push(ObstacleEntry {
            spec: obstacle,
            collider,
        });
        Ok(self.obstacles.len() - 1)
    }

    /// The obstacles, indexed by [`ObstacleId`].
    pub fn obstacles(&self) -> impl Iterator<Item = &Obstacle> {
        self.obstacles.iter().map(|o| &o.spec)
    }

    fn obstacle_collider(&self, id: ObstacleId) -> Result<ColliderHandle> {
        let count = self.obstacles.len();
        self.obstacles
            .get(id)
            .map(|o| o.collider)
            .ok_or(SimError::UnknownObstacle { id, count })
    }

    /// World pose of a collider from its parent body's current pose (rapier only syncs
    /// collider poses inside a step, so `Collider::position` is stale after a reset).
    fn collider_pose(&self, c: ColliderHandle) -> Option<Pose> {
        let col = self.world.colliders.get(c)?;
        match (col.parent(), col.position_wrt_parent()) {
            (Some(body), Some(local)) => Some(*self.world.bodies.get(body)?.position() * *local),
            _ => Some(*col.position()),
        }
    }

    /// Separation of two colliders at the current poses; 0 when they touch or overlap.
    fn pair_distance(&self, a: ColliderHandle, b: ColliderHandle) -> f64 {
        let (Some(pa), Some(pb)) = (self.collider_pose(a), self.collider_pose(b)) else {
            return f64::INFINITY;
        };
        let (sa, sb) = (self.world.colliders[a].shape(), self.world.colliders[b].shape());
        distance(&pa, sa, &pb, sb).map_or(f64::INFINITY, |d| d.distance.max(0.0) as f64)
    }

    fn link_colliders_of(&self, link: &str) -> Result<impl Iterator<Item = ColliderHandle> + '_> {
        let index = self.model.link_index(link)?;
        Ok(self
            .link_colliders
            .iter()
            .filter(move |(l, _)| *l == index)
            .map(|(_, c)| *c))
    }

    /// Smallest distance between the shapes of link `link` and obstacle `obstacle` at
    /// the current poses (m; 0 when they touch or overlap, +∞ if the link has no shape).
    pub fn obstacle_distance(&self, link: &str, obstacle: ObstacleId) -> Result<f64> {
        let obs = self.obstacle_collider(obstacle)?;
        Ok(self
            .link_colliders_of(link)?
            .map(|c| self.pair_distance(c, obs))
            .fold(f64::INFINITY, f64::min))
    }

    /// Whether link `link` is within `contact_margin` of obstacle `obstacle`.
    pub fn touching(&self, link: &str, obstacle: ObstacleId) -> Result<bool> {
        Ok(self.obstacle_distance(link, obstacle)? <= self.options.contact_margin)
    }

    /// Every (link, obstacle) pair within `contact_margin`, in URDF link order.
    pub fn contacts(&self) -> Vec<Contact> {
        let names = self.model.link_names();
        let mut out: Vec<Contact> = Vec::new();
        for (link, c) in &self.link_colliders {
            for (id, obs) in self.obstacles.iter().enumerate() {
                let contact = Contact {
                    link: names[*link].to_string(),
                    obstacle: id,
                };
                if !out.contains(&contact) && self.pair_distance(*c, obs.collider) <= self.options.contact_margin {
                    out.push(contact);
                }
            }
        }
        out.sort_by_key(|c| (self.model.link_index(&c.link).unwrap_or(usize::MAX), c.obstacle));
        out
    }

    /// Whether any link is within `contact_margin` of any obstacle (the per-step check).
    pub fn any_obstacle_contact(&self) -> bool {
        let margin = self.options.contact_margin;
        self.link_colliders.iter().any(|(_, c)| {
            self.obstacles
                .iter()
                .any(|o| self.pair_distance(*c, o.collider) <= margin)
        })
    }

    /// Whether link `link` is within `contact_margin` of the ground (false without ground).
    pub fn touching_ground(&self, link: &str) -> Result<bool> {
        let Some(ground) = self.ground else {
            return Ok(false);
        };
        Ok(self
            .link_colliders_of(link)?
            .any(|c| self.pair_distance(c, ground) <= self.options.contact_margin))
    }
}

/// Thresholds of the fall test for a free-floating robot (SPEC §4.3: a sole tilting
/// more than 20°, a non-sole body touching the floor, or the base height halving).
#[derive(Debug, Clone, PartialEq)]
pub struct FallCriteria {
    /// The robot has fallen when the root link's origin is lower than this (m).
    pub min_base_height: f64,
    /// … or when a sole's +z axis leans more than this from the world +z (rad).
    pub max_sole_tilt: f64,
    /// Links allowed to touch the ground (the soles); any other link touching it is a fall.
    pub soles: Vec<String>,
}

/// The fall test's verdict and the quantities behind it.
#[derive(Debug, Clone, PartialEq)]
pub struct FallStatus {
    /// Any criterion met.
    pub fell: bool,
    /// Height of the root link's origin (m).
    pub base_height: f64,
    /// Largest sole tilt (rad; 0 without soles).
    pub sole_tilt: f64,
    /// First non-sole link touching the ground, if any.
    pub ground_contact: Option<String>,
}

impl PhysicsSim {
    /// Evaluates `criteria` at the current state; fails on an unknown sole link.
    pub fn fall_status(&self, criteria: &FallCriteria) -> Result<FallStatus> {
        crate::error::check_finite("fall criteria", &[criteria.min_base_height, criteria.max_sole_tilt])?;
        let base_height = self.base_pose().translation.z;
        let mut sole_tilt: f64 = 0.0;
        for sole in &criteria.soles {
            let up = self.link_pose(sole)?.rotation * nalgebra::Vector3::z();
            sole_tilt = sole_tilt.max(up.z.clamp(-1.0, 1.0).acos());
        }
        let mut ground_contact = None;
        for name in self.model.link_names() {
            if !criteria.soles.iter().any(|s| s == name) && self.touching_ground(name)? {
                ground_contact = Some(name.to_string());
                break;
            }
        }
        let fell =
            base_height < criteria.min_base_height || sole_tilt > criteria.max_sole_tilt || ground_contact.is_some();
        Ok(FallStatus {
            fell,
            base_height,
            sole_tilt,
            ground_contact,
        })
    }
}
