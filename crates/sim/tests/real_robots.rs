//! Real robot descriptions (issue #17): the test arm `tests/robots/arm7_description` has
//! collision meshes in binary and ASCII STL, OBJ and COLLADA, `package://` and relative
//! paths, a continuous wrist, prismatic fingers, one of them a `<mimic>` of the other.
use std::path::{Path, PathBuf};

use sim::urdf::mesh::MAX_MESH_TRIANGLES;
use sim::{JointKind, PhysicsConfig, RootMode, ServoConfig, SimError, UrdfModel, World, WorldConfig};

const PACKAGE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/robots/arm7_description");

fn arm7_path() -> String {
    format!("{PACKAGE}/urdf/arm7.urdf")
}

/// A fresh empty folder for one test (cache or hostile files).
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("latentrl-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn arm7() -> UrdfModel {
    UrdfModel::from_file_with_cache(arm7_path(), None).expect("arm7 loads")
}

#[test]
fn arm7_joints_are_read_as_published() {
    let model = arm7();
    let names = model.joint_names();
    assert_eq!(names.len(), 8, "7 arm joints and the leading finger: {names:?}");
    let kinds: Vec<JointKind> = model.joints().iter().map(|j| j.kind).collect();
    assert_eq!(kinds[6], JointKind::Continuous);
    assert_eq!(kinds[7], JointKind::Prismatic);
    assert!(model.joints()[6].lower.is_infinite() && model.joints()[6].upper.is_infinite());
    assert_eq!(model.joints()[0].effort, Some(87.0));
    assert_eq!(model.joints()[4].effort, Some(12.0));
    let mimic = &model.mimics()[0];
    assert_eq!(mimic.joint.name, "finger_joint2");
    assert_eq!((mimic.leader, mimic.multiplier, mimic.offset), (7, 1.0, 0.0));
}

#[test]
fn every_mesh_format_gives_the_hull_of_its_prism() {
    // Links 0–7 are 24-sided prisms of radius 0.06 and length 0.12 (96 triangles each):
    // their hulls keep exactly the 48 rim vertices, at radius 0.06 and z = ±0.06, whatever
    // the format (binary STL 0–2, ASCII STL 3, OBJ 4–5, COLLADA 6–7).
    let shapes = arm7().collision_shapes();
    assert_eq!(shapes.len(), 11);
    for s in &shapes[..8] {
        let (triangles, vertices, cached) = s.hull.expect("a mesh hull");
        assert_eq!((triangles, vertices, cached), (96, 48, false), "link {}", s.link);
        let file = s.file.as_deref().unwrap();
        assert!(Path::new(file).is_file(), "{file}");
    }
    let model = arm7();
    for (_, hull) in model.hull_points() {
        for p in &hull {
            let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
            let on_rim = (r - 0.06).abs() < 1e-6 && (p[2].abs() - 0.06).abs() < 1e-6;
            let on_box = p.iter().all(|c| c.abs() < 0.11);
            assert!(on_rim || hull.len() == 8 && on_box, "{p:?}");
        }
    }
}

#[test]
fn package_and_relative_paths_resolve_to_the_same_folder() {
    let shapes = arm7().collision_shapes();
    let folder = |i: usize| {
        let file = PathBuf::from(shapes[i].file.clone().unwrap());
        std::fs::canonicalize(file.parent().unwrap()).unwrap()
    };
    // Link 1 by package://, link 2 by ../meshes relative to urdf/.
    assert_eq!(folder(1), folder(2));
    assert_eq!(
        folder(1),
        std::fs::canonicalize(format!("{PACKAGE}/meshes/collision")).unwrap()
    );
}

#[test]
fn visual_meshes_are_listed_and_not_simulated() {
    let model = arm7();
    let visuals = model.visual_shapes();
    assert_eq!(visuals.len(), 8);
    assert!(
        visuals
            .iter()
            .all(|v| v.kind == "mesh" && v.hull.is_none() && v.file.is_some())
    );
}

#[test]
fn second_load_reads_the_cache_and_simulates_bit_identically() {
    let cache = scratch("hull-cache");
    let fresh = arm7();
    let _fill = UrdfModel::from_file_with_cache(arm7_path(), Some(&cache)).unwrap();
    let second = UrdfModel::from_file_with_cache(arm7_path(), Some(&cache)).unwrap();
    let hits = |m: &UrdfModel| m.collision_shapes().iter().filter(|s| s.hull.unwrap().2).count();
    assert_eq!((hits(&fresh), hits(&second)), (0, 11));
    assert_eq!(fresh.hull_points(), second.hull_points());
    let run = |model: UrdfModel| {
        let config = WorldConfig {
            floor: Some(0.0),
            ..WorldConfig::default()
        };
        let mut w = World::new(model, config).unwrap();
        w.set_targets(&[0.5, 1.2, 0.0, -1.0, 0.0, 2.5, 0.3, 0.04]).unwrap();
        w.step(480);
        w.joint_positions()
    };
    let second_hulls = second.hull_points();
    let (a, b) = (run(fresh), run(second));
    assert!(
        a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()),
        "{a:?} vs {b:?}"
    );
    // A damaged entry is ignored, not trusted.
    for entry in std::fs::read_dir(&cache).unwrap() {
        std::fs::write(entry.unwrap().path(), b"LRHULL01garbage").unwrap();
    }
    let third = UrdfModel::from_file_with_cache(arm7_path(), Some(&cache)).unwrap();
    assert!(hits(&third) < 11, "a damaged entry was trusted");
    assert_eq!(third.hull_points(), second_hulls);
    std::fs::remove_dir_all(cache).unwrap();
}

#[test]
fn mimic_finger_follows_its_leader() {
    let mut w = World::new(arm7(), WorldConfig::default()).unwrap();
    for target in [0.03, 0.01, 0.04] {
        w.set_target("finger_joint1", target).unwrap();
        w.step(120);
        let leader = w.joint_positions()[7];
        let follower = w.mimic_positions()[0];
        assert!((leader - target).abs() < 1e-3, "leader {leader} vs target {target}");
        assert!(
            (follower - leader).abs() < 1e-3,
            "follower {follower} vs leader {leader}"
        );
    }
}

#[test]
fn arm_holds_a_posture_under_its_effort_caps() {
    // Gravity on; kp 20000 within the URDF's 87 / 12 N·m caps. Measured drift of the hand over
    // 2 s: see the assertion (steady-state PD error under gravity, ≈ torque / kp).
    let config = WorldConfig {
        servo: ServoConfig {
            kp: 20_000.0,
            kd: 200.0,
            ..ServoConfig::default()
        },
        ..WorldConfig::default()
    };
    let mut w = World::new(arm7(), config).unwrap();
    let posture = [0.3, 0.6, -0.2, -1.8, 0.4, 2.0, 0.8, 0.02];
    w.reset(&posture).unwrap();
    let hand = w.frame("tcp", [0.0; 3]).unwrap();
    let start = nalgebra::Vector3::from(w.frame_position(&hand));
    w.step(480);
    let end = nalgebra::Vector3::from(w.frame_position(&hand));
    let drift = (end - start).norm();
    assert!(drift < 0.003, "the hand drifted {drift} m in 2 s");
    assert!(w.joint_positions().iter().all(|q| q.is_finite()));
}

#[test]
fn floating_base_arm_stands_on_a_floor() {
    let config = WorldConfig {
        root: RootMode::Floating,
        floor: Some(0.0),
        ..WorldConfig::default()
    };
    let mut w = World::new(arm7(), config).unwrap();
    let base = nalgebra::Isometry3::translation(0.0, 0.0, 0.061);
    w.reset_with_base(&[0.0, 0.0, 0.0, -1.5, 0.0, 1.5, 0.0, 0.0], &base)
        .unwrap();
    w.step(480);
    let z = w.base_pose().translation.z;
    assert!((0.04..0.08).contains(&z), "base at z = {z} after 2 s on the floor");
}

#[test]
fn ignore_collisions_names_links_and_rejects_unknown_ones() {
    let physics = PhysicsConfig {
        self_collisions: true,
        ignore_collisions: vec![["link2".into(), "link4".into()], ["hand".into(), "no_such_link".into()]],
        ..PhysicsConfig::default()
    };
    let config = WorldConfig {
        physics,
        ..WorldConfig::default()
    };
    let err = World::new(arm7(), config).err().expect("unknown link refused");
    assert!(err.to_string().contains("physics.ignore_collisions[1][1]"), "{err}");
    assert!(err.to_string().contains("link2"), "lists the links: {err}");
}

/// A copy of the arm's package in a scratch folder with link 3's mesh replaced by `bytes`
/// (written as `name`), and its URDF path.
fn arm_with_mesh(test: &str, name: &str, bytes: &[u8]) -> PathBuf {
    let root = scratch(test).join("arm7_description");
    for sub in ["urdf", "meshes/collision"] {
        std::fs::create_dir_all(root.join(sub)).unwrap();
        for entry in std::fs::read_dir(format!("{PACKAGE}/{sub}")).unwrap() {
            let path = entry.unwrap().path();
            std::fs::copy(&path, root.join(sub).join(path.file_name().unwrap())).unwrap();
        }
    }
    std::fs::write(root.join("meshes/collision").join(name), bytes).unwrap();
    let urdf = root.join("urdf/arm7.urdf");
    let text = std::fs::read_to_string(&urdf)
        .unwrap()
        .replace("collision/link3.stl", &format!("collision/{name}"));
    std::fs::write(&urdf, text).unwrap();
    urdf
}

/// Removes the scratch folder of an [`arm_with_mesh`] copy.
fn remove_copy(urdf: &Path) {
    std::fs::remove_dir_all(urdf.ancestors().nth(3).unwrap()).unwrap();
}

fn mesh_error(urdf: &Path) -> (String, String, String) {
    match UrdfModel::from_file_with_cache(urdf, None) {
        Err(SimError::Mesh { link, path, reason, .. }) => (link, path, reason),
        Err(other) => panic!("expected a mesh error, got {other}"),
        Ok(_) => panic!("expected a mesh error, {} loaded", urdf.display()),
    }
}

fn binary_stl(triangles: &[[[f32; 3]; 3]]) -> Vec<u8> {
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
fn bad_meshes_are_refused_naming_link_and_file() {
    let cases: Vec<(&str, &str, Vec<u8>, &str)> = vec![
        ("mesh-empty", "empty.stl", Vec::new(), "not a mesh"),
        (
            "mesh-nan",
            "nan.obj",
            b"v 0 0 0\nv 1 0 0\nv nan 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\n".to_vec(),
            "non-finite",
        ),
        (
            "mesh-flat",
            "flat.obj",
            b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n".to_vec(),
            "flat",
        ),
        (
            "mesh-text",
            "words.obj",
            b"this is not a mesh\n".to_vec(),
            "no triangles",
        ),
    ];
    for (test, name, bytes, says) in cases {
        let urdf = arm_with_mesh(test, name, &bytes);
        let (link, path, reason) = mesh_error(&urdf);
        assert_eq!(link, "link3", "{test}");
        assert!(path.ends_with(name), "{test}: {path}");
        assert!(reason.contains(says), "{test}: {reason}");
        remove_copy(&urdf);
    }
}

#[test]
fn a_mesh_with_too_many_triangles_is_refused() {
    let tri = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let urdf = arm_with_mesh("mesh-huge", "huge.stl", &binary_stl(&vec![tri; MAX_MESH_TRIANGLES + 1]));
    let (_, _, reason) = mesh_error(&urdf);
    assert!(
        reason.contains(&format!("{} triangles", MAX_MESH_TRIANGLES + 1)),
        "{reason}"
    );
    remove_copy(&urdf);
}

#[test]
fn missing_meshes_and_escaping_paths_are_refused() {
    let urdf = arm_with_mesh("mesh-missing", "link3.stl", b"");
    std::fs::remove_file(urdf.parent().unwrap().join("../meshes/collision/link3.stl")).unwrap();
    let (link, path, reason) = mesh_error(&urdf);
    assert_eq!(link, "link3");
    assert!(
        path.ends_with("meshes/collision/link3.stl") && reason.contains("cannot read"),
        "{path}: {reason}"
    );
    remove_copy(&urdf);

    let text = std::fs::read_to_string(arm7_path()).unwrap();
    let device = text.replace("package://arm7_description/meshes/collision/link3.stl", "/dev/zero");
    let err = UrdfModel::parse_with(&device, "edited.urdf", Path::new(&format!("{PACKAGE}/urdf")), None).unwrap_err();
    assert!(err.to_string().contains("/dev/zero: is not a regular file"), "{err}");
    for (from, to, says) in [
        (
            "arm7_description/meshes/collision/link3.stl",
            "arm7_description/../../secret.stl",
            "leaves its package",
        ),
        (
            "arm7_description/meshes/collision/link3.stl",
            "other_description/link3.stl",
            "no folder \"other_description\"",
        ),
    ] {
        let edited = text.replace(from, to);
        let err =
            UrdfModel::parse_with(&edited, "edited.urdf", Path::new(&format!("{PACKAGE}/urdf")), None).unwrap_err();
        assert!(matches!(&err, SimError::Mesh { link, .. } if link == "link3"), "{err}");
        assert!(err.to_string().contains(says), "{err}");
    }
}

#[test]
fn broken_mimics_are_refused_naming_the_joint() {
    let text = std::fs::read_to_string(arm7_path()).unwrap();
    let folder = PathBuf::from(format!("{PACKAGE}/urdf"));
    let missing = text.replace("mimic joint=\"finger_joint1\"", "mimic joint=\"finger_jointX\"");
    let cycle = text.replace(
        "name=\"finger_joint1\" type=\"prismatic\">",
        "name=\"finger_joint1\" type=\"prismatic\"><mimic joint=\"finger_joint2\"/>",
    );
    for (xml, says) in [
        (missing, "joint \"finger_joint2\" mimics joint \"finger_jointX\""),
        (
            cycle,
            "mimic joints form a cycle: finger_joint1 -> finger_joint2 -> finger_joint1",
        ),
    ] {
        let err = UrdfModel::parse_with(&xml, "edited.urdf", &folder, None).unwrap_err();
        assert!(matches!(err, SimError::MalformedUrdf { .. }), "{err}");
        assert!(err.to_string().contains(says), "{err}");
    }
}

#[test]
fn listed_link_pairs_stop_colliding() {
    // Links 5 and 7 are not joined (link 6 lies between) but their prisms overlap (origins
    // 0.088 m apart, radius 0.06): with self-collisions on they push each other off the target
    // posture; listed in ignore_collisions they do not. Links 5–6 and 6–7 overlap as much but
    // are adjacent: that the arm then holds its posture shows adjacent links never collide.
    let drift = |ignore: Vec<[String; 2]>| {
        let physics = PhysicsConfig {
            self_collisions: true,
            ignore_collisions: ignore,
            ..PhysicsConfig::default()
        };
        let config = WorldConfig {
            physics,
            ..WorldConfig::default()
        };
        let mut w = World::new(arm7(), config).unwrap();
        let posture = [0.0, 0.0, 0.0, -1.5, 0.0, 1.5, 0.0, 0.02];
        w.reset(&posture).unwrap();
        w.step(240);
        let q = w.joint_positions();
        q.iter().zip(posture).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max)
    };
    let colliding = drift(Vec::new());
    let ignored = drift(vec![["link5".into(), "link7".into()]]);
    assert!(ignored < 0.01, "{ignored}");
    assert!(colliding > 10.0 * ignored, "{colliding} vs {ignored}");
}

#[test]
fn an_empty_root_keeps_the_origin_of_its_fixed_joint() {
    // rapier3d-urdf drops an empty root link and anchored its child at the world origin; the
    // child must sit at the fixed joint's origin (here 90° of yaw and an offset), as in the URDF.
    let xml = r#"<robot name="mounted">
      <link name="world"/>
      <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
      <link name="arm"><inertial><origin xyz="0.25 0 0"/><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
      <joint name="mount" type="fixed"><parent link="world"/><child link="base"/><origin xyz="0.1 0.2 0.3" rpy="0 0 1.5707963267948966"/></joint>
      <joint name="shoulder" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
      <link name="tip"/>
      <joint name="tip_joint" type="fixed"><parent link="arm"/><child link="tip"/><origin xyz="0.5 0 0"/></joint>
    </robot>"#;
    let w = World::new(UrdfModel::parse(xml).unwrap(), WorldConfig::default()).unwrap();
    let close = |a: [f64; 3], b: [f64; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-6);
    let at = |link: &str| w.frame_position(&w.frame(link, [0.0; 3]).unwrap());
    assert!(close(at("world"), [0.0; 3]), "{:?}", at("world"));
    assert!(close(at("base"), [0.1, 0.2, 0.3]), "{:?}", at("base"));
    // The arm points along the base's x, which the yaw turns onto world y.
    assert!(close(at("tip"), [0.1, 0.7, 0.4]), "{:?}", at("tip"));
}
