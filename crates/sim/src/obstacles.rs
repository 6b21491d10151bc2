//! Static obstacles and contact queries (docs/method.md §Reward and endings: touching an obstacle ⇒
//! −1, terminate).
//!
//! Every query is an exact shape-distance test (parry) at the **current** body poses,
//! not a read of rapier's narrow phase: the narrow phase is only refreshed inside a
//! physics step, so after a reset it would report the contacts of the previous
//! episode, and refreshing it by hand (`PhysicsWorld::detect_collisions`) swallows the
//! pending body changes of the next step (measured on 0.36.1: a robot queried that way
//! before its first step is never simulated). A link "touches" an obstacle when their
//! shapes are within [`crate::world::PhysicsConfig::contact_margin`] (solid obstacles stop the
//! robot a hair short of penetration, so a margin of 0 would miss resting contact).
//! Distances are exact for spheres; parry's GJK reads capsule–box gaps ≈ 0.4 mm long
//! (measured), so the effective margin against boxes is ≈ 0.6 mm at the default 1 mm.

use rapier3d::parry::query::distance;
use rapier3d::prelude::{ColliderBuilder, ColliderHandle, Pose};

use crate::error::{Result, SimError, check_finite};
use crate::pose::to_pose;
use crate::shapes::{Contact, Obstacle, ObstacleId};
use crate::world::{ObstacleEntry, World};

impl World {
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
        Ok(self.obstacle_distance(link, obstacle)? <= self.config.physics.contact_margin)
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
                if !out.contains(&contact) && self.pair_distance(*c, obs.collider) <= self.config.physics.contact_margin
                {
                    out.push(contact);
                }
            }
        }
        out.sort_by_key(|c| (self.model.link_index(&c.link).unwrap_or(usize::MAX), c.obstacle));
        out
    }

    /// Whether any link is within `contact_margin` of any obstacle (the per-step check).
    pub fn any_obstacle_contact(&self) -> bool {
        let margin = self.config.physics.contact_margin;
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
            .any(|c| self.pair_distance(c, ground) <= self.config.physics.contact_margin))
    }
}
