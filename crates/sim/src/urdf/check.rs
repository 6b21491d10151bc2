//! Checks on a URDF that the loader does not make: it would panic (a joint naming a
//! missing link), ignore silently (mimic couplings) or fail with an opaque XML error
//! (an unknown joint type).

use std::collections::HashSet;

use rapier3d_urdf::urdf_rs;

use super::{JointInfo, JointKind, MimicInfo};
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

/// The largest URDF read (bytes), as a file or a string: real robot descriptions have 10 KB to
/// 1 MB (a 500-link chain with visuals and comments a few MB).
pub const MAX_URDF_BYTES: u64 = 16 << 20;

/// The deepest element nesting a URDF may have (real robot descriptions nest < 10 levels; the
/// XML parser recurses per level, and 50 000 levels overflowed the stack).
pub const MAX_URDF_DEPTH: usize = 256;

/// The most links a URDF may have: building the multibody grows about cubically with them
/// (300 links 0.3 s, 1000 links 10 s) and does not poll Ctrl-C.
pub const MAX_URDF_LINKS: usize = 500;

/// Refuses, before the XML parser runs, a document of more than [`MAX_URDF_BYTES`], nested
/// deeper than [`MAX_URDF_DEPTH`] or with more than [`MAX_URDF_LINKS`] `<link` elements (a scan
/// of the text, comments removed).
pub(super) fn check_size(xml: &str, origin: &str) -> Result<()> {
    if xml.len() as u64 > MAX_URDF_BYTES {
        return Err(SimError::MalformedUrdf {
            origin: origin.to_string(),
            reason: crate::files::too_large(xml.len() as u64, MAX_URDF_BYTES, "a URDF"),
        });
    }
    let clean = strip_comments(xml);
    let bytes = clean.as_bytes();
    let (mut depth, mut deepest, mut links) = (0usize, 0usize, 0usize);
    for (i, _) in clean.match_indices('<') {
        match bytes.get(i + 1) {
            Some(b'/') => depth = depth.saturating_sub(1),
            Some(b'?' | b'!') => {}
            Some(_) => {
                let self_closing = clean[i..].find('>').is_some_and(|end| clean[i..i + end].ends_with('/'));
                if !self_closing {
                    depth += 1;
                    deepest = deepest.max(depth);
                }
                let name = &clean[i + 1..];
                if name.starts_with("link")
                    && name[4..].starts_with(|c: char| c.is_whitespace() || c == '>' || c == '/')
                {
                    links += 1;
                }
            }
            None => {}
        }
    }
    let refuse = |reason: String| {
        Err(SimError::MalformedUrdf {
            origin: origin.to_string(),
            reason,
        })
    };
    if deepest > MAX_URDF_DEPTH {
        return refuse(format!(
            "elements nested {deepest} deep, more than the {MAX_URDF_DEPTH} a URDF may have"
        ));
    }
    if links > MAX_URDF_LINKS {
        return refuse(format!(
            "{links} links, more than the {MAX_URDF_LINKS} a robot may have"
        ));
    }
    Ok(())
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
    // `spherical` joints become three continuous ones (`repair::split_spherical`).
    const SUPPORTED: [&str; 5] = ["revolute", "continuous", "prismatic", "fixed", "spherical"];
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

/// `(link index, problem)` of every link with mass whose `<inertia>` the physics cannot take
/// ([`inertia_problem`]), all of them (so that a user sees every one at once).
pub(super) fn inertia_problems(robot: &urdf_rs::Robot) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    for (l, link) in robot.links.iter().enumerate() {
        let i = &link.inertial;
        if i.mass.value > 0.0
            && let Some(problem) = inertia_problem(i.mass.value, &i.inertia)
        {
            out.push((l, problem));
        }
    }
    out
}

/// Structural checks the loader does not make (it would panic or silently drop things).
///
/// Returns the actuated joints and the mimic joints (each coupled to an actuated leader).
pub(super) fn check_robot(robot: &urdf_rs::Robot, origin: &str) -> Result<(Vec<JointInfo>, Vec<MimicInfo>)> {
    let bad = |reason: String| SimError::MalformedUrdf {
        origin: origin.to_string(),
        reason,
    };
    let mut names = HashSet::new();
    for link in &robot.links {
        if !names.insert(link.name.as_str()) {
            return Err(bad(format!("duplicate link name {:?}", link.name)));
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
        let centre = i.origin.xyz.0.iter().chain(i.origin.rpy.0.iter());
        if values.iter().chain(centre).any(|v| !v.is_finite()) || i.mass.value < 0.0 {
            return Err(bad(format!(
                "link {:?} has a negative or non-finite <inertial>",
                link.name
            )));
        }
        let owner = format!("link {:?}", link.name);
        check_magnitudes(&owner, link_numbers(link)).map_err(bad)?;
        check_lengths(&owner, link_lengths(link)).map_err(bad)?;
        check_collisions(link).map_err(bad)?;
    }
    let mut joint_names = HashSet::new();
    let mut actuated = Vec::new();
    let mut followers = Vec::new();
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
    }
    check_tree(robot).map_err(bad)?;
    for joint in &robot.joints {
        let owner = format!("joint {:?}", joint.name);
        check_magnitudes(&owner, joint_numbers(joint)).map_err(bad)?;
        check_lengths(&owner, joint.origin.xyz.0.map(|v| ("origin xyz", v)).to_vec()).map_err(bad)?;
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
        // rapier normalises the axis in f32: one too short there becomes zero (silently X).
        let axis_norm2: f32 = joint.axis.xyz.0.iter().map(|v| (*v as f32) * (*v as f32)).sum();
        if !axis_norm2.is_normal() {
            return Err(bad(format!("joint {:?} has a zero axis", joint.name)));
        }
        let (lower, upper) = match kind {
            JointKind::Continuous => (f64::NEG_INFINITY, f64::INFINITY),
            _ => (joint.limit.lower, joint.limit.upper),
        };
        if kind != JointKind::Continuous {
            check_lengths(&owner, vec![("limit lower", lower), ("limit upper", upper)]).map_err(bad)?;
        }
        if kind != JointKind::Continuous && !(lower.is_finite() && upper.is_finite() && lower < upper) {
            let advice = if lower == upper {
                ": it cannot move; make it type=\"fixed\", or give it a range"
            } else {
                ""
            };
            return Err(bad(format!(
                "joint {:?} needs <limit lower upper> with lower < upper, got [{lower}, {upper}]{advice}",
                joint.name
            )));
        }
        let child = robot.links.iter().find(|l| l.name == joint.child.link);
        if child.is_some_and(|l| l.inertial.mass.value <= 0.0 && !carried_by_fixed_children(robot, l)) {
            return Err(bad(format!(
                "link {:?} is moved by joint {:?} but has no mass, nor has a link fixed to it: give it an \
                 <inertial> (what the joint turns: a flange, a tool), or make {:?} type=\"fixed\" if no task moves it",
                joint.child.link, joint.name, joint.name
            )));
        }
        let positive = |v: f64| (v.is_finite() && v > 0.0).then_some(v);
        let dynamics = joint.dynamics.as_ref();
        let info = JointInfo {
            name: joint.name.clone(),
            kind,
            child_link: joint.child.link.clone(),
            lower,
            upper,
            effort: positive(joint.limit.effort),
            velocity: positive(joint.limit.velocity),
            damping: dynamics.map(|d| d.damping).filter(|v| v.is_finite() && *v >= 0.0),
            friction: dynamics.map(|d| d.friction).filter(|v| v.is_finite() && *v >= 0.0),
        };
        match &joint.mimic {
            Some(mimic) => followers.push((info, mimic)),
            None => actuated.push(info),
        }
    }
    let mimics = couple(&actuated, &followers).map_err(bad)?;
    Ok((actuated, mimics))
}

/// Whether a massless `link` is a bare frame (no shape, no inertia) with a link of mass fixed
/// to it, directly or through other fixed joints: the loader then moves that link in its place
/// (rapier3d-urdf's `squeeze_empty_fixed_links`), so the joint turns a mass.
fn carried_by_fixed_children(robot: &urdf_rs::Robot, link: &urdf_rs::Link) -> bool {
    let t = &link.inertial.inertia;
    let bare = link.visual.is_empty()
        && link.collision.is_empty()
        && [t.ixx, t.ixy, t.ixz, t.iyy, t.iyz, t.izz].iter().all(|v| *v == 0.0);
    let mut names = vec![link.name.as_str()];
    let mut k = 0;
    while k < names.len() {
        let parent = names[k];
        k += 1;
        for joint in robot
            .joints
            .iter()
            .filter(|j| j.parent.link == parent && j.joint_type == urdf_rs::JointType::Fixed)
        {
            let Some(child) = robot.links.iter().find(|l| l.name == joint.child.link) else {
                continue;
            };
            if child.inertial.mass.value > 0.0 {
                return bare;
            }
            names.push(&child.name); // a tree ([`check_tree`], checked first): the walk ends
        }
    }
    false
}

/// Refuses a joint graph that is not one tree (issue #38): a joint whose parent is its child,
/// a link that is the child of two joints, joints that form a cycle (its links reachable from
/// no root), several root links. rapier3d-urdf builds a multibody from any of them: a
/// self-loop reached an LU panic, a 2-cycle loaded as a normal arm with the cycle's links
/// cut off from the shoulder. Every link and joint is named; every joint names existing links.
fn check_tree(robot: &urdf_rs::Robot) -> std::result::Result<(), String> {
    use std::collections::HashMap;
    let mut parent_joint: HashMap<&str, &urdf_rs::Joint> = HashMap::new();
    for joint in &robot.joints {
        let (parent, child) = (joint.parent.link.as_str(), joint.child.link.as_str());
        if parent == child {
            return Err(format!(
                "joint {:?} has link {parent:?} as both its parent and its child: a joint joins two links",
                joint.name
            ));
        }
        if let Some(first) = parent_joint.insert(child, joint) {
            return Err(format!(
                "link {child:?} is the child of two joints, {:?} (parent {:?}) and {:?} (parent {parent:?}): \
                 each link has one parent joint (a closed chain is not supported)",
                first.name, first.parent.link, joint.name
            ));
        }
    }
    // Up from each link along parent joints: a walk that comes back to a link of its own is a
    // cycle, and its links lead to no root.
    let mut done: HashSet<&str> = HashSet::new();
    for link in &robot.links {
        let mut walk: Vec<&str> = Vec::new();
        let mut at = link.name.as_str();
        while !done.contains(at) {
            if let Some(k) = walk.iter().position(|l| *l == at) {
                // Parent to child: each link's parent joint, the walk reversed.
                let cycle: Vec<&urdf_rs::Joint> = walk[k..].iter().rev().map(|l| parent_joint[l]).collect();
                let joints: Vec<String> = cycle
                    .iter()
                    .map(|j| format!("{:?} ({:?} -> {:?})", j.name, j.parent.link, j.child.link))
                    .collect();
                let links: Vec<String> = cycle.iter().map(|j| format!("{:?}", j.parent.link)).collect();
                return Err(format!(
                    "joints {} form a cycle: links {} lead to no root link",
                    joints.join(", "),
                    links.join(", ")
                ));
            }
            walk.push(at);
            match parent_joint.get(at) {
                Some(j) => at = j.parent.link.as_str(),
                None => break,
            }
        }
        done.extend(walk);
    }
    let roots: Vec<&str> = robot
        .links
        .iter()
        .map(|l| l.name.as_str())
        .filter(|l| !parent_joint.contains_key(l))
        .collect();
    if roots.len() > 1 {
        let under = |link: &str, root: &str| {
            let mut at = link;
            while let Some(j) = parent_joint.get(at) {
                at = j.parent.link.as_str();
            }
            at == root
        };
        let size = |root: &str| robot.links.iter().filter(|l| under(&l.name, root)).count();
        let listed: Vec<String> = roots
            .iter()
            .map(|r| format!("{r:?} (a tree of {} links)", size(r)))
            .collect();
        return Err(format!(
            "{} links are the child of no joint: {}; a robot has one root link, and every other link \
             is reachable from it (join the others to the tree with a joint, e.g. type=\"fixed\")",
            roots.len(),
            listed.join(", ")
        ));
    }
    Ok(())
}

/// Resolves every mimic joint to the actuated joint at the end of its chain of leaders
/// (`q = multiplier · q_leader + offset`, composed along the chain).
fn couple(
    actuated: &[JointInfo],
    followers: &[(JointInfo, &urdf_rs::Mimic)],
) -> std::result::Result<Vec<MimicInfo>, String> {
    let mut out = Vec::with_capacity(followers.len());
    for (info, mimic) in followers {
        let (mut multiplier, mut offset) = (1.0, 0.0);
        let mut chain = vec![info.name.as_str()];
        let mut next = *mimic;
        let leader = loop {
            let m = next.multiplier.unwrap_or(1.0);
            let o = next.offset.unwrap_or(0.0);
            if !(m.is_finite() && o.is_finite() && m.abs() <= LENGTH_MAX && o.abs() <= LENGTH_MAX) {
                return Err(format!(
                    "joint {:?} has <mimic multiplier={m} offset={o}>: both must be finite, within ±{LENGTH_MAX}",
                    chain[chain.len() - 1]
                ));
            }
            (multiplier, offset) = (multiplier * m, multiplier * o + offset);
            let name = next.joint.as_str();
            if chain.contains(&name) {
                chain.push(name);
                return Err(format!("mimic joints form a cycle: {}", chain.join(" -> ")));
            }
            if let Some(i) = actuated.iter().position(|j| j.name == name) {
                break i;
            }
            match followers.iter().find(|(f, _)| f.name == name) {
                Some((_, m)) => {
                    chain.push(name);
                    next = m;
                }
                None => {
                    return Err(format!(
                        "joint {:?} mimics joint {name:?}, which is not a moving joint of the robot",
                        chain[chain.len() - 1]
                    ));
                }
            }
        };
        out.push(MimicInfo {
            joint: info.clone(),
            leader,
            multiplier,
            offset,
        });
    }
    Ok(out)
}

/// Largest magnitude rapier's f32 holds: a larger finite f64 becomes ±inf in the physics.
const F32_MAX: f64 = f32::MAX as f64;

/// Fails on the first finite value whose magnitude does not fit in f32 (non-finite ones
/// are left to the checks that name them).
fn check_magnitudes(owner: &str, values: Vec<(&'static str, f64)>) -> std::result::Result<(), String> {
    match values.iter().find(|(_, v)| v.is_finite() && v.abs() > F32_MAX) {
        Some((what, v)) => Err(format!(
            "{owner} has {what} = {v:e}, too large for the f32 physics (|value| <= {F32_MAX:e})"
        )),
        None => Ok(()),
    }
}

/// Largest length (m) and joint limit (m or rad) accepted: rapier's f32 keeps 0.1 mm at
/// 1 km, and a joint origin of 1e20 m (m·r² overflowing f32) gave NaN in the first steps.
const LENGTH_MAX: f64 = 1e3;

/// Fails on the first finite value beyond ±[`LENGTH_MAX`].
fn check_lengths(owner: &str, values: Vec<(&'static str, f64)>) -> std::result::Result<(), String> {
    match values.iter().find(|(_, v)| v.is_finite() && v.abs() > LENGTH_MAX) {
        Some((what, v)) => Err(format!(
            "{owner} has {what} = {v:e}: lengths and joint limits must lie within ±{LENGTH_MAX} (m or rad)"
        )),
        None => Ok(()),
    }
}

/// The lengths of a link: inertial and collision origins, collision sizes.
fn link_lengths(link: &urdf_rs::Link) -> Vec<(&'static str, f64)> {
    let mut out: Vec<(&'static str, f64)> = link.inertial.origin.xyz.0.map(|v| ("inertial origin", v)).to_vec();
    for c in &link.collision {
        out.extend(c.origin.xyz.0.map(|v| ("collision origin", v)));
        out.extend(geometry_sizes(&c.geometry));
    }
    out
}

/// Every number of a link that reaches rapier: inertial, collision poses and sizes.
fn link_numbers(link: &urdf_rs::Link) -> Vec<(&'static str, f64)> {
    let i = &link.inertial;
    let t = &i.inertia;
    let mut out = vec![
        ("mass", i.mass.value),
        ("ixx", t.ixx),
        ("iyy", t.iyy),
        ("izz", t.izz),
        ("ixy", t.ixy),
        ("ixz", t.ixz),
        ("iyz", t.iyz),
    ];
    let pose = |name, p: &urdf_rs::Pose| {
        let xyz = p.xyz.0.map(|v| (name, v));
        let rpy = p.rpy.0.map(|v| (name, v));
        xyz.into_iter().chain(rpy)
    };
    out.extend(pose("inertial origin", &i.origin));
    for c in &link.collision {
        out.extend(pose("collision origin", &c.origin));
        out.extend(geometry_sizes(&c.geometry));
    }
    out
}

/// Every number of a joint that reaches rapier or the servos.
fn joint_numbers(joint: &urdf_rs::Joint) -> Vec<(&'static str, f64)> {
    let l = &joint.limit;
    let mut out = vec![
        ("limit lower", l.lower),
        ("limit upper", l.upper),
        ("limit effort", l.effort),
        ("limit velocity", l.velocity),
    ];
    out.extend(joint.origin.xyz.0.map(|v| ("origin xyz", v)));
    out.extend(joint.origin.rpy.0.map(|v| ("origin rpy", v)));
    out.extend(joint.axis.xyz.0.map(|v| ("axis", v)));
    if let Some(d) = &joint.dynamics {
        out.extend([("dynamics damping", d.damping), ("dynamics friction", d.friction)]);
    }
    out
}

/// The sizes of a collision shape (box edges, radii, lengths).
fn geometry_sizes(g: &urdf_rs::Geometry) -> Vec<(&'static str, f64)> {
    match g {
        urdf_rs::Geometry::Box { size } => size.0.map(|v| ("box size", v)).to_vec(),
        urdf_rs::Geometry::Cylinder { radius, length } | urdf_rs::Geometry::Capsule { radius, length } => {
            vec![("radius", *radius), ("length", *length)]
        }
        urdf_rs::Geometry::Sphere { radius } => vec![("radius", *radius)],
        urdf_rs::Geometry::Mesh { scale, .. } => {
            scale.map_or(Vec::new(), |s| s.0.map(|v| ("mesh scale", v.abs())).to_vec())
        }
    }
}

/// Collision shapes need finite poses and finite, non-negative sizes.
fn check_collisions(link: &urdf_rs::Link) -> std::result::Result<(), String> {
    for c in &link.collision {
        let mut pose = c.origin.xyz.0.iter().chain(c.origin.rpy.0.iter());
        if pose.any(|v| !v.is_finite()) {
            return Err(format!("link {:?} has a non-finite <collision> origin", link.name));
        }
        if let Some((what, v)) = geometry_sizes(&c.geometry)
            .into_iter()
            .find(|(_, v)| !(v.is_finite() && *v >= 0.0))
        {
            return Err(format!(
                "link {:?} has a <collision> {what} of {v}: sizes must be finite and >= 0",
                link.name
            ));
        }
    }
    Ok(())
}

/// Smallest radius of gyration (m) a link with mass may have about any axis: below it the
/// f32 multibody mass matrix is numerically singular (a principal moment of 1e-20 kg·m²
/// on a 40 g link of the humanoid gave NaN). The largest is [`LENGTH_MAX`].
const MIN_GYRATION_RADIUS: f64 = 1e-6;

/// Slack on the triangle inequality of the principal moments, for rounded values in files.
const TRIANGLE_SLACK: f64 = 1e-2;

/// Why the inertia tensor of a link with `mass` > 0 cannot be simulated, or `None`.
///
/// It must be positive definite as rapier sees it (Sylvester's criterion on the values
/// narrowed to f32, diagonal normal in f32), have every principal moment at least
/// `mass · MIN_GYRATION_RADIUS²` and at most `mass · LENGTH_MAX²`, and satisfy the triangle inequality of a rigid body
/// (each principal moment at most the sum of the other two, within `TRIANGLE_SLACK`).
/// A zero, singular or unphysical tensor makes the multibody mass matrix singular or so
/// ill-conditioned in f32 that the first steps give NaN, and the next one panics in rapier.
pub(super) fn inertia_problem(mass: f64, t: &urdf_rs::Inertia) -> Option<String> {
    let f = |v: f64| f64::from(v as f32);
    let (xx, yy, zz, xy, xz, yz) = (f(t.ixx), f(t.iyy), f(t.izz), f(t.ixy), f(t.ixz), f(t.iyz));
    let diagonal = [xx, yy, zz].iter().all(|v| *v > 0.0 && (*v as f32).is_normal());
    let minor2 = xx * yy - xy * xy;
    let det = xx * (yy * zz - yz * yz) - xy * (xy * zz - yz * xz) + xz * (xy * yz - yy * xz);
    if !(diagonal && minor2 > 0.0 && det > 0.0 && (mass as f32).is_normal()) {
        return Some("is not positive definite (in f32)".to_string());
    }
    let matrix = nalgebra::Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz);
    let mut moments: Vec<f64> = matrix.symmetric_eigenvalues().iter().copied().collect();
    moments.sort_by(f64::total_cmp);
    let floor = mass * MIN_GYRATION_RADIUS * MIN_GYRATION_RADIUS;
    if moments[0] < floor {
        return Some(format!(
            "has a principal moment {:.4e} below mass x (1 um)^2 = {floor:.4e} kg m^2",
            moments[0]
        ));
    }
    let ceiling = mass * LENGTH_MAX * LENGTH_MAX;
    if moments[2] > ceiling {
        return Some(format!(
            "has a principal moment {:.4e} above mass x (1 km)^2 = {ceiling:.4e} kg m^2",
            moments[2]
        ));
    }
    if moments[2] > (moments[0] + moments[1]) * (1.0 + TRIANGLE_SLACK) {
        return Some(format!(
            "breaks the triangle inequality: principal moments {:.4e}, {:.4e}, {:.4e} \
             (the largest may not exceed the sum of the other two)",
            moments[0], moments[1], moments[2]
        ));
    }
    None
}
