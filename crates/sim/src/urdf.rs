//! Reading a URDF robot description and checking it before rapier3d-urdf builds it.
//!
//! [`UrdfModel`] parses a file or a string (with the `urdf-rs` version that
//! rapier3d-urdf 0.36.1 re-exports), rejects what the physics plant cannot simulate,
//! loads its collision meshes as convex hulls ([`mesh`]) and lists the actuated joints in
//! URDF order. [`crate::world::World`] then inserts it into a rapier world as one multibody
//! (reduced coordinates). docs/robots.md lists what is supported.
//!
//! What rapier3d-urdf 0.36.1 ignores, and what we do about it:
//! - `<dynamics damping friction>`: read here ([`JointInfo::damping`], [`JointInfo::friction`])
//!   and written into the multibody's per-DoF damping / dry friction by the plant.
//! - `limit.effort`: read here ([`JointInfo::effort`]) and used as the PD torque cap
//!   (see [`crate::world::ServoConfig::use_urdf_effort`]).
//! - `limit.velocity`: read ([`JointInfo::velocity`]) but **not enforced**.
//! - `<mimic>`: the follower is not a coordinate of postures; its own servo tracks
//!   `multiplier · q_leader + offset` of the leader's current position every physics step
//!   ([`MimicInfo`]). `<safety_controller>`: ignored.
//! - Mesh collision shapes: read here (STL, OBJ, COLLADA), one convex hull each, cached.
//! - `<visual>`: not in the physics; [`UrdfModel::visual_shapes`] lists them for drawing.
//!
//! Supported joint types: `revolute`, `continuous`, `prismatic` (actuated, one DoF each)
//! and `fixed`. `floating`, `planar` and `spherical` joints are rejected; a free-floating
//! robot gets its 6 root DoF from [`RootMode::Floating`] instead.

use std::path::{Path, PathBuf};

use latent_core::choice;
use rapier3d_urdf::urdf_rs;

use crate::error::{Result, SimError};

pub mod cache;
mod check;
mod insert;
mod lint;
pub mod mesh;
mod mesh_counts;
mod repair;
mod summary;
pub use check::{MAX_URDF_BYTES, MAX_URDF_DEPTH, MAX_URDF_LINKS};
use check::{check_joint_types, check_robot, check_size, inertia_problem, inertia_problems};
pub(crate) use insert::JointSlot;
use mesh::MeshHull;
pub use summary::{HullSummary, JointSummary, MimicSummary, ShapeSummary, UrdfSummary};

choice! {
    /// How the root link of the robot is attached to the world.
    pub enum RootMode {
        /// The root link is welded to the world (arms on a fixed base).
        Fixed = "fixed",
        /// The root link floats freely with 6 DoF (a humanoid standing on a floor).
        Floating = "floating",
    }
}

// `choice!` declares the enum; its variants take no `#[default]`.
#[allow(clippy::derivable_impls)]
impl Default for RootMode {
    fn default() -> Self {
        Self::Fixed
    }
}

/// How a URDF is loaded: the repairs a user asks for (docs/robots.md).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LoadOptions {
    /// Repair every `<inertia>` the physics refuses (triangle inequality broken, not positive
    /// definite, all zero) instead of refusing it, each reported in [`UrdfModel::warnings`]:
    /// principal moments set to their mean (MuJoCo's `balanceinertia`), or a solid box
    /// filling the link's collision shapes when that mean is too small.
    pub balance_inertia: bool,
}

/// How far (rad or m) a mimic joint's demo column may lie from its leader's coupling
/// ([`UrdfModel::demo_columns`]).
pub const MIMIC_TOLERANCE: f64 = 1e-3;

/// Kind of an actuated (one-DoF) joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum JointKind {
    /// Hinge with position limits; the coordinate is an angle in radians.
    Revolute,
    /// Hinge without limits; the coordinate is an angle in radians.
    Continuous,
    /// Slider with position limits; the coordinate is a length in metres.
    Prismatic,
}

/// One actuated joint as written in the URDF (serialised without its child link, its kind as
/// `type`).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct JointInfo {
    /// Joint name.
    pub name: String,
    /// Joint kind.
    #[serde(rename = "type")]
    pub kind: JointKind,
    /// Name of the link the joint moves.
    #[serde(skip)]
    pub child_link: String,
    /// Lower position limit (−∞ for continuous joints).
    pub lower: f64,
    /// Upper position limit (+∞ for continuous joints).
    pub upper: f64,
    /// `limit.effort` (N·m or N) if given and positive: the torque cap.
    pub effort: Option<f64>,
    /// `limit.velocity` (rad/s or m/s) if given and positive; recorded, not enforced.
    pub velocity: Option<f64>,
    /// `<dynamics damping>` if given (N·m·s/rad).
    pub damping: Option<f64>,
    /// `<dynamics friction>` if given (N·m), applied as dry joint friction.
    pub friction: Option<f64>,
}

/// A joint coupled to another (`<mimic>`): not a coordinate of postures, its servo follows
/// `multiplier · q_leader + offset`.
#[derive(Debug, Clone, PartialEq)]
pub struct MimicInfo {
    /// The coupled joint as written (its limits clamp the coupled target).
    pub joint: JointInfo,
    /// Index of the actuated joint it follows (the end of a chain of mimics).
    pub leader: usize,
    /// Multiplier of the leader's position (composed along a chain).
    pub multiplier: f64,
    /// Offset added (rad or m, composed along a chain).
    pub offset: f64,
}

impl MimicInfo {
    /// The coupled position for leader position `q`, clamped to the joint's limits.
    pub fn follow(&self, q: f64) -> f64 {
        (self.multiplier * q + self.offset).clamp(self.joint.lower, self.joint.upper)
    }
}

/// One collision or visual shape of a link, as the URDF gives it (for drawing and
/// `latentrl urdf-info`; the physics builds its colliders from the collision ones).
#[derive(Debug, Clone, PartialEq)]
pub struct ShapeInfo {
    /// Index of the link (URDF order).
    pub link: usize,
    /// "box", "sphere", "cylinder" or "capsule" (axis z), or "mesh".
    pub kind: &'static str,
    /// box: the 3 side lengths; sphere: the radius; cylinder, capsule: radius and length; mesh:
    /// the scale.
    pub size: Vec<f64>,
    /// Pose of the shape in its link's frame.
    pub origin: nalgebra::Isometry3<f64>,
    /// A mesh's file as resolved (the filename as written if it could not be), else `None`.
    pub file: Option<String>,
    /// A collision mesh's triangles in the file and vertices of its hull, and whether the
    /// hull came from the cache; `None` for primitives and visual shapes.
    pub hull: Option<(usize, usize, bool)>,
    /// A collision mesh's hull vertices in the shape's frame (scaled), to draw it; empty for
    /// primitives and visual shapes.
    pub points: Vec<[f64; 3]>,
}

/// A parsed and checked URDF robot.
#[derive(Debug, Clone)]
pub struct UrdfModel {
    pub(crate) robot: urdf_rs::Robot,
    pub(crate) origin: String,
    folder: PathBuf,
    joints: Vec<JointInfo>,
    mimics: Vec<MimicInfo>,
    /// `(link, collision element)` → its hull, for every mesh collision shape.
    pub(crate) hulls: Vec<((usize, usize), MeshHull)>,
    /// What was repaired while loading, one sentence each.
    warnings: Vec<String>,
}

impl UrdfModel {
    /// Reads and checks a URDF file.
    ///
    /// Fails with [`SimError::MissingFile`] if it cannot be read, is not a regular file (a FIFO,
    /// a device, a directory: [`crate::files`]) or has more than [`MAX_URDF_BYTES`], and
    /// otherwise as [`UrdfModel::parse_named`].
    pub fn from_file(path: impl AsRef<Path>) -> Result<Self> {
        Self::from_file_with_cache(path, cache::default_folder().as_deref())
    }

    /// [`UrdfModel::from_file`] with the mesh hull cache in `cache` (`None`: no cache).
    pub fn from_file_with_cache(path: impl AsRef<Path>, cache: Option<&Path>) -> Result<Self> {
        Self::from_file_with_options(path, cache, LoadOptions::default())
    }

    /// [`UrdfModel::from_file_with_cache`] with the repairs of `options`.
    pub fn from_file_with_options(path: impl AsRef<Path>, cache: Option<&Path>, options: LoadOptions) -> Result<Self> {
        let path = path.as_ref();
        let origin = path.display().to_string();
        // The variant's message says "cannot read URDF file …" already.
        let xml = crate::files::read_text(path, MAX_URDF_BYTES, "a URDF").map_err(|reason| SimError::MissingFile {
            path: origin.clone(),
            reason: reason.trim_start_matches("cannot read it: ").to_string(),
        })?;
        let parent = path
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let folder = std::fs::canonicalize(parent).unwrap_or_else(|_| parent.to_path_buf());
        Self::parse_with_options(&xml, &origin, &folder, cache, options)
    }

    /// Parses and checks a URDF document held in a string (mesh paths relative to the
    /// current folder).
    pub fn parse(xml: &str) -> Result<Self> {
        Self::parse_named(xml, "<string>", Path::new("."))
    }

    /// Parses and checks a URDF document as [`UrdfModel::parse_with`], with the default hull
    /// cache ([`cache::default_folder`]).
    pub fn parse_named(xml: &str, origin: &str, folder: &Path) -> Result<Self> {
        Self::parse_with(xml, origin, folder, cache::default_folder().as_deref())
    }

    /// Parses and checks a URDF document; `origin` names it in error messages, mesh files are
    /// found from `folder` ([`mesh::resolve`]) and their hulls cached in `cache`.
    ///
    /// Errors: [`SimError::UnsupportedJointType`] for a joint type other than revolute,
    /// continuous, prismatic or fixed (including unknown type strings);
    /// [`SimError::MalformedUrdf`] for bad XML, duplicate names, joints naming missing links,
    /// a mimic joint naming no moving joint or in a cycle of mimics,
    /// a joint graph that is not one tree (a joint joining a link to itself, a link with two
    /// parents, a cycle of joints, several root links: the joints and links named), empty or
    /// non-finite limits, a moving link without mass, a
    /// link with mass whose inertia tensor is not positive definite, breaks the triangle
    /// inequality or has a radius of gyration outside [1 µm, 1 km], non-finite inertial or
    /// collision poses, negative or non-finite collision sizes, a zero axis, a length or joint
    /// limit beyond ±1000 (m or rad), or a number too large for rapier's f32 (|value| > 3.4e38);
    /// [`SimError::Mesh`] for a collision mesh that cannot be found, read or hulled
    /// ([`mesh::load_hull`]). A document of more than [`MAX_URDF_BYTES`], nested deeper
    /// than [`MAX_URDF_DEPTH`] or with more than [`MAX_URDF_LINKS`] links is refused as
    /// malformed before it is parsed.
    pub fn parse_with(xml: &str, origin: &str, folder: &Path, cache: Option<&Path>) -> Result<Self> {
        Self::parse_with_options(xml, origin, folder, cache, LoadOptions::default())
    }

    /// A robot from `source`: the URDF XML itself if it starts with `<` (after white space;
    /// mesh paths relative to the working folder), else the path of a URDF file; with the
    /// default hull cache and the repairs of `options`.
    pub fn from_xml_or_file(source: &Path, options: LoadOptions) -> Result<Self> {
        let cache = cache::default_folder();
        match source.to_str() {
            Some(text) if text.trim_start().starts_with('<') => {
                Self::parse_with_options(text, "<string>", Path::new("."), cache.as_deref(), options)
            }
            _ => Self::from_file_with_options(source, cache.as_deref(), options),
        }
    }

    /// [`UrdfModel::parse_with`] with the repairs of `options`. Before the XML parser, a scan of
    /// the text refuses SDF, MJCF and xacro files by name and a malformed number naming its
    /// line and element, and repairs xacro's `$(optenv …)` and stray elements in `<geometry>`;
    /// after it, revolute joints without a range load as continuous and spherical joints as
    /// three continuous ones. Every repair is in [`UrdfModel::warnings`]. Without
    /// `balance_inertia`, the links whose inertia the physics cannot take are refused all in
    /// one error.
    pub fn parse_with_options(
        xml: &str,
        origin: &str,
        folder: &Path,
        cache: Option<&Path>,
        options: LoadOptions,
    ) -> Result<Self> {
        check_size(xml, origin)?;
        let scan = lint::scan(xml, origin)?;
        check_joint_types(&scan.text, origin)?;
        let bad = |reason: String| SimError::MalformedUrdf {
            origin: origin.to_string(),
            reason,
        };
        let mut robot = urdf_rs::read_from_string(&scan.text).map_err(|e| bad(e.to_string()))?;
        let mut warnings = scan.warnings;
        repair::unlimited_revolutes(&mut robot, &scan.no_range, &mut warnings);
        repair::split_spherical(&mut robot, &mut warnings).map_err(bad)?;
        repair::massless_frames(&mut robot, |m, t| inertia_problem(m, t).is_some(), &mut warnings);
        let (joints, mimics) = check_robot(&robot, origin)?;
        let mut model = Self {
            robot,
            origin: origin.to_string(),
            folder: folder.to_path_buf(),
            joints,
            mimics,
            hulls: Vec::new(),
            warnings,
        };
        let mut notes = Vec::new();
        model.hulls = model.load_hulls(cache, &mut notes)?;
        model.warnings.extend(notes);
        model.balance_inertia(options.balance_inertia)?;
        Ok(model)
    }

    /// Refuses (all in one error), or with `repair` balances, every link whose inertia the
    /// physics cannot take ([`repair::balanced`]).
    fn balance_inertia(&mut self, repair: bool) -> Result<()> {
        let problems = inertia_problems(&self.robot);
        if problems.is_empty() {
            return Ok(());
        }
        let bad = |reason: String| SimError::MalformedUrdf {
            origin: self.origin.clone(),
            reason,
        };
        if !repair {
            let list: Vec<String> = problems
                .iter()
                .map(|(l, p)| {
                    let link = &self.robot.links[*l];
                    format!(
                        "link {:?} has mass {} but its <inertia> {p}",
                        link.name, link.inertial.mass.value
                    )
                })
                .collect();
            return Err(bad(format!(
                "{} link(s) with an inertia the physics cannot take: {}; `latentrl urdf-info \
                 --balance-inertia` (LoadOptions::balance_inertia) repairs them, reporting each",
                list.len(),
                list.join("; ")
            )));
        }
        for (l, _) in problems {
            let link = &self.robot.links[l];
            let mut points = Vec::new();
            for (c, collision) in link.collision.iter().enumerate() {
                let pose = crate::pose::origin_pose(&collision.origin);
                let local = repair::primitive_corners(&collision.geometry).unwrap_or_else(|| {
                    let hull = self.hulls.iter().find(|(at, _)| *at == (l, c));
                    hull.map_or(Vec::new(), |(_, h)| {
                        h.points
                            .iter()
                            .map(|p| nalgebra::Point3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])))
                            .collect()
                    })
                });
                points.extend(local.iter().map(|p| pose * p));
            }
            let mass = link.inertial.mass.value;
            let Some((inertia, what)) = repair::balanced(link, &points, |t| inertia_problem(mass, t).is_none()) else {
                return Err(bad(format!(
                    "link {:?} has mass {mass} but an <inertia> {}, and no collision shape to size a \
                     repair from: give it an <inertia>",
                    link.name,
                    inertia_problem(mass, &link.inertial.inertia).unwrap_or_default()
                )));
            };
            self.warnings.push(format!("link {:?}: <inertia> {what}", link.name));
            self.robot.links[l].inertial.inertia = inertia;
        }
        Ok(())
    }

    /// What was repaired while loading (xacro leftovers, ranges, spherical joints, inertias),
    /// one sentence each naming the line, joint or link, and the hull cache folder or entries
    /// not used and why ([`cache`]); empty for a clean URDF and cache.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The convex hull of every mesh collision shape ([`mesh::load_hull`]); a cache folder that
    /// others may write is not used, and that, and each cache entry not used, is a sentence in
    /// `warnings`.
    fn load_hulls(&self, cache: Option<&Path>, warnings: &mut Vec<String>) -> Result<Vec<((usize, usize), MeshHull)>> {
        let meshes = self.robot.links.iter().flat_map(|l| &l.collision);
        let has_mesh = meshes
            .into_iter()
            .any(|c| matches!(c.geometry, urdf_rs::Geometry::Mesh { .. }));
        let cache = cache.filter(|dir| !has_mesh || cache::trusted(dir).map_err(|why| warnings.push(why)).is_ok());
        let mut out = Vec::new();
        for (l, link) in self.robot.links.iter().enumerate() {
            for (c, collision) in link.collision.iter().enumerate() {
                let urdf_rs::Geometry::Mesh { filename, scale } = &collision.geometry else {
                    continue;
                };
                let failed = |path: String, reason: String| SimError::Mesh {
                    link: link.name.clone(),
                    path,
                    reason,
                    origin: self.origin.clone(),
                };
                let path = mesh::resolve(filename, &self.folder).map_err(|e| failed(filename.clone(), e))?;
                let scale = scale.map_or([1.0; 3], |s| s.0);
                let hull = mesh::load_hull(&path, scale, cache, warnings)
                    .map_err(|e| failed(path.display().to_string(), e))?;
                out.push(((l, c), hull));
            }
        }
        Ok(out)
    }

    /// The robot's name attribute.
    pub fn name(&self) -> &str {
        &self.robot.name
    }

    /// The actuated joints, in URDF order (the order of postures and targets).
    pub fn joints(&self) -> &[JointInfo] {
        &self.joints
    }

    /// The mimic joints, in URDF order: each follows an actuated joint.
    pub fn mimics(&self) -> &[MimicInfo] {
        &self.mimics
    }

    /// Whether `name` is a joint with a servo (actuated or mimic): what `servo.joints` may name.
    pub fn is_servoed(&self, name: &str) -> bool {
        self.joint_index(name).is_ok() || self.mimics.iter().any(|m| m.joint.name == name)
    }

    /// The columns of demonstrations named `names` (rows of `names.len()` values each) as
    /// postures: for each actuated joint in URDF order, the index of its column. Columns may
    /// come in any order; a mimic joint's column is checked against its leader's
    /// ([`MimicInfo::follow`], within [`MIMIC_TOLERANCE`]) and dropped. Fails naming the
    /// missing, unknown or repeated joint, a row of another length, or the first row where a
    /// mimic column disagrees.
    pub fn demo_columns(&self, names: &[&str], rows: &[Vec<f64>]) -> Result<Vec<usize>> {
        let bad = |reason: String| SimError::DemoColumns { reason };
        if let Some(row) = rows.iter().find(|row| row.len() != names.len()) {
            let n = names.len();
            return Err(bad(format!("postures: {} columns for {n} joint names", row.len())));
        }
        for (k, name) in names.iter().enumerate() {
            if names[..k].contains(name) {
                return Err(bad(format!("joint {name:?} has two columns")));
            }
        }
        let unknown: Vec<&str> = names.iter().copied().filter(|n| !self.is_servoed(n)).collect();
        let missing: Vec<&str> = self.joint_names().into_iter().filter(|j| !names.contains(j)).collect();
        if !unknown.is_empty() || !missing.is_empty() {
            let listed = |names: &[&str]| {
                format!(
                    "[{}]",
                    names.iter().map(|n| format!("'{n}'")).collect::<Vec<_>>().join(", ")
                )
            };
            let mimics: Vec<&str> = self.mimics.iter().map(|m| m.joint.name.as_str()).collect();
            return Err(bad(format!(
                "missing {}, not joints of the robot {} (the columns are its actuated joints {}, in any order, \
                 and optionally its mimic joints {}; --joint-map NAME= (joint_map={{'NAME': ''}}) leaves another column out)",
                listed(&missing),
                listed(&unknown),
                listed(&self.joint_names()),
                listed(&mimics)
            )));
        }
        let column = |name: &str| names.iter().position(|n| *n == name).unwrap_or(0);
        let order: Vec<usize> = self.joints.iter().map(|j| column(&j.name)).collect();
        for m in &self.mimics {
            let Some(c) = names.iter().position(|n| *n == m.joint.name) else {
                continue;
            };
            let leader = order[m.leader];
            for (r, row) in rows.iter().enumerate() {
                let (value, expected) = (row[c], m.follow(row[leader]));
                let close = (value - expected).abs() <= MIMIC_TOLERANCE; // false for NaN
                if !close {
                    return Err(bad(format!(
                        "row {r}: mimic joint {:?} is {value}, but {} * {:?} ({}) + {} gives {expected} \
                         (clamped to its limits; tolerance {MIMIC_TOLERANCE})",
                        m.joint.name, m.multiplier, self.joints[m.leader].name, row[leader], m.offset
                    )));
                }
            }
        }
        Ok(order)
    }

    /// [`UrdfModel::demo_columns`] of the robot in the URDF file at `path`.
    pub fn demo_columns_of_file(path: &Path, names: &[String], rows: &[Vec<f64>]) -> Result<Vec<usize>> {
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        Self::from_file(path)?.demo_columns(&names, rows)
    }

    /// Names of the joints with a servo: the actuated ones, then the mimic ones.
    pub fn servoed_names(&self) -> Vec<&str> {
        let mimics = self.mimics.iter().map(|m| m.joint.name.as_str());
        self.joint_names().into_iter().chain(mimics).collect()
    }

    /// Total mass of the robot's links (kg).
    pub fn total_mass(&self) -> f64 {
        self.robot.links.iter().map(|l| l.inertial.mass.value).sum()
    }

    /// Names of the actuated joints, in URDF order.
    pub fn joint_names(&self) -> Vec<&str> {
        self.joints.iter().map(|j| j.name.as_str()).collect()
    }

    /// Index of the actuated joint called `name`, or [`SimError::UnknownJoint`].
    pub fn joint_index(&self, name: &str) -> Result<usize> {
        self.joints
            .iter()
            .position(|j| j.name == name)
            .ok_or_else(|| SimError::UnknownJoint {
                name: name.to_string(),
                known: self.joint_names().join(", "),
            })
    }

    /// Names of every URDF link (including body-less frames such as hands), in URDF order.
    pub fn link_names(&self) -> Vec<&str> {
        self.robot.links.iter().map(|l| l.name.as_str()).collect()
    }

    /// Every collision shape, link by link in URDF order.
    pub fn collision_shapes(&self) -> Vec<ShapeInfo> {
        let mut out = Vec::new();
        for (l, link) in self.robot.links.iter().enumerate() {
            for (c, collision) in link.collision.iter().enumerate() {
                let hull = self.hulls.iter().find(|(at, _)| *at == (l, c)).map(|(_, h)| h);
                let mut info = self.shape(l, &collision.geometry, &collision.origin);
                if let Some(h) = hull {
                    info.file = Some(h.path.display().to_string());
                    info.hull = Some((h.source_triangles, h.points.len(), h.cached));
                    info.points = h.points.iter().map(|p| p.map(f64::from)).collect();
                }
                out.push(info);
            }
        }
        out
    }

    /// `(link, hull vertices)` of every mesh collision shape, in URDF order: what the physics
    /// collides with.
    pub fn hull_points(&self) -> Vec<(usize, Vec<[f32; 3]>)> {
        self.hulls.iter().map(|((l, _), h)| (*l, h.points.clone())).collect()
    }

    /// Every visual shape, link by link in URDF order (not in the physics; to draw the robot).
    pub fn visual_shapes(&self) -> Vec<ShapeInfo> {
        let mut out = Vec::new();
        for (l, link) in self.robot.links.iter().enumerate() {
            out.extend(link.visual.iter().map(|v| self.shape(l, &v.geometry, &v.origin)));
        }
        out
    }

    /// A shape of link `link` as [`ShapeInfo`] (a mesh's file resolved where possible).
    fn shape(&self, link: usize, geometry: &urdf_rs::Geometry, origin: &urdf_rs::Pose) -> ShapeInfo {
        let (kind, size, file) = match geometry {
            urdf_rs::Geometry::Box { size } => ("box", size.0.to_vec(), None),
            urdf_rs::Geometry::Sphere { radius } => ("sphere", vec![*radius], None),
            urdf_rs::Geometry::Cylinder { radius, length } => ("cylinder", vec![*radius, *length], None),
            urdf_rs::Geometry::Capsule { radius, length } => ("capsule", vec![*radius, *length], None),
            urdf_rs::Geometry::Mesh { filename, scale } => {
                let file = mesh::resolve(filename, &self.folder).map_or(filename.clone(), |p| p.display().to_string());
                ("mesh", scale.map_or(vec![1.0; 3], |s| s.0.to_vec()), Some(file))
            }
        };
        ShapeInfo {
            link,
            kind,
            size,
            origin: crate::pose::origin_pose(origin),
            file,
            hull: None,
            points: Vec::new(),
        }
    }

    /// `(parent link, child link)` of every URDF joint, fixed ones included: the kinematic
    /// tree, e.g. to draw it.
    pub fn edges(&self) -> Vec<(&str, &str)> {
        self.robot
            .joints
            .iter()
            .map(|j| (j.parent.link.as_str(), j.child.link.as_str()))
            .collect()
    }

    /// Index of the URDF link called `name`, or [`SimError::UnknownLink`].
    pub fn link_index(&self, name: &str) -> Result<usize> {
        self.robot
            .links
            .iter()
            .position(|l| l.name == name)
            .ok_or_else(|| SimError::UnknownLink {
                name: name.to_string(),
                known: self.link_names().join(", "),
            })
    }
}
