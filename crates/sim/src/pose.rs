//! Conversions between the f64 nalgebra poses of this crate's API and rapier's f32 (glam)
//! poses, and URDF `<origin>` elements as poses.

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};
use rapier3d::math::Rot3;
use rapier3d::prelude::{Pose, Real, Vector};
use rapier3d_urdf::urdf_rs;

/// An f64 isometry narrowed to a rapier (glam, f32) pose.
pub(crate) fn to_pose(iso: &Isometry3<f64>) -> Pose {
    let t = iso.translation.vector;
    let q = iso.rotation.quaternion();
    let rotation = Rot3::from_xyzw(q.i as Real, q.j as Real, q.k as Real, q.w as Real).normalize();
    Pose::from_parts(Vector::new(t.x as Real, t.y as Real, t.z as Real), rotation)
}

/// A rapier (glam, f32) pose widened to an f64 nalgebra isometry.
pub(crate) fn to_isometry(p: &Pose) -> Isometry3<f64> {
    let t = p.translation;
    let q = p.rotation;
    let quat = Quaternion::new(q.w as f64, q.x as f64, q.y as f64, q.z as f64);
    Isometry3::from_parts(
        Translation3::new(t.x as f64, t.y as f64, t.z as f64),
        UnitQuaternion::from_quaternion(quat),
    )
}

/// An f64 vector narrowed to rapier's f32.
pub(crate) fn to_vector(v: [f64; 3]) -> Vector {
    Vector::new(v[0] as Real, v[1] as Real, v[2] as Real)
}

/// A URDF `<origin>` as an f64 pose: R = Rz(yaw)·Ry(pitch)·Rx(roll) (URDF convention).
pub(crate) fn origin_pose(o: &urdf_rs::Pose) -> Isometry3<f64> {
    let [x, y, z] = o.xyz.0;
    let [roll, pitch, yaw] = o.rpy.0;
    Isometry3::from_parts(
        Translation3::new(x, y, z),
        UnitQuaternion::from_euler_angles(roll, pitch, yaw),
    )
}
