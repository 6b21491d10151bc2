//! Repairs of a parsed URDF whose meaning is clear but which the physics cannot take as
//! written (issue #41), each reported as a warning naming the joint or link:
//!
//! - a revolute joint whose `<limit>` gives no `lower` and no `upper` (the parser makes it
//!   [0, 0], a joint that cannot move): loaded as continuous, as pybullet does (it reads an
//!   absent range as no limit); an explicit `lower="0" upper="0"` is refused;
//! - a `spherical` joint: three continuous joints `NAME_x`, `NAME_y`, `NAME_z` (rotations
//!   about the joint frame's x, then the new y, then the new z) through two small frames;
//! - a frame link (no shape, on a fixed joint) with a negligible mass and an inertia the
//!   physics refuses, as exporters write tool frames (onshape-to-robot's `mass 1e-9`, zero
//!   inertia: the SO-101's `gripper_frame_link`): loaded massless, so the loader folds it into
//!   its parent, as it does a frame link without `<inertial>`;
//! - with `balance_inertia` ([`super::LoadOptions`]): an `<inertia>` the physics refuses
//!   (triangle inequality broken, not positive definite, too small): its principal moments
//!   set to their mean (MuJoCo's `balanceinertia`), or, when that mean is still too small (an
//!   all-zero tensor), a solid box filling the link's collision shapes' bounds.

use std::collections::HashSet;

use nalgebra::{Matrix3, Point3, UnitQuaternion};
use rapier3d_urdf::urdf_rs;

use crate::pose::origin_pose;

/// Share of the child link's mass (and inertia) given to each of the two frames between the
/// three joints a spherical joint becomes.
pub(super) const GIMBAL_SHARE: f64 = 1e-3;

/// A mass at most this share of the robot's is negligible on a frame link ([`massless_frames`]).
pub(super) const FRAME_MASS_SHARE: f64 = 1e-6;

/// Loads as massless every link with no visual or collision shape, attached by a fixed joint,
/// whose mass is at most [`FRAME_MASS_SHARE`] of the robot's and whose inertia the physics
/// cannot take (`refused`): a named frame, whose mass cannot matter.
pub(super) fn massless_frames(
    robot: &mut urdf_rs::Robot,
    refused: impl Fn(f64, &urdf_rs::Inertia) -> bool,
    warnings: &mut Vec<String>,
) {
    let total: f64 = robot
        .links
        .iter()
        .map(|l| l.inertial.mass.value)
        .filter(|m| m.is_finite())
        .sum();
    for link in &mut robot.links {
        let mass = link.inertial.mass.value;
        let fixed = robot
            .joints
            .iter()
            .find(|j| j.child.link == link.name && j.joint_type == urdf_rs::JointType::Fixed);
        let Some(joint) = fixed else { continue };
        if link.visual.is_empty()
            && link.collision.is_empty()
            && mass > 0.0
            && mass <= FRAME_MASS_SHARE * total
            && refused(mass, &link.inertial.inertia)
        {
            warnings.push(format!(
                "link {:?}: a frame (no shape, on fixed joint {:?}) with mass {mass:e} kg, under {FRAME_MASS_SHARE:e} of \
                 the robot's, and an <inertia> the physics cannot take: loaded massless",
                link.name, joint.name
            ));
            link.inertial = urdf_rs::Inertial::default();
        }
    }
}

/// Loads revolute joints without a range as continuous; `no_range` from the text scan.
pub(super) fn unlimited_revolutes(robot: &mut urdf_rs::Robot, no_range: &HashSet<String>, warnings: &mut Vec<String>) {
    for joint in &mut robot.joints {
        if joint.joint_type == urdf_rs::JointType::Revolute && no_range.contains(&joint.name) {
            joint.joint_type = urdf_rs::JointType::Continuous;
            warnings.push(format!(
                "joint {:?}: revolute without <limit lower upper>, loaded as continuous (no limits), \
                 as pybullet does",
                joint.name
            ));
        }
    }
}

/// Replaces every `spherical` joint by three continuous joints (see the module doc); fails
/// naming the joint if a new name is taken.
pub(super) fn split_spherical(robot: &mut urdf_rs::Robot, warnings: &mut Vec<String>) -> Result<(), String> {
    let spherical: Vec<usize> = (0..robot.joints.len())
        .filter(|i| robot.joints[*i].joint_type == urdf_rs::JointType::Spherical)
        .collect();
    let mut said = Vec::new();
    for &j in spherical.iter().rev() {
        let joint = robot.joints[j].clone();
        let name = &joint.name;
        let taken = |n: &str| robot.links.iter().any(|l| l.name == n) || robot.joints.iter().any(|k| k.name == n);
        let frames = [format!("{name}_x_link"), format!("{name}_y_link")];
        let joints = [format!("{name}_x"), format!("{name}_y"), format!("{name}_z")];
        if let Some(n) = frames.iter().chain(&joints).find(|n| taken(n)) {
            return Err(format!(
                "joint {name:?} is spherical; it would become three continuous joints, but the name {n:?} is taken: \
                 rename it, or write the three joints yourself"
            ));
        }
        let child = robot.links.iter().find(|l| l.name == joint.child.link);
        let (mass, moment) = child.map_or((1.0, 1.0), |l| {
            let t = &l.inertial.inertia;
            (l.inertial.mass.value, (t.ixx + t.iyy + t.izz) / 3.0)
        });
        let share = |v: f64| {
            if v.is_finite() && v > 0.0 {
                v * GIMBAL_SHARE
            } else {
                GIMBAL_SHARE
            }
        };
        let (m, i) = (share(mass), share(moment).max(share(mass) * 1e-4));
        for frame in &frames {
            robot.links.push(urdf_rs::Link {
                name: frame.clone(),
                inertial: urdf_rs::Inertial {
                    origin: urdf_rs::Pose::default(),
                    mass: urdf_rs::Mass { value: m },
                    inertia: urdf_rs::Inertia {
                        ixx: i,
                        iyy: i,
                        izz: i,
                        ..Default::default()
                    },
                },
                visual: Vec::new(),
                collision: Vec::new(),
            });
        }
        let ends = [
            joint.parent.link.clone(),
            frames[0].clone(),
            frames[1].clone(),
            joint.child.link.clone(),
        ];
        let mut replacement = Vec::new();
        for (k, new_name) in joints.iter().enumerate() {
            let mut axis = [0.0; 3];
            axis[k] = 1.0;
            let mut part = joint.clone();
            part.name = new_name.clone();
            part.joint_type = urdf_rs::JointType::Continuous;
            part.parent.link = ends[k].clone();
            part.child.link = ends[k + 1].clone();
            part.axis.xyz = urdf_rs::Vec3(axis);
            part.mimic = None;
            if k > 0 {
                part.origin = urdf_rs::Pose::default();
            }
            replacement.push(part);
        }
        robot.joints.splice(j..=j, replacement);
        said.push(format!(
            "joint {name:?}: spherical, loaded as three continuous joints {:?}, {:?}, {:?} (about x, then y, \
             then z of its frame) through two frames of {GIMBAL_SHARE} x the mass of link {:?}",
            joints[0], joints[1], joints[2], joint.child.link
        ));
    }
    warnings.extend(said.into_iter().rev());
    Ok(())
}

/// The inertia tensor of `link`, in its inertial frame.
fn tensor(t: &urdf_rs::Inertia) -> Matrix3<f64> {
    Matrix3::new(t.ixx, t.ixy, t.ixz, t.ixy, t.iyy, t.iyz, t.ixz, t.iyz, t.izz)
}

/// The balanced tensor of a link: its principal moments' mean on the diagonal when
/// `accept(mean)` holds, else a solid box over `points` (the link's collision shapes'
/// corners or hull vertices, in the link frame). `None` if neither is possible (no shapes).
/// Returns the tensor (in the inertial frame) and what was done.
pub(super) fn balanced(
    link: &urdf_rs::Link,
    points: &[Point3<f64>],
    accept: impl Fn(&urdf_rs::Inertia) -> bool,
) -> Option<(urdf_rs::Inertia, String)> {
    let mass = link.inertial.mass.value;
    let before = tensor(&link.inertial.inertia);
    let mut moments: Vec<f64> = before.symmetric_eigenvalues().iter().copied().collect();
    moments.sort_by(f64::total_cmp);
    let mean = before.trace() / 3.0;
    let isotropic = urdf_rs::Inertia {
        ixx: mean,
        iyy: mean,
        izz: mean,
        ..Default::default()
    };
    if accept(&isotropic) {
        return Some((
            isotropic,
            format!(
                "principal moments {:.4e}, {:.4e}, {:.4e} kg m^2 replaced by their mean {mean:.4e}",
                moments[0], moments[1], moments[2]
            ),
        ));
    }
    let first = points.first()?;
    let (mut lo, mut hi) = (first.coords, first.coords);
    for p in points {
        lo = lo.inf(&p.coords);
        hi = hi.sup(&p.coords);
    }
    let e = hi - lo;
    let box_link = Matrix3::from_diagonal(&nalgebra::Vector3::new(
        mass / 12.0 * (e.y * e.y + e.z * e.z),
        mass / 12.0 * (e.x * e.x + e.z * e.z),
        mass / 12.0 * (e.x * e.x + e.y * e.y),
    ));
    let r: UnitQuaternion<f64> = origin_pose(&link.inertial.origin).rotation;
    let m = r.to_rotation_matrix();
    let t = m.matrix().transpose() * box_link * m.matrix();
    let estimate = urdf_rs::Inertia {
        ixx: t[(0, 0)],
        ixy: t[(0, 1)],
        ixz: t[(0, 2)],
        iyy: t[(1, 1)],
        iyz: t[(1, 2)],
        izz: t[(2, 2)],
    };
    accept(&estimate).then(|| {
        (
            estimate,
            format!(
                "principal moments {:.4e}, {:.4e}, {:.4e} kg m^2 replaced by a solid box of {mass} kg filling its \
                 collision shapes ({:.3} x {:.3} x {:.3} m)",
                moments[0], moments[1], moments[2], e.x, e.y, e.z
            ),
        )
    })
}

/// Corners of a collision primitive's bounding box in its own frame (`None` for a mesh).
pub(super) fn primitive_corners(g: &urdf_rs::Geometry) -> Option<Vec<Point3<f64>>> {
    let half = match g {
        urdf_rs::Geometry::Box { size } => [size.0[0] / 2.0, size.0[1] / 2.0, size.0[2] / 2.0],
        urdf_rs::Geometry::Sphere { radius } => [*radius; 3],
        urdf_rs::Geometry::Cylinder { radius, length } => [*radius, *radius, length / 2.0],
        urdf_rs::Geometry::Capsule { radius, length } => [*radius, *radius, length / 2.0 + radius],
        urdf_rs::Geometry::Mesh { .. } => return None,
    };
    let mut out = Vec::with_capacity(8);
    for sx in [-1.0, 1.0] {
        for sy in [-1.0, 1.0] {
            for sz in [-1.0, 1.0] {
                out.push(Point3::new(sx * half[0], sy * half[1], sz * half[2]));
            }
        }
    }
    Some(out)
}
