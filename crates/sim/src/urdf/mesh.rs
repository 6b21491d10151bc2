//! Collision meshes: finding a URDF `<mesh filename>`, reading it (STL, OBJ, COLLADA with
//! the `mesh-loader` crate) and turning it into one convex hull (parry's quickhull).
//!
//! Why a convex hull and not the triangle mesh: a robot link is a moving body, and rapier
//! finds contacts between two triangle meshes only at their surfaces (no volume: a link can
//! end up inside an obstacle and stay there) and at many times the cost of a convex shape.
//! One hull per mesh file is what MuJoCo does with every mesh geom; it fills concave parts
//! (a gripper's gap), which a convex decomposition would keep, at more shapes per link.
//!
//! Hulls are cached on disk ([`super::cache`]) under the hash of the file's bytes and the
//! scale, so a second load of the same robot saves the hull; the mesh is still parsed, to check
//! the entry against it ([`load_hull`]). A hull is built from the same points and triangles
//! either way, so the physics is bit-identical with or without the cache.

use std::path::{Component, Path, PathBuf};

use rapier3d::parry::transformation::try_convex_hull;
use rapier3d::prelude::{SharedShape, Vector};

use super::{cache, mesh_counts};

/// The largest mesh file read (bytes): bounds the memory a malformed or huge mesh takes.
pub const MAX_MESH_BYTES: u64 = 128 << 20;

/// The most triangles a collision mesh may have: real collision meshes have a few thousand
/// (a 7-DoF arm's 2k–10k per link); a million is a visual scan, to be simplified first.
pub const MAX_MESH_TRIANGLES: usize = 500_000;

/// A collision mesh turned into its convex hull.
#[derive(Debug, Clone)]
pub struct MeshHull {
    /// The file the mesh was read from (after `package://` and relative paths were resolved).
    pub path: PathBuf,
    /// Triangles in the file (all its meshes).
    pub source_triangles: usize,
    /// Vertices of the hull (scaled, in the link's collision frame).
    pub points: Vec<[f32; 3]>,
    /// Triangles of the hull (indices into `points`).
    pub triangles: Vec<[u32; 3]>,
    /// Whether the hull came from the cache.
    pub cached: bool,
    /// The collider shape: the convex polyhedron of `points` (built once, shared by every world).
    pub(crate) shape: SharedShape,
}

impl MeshHull {
    /// The hull of `points` and `triangles` with its collider shape, or an error if they enclose
    /// no volume (rapier cannot build it, or it is flat: [`is_flat`]).
    fn new(
        path: &Path,
        source_triangles: usize,
        points: Vec<[f32; 3]>,
        triangles: Vec<[u32; 3]>,
        cached: bool,
    ) -> Result<Self, String> {
        let vertices = points.iter().map(|p| Vector::new(p[0], p[1], p[2])).collect();
        let shape = SharedShape::convex_mesh(vertices, &triangles)
            .filter(|_| !is_flat(&points, &triangles))
            .ok_or("has no convex hull with a volume: is it flat?")?;
        Ok(Self {
            path: path.to_path_buf(),
            source_triangles,
            points,
            triangles,
            cached,
            shape,
        })
    }
}

/// The file a URDF mesh `filename` names, for a URDF in folder `urdf_dir`.
///
/// - `package://NAME/REST`: REST inside the package root, the nearest folder named NAME that
///   is the URDF's folder or one of its ancestors, or a folder NAME inside one of those (the
///   layout of a ROS description package, and of a URDF copied next to its package).
///   REST may not leave the package root (`..`).
/// - `file:///abs/path` and absolute paths: as written.
/// - Anything else: relative to the URDF's folder.
pub fn resolve(filename: &str, urdf_dir: &Path) -> Result<PathBuf, String> {
    if let Some(rest) = filename.strip_prefix("package://") {
        let (package, inner) = rest.split_once('/').unwrap_or((rest, ""));
        if package.is_empty() || inner.is_empty() {
            return Err("a package:// path needs a package name and a file: package://NAME/FILE".to_string());
        }
        let inside = Path::new(inner).components().all(|c| matches!(c, Component::Normal(_)));
        if !inside {
            return Err(format!(
                "{filename:?} leaves its package folder: package paths may not contain '..' or start at '/'"
            ));
        }
        let root = package_root(package, urdf_dir).ok_or_else(|| {
            format!(
                "no folder {package:?} is {} or one of its ancestors, or lies in one of them",
                urdf_dir.display()
            )
        })?;
        return Ok(root.join(inner));
    }
    let path = filename.strip_prefix("file://").unwrap_or(filename);
    Ok(urdf_dir.join(path))
}

/// The root of package `name` as [`resolve`] finds it.
fn package_root(name: &str, urdf_dir: &Path) -> Option<PathBuf> {
    let start = std::path::absolute(urdf_dir).ok()?;
    start.ancestors().find_map(|dir| {
        if dir.file_name().is_some_and(|n| n == name) {
            Some(dir.to_path_buf())
        } else {
            let inner = dir.join(name);
            inner.is_dir().then_some(inner)
        }
    })
}

/// Reads the mesh at `path`, scales it and returns its convex hull: from the cache folder
/// `cache` if given and its entry there is this mesh's hull (checked: `check_entry`), else
/// computed and stored there. An entry that is there but not used, or a cache folder others
/// may write, is a sentence in `warnings` ([`super::cache`]).
///
/// Errors (a sentence naming what was wrong; the caller adds the link and the path): a file
/// that is missing, unreadable, not a regular file, larger than [`MAX_MESH_BYTES`], declaring
/// more values than it holds ([`super::mesh_counts`]) or not a mesh the readers know; a mesh
/// without triangles, with more than [`MAX_MESH_TRIANGLES`], with a non-finite vertex, or flat
/// (no volume: no hull).
pub fn load_hull(
    path: &Path,
    scale: [f64; 3],
    cache: Option<&Path>,
    warnings: &mut Vec<String>,
) -> Result<MeshHull, String> {
    let bytes = crate::files::read_bounded(path, MAX_MESH_BYTES, "a mesh file")?;
    let (points, source_triangles) = read_points(&bytes, path, scale)?;
    let key = cache::key(&bytes, scale);
    if let Some(dir) = cache {
        match cache::read(dir, &key) {
            Ok(None) => {}
            Ok(Some((hull, triangles, source))) => {
                let hit = check_entry(&points, source_triangles, &hull, &triangles, source)
                    .and_then(|()| MeshHull::new(path, source, hull, triangles, true));
                match hit {
                    Ok(hit) => return Ok(hit),
                    Err(why) => warnings.push(format!(
                        "hull cache entry {} is not the hull of {}: {why}; not used",
                        dir.join(&key).display(),
                        path.display()
                    )),
                }
            }
            Err(why) => warnings.push(why),
        }
    }
    let made = hull_of_points(&points, path, source_triangles)?;
    if let Some(dir) = cache {
        cache::write(dir, &key, &made.points, &made.triangles, made.source_triangles);
    }
    Ok(made)
}

/// The convex hull of the mesh file held in `bytes` (`path` names it and gives its format by
/// extension), scaled: [`load_hull`] without the file and the cache (the fuzz target's entry).
pub fn hull_of_bytes(bytes: &[u8], path: &Path, scale: [f64; 3]) -> Result<MeshHull, String> {
    let (points, source_triangles) = read_points(bytes, path, scale)?;
    hull_of_points(&points, path, source_triangles)
}

/// The convex hull of a mesh's (scaled) `points`.
fn hull_of_points(points: &[Vector], path: &Path, source_triangles: usize) -> Result<MeshHull, String> {
    let (hull, triangles) = try_convex_hull(points).map_err(|e| format!("has no convex hull ({e:?}): is it flat?"))?;
    let points: Vec<[f32; 3]> = hull.iter().map(|p| [p.x, p.y, p.z]).collect();
    MeshHull::new(path, source_triangles, points, triangles, false)
}

/// Whether a cache entry (`hull`, `triangles`, `source` triangles) is the convex hull of a
/// mesh of `points` (scaled) and `source_triangles`: the same triangle count; every hull vertex
/// one of the mesh's (bit for bit, as the hull is made of them); triangles that close one
/// consistently oriented surface using every hull vertex; and the mesh reaching no further than
/// the hull in any of [`SUPPORT_DIRECTIONS`] directions ([`support_gap`]). Then the entry's hull
/// lies within the mesh and holds it up to [`SUPPORT_SLACK`] of its size. `Err` says what failed.
fn check_entry(
    points: &[Vector],
    source_triangles: usize,
    hull: &[[f32; 3]],
    triangles: &[[u32; 3]],
    source: usize,
) -> Result<(), String> {
    use std::collections::{HashMap, HashSet};
    if source != source_triangles {
        return Err(format!(
            "it records {source} triangles in the mesh, which has {source_triangles}"
        ));
    }
    let bits = |p: [f32; 3]| p.map(f32::to_bits);
    let vertices: HashSet<[u32; 3]> = points.iter().map(|v| bits([v.x, v.y, v.z])).collect();
    if let Some(p) = hull.iter().find(|p| !vertices.contains(&bits(**p))) {
        return Err(format!("its vertex {p:?} is no vertex of the mesh"));
    }
    let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
    for t in triangles {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            *edges.entry((a, b)).or_default() += 1;
        }
    }
    let closed = edges
        .iter()
        .all(|(&(a, b), &n)| n == 1 && edges.get(&(b, a)) == Some(&1));
    let used: HashSet<u32> = triangles.iter().flatten().copied().collect();
    if hull.len() < 4 || !closed || used.len() != hull.len() {
        return Err("its triangles do not close one surface over its vertices".to_string());
    }
    let distinct: Vec<[f32; 3]> = vertices.iter().map(|b| b.map(f32::from_bits)).collect();
    match support_gap(&distinct, hull) {
        Some((gap, d)) => Err(format!(
            "the mesh reaches {gap:.3e} beyond it in direction [{:.3}, {:.3}, {:.3}], more than \
             {SUPPORT_SLACK} of the mesh's size",
            d[0], d[1], d[2]
        )),
        None => Ok(()),
    }
}

/// Directions, spread evenly over the sphere, in which a cached hull must reach as far as its
/// mesh ([`support_gap`]): about 6° apart.
const SUPPORT_DIRECTIONS: usize = 1024;

/// How much less far than its mesh (a share of the mesh's size) a cached hull may reach in a
/// direction. parry's quickhull drops vertices within its own tolerance of a face: over the 264
/// STL meshes of the SO-101, Unitree Go1 and G1, Kinova Gen3 and ViperX descriptions it reached
/// at most 2.4e-5 of the size less far than the mesh (`docs/robustness.md`).
const SUPPORT_SLACK: f64 = 1e-3;

/// The largest amount by which `mesh` reaches further than the hull `points` in one of
/// [`SUPPORT_DIRECTIONS`] directions (a Fibonacci sphere), and that direction, if it is more
/// than [`SUPPORT_SLACK`] of the mesh's bounding-box diagonal. Coordinates relative to the
/// hull's centre in f32 (a hull far from the origin keeps its precision). Support values, not
/// the hull's face planes: parry's hull has sliver faces whose planes cut through the mesh
/// (the SO-101's: by up to half its size) though the hull holds every vertex.
fn support_gap(mesh: &[[f32; 3]], points: &[[f32; 3]]) -> Option<(f64, [f64; 3])> {
    type V = nalgebra::Vector3<f64>;
    let centre = points.iter().map(|q| V::from(q.map(f64::from))).sum::<V>() / points.len() as f64;
    let at = |q: &[f32; 3]| (V::from(q.map(f64::from)) - centre).map(|c| c as f32);
    let (mesh, hull): (Vec<_>, Vec<_>) = (mesh.iter().map(at).collect(), points.iter().map(at).collect());
    let (lo, hi) = mesh
        .iter()
        .fold((V::repeat(f64::MAX), V::repeat(f64::MIN)), |(lo, hi), q| {
            let q = q.map(f64::from);
            (lo.inf(&q), hi.sup(&q))
        });
    let size = (hi - lo).norm();
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let directions: Vec<V> = (0..SUPPORT_DIRECTIONS)
        .map(|k| {
            let z = 1.0 - (2 * k + 1) as f64 / SUPPORT_DIRECTIONS as f64;
            let r = (1.0 - z * z).sqrt();
            V::new(r * (golden * k as f64).cos(), r * (golden * k as f64).sin(), z)
        })
        .collect();
    let axis = |c: usize| directions.iter().map(|d| d[c] as f32).collect::<Vec<f32>>();
    let (ux, uy, uz) = (axis(0), axis(1), axis(2));
    // Each point against every direction: the inner loop over directions vectorises.
    let reach = |set: &[nalgebra::Vector3<f32>]| {
        let mut most = vec![f32::MIN; SUPPORT_DIRECTIONS];
        for q in set {
            for (m, ((x, y), z)) in most.iter_mut().zip(ux.iter().zip(&uy).zip(&uz)) {
                *m = m.max(q.x * x + q.y * y + q.z * z);
            }
        }
        most
    };
    let (far, near) = (reach(&mesh), reach(&hull));
    directions
        .iter()
        .zip(far.iter().zip(&near))
        .map(|(d, (f, n))| (f64::from(*f) - f64::from(*n), (*d).into()))
        .filter(|(gap, _)| *gap > SUPPORT_SLACK * size)
        .max_by(|a, b| a.0.total_cmp(&b.0))
}

/// Whether a hull encloses (almost) no volume: less than 1e-9 of its bounding box's diagonal
/// cubed (a flat or needle-thin mesh, which rapier cannot give a contact normal).
fn is_flat(points: &[[f32; 3]], triangles: &[[u32; 3]]) -> bool {
    let p = |i: u32| nalgebra::Vector3::from(points[i as usize].map(f64::from));
    let volume: f64 = triangles
        .iter()
        .map(|t| p(t[0]).dot(&p(t[1]).cross(&p(t[2]))))
        .sum::<f64>()
        / 6.0;
    let (lo, hi) = points.iter().fold(([f64::MAX; 3], [f64::MIN; 3]), |(lo, hi), q| {
        (
            [0, 1, 2].map(|k| lo[k].min(f64::from(q[k]))),
            [0, 1, 2].map(|k| hi[k].max(f64::from(q[k]))),
        )
    });
    let diagonal = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    volume.abs().partial_cmp(&(1e-9 * diagonal.powi(3))) != Some(std::cmp::Ordering::Greater)
}

/// The refusal of a mesh of `triangles` > [`MAX_MESH_TRIANGLES`].
pub(super) fn too_many_triangles(triangles: usize) -> String {
    format!(
        "has {triangles} triangles, more than the {MAX_MESH_TRIANGLES} a collision mesh may have \
         (simplify it first, e.g. with a decimation in MeshLab or Blender)"
    )
}

/// Every vertex of every mesh in the file, scaled, and the number of triangles.
fn read_points(bytes: &[u8], path: &Path, scale: [f64; 3]) -> Result<(Vec<Vector>, usize), String> {
    // OBJ material libraries are not needed for collisions: refuse to read them.
    let no_materials = |_: &Path| Err(std::io::Error::other("materials are not read"));
    // The counts the file declares fit in its bytes: the reader allocates what they say.
    mesh_counts::check(bytes, path)?;
    // The reader asserts on some malformed files (a COLLADA input naming another mesh's
    // vertices): a panic there is this file's error, not the caller's.
    let load = || mesh_loader::Loader::default().load_from_slice_with_reader(bytes, path, no_materials);
    let scene = std::panic::catch_unwind(std::panic::AssertUnwindSafe(load))
        .map_err(|_| "made the mesh reader fail (a malformed file)".to_string())?
        .map_err(|e| format!("is not a mesh the STL, OBJ and COLLADA readers accept: {e}"))?;
    let triangles: usize = scene.meshes.iter().map(|m| m.faces.len()).sum();
    if triangles == 0 {
        return Err("has no triangles".to_string());
    }
    if triangles > MAX_MESH_TRIANGLES {
        return Err(too_many_triangles(triangles));
    }
    let s = scale.map(|v| v as f32);
    let mut points = Vec::new();
    for mesh in &scene.meshes {
        for v in &mesh.vertices {
            if !v.iter().all(|c| c.is_finite()) {
                return Err(format!("has a non-finite vertex {v:?} in mesh {:?}", mesh.name));
            }
            points.push(Vector::new(v[0] * s[0], v[1] * s[1], v[2] * s[2]));
        }
    }
    Ok((points, triangles))
}
