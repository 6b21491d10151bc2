//! Standing and falling (docs/method.md §Experiment 3): the fall test of a free-floating robot, its
//! centre of mass and static support margin, and a reset that stands it on a floor.
//!
//! - **Fall** ([`FallCriteria`]): a sole tilting more than its limit (20° for the humanoid),
//!   a non-sole link touching the floor, or the base below a height (half its standing one).
//! - **Centre of mass** ([`center_of_mass`]): the mass-weighted mean of the URDF
//!   `<inertial>` origins at the current link poses (not rapier's body masses, which
//!   read differently before the first step, docs/pitfalls.md §rapier3d).
//! - **Support margin** ([`support_margin`]): signed distance (m) from the centre of mass
//!   projected on the floor to the edge of the support polygon, positive inside. The polygon
//!   is the 2-D convex hull of the sole points ([`sole_points`]: the corners of the soles' box
//!   shapes, the lowest point of their other shapes) within [`SOLE_CONTACT_TOLERANCE`] of the
//!   lowest (a tipping foot keeps only its touching edge).
//! - **Soles without a box** (a quadruped's sphere feet): no sole plane to tilt or to stand
//!   flat, so their tilt is not tested and a reset stands the robot upright on its lowest point.

use latent_core::CoreError;
use nalgebra::{Isometry3, Point2, Point3, Translation3, UnitQuaternion, Vector3};
use rapier3d_urdf::urdf_rs;

use crate::error::{Result, SimError, check_finite};
use crate::urdf::UrdfModel;
use crate::world::World;

/// Sole corners up to this far (m) above the lowest sole corner count as touching.
pub const SOLE_CONTACT_TOLERANCE: f64 = 2e-3;

/// Height (m) above the floor of the lowest sole corner when a robot is put on the ground.
pub const GROUND_CLEARANCE: f64 = 5e-4;

/// The largest sole tilt (rad) before a robot counts as fallen, unless a task says otherwise:
/// 20° (docs/method.md §Experiment 3).
pub const MAX_SOLE_TILT: f64 = 20f64.to_radians();

/// Thresholds of the fall test for a free-floating robot (docs/method.md §Experiment 3: a sole
/// tilting more than 20°, a non-sole body touching the floor, or the base height halving).
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

impl World {
    /// Evaluates `criteria` at the current state; fails on an unknown sole link.
    pub fn fall_status(&self, criteria: &FallCriteria) -> Result<FallStatus> {
        check_finite("fall criteria", &[criteria.min_base_height, criteria.max_sole_tilt])?;
        let base_height = self.base_pose().translation.z;
        let mut sole_tilt: f64 = 0.0;
        for sole in &criteria.soles {
            let pose = self.link_pose(sole)?; // an unknown sole is an error, whatever its shapes
            if !has_box(&self.model, sole) {
                continue;
            }
            let up = pose.rotation * nalgebra::Vector3::z();
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

/// Centre of mass of the whole robot in world coordinates (m), from the URDF inertials.
pub fn center_of_mass(sim: &World) -> Result<Point3<f64>> {
    let mut total = 0.0;
    let mut sum = Vector3::zeros();
    for link in &sim.model.robot.links {
        let m = link.inertial.mass.value;
        if m <= 0.0 {
            continue;
        }
        let [x, y, z] = link.inertial.origin.xyz.0;
        let p = sim.link_pose(&link.name)? * Point3::new(x, y, z);
        sum += m * p.coords;
        total += m;
    }
    if total <= 0.0 {
        return Err(SimError::Input(CoreError::InvalidParameter {
            name: "mass",
            value: total,
            reason: "the robot has no mass",
        }));
    }
    Ok(Point3::from(sum / total))
}

/// Whether link `link` has a box collision shape: a sole plane to stand flat and to tilt.
pub fn has_box(model: &UrdfModel, link: &str) -> bool {
    model.robot.links.iter().filter(|l| l.name == link).any(|l| {
        l.collision
            .iter()
            .any(|c| matches!(c.geometry, urdf_rs::Geometry::Box { .. }))
    })
}

/// World points where sole `sole` may touch the floor: the corners of its box collision shapes
/// and the lowest point of each other shape (a sphere foot's bottom, a mesh hull's lowest
/// vertex).
pub fn sole_points(sim: &World, sole: &str) -> Result<Vec<Point3<f64>>> {
    let mut points = box_corners(sim, &sim.model, sole)?;
    points.extend(sim.lowest_points_of(sole, |shape| shape.as_cuboid().is_none())?);
    Ok(points)
}

/// World corners of every box collision shape of link `link`.
fn box_corners(sim: &World, model: &UrdfModel, link: &str) -> Result<Vec<Point3<f64>>> {
    let pose = sim.link_pose(link)?;
    let urdf = model
        .robot
        .links
        .iter()
        .find(|l| l.name == link)
        .ok_or_else(|| SimError::UnknownLink {
            name: link.to_string(),
            known: "URDF links".to_string(),
        })?;
    let mut out = Vec::new();
    for c in &urdf.collision {
        if let urdf_rs::Geometry::Box { size } = &c.geometry {
            let [sx, sy, sz] = size.0;
            let [x, y, z] = c.origin.xyz.0;
            let [r, p, w] = c.origin.rpy.0;
            let local = Isometry3::from_parts(Translation3::new(x, y, z), UnitQuaternion::from_euler_angles(r, p, w));
            for i in 0..8 {
                let sign = |bit: usize| if i & bit == 0 { -0.5 } else { 0.5 };
                let corner = Point3::new(sign(1) * sx, sign(2) * sy, sign(4) * sz);
                out.push(pose * local * corner);
            }
        }
    }
    Ok(out)
}

/// 2-D convex hull (Andrew's monotone chain), counter-clockwise, no repeated point.
fn convex_hull(mut pts: Vec<Point2<f64>>) -> Vec<Point2<f64>> {
    pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    pts.dedup_by(|a, b| (*a - *b).norm() < 1e-9);
    if pts.len() < 3 {
        return pts;
    }
    let cross = |o: Point2<f64>, a: Point2<f64>, b: Point2<f64>| (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
    let mut hull: Vec<Point2<f64>> = Vec::with_capacity(2 * pts.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &Point2<f64>>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2 && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0 {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// Distance from `p` to the segment `a`–`b`.
fn segment_distance(p: Point2<f64>, a: Point2<f64>, b: Point2<f64>) -> f64 {
    let ab = b - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + t * ab)).norm()
}

/// Signed distance (m) from `p` to the boundary of the counter-clockwise polygon `hull`,
/// positive inside; for fewer than 3 vertices the negated distance to the point/segment.
pub fn polygon_margin(p: Point2<f64>, hull: &[Point2<f64>]) -> f64 {
    match hull.len() {
        0 => f64::NEG_INFINITY,
        1 => -(p - hull[0]).norm(),
        2 => -segment_distance(p, hull[0], hull[1]),
        n => {
            let mut dist = f64::INFINITY;
            let mut inside = true;
            for i in 0..n {
                let (a, b) = (hull[i], hull[(i + 1) % n]);
                dist = dist.min(segment_distance(p, a, b));
                let e = b - a;
                if e.x * (p.y - a.y) - e.y * (p.x - a.x) < 0.0 {
                    inside = false;
                }
            }
            if inside { dist } else { -dist }
        }
    }
}

/// Support margin (m) of the current state: see the module docs. Fails on an unknown
/// sole link; `-∞` when the soles have no box shape.
pub fn support_margin(sim: &World, soles: &[String]) -> Result<f64> {
    let mut corners = Vec::new();
    for sole in soles {
        corners.extend(sole_points(sim, sole)?);
    }
    let lowest = corners.iter().map(|c| c.z).fold(f64::INFINITY, f64::min);
    let touching: Vec<Point2<f64>> = corners
        .iter()
        .filter(|c| c.z <= lowest + SOLE_CONTACT_TOLERANCE)
        .map(|c| Point2::new(c.x, c.y))
        .collect();
    let com = center_of_mass(sim)?;
    Ok(polygon_margin(Point2::new(com.x, com.y), &convex_hull(touching)))
}

/// Resets the robot to `posture` with the first sole flat on the ground: the base is
/// placed so that this sole's frame stands at `stance` (x, y), or keeps the x–y position it
/// has at the identity base if `stance` is `None`, with the heading it has there, no roll or
/// pitch, and its lowest box corner `clearance` (m) above `ground`. A sole without a box (no
/// plane to stand flat) stands at `stance` the same way with the base upright, the robot's
/// lowest point `clearance` above `ground`.
pub fn reset_on_ground(
    sim: &mut World,
    posture: &[f64],
    sole: &str,
    ground: f64,
    clearance: f64,
    stance: Option<[f64; 2]>,
) -> Result<()> {
    check_finite("ground height and clearance", &[ground, clearance])?;
    sim.reset_with_base(posture, &Isometry3::identity())?;
    if !has_box(&sim.model, sole) {
        let at = sim.link_pose(sole)?.translation;
        let [x, y] = stance.unwrap_or([at.x, at.y]);
        check_finite("stance", &[x, y])?;
        return stand_upright(sim, posture, ground, clearance, [x - at.x, y - at.y]);
    }
    let sole_pose = sim.link_pose(sole)?;
    let (_, _, yaw) = sole_pose.rotation.euler_angles();
    let [x, y] = stance.unwrap_or([sole_pose.translation.x, sole_pose.translation.y]);
    check_finite("stance", &[x, y])?;
    let flat = Isometry3::from_parts(
        Translation3::new(x, y, 0.0),
        UnitQuaternion::from_euler_angles(0.0, 0.0, yaw),
    );
    let base = flat * sole_pose.inverse();
    sim.reset_with_base(posture, &base)?;
    let lowest = box_corners(sim, &sim.model, sole)?
        .iter()
        .map(|c| c.z)
        .fold(f64::INFINITY, f64::min);
    let lifted = Isometry3::translation(0.0, 0.0, ground + clearance - lowest) * base;
    sim.reset_with_base(posture, &lifted)
}

/// Resets the robot to `posture` with its base upright, moved by `shift` (x, y) from the
/// origin and lifted so that its lowest collision point stands `clearance` (m) above `ground`
/// (a robot without shapes: its base lifted by `clearance`). For robots with no sole to stand flat.
pub fn stand_upright(sim: &mut World, posture: &[f64], ground: f64, clearance: f64, shift: [f64; 2]) -> Result<()> {
    sim.reset_with_base(posture, &Isometry3::identity())?;
    let lowest = sim.lowest_point().unwrap_or(ground);
    sim.reset_with_base(
        posture,
        &Isometry3::translation(shift[0], shift[1], ground + clearance - lowest),
    )
}

/// [`reset_on_ground`] on the world's own floor (an error if it has none), the sole where it
/// stands at the identity base.
pub fn reset_on_floor(sim: &mut World, posture: &[f64], sole: &str, clearance: f64) -> Result<()> {
    let Some(ground) = sim.config.floor else {
        return Err(
            CoreError::Argument("reset_on_ground: this world has no floor (a floor height is needed)".into()).into(),
        );
    };
    reset_on_ground(sim, posture, sole, ground, clearance, None)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn margin_of_a_square_is_the_distance_to_its_nearest_edge() {
        let pts = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (0.5, 0.5)]
            .iter()
            .map(|&(x, y)| Point2::new(x, y))
            .collect();
        let hull = convex_hull(pts);
        assert_eq!(hull.len(), 4);
        assert!((polygon_margin(Point2::new(0.5, 0.2), &hull) - 0.2).abs() < 1e-12);
        assert!((polygon_margin(Point2::new(0.5, -0.3), &hull) + 0.3).abs() < 1e-12);
        assert!((polygon_margin(Point2::new(2.0, 0.5), &[hull[1], hull[2]]) + 1.0).abs() < 1e-12);
    }
}
