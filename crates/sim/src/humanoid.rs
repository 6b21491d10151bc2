//! The humanoid fall check (SPEC §4.3, paper Fig. 7a): drive a free-floating robot
//! standing on the ground through a sequence of joint targets and report, per segment,
//! whether it fell, its smallest support margin and its grip error.
//!
//! - **Centre of mass** ([`center_of_mass`]): the mass-weighted mean of the URDF
//!   `<inertial>` origins at the current link poses (not rapier's body masses, which
//!   read differently before the first step, PITFALLS.md).
//! - **Support margin** ([`support_margin`]): signed distance (m) from the centre of
//!   mass projected on the ground to the edge of the support polygon, positive inside.
//!   The polygon is the 2-D convex hull of the bottom corners of the sole boxes that are
//!   within [`SOLE_CONTACT_TOLERANCE`] of the lowest sole corner (a tipping foot keeps
//!   only its touching edge).
//! - **Grip error**: distance between the two hand frames minus the object width.
//! - **Fall**: [`crate::FallCriteria`] (a sole tilting > 20°, a non-sole link touching
//!   the ground, or the base height halving).

use latent_core::CoreError;
use nalgebra::{Isometry3, Point2, Point3, Translation3, UnitQuaternion, Vector3};
use rapier3d_urdf::urdf_rs;

use crate::error::{Result, SimError, check_finite};
use crate::obstacles::{FallCriteria, FallStatus};
use crate::pd::PdGains;
use crate::plant::{PhysicsSim, SimOptions};
use crate::urdf::{RootMode, UrdfModel};

/// The humanoid's world and servos (SPEC §4.3; Python `latentrl.humanoid.SERVO` and
/// `PHYSICS`): a free-floating root over a ground at z = 0, servo PD kp 8 N·m/rad,
/// kd 0.1 N·m·s/rad, torque capped at 1.2 N·m, and 1 solver iteration of 4 PGS passes
/// (stands 10 s within 1 mm at a third of the cost of rapier's 4 × 1, `tests/humanoid.rs`).
pub fn sim_options() -> SimOptions {
    SimOptions {
        root: RootMode::Floating,
        ground: Some(0.0),
        gains: PdGains {
            kp: 8.0,
            kd: 0.1,
            max_force: 1.2,
        },
        solver_iterations: 1,
        pgs_iterations: 4,
        ..SimOptions::default()
    }
}

/// Sole corners up to this far (m) above the lowest sole corner count as touching.
pub const SOLE_CONTACT_TOLERANCE: f64 = 2e-3;

/// What the fall check measures and for how long it holds each target.
#[derive(Debug, Clone, PartialEq)]
pub struct FallCheckConfig {
    /// Time each target of the sequence is held (s); rounded up to whole physics steps.
    pub hold: f64,
    /// The two sole links (box collision shapes); their corners make the support polygon.
    pub soles: [String; 2],
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

impl Default for FallCheckConfig {
    /// The KHR-1HV-like robot of `python/latentrl/data/khr1hv.urdf`, held 1 s per target.
    fn default() -> Self {
        let soles = ["l_foot".to_string(), "r_foot".to_string()];
        Self {
            hold: 1.0,
            hands: ["l_hand".to_string(), "r_hand".to_string()],
            grip_width: 0.10,
            fall: FallCriteria {
                min_base_height: 0.0,
                max_sole_tilt: 20f64.to_radians(),
                soles: soles.to_vec(),
            },
            soles,
            check_every: 4,
        }
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

/// Centre of mass of the whole robot in world coordinates (m), from the URDF inertials.
pub fn center_of_mass(sim: &PhysicsSim) -> Result<Point3<f64>> {
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

/// World corners of every box collision shape of link `link`.
fn box_corners(sim: &PhysicsSim, model: &UrdfModel, link: &str) -> Result<Vec<Point3<f64>>> {
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
pub fn support_margin(sim: &PhysicsSim, soles: &[String]) -> Result<f64> {
    let mut corners = Vec::new();
    for sole in soles {
        corners.extend(box_corners(sim, &sim.model, sole)?);
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
/// placed so that this sole's frame keeps its x–y position and heading at the identity
/// base, with no roll or pitch, and its lowest box corner `clearance` (m) above `ground`.
pub fn reset_on_ground(sim: &mut PhysicsSim, posture: &[f64], sole: &str, ground: f64, clearance: f64) -> Result<()> {
    check_finite("ground height and clearance", &[ground, clearance])?;
    sim.reset_with_base(posture, &Isometry3::identity())?;
    let sole_pose = sim.link_pose(sole)?;
    let (_, _, yaw) = sole_pose.rotation.euler_angles();
    let flat = Isometry3::from_parts(
        Translation3::new(sole_pose.translation.x, sole_pose.translation.y, 0.0),
        UnitQuaternion::from_euler_angles(0.0, 0.0, yaw),
    );
    let base = flat * sole_pose.inverse();
    sim.reset_with_base(posture, &base)?;
    let lowest = box_corners(sim, &sim.model, sole)?
        .iter()
        .map(|c| c.z)
        .fold(f64::INFINITY, f64::min);
    if !lowest.is_finite() {
        return Err(SimError::Input(CoreError::InvalidParameter {
            name: "sole",
            value: f64::NAN,
            reason: "the sole link has no box collision shape",
        }));
    }
    let lifted = Isometry3::translation(0.0, 0.0, ground + clearance - lowest) * base;
    sim.reset_with_base(posture, &lifted)
}

/// The fall check: resets the robot at `start` standing on the ground, then holds each
/// of `targets` for `config.hold` seconds, reporting one [`SegmentReport`] per target.
///
/// Once the robot has fallen every later segment reports `fell` too (it stays down).
/// When `config.fall.min_base_height` is ≤ 0 it is set to half the base height at the
/// start posture. Fails on wrong lengths, non-finite values, postures outside the joint
/// limits (targets are clamped), unknown links or a non-positive hold.
pub fn run_fall_check(
    sim: &mut PhysicsSim,
    start: &[f64],
    targets: &[Vec<f64>],
    config: &FallCheckConfig,
) -> Result<Vec<SegmentReport>> {
    run_fall_check_observed(sim, start, targets, config, |_, _| {})
}

/// [`run_fall_check`] that also calls `observe(sim, fell)` after the reset and after every
/// check (every `config.check_every` physics steps; `sim.time()` is the time since the start),
/// e.g. to record the robot's poses for a picture.
pub fn run_fall_check_observed(
    sim: &mut PhysicsSim,
    start: &[f64],
    targets: &[Vec<f64>],
    config: &FallCheckConfig,
    mut observe: impl FnMut(&PhysicsSim, bool),
) -> Result<Vec<SegmentReport>> {
    check_finite("hold", &[config.hold, config.grip_width])?;
    if config.hold <= 0.0 || config.check_every == 0 {
        return Err(SimError::Input(CoreError::InvalidParameter {
            name: "hold",
            value: config.hold,
            reason: "hold must be > 0 and check_every ≥ 1",
        }));
    }
    let ground = sim.options.ground.unwrap_or(0.0);
    reset_on_ground(sim, start, &config.soles[0], ground, 5e-4)?;
    let mut fall = config.fall.clone();
    if fall.min_base_height <= 0.0 {
        fall.min_base_height = ground + 0.5 * (sim.base_pose().translation.z - ground);
    }
    let hands = [
        sim.frame(&config.hands[0], [0.0; 3])?,
        sim.frame(&config.hands[1], [0.0; 3])?,
    ];
    let grip = |sim: &PhysicsSim| {
        let (a, b) = (sim.frame_position(&hands[0]), sim.frame_position(&hands[1]));
        let d = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
        d - config.grip_width
    };
    let steps = (config.hold / sim.options.dt).ceil() as usize;
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
