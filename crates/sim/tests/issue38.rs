//! Issue #38, items 3–5: files read only if regular and under their cap (a FIFO answers at once,
//! a device or an oversized file is refused naming the cap), mesh counts checked against the
//! bytes present, URDF joint graphs that are not one tree refused naming their joints, and a
//! hull cache that is verified, not trusted.
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::Duration;

use sim::urdf::cache::MAX_CACHE_ENTRY_BYTES;
use sim::{MAX_URDF_BYTES, SimError, Task, UrdfModel};

/// A fresh empty folder for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("latentrl-issue38-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// `f()` run on a thread, or a failure if it has not answered within 10 s (a blocking read).
fn within<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(f());
    });
    rx.recv_timeout(Duration::from_secs(10))
        .expect("no answer within 10 s: the read blocked")
}

fn mkfifo(path: &Path) {
    let made = std::process::Command::new("mkfifo").arg(path).status().unwrap();
    assert!(made.success(), "mkfifo {}", path.display());
}

const INERTIAL: &str =
    r#"<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>"#;

/// A one-link robot whose collision shape is the mesh `mesh` (a path relative to the URDF).
fn mesh_robot(mesh: &str) -> String {
    format!(
        r#"<robot name="m"><link name="base">{INERTIAL}<collision><geometry><mesh filename="{mesh}"/></geometry></collision></link></robot>"#
    )
}

/// A binary STL of the unit cube (12 triangles, 8 vertices).
fn cube_stl() -> Vec<u8> {
    cube_stl_with(&[])
}

/// The unit cube's corner `i` (its bits are x, y, z).
fn corner(i: usize) -> [f32; 3] {
    [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32]
}

/// The unit cube's 12 triangles over its corners, outward.
const CUBE_FACES: [[u32; 3]; 12] = [
    [0, 2, 1],
    [1, 2, 3],
    [4, 5, 6],
    [5, 7, 6],
    [0, 1, 4],
    [1, 5, 4],
    [2, 6, 3],
    [3, 6, 7],
    [0, 4, 2],
    [2, 4, 6],
    [1, 3, 5],
    [3, 7, 5],
];

/// A binary STL of the unit cube's 12 triangles, then `more` triangles.
fn cube_stl_with(more: &[[[f32; 3]; 3]]) -> Vec<u8> {
    let triangles: Vec<[[f32; 3]; 3]> = CUBE_FACES
        .iter()
        .map(|f| f.map(|i| corner(i as usize)))
        .chain(more.iter().copied())
        .collect();
    let mut out = vec![0u8; 80];
    out.extend((triangles.len() as u32).to_le_bytes());
    for t in triangles {
        out.extend([0u8; 12]);
        out.extend(t.iter().flatten().flat_map(|v| v.to_le_bytes()));
        out.extend([0u8; 2]);
    }
    out
}

#[test]
fn issue38_a_fifo_as_urdf_task_or_mesh_is_refused_at_once() {
    let dir = scratch("fifo");
    let fifo = dir.join("pipe");
    mkfifo(&fifo);
    let at = fifo.clone();
    let err = within(move || UrdfModel::from_file_with_cache(&at, None).unwrap_err());
    assert!(matches!(err, SimError::MissingFile { .. }), "{err}");
    assert!(
        err.to_string().contains("pipe: is not a regular file (a FIFO)"),
        "{err}"
    );

    let at = fifo.clone();
    let err = within(move || Task::load(&at).unwrap_err()).to_string();
    assert!(err.contains("pipe: is not a regular file (a FIFO)"), "{err}");

    std::fs::write(dir.join("robot.urdf"), mesh_robot("pipe")).unwrap();
    let urdf = dir.join("robot.urdf");
    let err = within(move || UrdfModel::from_file_with_cache(&urdf, None).unwrap_err()).to_string();
    assert!(err.contains("collision mesh of link \"base\""), "{err}");
    assert!(err.contains("is not a regular file (a FIFO)"), "{err}");
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn issue38_devices_directories_and_files_over_the_cap_are_refused_naming_the_cap() {
    let err = UrdfModel::from_file_with_cache("/dev/zero", None)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("/dev/zero: is not a regular file (a character device)"),
        "{err}"
    );
    let err = Task::load("/dev/zero").unwrap_err().to_string();
    assert!(err.contains("is not a regular file (a character device)"), "{err}");
    let dir = scratch("cap");
    let err = Task::load(&dir).unwrap_err().to_string();
    assert!(err.contains("is not a regular file (a directory)"), "{err}");

    let big = dir.join("big.toml");
    std::fs::write(&big, vec![b'#'; (1 << 20) + 1]).unwrap();
    let err = Task::load(&big).unwrap_err().to_string();
    assert!(
        err.contains("is 1048577 bytes, more than the 1048576 bytes (1 MiB) a task file may have"),
        "{err}"
    );
    let big = dir.join("big.urdf");
    std::fs::write(&big, vec![b' '; MAX_URDF_BYTES as usize + 1]).unwrap();
    let err = UrdfModel::from_file_with_cache(&big, None).unwrap_err().to_string();
    assert!(
        err.contains("more than the 16777216 bytes (16 MiB) a URDF may have"),
        "{err}"
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn issue38_mesh_counts_beyond_their_bytes_are_refused_before_reading() {
    let dir = scratch("counts");
    // 1 KB of COLLADA declaring 2·10⁹ floats: the reader would have asked for 8 GB and aborted.
    let dae = r##"<?xml version="1.0"?><COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
<library_geometries><geometry id="g"><mesh><source id="p"><float_array id="a" count="2000000000">0 0 0 1 0 0 0 1 0 0 0 1</float_array>
<technique_common><accessor source="#a" count="4" stride="3"><param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
<vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
<triangles count="4"><input semantic="VERTEX" source="#v" offset="0"/><p>0 2 1 0 1 3 0 3 2 1 2 3</p></triangles></mesh></geometry></library_geometries>
<library_visual_scenes><visual_scene id="s"><node><instance_geometry url="#g"/></node></visual_scene></library_visual_scenes><scene><instance_visual_scene url="#s"/></scene></COLLADA>"##;
    std::fs::write(dir.join("bomb.dae"), dae).unwrap();
    std::fs::write(dir.join("robot.urdf"), mesh_robot("bomb.dae")).unwrap();
    let err = UrdfModel::from_file_with_cache(dir.join("robot.urdf"), None).unwrap_err();
    let SimError::Mesh { reason, .. } = &err else {
        panic!("{err}")
    };
    assert!(
        reason.contains("line 2: <float_array> declares count=2000000000 values but holds 12"),
        "{reason}"
    );
    // The same file with a truthful count loads.
    std::fs::write(dir.join("bomb.dae"), dae.replace("2000000000", "12")).unwrap();
    UrdfModel::from_file_with_cache(dir.join("robot.urdf"), None).unwrap();

    let mut stl = cube_stl();
    stl[80..84].copy_from_slice(&4_000_000_000u32.to_le_bytes());
    std::fs::write(dir.join("cube.stl"), &stl).unwrap();
    std::fs::write(dir.join("robot.urdf"), mesh_robot("cube.stl")).unwrap();
    let err = UrdfModel::from_file_with_cache(dir.join("robot.urdf"), None).unwrap_err();
    assert!(err.to_string().contains("declares 4000000000 triangles"), "{err}");
    std::fs::remove_dir_all(dir).unwrap();
}

/// A robot of links `a`, `b`, `c` (and `d`) joined by `joints`, each `(name, parent, child)`.
fn graph(joints: &[(&str, &str, &str)], links: &[&str]) -> String {
    let links: String = links
        .iter()
        .map(|l| format!(r#"<link name="{l}">{INERTIAL}</link>"#))
        .collect();
    let joints: String = joints
        .iter()
        .map(|(n, p, c)| {
            format!(
                r#"<joint name="{n}" type="revolute"><parent link="{p}"/><child link="{c}"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>"#
            )
        })
        .collect();
    format!(r#"<robot name="g">{links}{joints}</robot>"#)
}

fn refused(xml: &str) -> String {
    match UrdfModel::parse_with(xml, "g.urdf", Path::new("."), None) {
        Err(SimError::MalformedUrdf { reason, .. }) => reason,
        Err(other) => panic!("expected a malformed URDF, got {other}"),
        Ok(_) => panic!("loaded: {xml}"),
    }
}

#[test]
fn issue38_joint_graphs_that_are_not_one_tree_are_refused_naming_their_joints() {
    let abc = ["a", "b", "c"];
    let ok = graph(&[("shoulder", "a", "b"), ("elbow", "b", "c")], &abc);
    UrdfModel::parse_with(&ok, "g.urdf", Path::new("."), None).unwrap();

    let err = refused(&graph(
        &[("shoulder", "a", "b"), ("elbow", "b", "c"), ("loop", "c", "c")],
        &abc,
    ));
    assert!(
        err.contains(r#"joint "loop" has link "c" as both its parent and its child"#),
        "{err}"
    );

    let err = refused(&graph(
        &[("shoulder", "a", "b"), ("elbow", "b", "c"), ("again", "a", "c")],
        &abc,
    ));
    assert!(
        err.contains(r#"link "c" is the child of two joints, "elbow" (parent "b") and "again" (parent "a")"#),
        "{err}"
    );

    // A 2-cycle beside the root: its links are reachable from no root.
    let err = refused(&graph(
        &[("shoulder", "a", "b"), ("there", "c", "d"), ("back", "d", "c")],
        &["a", "b", "c", "d"],
    ));
    assert!(err.contains("form a cycle"), "{err}");
    assert!(
        err.contains(r#""there" ("c" -> "d")"#) && err.contains(r#""back" ("d" -> "c")"#),
        "{err}"
    );
    assert!(err.contains("lead to no root link"), "{err}");

    // A 3-cycle with no root at all.
    let err = refused(&graph(&[("ab", "a", "b"), ("bc", "b", "c"), ("ca", "c", "a")], &abc));
    assert!(
        err.contains(r#""ab""#) && err.contains(r#""bc""#) && err.contains(r#""ca""#),
        "{err}"
    );

    // Two roots: a link no joint reaches.
    let err = refused(&graph(&[("shoulder", "a", "b")], &abc));
    assert!(
        err.contains(r#"2 links are the child of no joint: "a" (a tree of 2 links), "c" (a tree of 1 links)"#),
        "{err}"
    );
}

/// A folder with `cube.stl` and `robot.urdf` colliding with it; the URDF's path.
fn cube_robot(dir: &Path) -> PathBuf {
    std::fs::write(dir.join("cube.stl"), cube_stl()).unwrap();
    let urdf = dir.join("robot.urdf");
    std::fs::write(&urdf, mesh_robot("cube.stl")).unwrap();
    urdf
}

/// The one entry of a cache folder.
fn entry(cache: &Path) -> PathBuf {
    let entries: Vec<PathBuf> = std::fs::read_dir(cache).unwrap().map(|e| e.unwrap().path()).collect();
    assert_eq!(entries.len(), 1, "{entries:?}");
    entries[0].clone()
}

/// An entry in the cache's format: `points`, `triangles`, and the source's triangle count.
fn entry_bytes(points: &[[f32; 3]], triangles: &[[u32; 3]], source: u32) -> Vec<u8> {
    let mut out = b"LRHULL01".to_vec();
    for word in [points.len() as u32, triangles.len() as u32, source] {
        out.extend(word.to_le_bytes());
    }
    out.extend(points.iter().flatten().flat_map(|v| v.to_le_bytes()));
    out.extend(triangles.iter().flatten().flat_map(|i| i.to_le_bytes()));
    out
}

/// Whether the first collision hull of `model` came from the cache.
fn cached(model: &UrdfModel) -> bool {
    model.collision_shapes()[0].hull.unwrap().2
}

/// parry's hull of a CAD mesh has sliver faces whose planes cut through the mesh (the SO-101's
/// STL meshes: by up to half their size), though it holds every vertex; a check of the mesh
/// against every face's plane refused every such entry, so each load hulled anew and warned.
#[test]
fn a_cached_hull_with_a_sliver_face_is_used() {
    let dir = scratch("sliver");
    let cache = dir.join("cache");
    // The cube with one more vertex `m` just inside its edge 0-1, on a triangle inside it.
    let m = [0.5, 1e-3, 1e-3];
    std::fs::write(
        dir.join("cube.stl"),
        cube_stl_with(&[[m, [0.5, 0.5, 0.5], [0.4, 0.5, 0.5]]]),
    )
    .unwrap();
    let urdf = dir.join("robot.urdf");
    std::fs::write(&urdf, mesh_robot("cube.stl")).unwrap();
    let fresh = UrdfModel::from_file_with_cache(&urdf, Some(&cache)).unwrap();
    // A hull as parry may write it: `m` on the surface, the four triangles around it tilted
    // inwards by 2 mrad, so the cube's far corners lie 2e-3 outside their planes.
    let points: Vec<[f32; 3]> = (0..8).map(corner).chain([m]).collect();
    let split = [[0, 2, 8], [8, 2, 1], [0, 8, 4], [8, 1, 4]]; // the faces at edge 0-1, through `m` (point 8)
    let faces: Vec<[u32; 3]> = CUBE_FACES
        .iter()
        .filter(|f| **f != [0, 2, 1] && **f != [0, 1, 4])
        .chain(&split)
        .copied()
        .collect();
    std::fs::write(entry(&cache), entry_bytes(&points, &faces, 13)).unwrap();
    let model = UrdfModel::from_file_with_cache(&urdf, Some(&cache)).unwrap();
    assert!(cached(&model) && model.warnings().is_empty(), "{:?}", model.warnings());
    assert_eq!(model.hull_points()[0].1.len(), 9);
    assert!(!cached(&fresh));
}

#[test]
fn issue38_a_tampered_cache_entry_is_not_used() {
    let dir = scratch("tamper");
    let cache = dir.join("cache");
    let urdf = cube_robot(&dir);
    let fresh = UrdfModel::from_file_with_cache(&urdf, Some(&cache)).unwrap();
    let again = UrdfModel::from_file_with_cache(&urdf, Some(&cache)).unwrap();
    assert!(!cached(&fresh) && cached(&again) && again.warnings().is_empty());
    let file = entry(&cache);

    // A hull of four of the cube's own corners (the vertex check passes): the rest of the cube
    // lies outside it.
    let tetra = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let forgeries = [
        (entry_bytes(&tetra, &faces, 12), "beyond it in direction"),
        (
            entry_bytes(&tetra.map(|p| p.map(|c| c * 0.5)), &faces, 12),
            "is no vertex of the mesh",
        ),
        (entry_bytes(&tetra, &faces[..3], 12), "do not close one surface"),
        (
            entry_bytes(&tetra, &faces, 7),
            "records 7 triangles in the mesh, which has 12",
        ),
        (
            entry_bytes(&tetra, &[[0, 1, 9]], 12),
            "has a triangle naming point 9 of 4",
        ),
        (b"LRHULL01\xff\xff\xff\xff".to_vec(), "too few for its counts"),
    ];
    for (forged, why) in forgeries {
        std::fs::write(&file, forged).unwrap();
        let model = UrdfModel::from_file_with_cache(&urdf, Some(&cache)).unwrap();
        assert!(!cached(&model), "a forged entry was used ({why})");
        assert_eq!(model.hull_points(), fresh.hull_points());
        let warnings = model.warnings().join("\n");
        assert!(
            warnings.contains(why) && warnings.contains("not used"),
            "{why}: {warnings}"
        );
        // Computed anew and rewritten: the next load is a clean hit.
        assert!(cached(&UrdfModel::from_file_with_cache(&urdf, Some(&cache)).unwrap()));
    }

    // Not a regular private file of at most its cap: not read.
    std::fs::remove_file(&file).unwrap();
    mkfifo(&file);
    let (u, c) = (urdf.clone(), cache.clone());
    let model = within(move || UrdfModel::from_file_with_cache(&u, Some(&c)).unwrap());
    assert!(
        model.warnings()[0].contains("is not a regular file (a FIFO): not used"),
        "{:?}",
        model.warnings()
    );
    std::fs::remove_file(&file).unwrap();
    std::fs::write(&file, vec![0u8; MAX_CACHE_ENTRY_BYTES as usize + 1]).unwrap();
    let model = UrdfModel::from_file_with_cache(&urdf, Some(&cache)).unwrap();
    assert!(
        model.warnings()[0].contains("(16 MiB) a hull cache entry may have"),
        "{:?}",
        model.warnings()
    );
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let model = UrdfModel::from_file_with_cache(&urdf, Some(&cache)).unwrap();
        assert!(cached(&model), "rewritten by the load before");
        std::fs::set_permissions(&file, std::fs::Permissions::from_mode(0o666)).unwrap();
        let model = UrdfModel::from_file_with_cache(&urdf, Some(&cache)).unwrap();
        assert!(!cached(&model));
        assert!(
            model.warnings()[0].contains("is writable by other users (mode 666)"),
            "{:?}",
            model.warnings()
        );
        let mode = std::fs::metadata(&file).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o600, "entries are written private");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

#[cfg(unix)]
#[test]
fn issue38_a_cache_folder_others_may_write_warns_and_is_not_used() {
    use std::os::unix::fs::PermissionsExt;
    let dir = scratch("shared-cache");
    let urdf = cube_robot(&dir);
    let cache = dir.join("cache");
    std::fs::create_dir(&cache).unwrap();
    std::fs::set_permissions(&cache, std::fs::Permissions::from_mode(0o777)).unwrap();
    for _ in 0..2 {
        let model = UrdfModel::from_file_with_cache(&urdf, Some(&cache)).unwrap();
        assert!(!cached(&model));
        let warning = model.warnings().join("\n");
        assert!(
            warning.contains(&format!(
                "hull cache folder {} is writable by other users (mode 777): not used",
                cache.display()
            )),
            "{warning}"
        );
    }
    assert_eq!(std::fs::read_dir(&cache).unwrap().count(), 0, "nothing written to it");

    // A private folder inside a folder anyone may write (no sticky bit): they could replace it.
    std::fs::set_permissions(&cache, std::fs::Permissions::from_mode(0o700)).unwrap();
    let inner = cache.join("hulls");
    std::fs::set_permissions(&cache, std::fs::Permissions::from_mode(0o777)).unwrap();
    let model = UrdfModel::from_file_with_cache(&urdf, Some(&inner)).unwrap();
    assert!(
        model.warnings()[0].contains("which any user may write (mode 777)"),
        "{:?}",
        model.warnings()
    );
    std::fs::set_permissions(&cache, std::fs::Permissions::from_mode(0o755)).unwrap();

    // Owned by another user (possible to set up only as root).
    let owned = std::process::Command::new("chown").arg("65534").arg(&cache).status();
    if owned.is_ok_and(|s| s.success()) {
        let model = UrdfModel::from_file_with_cache(&urdf, Some(&cache)).unwrap();
        assert!(!cached(&model));
        assert!(
            model.warnings()[0].contains("is owned by user 65534, not by us"),
            "{:?}",
            model.warnings()
        );
    }
    // A robot without meshes never reads the cache: no warning.
    let model = UrdfModel::parse_with(&graph(&[("j", "a", "b")], &["a", "b"]), "g", &dir, Some(&cache)).unwrap();
    assert!(model.warnings().is_empty());
    std::fs::remove_dir_all(dir).unwrap();
}
