//! What a URDF holds as plain data (`latentrl urdf-info`, drawing a robot): its joints, actuated
//! first in URDF order and then the mimic ones, its links and shapes, mass and repairs.

use serde::Serialize;

use super::{JointInfo, ShapeInfo, UrdfModel};

/// A robot's contents, serialised as nested tables.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct UrdfSummary {
    /// The robot's name.
    pub name: String,
    /// Every joint: the actuated ones in URDF order, then the mimic ones.
    pub joints: Vec<JointSummary>,
    /// Every link, in URDF order.
    pub links: Vec<String>,
    /// The collision shapes.
    pub collision: Vec<ShapeSummary>,
    /// The visual shapes.
    pub visual: Vec<ShapeSummary>,
    /// Total mass of the inertials (kg).
    pub total_mass: f64,
    /// What loading repaired, one sentence each.
    pub warnings: Vec<String>,
}

/// One joint and, for a mimic joint, its leader and coupling.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JointSummary {
    /// The joint.
    #[serde(flatten)]
    pub joint: JointInfo,
    /// For a mimic joint: its leader and coupling.
    pub mimic: Option<MimicSummary>,
}

/// A mimic joint's coupling: `q = multiplier · q_leader + offset`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MimicSummary {
    /// The leader joint's name.
    pub leader: String,
    /// The multiplier.
    pub multiplier: f64,
    /// The offset.
    pub offset: f64,
}

/// One shape ([`ShapeInfo`] with its link named).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ShapeSummary {
    /// Its link's name.
    pub link: String,
    /// "box", "sphere", "cylinder", "capsule" or "mesh".
    pub kind: &'static str,
    /// Its size ([`ShapeInfo::size`]).
    pub size: Vec<f64>,
    /// Position and quaternion (x, y, z, w) in the link's frame.
    pub origin: Vec<f64>,
    /// A mesh's resolved file.
    pub file: Option<String>,
    /// A collision mesh's hull.
    pub hull: Option<HullSummary>,
    /// A collision mesh's hull vertices in the shape's frame.
    pub points: Vec<Vec<f64>>,
}

/// A collision mesh's convex hull.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HullSummary {
    /// Triangles in the mesh file.
    pub triangles: usize,
    /// Vertices of the hull.
    pub vertices: usize,
    /// Whether the hull came from the cache.
    pub cached: bool,
}

impl ShapeSummary {
    /// `shape` with its link named from `links`.
    pub fn new(shape: &ShapeInfo, links: &[&str]) -> Self {
        let (t, q) = (shape.origin.translation.vector, shape.origin.rotation.coords);
        Self {
            link: links[shape.link].to_string(),
            kind: shape.kind,
            size: shape.size.clone(),
            origin: vec![t.x, t.y, t.z, q.x, q.y, q.z, q.w],
            file: shape.file.clone(),
            hull: shape.hull.map(|(triangles, vertices, cached)| HullSummary {
                triangles,
                vertices,
                cached,
            }),
            points: shape.points.iter().map(|p| p.to_vec()).collect(),
        }
    }

    /// Every shape of `shapes`.
    pub fn all(shapes: &[ShapeInfo], links: &[&str]) -> Vec<Self> {
        shapes.iter().map(|s| Self::new(s, links)).collect()
    }
}

impl UrdfModel {
    /// What the URDF file at `path` holds, read with the default hull cache and the repairs of
    /// `options` ([`UrdfModel::summary`]).
    pub fn summary_of_file(path: &std::path::Path, options: super::LoadOptions) -> crate::error::Result<UrdfSummary> {
        let cache = super::cache::default_folder();
        Ok(Self::from_file_with_options(path, cache.as_deref(), options)?.summary())
    }

    /// What this robot holds as plain data.
    pub fn summary(&self) -> UrdfSummary {
        let links = self.link_names();
        let actuated = self.joints().iter().map(|j| (j, None));
        let mimics = self.mimics().iter().map(|m| {
            let coupling = MimicSummary {
                leader: self.joints()[m.leader].name.clone(),
                multiplier: m.multiplier,
                offset: m.offset,
            };
            (&m.joint, Some(coupling))
        });
        let joints = actuated
            .chain(mimics)
            .map(|(j, mimic)| JointSummary {
                joint: j.clone(),
                mimic,
            })
            .collect();
        UrdfSummary {
            name: self.name().to_string(),
            joints,
            links: links.iter().map(|l| l.to_string()).collect(),
            collision: ShapeSummary::all(&self.collision_shapes(), &links),
            visual: ShapeSummary::all(&self.visual_shapes(), &links),
            total_mass: self.total_mass(),
            warnings: self.warnings().to_vec(),
        }
    }
}
