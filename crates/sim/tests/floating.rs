//! A free-floating robot on the ground: root DoFs, reset of the base, contacts, fall test.
use nalgebra::Isometry3;
use sim::{FallCriteria, RootMode, UrdfModel, World, WorldConfig};

/// A 0.2 × 0.2 × 0.1 m block (1 kg) with a 0.3 m arm on a hinge about y at its top.
const ROBOT: &str = r#"<robot name="block">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="4e-3" ixy="0" ixz="0" iyy="4e-3" iyz="0" izz="7e-3"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <link name="arm">
    <inertial><origin xyz="0 0 0.15"/><mass value="0.2"/>
      <inertia ixx="1.5e-3" ixy="0" ixz="0" iyy="1.5e-3" iyz="0" izz="1e-5"/></inertial>
    <collision><origin xyz="0 0 0.15"/><geometry><capsule radius="0.01" length="0.28"/></geometry></collision>
  </link>
  <joint name="hinge" type="revolute">
    <origin xyz="0 0 0.05"/><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>
    <limit lower="-1.5" upper="1.5" effort="50" velocity="5"/>
  </joint>
</robot>"#;

fn block() -> World {
    let options = WorldConfig {
        root: RootMode::Floating,
        floor: Some(0.0),
        ..WorldConfig::default()
    };
    World::new(UrdfModel::parse(ROBOT).unwrap(), options).unwrap()
}

#[test]
fn floating_block_falls_onto_the_ground_and_keeps_moving_its_arm() {
    let mut sim = block();
    assert_eq!(sim.num_joints(), 1, "the free root is not part of the posture");
    sim.reset_with_base(&[0.0], &Isometry3::translation(0.1, -0.2, 0.3))
        .unwrap();
    let base = sim.base_pose().translation;
    assert!((base.x - 0.1).abs() < 1e-6 && (base.z - 0.3).abs() < 1e-6, "{base:?}");
    assert!(!sim.touching_ground("base").unwrap());
    sim.step(480);
    let z = sim.base_pose().translation.z;
    assert!((z - 0.05).abs() < 5e-3, "the block rests on the ground: z = {z}");
    assert!(sim.touching_ground("base").unwrap());
    // Bodies never sleep: a new target after 2 s of rest still moves the arm.
    sim.set_targets(&[0.5]).unwrap();
    sim.step(60);
    assert!(
        (sim.joint_positions()[0] - 0.5).abs() < 0.05,
        "{:?}",
        sim.joint_positions()
    );
}

#[test]
fn fall_test_reads_base_height_tilt_and_ground_contacts() {
    let mut sim = block();
    sim.reset_with_base(&[0.0], &Isometry3::translation(0.0, 0.0, 0.3))
        .unwrap();
    sim.step(240);
    let standing = FallCriteria {
        min_base_height: 0.03,
        max_sole_tilt: 0.35,
        soles: vec!["base".into()],
    };
    let status = sim.fall_status(&standing).unwrap();
    assert!(
        !status.fell && status.sole_tilt < 0.05 && status.ground_contact.is_none(),
        "{status:?}"
    );
    let strict = FallCriteria {
        min_base_height: 0.1,
        ..standing.clone()
    };
    assert!(sim.fall_status(&strict).unwrap().fell);
    // A hard swing sideways tips the block: the arm (not a sole) hits the floor.
    sim.set_targets(&[1.5]).unwrap();
    sim.step(240);
    let status = sim.fall_status(&standing).unwrap();
    assert_eq!(status.ground_contact.as_deref(), Some("arm"), "{status:?}");
    assert!(status.fell);
}

#[test]
fn reset_on_floor_stands_the_sole_on_the_worlds_floor_and_needs_one() {
    let mut sim = block();
    sim::fall::reset_on_floor(&mut sim, &[0.0], "base", 0.0).unwrap();
    let z = sim.base_pose().translation.z;
    assert!(
        (z - 0.05).abs() < 1e-9,
        "the block's 0.1 m box rests on the floor: z = {z}"
    );
    let options = WorldConfig {
        root: RootMode::Floating,
        ..WorldConfig::default()
    };
    let mut bare = World::new(UrdfModel::parse(ROBOT).unwrap(), options).unwrap();
    let err = sim::fall::reset_on_floor(&mut bare, &[0.0], "base", 0.0).unwrap_err();
    assert!(err.to_string().contains("no floor"), "{err}");
}

/// A 0.4 × 0.2 × 0.1 m body (4 kg) on four 0.2 m legs, each hinged about y at a corner and
/// ending in a fixed sphere foot (r 2 cm) as a Unitree quadruped's do.
fn quadruped() -> String {
    let mut body = String::from(
        r#"<robot name="quad"><link name="body"><inertial><mass value="4"/>
        <inertia ixx="0.017" ixy="0" ixz="0" iyy="0.057" iyz="0" izz="0.067"/></inertial>
        <collision><geometry><box size="0.4 0.2 0.1"/></geometry></collision></link>"#,
    );
    for (name, x, y) in [
        ("fl", 0.2, 0.1),
        ("fr", 0.2, -0.1),
        ("hl", -0.2, 0.1),
        ("hr", -0.2, -0.1),
    ] {
        body.push_str(&format!(
            r#"<link name="{name}_leg"><inertial><origin xyz="0 0 -0.1"/><mass value="0.3"/>
            <inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-4"/></inertial>
            <collision><origin xyz="0 0 -0.1"/><geometry><cylinder radius="0.015" length="0.16"/></geometry></collision></link>
            <joint name="{name}_hip" type="revolute"><origin xyz="{x} {y} -0.05"/><parent link="body"/>
            <child link="{name}_leg"/><axis xyz="0 1 0"/><limit lower="-0.8" upper="0.8" effort="40" velocity="10"/></joint>
            <link name="{name}_foot"><inertial><mass value="0.05"/>
            <inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/></inertial>
            <collision><geometry><sphere radius="0.02"/></geometry></collision></link>
            <joint name="{name}_ankle" type="fixed"><origin xyz="0 0 -0.2"/><parent link="{name}_leg"/>
            <child link="{name}_foot"/></joint>"#
        ));
    }
    body + "</robot>"
}

/// Sphere feet as soles (issue #37's zoo has box feet only; a Go1's and a G1's are spheres): the
/// task loads, a reset stands the body upright with the feet on the floor, the support polygon
/// is the four feet's lowest points (the centre of mass 0.1 m inside its long side), and
/// tilting legs is no fall where a sole plane would have tilted past 20°.
#[test]
fn a_quadruped_with_sphere_feet_stands_on_them() {
    use sim::task::parse_toml;
    let dir = std::env::temp_dir().join(format!("latentrl-quad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("quad.urdf"), quadruped()).unwrap();
    let config = parse_toml(
        r#"name = "quad"
urdf = "quad.urdf"
root = "floating"
effectors = ["fl_foot"]
[floor]
height = 0.0
[target]
position = [[0.3, 0.1, 0.05]]
[fall]
soles = ["fl_foot", "fr_foot", "hl_foot", "hr_foot"]
"#,
    )
    .unwrap();
    let task = std::sync::Arc::new(sim::Task::from_config(config, &dir, "quad.toml").unwrap());
    let mut plant = sim::TaskPlant::new(task, None).unwrap();
    for posture in [[0.0; 4], [0.5; 4]] {
        assert_eq!(latent_core::Plant::reset(&mut plant, &posture), None, "{posture:?}");
        let world = plant.world();
        let lowest = world.lowest_point().unwrap();
        assert!(
            (lowest - sim::fall::GROUND_CLEARANCE).abs() < 1e-6,
            "lowest point {lowest}"
        );
        let up = world.base_pose().rotation * nalgebra::Vector3::z();
        assert!(up.z > 1.0 - 1e-9, "the body stands upright: {up:?}");
        let feet: Vec<f64> = ["fl_foot", "hr_foot"]
            .iter()
            .map(|f| sim::fall::sole_points(world, f).unwrap()[0].z)
            .collect();
        assert!(feet.iter().all(|z| (z - lowest).abs() < 1e-6), "{feet:?}");
    }
    let margin = plant.support_margin().unwrap();
    assert!((margin - 0.1).abs() < 1e-3, "support margin {margin}");
    let mut reached = [0.0; 4];
    for _ in 0..20 {
        let outcome = latent_core::Plant::step(&mut plant, &[0.5; 4], &mut reached);
        assert_eq!(outcome.end, None, "the legs lean 29°, the feet stay down");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
