//! Issue #8: inputs found by `cargo fuzz` (fuzz/, targets `urdf_parse` and `urdf_numbers`)
//! and their neighbours. Each was accepted by `UrdfModel::parse`, then made the posture NaN
//! in the first steps and panicked inside rapier on the next; now `parse` rejects it with a
//! `MalformedUrdf` naming the link or joint.
mod common;

const KHR1HV: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../python/latentrl/data/khr1hv.urdf");

/// The inertia of the humanoid's right forearm (40 g), as written in khr1hv.urdf.
const FOREARM: &str =
    r#"<mass value="0.04"/><inertia ixx="1.825e-05" ixy="0" ixz="0" iyy="1.825e-05" iyz="0" izz="3.840e-06"/>"#;

/// The humanoid with the first link inertia equal to [`FOREARM`] replaced by `to`.
fn humanoid_with(to: &str) -> String {
    let xml = std::fs::read_to_string(KHR1HV).unwrap();
    assert!(xml.contains(FOREARM), "the forearm inertia is in khr1hv.urdf");
    xml.replacen(FOREARM, to, 1)
}

use sim::{RootMode, SimError, UrdfModel, World, WorldConfig};

fn floating() -> WorldConfig {
    WorldConfig {
        root: RootMode::Floating,
        floor: Some(-1.0),
        ..WorldConfig::default()
    }
}

/// The shipped two-arm URDF with its first occurrence of `from` replaced by `to`.
fn arms_with(from: &str, to: &str) -> String {
    let xml = std::fs::read_to_string(common::TWO_ARMS).unwrap();
    assert!(xml.contains(from), "{from} is in two_arms.urdf");
    xml.replacen(from, to, 1)
}

fn malformed(xml: &str) -> String {
    match UrdfModel::parse(xml) {
        Err(SimError::MalformedUrdf { reason, .. }) => reason,
        other => panic!("expected MalformedUrdf, got {other:?}"),
    }
}

/// The fuzzer's input (minimised by hand): the base's `izz` underflows to 0. With a floating
/// root the multibody mass matrix was singular, the first steps made the posture NaN and the
/// next one panicked in rapier (`f32::clamp` with NaN bounds in the joint-motor constraint).
#[test]
fn zero_inertia_on_a_body_with_mass_is_rejected() {
    let xml = arms_with(r#"izz="1.0e-3""#, r#"izz="1.0e-99999993""#);
    let reason = malformed(&xml);
    assert!(
        reason.contains("\"base\"") && reason.contains("positive definite"),
        "{reason}"
    );
    for izz in ["0", "-1e-3", "1e-46"] {
        let reason = malformed(&arms_with(r#"izz="1.0e-3""#, &format!(r#"izz="{izz}""#)));
        assert!(reason.contains("positive definite"), "izz = {izz}: {reason}");
    }
}

#[test]
fn indefinite_inertia_tensor_is_rejected() {
    // Positive diagonal, but ixy² > ixx·iyy.
    let xml = arms_with(r#"ixy="0""#, r#"ixy="2.0e-3""#);
    assert!(malformed(&xml).contains("positive definite"));
}

#[test]
fn the_intact_arms_still_step_finitely_with_a_floating_root() {
    let xml = std::fs::read_to_string(common::TWO_ARMS).unwrap();
    let mut sim = World::new(UrdfModel::parse(&xml).unwrap(), floating()).unwrap();
    sim.set_targets(&[1.55, -1.5, 1.55, 1.5]).unwrap();
    sim.step(8);
    assert!(sim.joint_positions().iter().all(|q| q.is_finite()));
}

#[test]
fn non_finite_or_negative_collision_shapes_are_rejected() {
    let cases = [
        (
            r#"<box size="0.3 0.04 0.04"/>"#,
            r#"<box size="nan 0.04 0.04"/>"#,
            "box size",
        ),
        (
            r#"<box size="0.3 0.04 0.04"/>"#,
            r#"<box size="0.3 -0.04 0.04"/>"#,
            "box size",
        ),
        (r#"radius="0.02""#, r#"radius="inf""#, "radius"),
        (r#"length="0.26""#, r#"length="-1""#, "length"),
        (
            r#"<origin xyz="0 -0.05 0""#,
            r#"<origin xyz="0 nan 0""#,
            "collision> origin",
        ),
    ];
    for (from, to, what) in cases {
        let reason = malformed(&arms_with(from, to));
        assert!(reason.contains(what), "{to}: {reason}");
    }
}

#[test]
fn non_finite_inertial_origin_is_rejected() {
    let xml = arms_with(
        r#"<origin xyz="0.15 0 0" rpy="0 0 0"/>"#,
        r#"<origin xyz="inf 0 0" rpy="0 0 0"/>"#,
    );
    assert!(malformed(&xml).contains("<inertial>"));
}

#[test]
fn numbers_beyond_f32_are_rejected_with_their_name() {
    let cases = [
        (r#"<mass value="0.5"/>"#, r#"<mass value="1e39"/>"#, "mass"),
        (r#"lower="-3.3""#, r#"lower="-1e300""#, "limit lower"),
        (r#"effort="1000""#, r#"effort="1e39""#, "limit effort"),
        (r#"<origin xyz="0.3 0 0""#, r#"<origin xyz="0.3 4e38 0""#, "origin xyz"),
        (r#"<capsule radius="0.02""#, r#"<capsule radius="1e40""#, "radius"),
    ];
    for (from, to, what) in cases {
        let reason = malformed(&arms_with(from, to));
        assert!(reason.contains(what) && reason.contains("f32"), "{to}: {reason}");
    }
}

#[test]
fn an_axis_that_vanishes_in_f32_is_a_zero_axis() {
    let xml = arms_with(r#"<axis xyz="0 0 1"/>"#, r#"<axis xyz="0 0 1e-30"/>"#);
    assert!(malformed(&xml).contains("zero axis"));
}

/// `urdf_numbers` found this: one forearm with ixx = 28.49 beside iyy = 1.8e-5, izz = 3.8e-6
/// (no rigid body has such moments). With a floating root the posture was NaN after 4 steps;
/// ixx = 0.1 panicked in rapier.
#[test]
fn inertia_breaking_the_triangle_inequality_is_rejected() {
    for ixx in ["28.49", "0.1"] {
        let to = FOREARM.replace(r#"ixx="1.825e-05""#, &format!(r#"ixx="{ixx}""#));
        let reason = malformed(&humanoid_with(&to));
        assert!(reason.contains("triangle inequality"), "ixx = {ixx}: {reason}");
    }
}

/// A principal moment of 1e-20 kg m² on the 40 g forearm (or all three) made NaN too.
#[test]
fn vanishing_principal_moment_is_rejected() {
    for izz in ["1e-20", "3.9e-14"] {
        let to = FOREARM.replace(r#"izz="3.840e-06""#, &format!(r#"izz="{izz}""#));
        let reason = malformed(&humanoid_with(&to));
        assert!(reason.contains("principal moment"), "izz = {izz}: {reason}");
    }
}

/// Thin but real bodies still load, and step finitely standing free.
#[test]
fn thin_rods_and_rounded_plates_still_load() {
    let rod = FOREARM.replace(r#"izz="3.840e-06""#, r#"izz="1e-12""#);
    let plate = FOREARM.replace(r#"izz="3.840e-06""#, r#"izz="3.66e-05""#);
    for to in [rod, plate] {
        let model = UrdfModel::parse(&humanoid_with(&to)).unwrap();
        let mut sim = World::new(model, floating()).unwrap();
        sim.step(8);
        assert!(sim.joint_positions().iter().all(|q| q.is_finite()), "{to}");
    }
}

/// `urdf_numbers` found this too: the humanoid's knee origin moved to z = 1e20 m (within
/// f32, but m·r² is not) panicked in rapier on the first steps.
#[test]
fn lengths_beyond_a_kilometre_are_rejected() {
    let knee = r#"<origin xyz="0 0 -0.065"/><parent link="l_thigh"/>"#;
    let xml = std::fs::read_to_string(KHR1HV).unwrap();
    assert!(xml.contains(knee));
    let reason = malformed(&xml.replacen(knee, r#"<origin xyz="0 0 1e20"/><parent link="l_thigh"/>"#, 1));
    assert!(
        reason.contains("\"l_knee\"") && reason.contains("origin xyz"),
        "{reason}"
    );
    for (from, to, what) in [
        (
            r#"<box size="0.3 0.04 0.04"/>"#,
            r#"<box size="0.3 2e3 0.04"/>"#,
            "box size",
        ),
        (r#"lower="-3.3""#, r#"lower="-1e4""#, "limit lower"),
    ] {
        let reason = malformed(&arms_with(from, to));
        assert!(reason.contains(what) && reason.contains("1000"), "{to}: {reason}");
    }
    let huge = FOREARM.replace("e-05", "e+05").replace("e-06", "e+05");
    assert!(malformed(&humanoid_with(&huge)).contains("(1 km)^2"));
}
