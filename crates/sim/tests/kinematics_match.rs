//! Link and hand poses of the physics plant against independent f64 forward kinematics.
mod common;

use nalgebra::{Matrix3, Matrix4, Vector3};
use sim::{PhysicsConfig, PlanarArms, UrdfModel, World, WorldConfig};

#[test]
fn hands_match_the_analytic_arms_for_random_postures() {
    let mut sim = common::arms(WorldConfig::default());
    let left = sim.frame("left_hand", [0.0; 3]).unwrap();
    let right = sim.frame("right_hand", [0.0; 3]).unwrap();
    let arms = PlanarArms::default();
    let mut rng = common::Rng(7);
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let posture = rng.arms_posture();
        sim.reset(&posture).unwrap();
        let expected = arms.hands(&posture);
        let [xl, yl, zl] = sim.frame_position(&left);
        let [xr, yr, zr] = sim.frame_position(&right);
        for (got, want) in [xl, yl, xr, yr].iter().zip(expected) {
            worst = worst.max((got - want).abs());
        }
        assert!(zl.abs() < 1e-6 && zr.abs() < 1e-6);
        let q = sim.joint_positions();
        for (a, b) in q.iter().zip(posture) {
            assert!((a - b).abs() < 1e-6, "reset gave {q:?}, asked {posture:?}");
        }
    }
    println!("largest hand error vs analytic FK: {worst:.2e} m");
    assert!(worst < 1e-4, "{worst}");
}

/// Homogeneous transform of a URDF origin: R = Rz(yaw)·Ry(pitch)·Rx(roll), written out.
fn origin(xyz: [f64; 3], rpy: [f64; 3]) -> Matrix4<f64> {
    let (sr, cr) = rpy[0].sin_cos();
    let (sp, cp) = rpy[1].sin_cos();
    let (sy, cy) = rpy[2].sin_cos();
    let rx = Matrix3::new(1.0, 0.0, 0.0, 0.0, cr, -sr, 0.0, sr, cr);
    let ry = Matrix3::new(cp, 0.0, sp, 0.0, 1.0, 0.0, -sp, 0.0, cp);
    let rz = Matrix3::new(cy, -sy, 0.0, sy, cy, 0.0, 0.0, 0.0, 1.0);
    let mut m = Matrix4::identity();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&(rz * ry * rx));
    m.fixed_view_mut::<3, 1>(0, 3).copy_from(&Vector3::from(xyz));
    m
}

/// Rotation by `angle` about the unit `axis` (Rodrigues).
fn about(axis: [f64; 3], angle: f64) -> Matrix4<f64> {
    let a = Vector3::from(axis).normalize();
    let k = Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0);
    let r = Matrix3::identity() + k * angle.sin() + k * k * (1.0 - angle.cos());
    let mut m = Matrix4::identity();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
    m
}

const CHAIN: [([f64; 3], [f64; 3], [f64; 3]); 3] = [
    ([0.1, -0.2, 0.3], [0.3, -0.5, 1.1], [0.0, 0.0, 1.0]),
    ([0.25, 0.05, -0.1], [-0.7, 0.4, 0.2], [0.0, 1.0, 1.0]),
    ([0.0, 0.2, 0.15], [1.2, 0.1, -0.9], [1.0, 0.0, 0.0]),
];
const TIP: ([f64; 3], [f64; 3]) = ([0.05, 0.02, 0.1], [0.4, -0.3, 0.2]);

fn chain_urdf() -> String {
    let link = |n: usize| {
        format!(
            r#"<link name="l{n}"><inertial><origin xyz="0.05 0 0" rpy="0 0 0"/><mass value="0.5"/>
            <inertia ixx="1e-3" ixy="0" ixz="0" iyy="1e-3" iyz="0" izz="1e-3"/></inertial></link>"#
        )
    };
    let v = |a: [f64; 3]| format!("{} {} {}", a[0], a[1], a[2]);
    let mut s = String::from("<robot name=\"chain\">");
    s += &link(0);
    for (i, (xyz, rpy, axis)) in CHAIN.iter().enumerate() {
        s += &link(i + 1);
        s += &format!(
            r#"<joint name="j{i}" type="revolute"><origin xyz="{}" rpy="{}"/><parent link="l{i}"/>
            <child link="l{}"/><axis xyz="{}"/><limit lower="-3" upper="3" effort="100" velocity="10"/></joint>"#,
            v(*xyz),
            v(*rpy),
            i + 1,
            v(*axis)
        );
    }
    s += &format!(
        r#"<link name="tip"/><joint name="tip_fixed" type="fixed"><origin xyz="{}" rpy="{}"/>
        <parent link="l3"/><child link="tip"/></joint></robot>"#,
        v(TIP.0),
        v(TIP.1)
    );
    s
}

#[test]
fn compound_rpy_chain_matches_independent_fk() {
    let model = UrdfModel::parse(&chain_urdf()).unwrap();
    let options = WorldConfig {
        physics: PhysicsConfig {
            gravity: [0.0; 3],
            ..PhysicsConfig::default()
        },
        ..WorldConfig::default()
    };
    let mut sim = World::new(model, options).unwrap();
    let mut rng = common::Rng(11);
    for _ in 0..50 {
        let q: Vec<f64> = (0..3).map(|_| rng.range(-2.5, 2.5)).collect();
        sim.reset(&q).unwrap();
        let mut t = Matrix4::identity();
        for (i, (xyz, rpy, axis)) in CHAIN.iter().enumerate() {
            t = t * origin(*xyz, *rpy) * about(*axis, q[i]);
            let got = sim.link_pose(&format!("l{}", i + 1)).unwrap().to_homogeneous();
            assert!((got - t).abs().max() < 1e-5, "link l{}: {got} vs {t}", i + 1);
        }
        let tip = t * origin(TIP.0, TIP.1);
        let got = sim.link_pose("tip").unwrap().to_homogeneous();
        assert!((got - tip).abs().max() < 1e-5, "tip: {got} vs {tip}");
    }
}
