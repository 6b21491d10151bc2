//! Issue #41: the defects of stock URDFs (pybullet_data), one synthetic robot per class, and
//! what the loader makes of each: refused naming line and element, or repaired and reported.
use std::path::Path;

use sim::urdf::LoadOptions;
use sim::{JointKind, SimError, UrdfModel, World, WorldConfig};

const INERTIA: &str =
    r#"<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>"#;

fn link(name: &str, inertial: &str) -> String {
    format!(
        r#"<link name="{name}">{inertial}<collision><geometry><box size="0.1 0.2 0.4"/></geometry></collision></link>"#
    )
}

fn robot(body: &str) -> String {
    format!(
        "<?xml version=\"1.0\"?>\n<robot name=\"t\">\n{}\n{body}\n</robot>",
        link("base", INERTIA)
    )
}

fn hinge(name: &str, child: &str, limit: &str) -> String {
    format!(
        r#"<joint name="{name}" type="revolute"><parent link="base"/><child link="{child}"/><axis xyz="0 0 1"/>{limit}</joint>"#
    )
}

fn load(xml: &str, balance_inertia: bool) -> Result<UrdfModel, SimError> {
    UrdfModel::parse_with_options(xml, "t.urdf", Path::new("."), None, LoadOptions { balance_inertia })
}

fn refusal(xml: &str) -> String {
    match load(xml, false) {
        Err(SimError::MalformedUrdf { reason, .. }) => reason,
        other => panic!("expected a malformed-URDF refusal, got {other:?}"),
    }
}

/// Steps the robot 1 s with its servos holding zero: every joint stays finite.
fn steps_finite(model: UrdfModel) {
    let mut world = World::new(model, WorldConfig::default()).unwrap();
    world.step(240);
    assert!(
        world.joint_positions().iter().all(|q| q.is_finite()),
        "{:?}",
        world.joint_positions()
    );
}

#[test]
fn inertias_breaking_the_triangle_inequality_are_all_named_then_balanced() {
    let bad = r#"<inertial><mass value="0.6"/><inertia ixx="4e-4" ixy="0" ixz="0" iyy="1.8e-3" iyz="0" izz="2.3e-3"/></inertial>"#;
    let xml = robot(&format!(
        "{}{}{}{}",
        link("a", bad),
        link("b", bad),
        hinge("ja", "a", r#"<limit lower="-1" upper="1" effort="10" velocity="1"/>"#),
        hinge("jb", "b", r#"<limit lower="-1" upper="1" effort="10" velocity="1"/>"#)
    ));
    let reason = refusal(&xml);
    assert!(
        reason.starts_with("2 link(s)") && reason.contains("link \"a\"") && reason.contains("link \"b\""),
        "{reason}"
    );
    assert!(reason.contains("--balance-inertia"), "{reason}");
    let model = load(&xml, true).unwrap();
    assert_eq!(model.warnings().len(), 2, "{:?}", model.warnings());
    let mean = (4e-4 + 1.8e-3 + 2.3e-3) / 3.0;
    assert!(
        model.warnings()[0].starts_with("link \"a\": <inertia> principal moments"),
        "{:?}",
        model.warnings()
    );
    assert!(
        model.warnings()[1].contains(&format!("their mean {mean:.4e}")),
        "{:?}",
        model.warnings()
    );
    steps_finite(model);
}

#[test]
fn an_all_zero_inertia_becomes_a_box_over_its_collision_shapes() {
    let zero = r#"<inertial><origin xyz="0 0 0.1"/><mass value="12"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>"#;
    let xml = robot(&format!(
        "{}{}",
        link("a", zero),
        hinge("j", "a", r#"<limit lower="-1" upper="1" effort="10" velocity="1"/>"#)
    ));
    let reason = refusal(&xml);
    assert!(reason.contains("is not positive definite"), "{reason}");
    let model = load(&xml, true).unwrap();
    let w = &model.warnings()[0];
    assert!(
        w.contains("solid box of 12 kg") && w.contains("0.100 x 0.200 x 0.400 m"),
        "{w}"
    );
    steps_finite(model);
    // No collision shape to size it from: refused, saying so.
    let bare = format!(
        r#"<link name="a">{zero}</link>{}"#,
        hinge("j", "a", r#"<limit lower="-1" upper="1" effort="10" velocity="1"/>"#)
    );
    let err = load(&robot(&bare), true).unwrap_err().to_string();
    assert!(err.contains("no collision shape to size a repair from"), "{err}");
}

#[test]
fn a_revolute_joint_without_a_range_is_continuous_an_explicit_zero_range_is_refused() {
    let xml = robot(&format!(
        "{}{}",
        link("a", INERTIA),
        hinge("j", "a", r#"<limit effort="10" velocity="1"/>"#)
    ));
    let model = load(&xml, false).unwrap();
    assert_eq!(model.joints()[0].kind, JointKind::Continuous);
    assert!(
        model.warnings()[0].contains("loaded as continuous"),
        "{:?}",
        model.warnings()
    );
    let zero = robot(&format!(
        "{}{}",
        link("a", INERTIA),
        hinge("j", "a", r#"<limit lower="0" upper="0" effort="10" velocity="1"/>"#)
    ));
    let reason = refusal(&zero);
    assert!(
        reason.contains("got [0, 0]: it cannot move; make it type=\"fixed\""),
        "{reason}"
    );
}

#[test]
fn a_spherical_joint_becomes_three_continuous_joints() {
    let ball =
        r#"<joint name="ball" type="spherical"><parent link="base"/><child link="a"/><origin xyz="0 0 0.5"/></joint>"#;
    let xml = robot(&format!("{}{ball}", link("a", INERTIA)));
    let model = load(&xml, false).unwrap();
    assert_eq!(model.joint_names(), ["ball_x", "ball_y", "ball_z"]);
    assert!(model.joints().iter().all(|j| j.kind == JointKind::Continuous));
    assert!(model.warnings()[0].contains("spherical, loaded as three continuous joints"));
    let mut world = World::new(model, WorldConfig::default()).unwrap();
    world.set_targets(&[0.3, -0.2, 0.5]).unwrap();
    world.step(480);
    let q = world.joint_positions();
    assert!(
        q.iter().zip([0.3, -0.2, 0.5]).all(|(q, t)| (q - t).abs() < 0.05),
        "{q:?}"
    );
    // A name the split would need is taken: refused naming it.
    let taken = robot(&format!("{}{}{ball}", link("a", INERTIA), link("ball_y_link", INERTIA)));
    assert!(refusal(&taken).contains("the name \"ball_y_link\" is taken"));
}

#[test]
fn other_formats_and_xacro_leftovers_are_named() {
    let err = |xml: &str| load(xml, false).unwrap_err().to_string();
    assert!(err("<?xml version='1.0'?>\n<sdf version='1.6'><model name='m'/></sdf>").contains("an SDF file"));
    assert!(err("<mujoco model='m'><worldbody/></mujoco>").contains("an MJCF file"));
    let xacro = robot(r#"<xacro:macro name="leg"><link name="x"/></xacro:macro>"#);
    assert!(err(&xacro).contains("line 4, <xacro:macro name=\"leg\">: a xacro file, not URDF: run xacro first"));
    let optenv = robot(&format!(
        r#"{}<joint name="imu" type="fixed"><origin xyz="$(optenv IMU_XYZ 0.19 0 0.149)"/><parent link="base"/><child link="a"/></joint>"#,
        link("a", INERTIA)
    ));
    let model = load(&optenv, false).unwrap();
    assert!(
        model.warnings()[0].contains("read as its default \"0.19 0 0.149\""),
        "{:?}",
        model.warnings()
    );
}

#[test]
fn a_malformed_number_names_its_line_and_element() {
    let xml = robot(&format!(
        "{}\n{}",
        link("a", INERTIA),
        hinge(
            "j",
            "a",
            r#"<limit lower="-1.57." upper="1.57" effort="1" velocity="1"/>"#
        )
    ));
    let reason = refusal(&xml);
    assert!(reason.starts_with("line 5, <limit lower=\"-1.57.\" upper=\"1.57\" effort=\"1\" velocity=\"1\"/>: lower: \"-1.57.\" is not a number"), "{reason}");
    let four = robot(
        r#"<joint name="j" type="fixed"><origin rpy="1 2 3 4"/><parent link="base"/><child link="base"/></joint>"#,
    );
    assert!(refusal(&four).contains("rpy: 4 numbers, expected 3"));
    let reason = refusal(&robot(&format!(
        "{}{}",
        link("a", INERTIA),
        hinge("j", "a", r#"<limit lower="-1" upper="1"/>"#)
    )));
    assert!(
        reason.contains("<limit lower=\"-1\" upper=\"1\"/>: effort and velocity are required"),
        "{reason}"
    );
}

#[test]
fn a_material_inside_geometry_is_dropped_and_reported() {
    let a = r#"<link name="a"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  <visual><geometry><box size="0.1 0.1 0.1"/><material name="grey"/></geometry></visual></link>"#;
    let model = load(
        &robot(&format!(
            "{a}{}",
            hinge("j", "a", r#"<limit lower="-1" upper="1" effort="10" velocity="1"/>"#)
        )),
        false,
    )
    .unwrap();
    assert!(
        model.warnings()[0].contains("<material> inside <geometry> of link \"a\" ignored"),
        "{:?}",
        model.warnings()
    );
    assert_eq!(model.visual_shapes().len(), 1);
}

#[test]
fn demo_columns_take_any_order_and_check_a_mimic_against_its_leader() {
    let follower = r#"<joint name="m" type="revolute"><parent link="base"/><child link="b"/><axis xyz="0 0 1"/>
  <limit lower="-2" upper="2" effort="10" velocity="1"/><mimic joint="ja" multiplier="2" offset="0.1"/></joint>"#;
    let limit = r#"<limit lower="-1" upper="1" effort="10" velocity="1"/>"#;
    let xml = robot(&format!(
        "{}{}{}{}{}{follower}",
        link("a", INERTIA),
        link("b", INERTIA),
        link("c", INERTIA),
        hinge("ja", "a", limit),
        hinge("jc", "c", limit)
    ));
    let model = load(&xml, false).unwrap();
    assert_eq!(model.joint_names(), ["ja", "jc"]);
    let rows = vec![vec![0.3, 1.1, 0.5], vec![-0.2, -0.3, -0.2]];
    assert_eq!(model.demo_columns(&["jc", "m", "ja"], &rows), Ok(vec![2, 0]));
    let reason = |names: &[&str], rows: &[Vec<f64>]| match model.demo_columns(names, rows) {
        Err(SimError::DemoColumns { reason }) => reason,
        other => panic!("expected a refusal, got {other:?}"),
    };
    let off = vec![rows[0].clone(), vec![-0.2, -0.25, -0.2]];
    let r = reason(&["jc", "m", "ja"], &off);
    assert!(
        r.starts_with("row 1: mimic joint \"m\" is -0.25, but 2 * \"ja\""),
        "{r}"
    );
    let r = reason(&["jc", "knee"], &[vec![0.0, 0.0]]);
    assert!(r.starts_with("missing ['ja'], not joints of the robot ['knee']"), "{r}");
    assert!(reason(&["ja", "jc", "ja"], &[vec![0.0; 3]]).contains("\"ja\" has two columns"));
    assert_eq!(reason(&["jc", "ja"], &rows), "postures: 3 columns for 2 joint names");
}

/// A tool frame as exporters write it (onshape-to-robot, the SO-101's `gripper_frame_link`): no
/// shape, a fixed joint, mass 1e-9 and a zero inertia. Loaded massless and folded into its
/// parent, with a warning; it still has a pose. A heavier such link is refused as before.
#[test]
fn a_frame_link_of_negligible_mass_is_loaded_massless() {
    let frame = |mass: &str| {
        format!(
            r#"<link name="tool"><inertial><mass value="{mass}"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link>
<joint name="tool_joint" type="fixed"><parent link="a"/><child link="tool"/><origin xyz="0 0 0.3"/></joint>"#
        )
    };
    let arm = format!(
        "{}{}",
        link("a", INERTIA),
        hinge("j", "a", r#"<limit lower="-1" upper="1" effort="10" velocity="1"/>"#)
    );
    let model = load(&robot(&format!("{arm}{}", frame("1e-9"))), false).unwrap();
    assert_eq!(model.warnings().len(), 1, "{:?}", model.warnings());
    assert!(
        model.warnings()[0]
            .starts_with(r#"link "tool": a frame (no shape, on fixed joint "tool_joint") with mass 1e-9 kg"#),
        "{:?}",
        model.warnings()
    );
    let mut world = World::new(model, WorldConfig::default()).unwrap();
    world.step(240);
    assert!(world.joint_positions().iter().all(|q| q.is_finite()));
    let tool = world.link_pose("tool").unwrap();
    assert!((tool.translation.vector.z - 0.3).abs() < 1e-3, "{tool:?}");
    // 1 g on a 2 kg robot is no frame to drop: refused as an inertia the physics cannot take.
    let reason = refusal(&robot(&format!("{arm}{}", frame("0.001"))));
    assert!(reason.contains(r#"link "tool" has mass 0.001"#), "{reason}");
}

/// A joint that turns a bare frame (no mass, no shape) is refused with what to do, unless a
/// link of mass is fixed to that frame: the loader then turns that link (the Gen3 lite's
/// `END_EFFECTOR` has neither).
#[test]
fn a_joint_turning_a_massless_link_is_refused_unless_a_mass_is_fixed_to_it() {
    let bare = r#"<link name="flange"/>"#;
    let turn = hinge(
        "j",
        "flange",
        r#"<limit lower="-1" upper="1" effort="10" velocity="1"/>"#,
    );
    let reason = refusal(&robot(&format!("{bare}{turn}")));
    assert!(
        reason.contains(r#"link "flange" is moved by joint "j" but has no mass, nor has a link fixed to it"#)
            && reason.contains(r#"make "j" type="fixed""#),
        "{reason}"
    );
    let tool = format!(
        r#"{}<joint name="mount" type="fixed"><parent link="flange"/><child link="tool"/><origin xyz="0 0 0.1"/></joint>"#,
        link("tool", INERTIA)
    );
    let model = load(&robot(&format!("{bare}{turn}{tool}")), false).unwrap();
    assert_eq!(model.joints().len(), 1);
    steps_finite(model);
}
