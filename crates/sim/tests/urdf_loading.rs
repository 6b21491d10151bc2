//! Loading URDFs: the shipped arms, and each kind of bad input → its `SimError` variant.
mod common;

use latent_core::CoreError;
use sim::{JointKind, PhysicsConfig, SimError, UrdfModel, World, WorldConfig};

fn robot(body: &str) -> String {
    format!(
        r#"<?xml version="1.0"?>
<robot name="t">
  <link name="base"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <link name="arm"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  {body}
</robot>"#
    )
}

const HINGE: &str = r#"<joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
  <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="2"/></joint>"#;

#[test]
fn arms_file_has_four_hinges_in_urdf_order() {
    let model = common::arms_model();
    assert_eq!(model.name(), "two_arms");
    assert_eq!(
        model.joint_names(),
        ["left_shoulder", "left_elbow", "right_shoulder", "right_elbow"]
    );
    let j = &model.joints()[1];
    assert_eq!(j.kind, JointKind::Revolute);
    assert_eq!(
        (j.lower, j.upper, j.effort, j.velocity),
        (-3.3, 0.3, Some(1000.0), Some(20.0))
    );
    assert_eq!(j.damping, None);
    assert_eq!(model.joint_index("right_elbow"), Ok(3));
    assert!(model.link_names().contains(&"left_hand"));
}

#[test]
fn arms_plant_reports_hand_frames_that_have_no_body() {
    let sim = common::arms(WorldConfig::default());
    assert_eq!(sim.num_joints(), 4);
    assert!(sim.frame("left_hand", [0.0; 3]).is_ok());
    assert!(matches!(
        sim.frame("left_foot", [0.0; 3]),
        Err(SimError::UnknownLink { .. })
    ));
}

#[test]
fn minimal_string_robot_loads() {
    let model = UrdfModel::parse(&robot(HINGE)).unwrap();
    assert_eq!(model.joint_names(), ["j"]);
    let sim = World::new(model, WorldConfig::default()).unwrap();
    assert_eq!(sim.joint_positions(), [0.0]);
}

#[test]
fn missing_file_is_reported_with_its_path() {
    let err = UrdfModel::from_file("/nonexistent/robot.urdf").unwrap_err();
    assert!(
        matches!(&err, SimError::MissingFile { path, .. } if path == "/nonexistent/robot.urdf"),
        "{err}"
    );
}

#[test]
fn malformed_tag_is_malformed_urdf() {
    let broken = robot(HINGE).replace("<child link=\"arm\"/>", "<child link=\"arm\">");
    let err = UrdfModel::parse(&broken).unwrap_err();
    assert!(
        matches!(&err, SimError::MalformedUrdf { origin, .. } if origin == "<string>"),
        "{err}"
    );
}

#[test]
fn unknown_and_unsupported_joint_types_are_named() {
    // `spherical` loads as three continuous joints (tests/stock_defects.rs).
    for kind in ["hinge", "floating", "planar"] {
        let err = UrdfModel::parse(&robot(&HINGE.replace("revolute", kind))).unwrap_err();
        assert!(
            matches!(&err, SimError::UnsupportedJointType { joint, kind: k, .. } if joint == "j" && k == kind),
            "{kind}: {err}"
        );
    }
    // A commented-out joint does not count.
    let commented = robot(&format!("<!-- <joint name=\"x\" type=\"hinge\"/> -->{HINGE}"));
    assert!(UrdfModel::parse(&commented).is_ok());
}

#[test]
fn structural_errors_are_malformed_urdf() {
    let cases = [
        HINGE.replace("child link=\"arm\"", "child link=\"nope\""),
        HINGE.replace("lower=\"-1\" upper=\"1\"", "lower=\"1\" upper=\"-1\""),
        format!("{HINGE}{}", HINGE.replace("name=\"j\"", "name=\"k\"")),
    ];
    for case in cases {
        let err = UrdfModel::parse(&robot(&case)).unwrap_err();
        assert!(matches!(err, SimError::MalformedUrdf { .. }), "{err}");
    }
}

#[test]
fn missing_mesh_names_its_link_and_the_path_tried() {
    let mesh = r#"<link name="m"><collision><geometry><mesh filename="a.stl"/></geometry></collision></link>
        <joint name="f" type="fixed"><parent link="arm"/><child link="m"/></joint>"#;
    let err = UrdfModel::parse(&robot(&format!("{HINGE}{mesh}"))).unwrap_err();
    assert!(
        matches!(&err, SimError::Mesh { link, path, .. } if link == "m" && path.ends_with("a.stl")),
        "{err}"
    );
}

#[test]
fn unknown_joint_name_lists_the_known_ones() {
    let mut sim = common::arms(WorldConfig::default());
    let err = sim.set_target("left_wrist", 0.1).unwrap_err();
    assert!(
        matches!(&err, SimError::UnknownJoint { known, .. } if known.contains("left_elbow")),
        "{err}"
    );
}

#[test]
fn bad_options_and_inputs_are_rejected() {
    let bad = WorldConfig {
        physics: PhysicsConfig {
            dt: 0.0,
            ..PhysicsConfig::default()
        },
        ..WorldConfig::default()
    };
    let err = World::new(common::arms_model(), bad).err().expect("dt = 0 is refused");
    assert_eq!(err.to_string(), "physics.dt must lie in (0, 0.05], got 0");
    let mut sim = common::arms(WorldConfig::default());
    assert!(matches!(
        sim.set_targets(&[0.0; 3]),
        Err(SimError::Input(CoreError::Shape { .. }))
    ));
    assert!(matches!(
        sim.set_targets(&[0.0, f64::NAN, 0.0, 0.0]),
        Err(SimError::Input(CoreError::NonFinite { index: 1, .. }))
    ));
    assert!(matches!(
        sim.reset(&[0.0, 1.0, 0.0, 0.0]),
        Err(SimError::InvalidJointParameter { .. })
    ));
    let gains = sim::PdGains {
        kp: -1.0,
        ..Default::default()
    };
    assert!(matches!(
        sim.set_gains("left_elbow", gains),
        Err(SimError::InvalidJointParameter { name: "kp", .. })
    ));
}
