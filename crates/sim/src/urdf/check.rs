//! Checks on a URDF that the loader does not make: it would panic (a joint naming a
//! missing link), drop things silently (meshes, mimic) or fail with an opaque XML error
//! (an unknown joint type).

use std::collections::HashSet;

use rapier3d_urdf::urdf_rs;

use super::{JointInfo, JointKind};
use crate::error::{Result, SimError};

/// Removes `<!-- … -->` comments so the joint-type scan does not read commented-out XML.
fn strip_comments(xml: &str) -> String {
    let mut out = String::with_capacity(xml.len());
    let mut rest = xml;
    while let Some(start) = rest.find("<!--") {
        out.push_str(&rest[..start]);
        match rest[start..].find("-->") {
            Some(end) => rest = &rest[start + end + 3..],
            None => return out,
        }
    }
    out.push_str(rest);
    out
}

/// Value of attribute `name` inside the text of one start tag.
fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let mut rest = tag;
    while let Some(pos) = rest.find(name) {
        let before_ok = pos == 0 || rest[..pos].ends_with(char::is_whitespace);
        let after = rest[pos + name.len()..].trim_start();
        if before_ok && let Some(after_eq) = after.strip_prefix('=') {
            let value = after_eq.trim_start();
            let quote = value.chars().next()?;
            if quote == '"' || quote == '\'' {
                let body = &value[1..];
                return body.find(quote).map(|end| &body[..end]);
            }
        }
        rest = &rest[pos + name.len()..];
    }
    None
}

/// Rejects joint types before `urdf-rs` turns an unknown one into an opaque XML error.
pub(super) fn check_joint_types(xml: &str, origin: &str) -> Result<()> {
    const SUPPORTED: [&str; 4] = ["revolute", "continuous", "prismatic", "fixed"];
    let clean = strip_comments(xml);
    let mut rest = clean.as_str();
    while let Some(pos) = rest.find("<joint") {
        let after = &rest[pos + "<joint".len()..];
        let is_tag = after.starts_with(|c: char| c.is_whitespace() || c == '>' || c == '/');
        let tag = &after[..after.find('>').unwrap_or(after.len())];
        // `<joint name=…/>` inside `<transmission>` has no type: not a kinematic joint.
        if is_tag
            && let Some(kind) = attribute(tag, "type")
            && !SUPPORTED.contains(&kind)
        {
            return Err(SimError::UnsupportedJointType {
                joint: attribute(tag, "name").unwrap_or("?").to_string(),
                kind: kind.to_string(),
                origin: origin.to_string(),
            });
        }
        rest = after;
    }
    Ok(())
}

/// Structural checks the loader does not make (it would panic or silently drop things).
pub(super) fn check_robot(robot: &urdf_rs::Robot, origin: &str) -> Result<Vec<JointInfo>> {
    let bad = |reason: String| SimError::MalformedUrdf {
        origin: origin.to_string(),
        reason,
    };
    let mut names = HashSet::new();
    for link in &robot.links {
        if !names.insert(link.name.as_str()) {
            return Err(bad(format!("duplicate link name {:?}", link.name)));
        }
        for c in &link.collision {
            if matches!(c.geometry, urdf_rs::Geometry::Mesh { .. }) {
                let link = link.name.clone();
                return Err(SimError::UnsupportedGeometry {
                    link,
                    kind: "mesh",
                    origin: origin.to_string(),
                });
            }
        }
        let i = &link.inertial;
        let values = [
            i.mass.value,
            i.inertia.ixx,
            i.inertia.iyy,
            i.inertia.izz,
            i.inertia.ixy,
            i.inertia.ixz,
            i.inertia.iyz,
        ];
        if values.iter().any(|v| !v.is_finite()) || i.mass.value < 0.0 {
            return Err(bad(format!(
                "link {:?} has a negative or non-finite <inertial>",
                link.name
            )));
        }
    }
    let mut joint_names = HashSet::new();
    let mut children = HashSet::new();
    let mut actuated = Vec::new();
    for joint in &robot.joints {
        if !joint_names.insert(joint.name.as_str()) {
            return Err(bad(format!("duplicate joint name {:?}", joint.name)));
        }
        for end in [&joint.parent.link, &joint.child.link] {
            if !names.contains(end.as_str()) {
                return Err(bad(format!(
                    "joint {:?} names link {end:?}, which does not exist",
                    joint.name
                )));
            }
        }
        if !children.insert(joint.child.link.as_str()) {
            return Err(bad(format!("link {:?} is the child of two joints", joint.child.link)));
        }
        if joint.mimic.is_some() {
            return Err(SimError::UnsupportedJointType {
                joint: joint.name.clone(),
                kind: "mimic".to_string(),
                origin: origin.to_string(),
            });
        }
        let pose = joint.origin.xyz.0.iter().chain(joint.origin.rpy.0.iter());
        if pose.chain(joint.axis.xyz.0.iter()).any(|v| !v.is_finite()) {
            return Err(bad(format!("joint {:?} has a non-finite origin or axis", joint.name)));
        }
        let kind = match joint.joint_type {
            urdf_rs::JointType::Revolute => JointKind::Revolute,
            urdf_rs::JointType::Continuous => JointKind::Continuous,
            urdf_rs::JointType::Prismatic => JointKind::Prismatic,
            urdf_rs::JointType::Fixed => continue,
            _ => {
                return Err(SimError::UnsupportedJointType {
                    joint: joint.name.clone(),
                    kind: format!("{:?}", joint.joint_type).to_lowercase(),
                    origin: origin.to_string(),
                });
            }
        };
        if joint.axis.xyz.0.iter().all(|v| *v == 0.0) {
            return Err(bad(format!("joint {:?} has a zero axis", joint.name)));
        }
        let (lower, upper) = match kind {
            JointKind::Continuous => (f64::NEG_INFINITY, f64::INFINITY),
            _ => (joint.limit.lower, joint.limit.upper),
        };
        if kind != JointKind::Continuous && !(lower.is_finite() && upper.is_finite() && lower < upper) {
            return Err(bad(format!(
                "joint {:?} needs <limit lower upper> with lower < upper, got [{lower}, {upper}]",
                joint.name
            )));
        }
        let child = robot.links.iter().find(|l| l.name == joint.child.link);
        if child.is_some_and(|l| l.inertial.mass.value <= 0.0) {
            return Err(bad(format!(
                "link {:?} is moved by joint {:?} but has no mass",
                joint.child.link, joint.name
            )));
        }
        let positive = |v: f64| (v.is_finite() && v > 0.0).then_some(v);
        let dynamics = joint.dynamics.as_ref();
        actuated.push(JointInfo {
            name: joint.name.clone(),
            kind,
            child_link: joint.child.link.clone(),
            lower,
            upper,
            effort: positive(joint.limit.effort),
            velocity: positive(joint.limit.velocity),
            damping: dynamics.map(|d| d.damping).filter(|v| v.is_finite() && *v >= 0.0),
            friction: dynamics.map(|d| d.friction).filter(|v| v.is_finite() && *v >= 0.0),
        });
    }
    Ok(actuated)
}
