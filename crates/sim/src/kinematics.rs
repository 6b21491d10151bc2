//! Kinematics of two planar 2-link arms (docs/method.md §Experiment 2, paper Sec. IV-B, Fig. 5):
//! forward kinematics of hands and elbows, an analytic inverse for a pair of hand targets, and
//! the grip rule: how far a pair of hands is from holding the object ([`grip_error`]).
//!
//! Conventions (ours; the paper leaves them open):
//! - A **posture** is `[q1_L, q2_L, q1_R, q2_R]` in radians: `q1` is the upper arm's angle
//!   from the +x axis (counter-clockwise), `q2` the elbow angle of the forearm relative to
//!   the upper arm. Hands are `[x_L, y_L, x_R, y_R]` in metres; the body faces +y.
//! - Elbows point **outward**: the left arm takes the branch `q2 ≤ 0`, the right arm
//!   `q2 ≥ 0`, so with the hands in front of the shoulders (y > 0) the left elbow lies to
//!   the left of the shoulder→hand line and the right elbow to its right.
//! - Angle continuity: the inverse reports the shoulder→hand direction in the window
//!   `(shoulder_cut, shoulder_cut + 2π]`. The default cut, −π/2, points straight behind the
//!   shoulder, so postures stay continuous (no 2π jumps) for every hand target in front of
//!   or beside the body (docs/pitfalls.md §GP numerics, joint angles from inverse kinematics).

use crate::bimanual::GRIP;
use crate::error::{Result, SimError, check_finite};
use latent_core::CoreError;

/// Geometry of the two arms. Every length is in metres, every angle in radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanarArms {
    /// Left shoulder (x, y); ours: (−0.15, 0).
    pub left_shoulder: [f64; 2],
    /// Right shoulder (x, y); ours: (0.15, 0).
    pub right_shoulder: [f64; 2],
    /// Upper-arm length `l1` (shoulder → elbow); ours: 0.3 m.
    pub upper_arm: f64,
    /// Forearm length `l2` (elbow → hand); ours: 0.3 m.
    pub forearm: f64,
    /// Lower end of the window `(cut, cut + 2π]` for the shoulder→hand direction in the
    /// inverse; −π/2 (straight behind the shoulder) keeps front-facing postures continuous.
    pub shoulder_cut: f64,
}

impl Default for PlanarArms {
    fn default() -> Self {
        Self {
            left_shoulder: [-0.15, 0.0],
            right_shoulder: [0.15, 0.0],
            upper_arm: 0.3,
            forearm: 0.3,
            shoulder_cut: -std::f64::consts::FRAC_PI_2,
        }
    }
}

/// Hand and elbow positions of one posture (forward kinematics).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArmsPose {
    /// `[x_L, y_L, x_R, y_R]`.
    pub hands: [f64; 4],
    /// `[x_L, y_L, x_R, y_R]` of the elbows (for drawing).
    pub elbows: [f64; 4],
}

/// Floating-point slack on the reach limits: targets this far (relative to `l1 + l2`)
/// beyond a limit are clamped onto it instead of rejected.
const REACH_SLACK: f64 = 1e-12;

impl PlanarArms {
    /// Fails with [`SimError::InvalidParameter`] unless lengths are > 0 and all values finite.
    pub fn validate(&self) -> Result<()> {
        for (name, value) in [("upper_arm", self.upper_arm), ("forearm", self.forearm)] {
            if !(value.is_finite() && value > 0.0) {
                return Err(SimError::Input(CoreError::InvalidParameter {
                    name,
                    value,
                    reason: "must be finite and > 0",
                }));
            }
        }
        let others = [
            ("left_shoulder.x", self.left_shoulder[0]),
            ("left_shoulder.y", self.left_shoulder[1]),
            ("right_shoulder.x", self.right_shoulder[0]),
            ("right_shoulder.y", self.right_shoulder[1]),
            ("shoulder_cut", self.shoulder_cut),
        ];
        for (name, value) in others {
            if !value.is_finite() {
                return Err(SimError::Input(CoreError::InvalidParameter {
                    name,
                    value,
                    reason: "must be finite",
                }));
            }
        }
        Ok(())
    }

    /// Smallest and largest shoulder→hand distance an arm reaches: `|l1 − l2|`, `l1 + l2`.
    pub fn reach(&self) -> (f64, f64) {
        ((self.upper_arm - self.forearm).abs(), self.upper_arm + self.forearm)
    }

    /// Forward kinematics of one arm: (elbow, hand) for shoulder angle `q1`, elbow angle `q2`.
    fn arm_forward(&self, shoulder: [f64; 2], q1: f64, q2: f64) -> ([f64; 2], [f64; 2]) {
        let elbow = [
            shoulder[0] + self.upper_arm * q1.cos(),
            shoulder[1] + self.upper_arm * q1.sin(),
        ];
        let q12 = q1 + q2;
        (
            elbow,
            [elbow[0] + self.forearm * q12.cos(), elbow[1] + self.forearm * q12.sin()],
        )
    }

    /// Hands and elbows of `posture` `[q1_L, q2_L, q1_R, q2_R]`.
    pub fn forward(&self, posture: &[f64; 4]) -> ArmsPose {
        let (el, hl) = self.arm_forward(self.left_shoulder, posture[0], posture[1]);
        let (er, hr) = self.arm_forward(self.right_shoulder, posture[2], posture[3]);
        ArmsPose {
            hands: [hl[0], hl[1], hr[0], hr[1]],
            elbows: [el[0], el[1], er[0], er[1]],
        }
    }

    /// Hands `[x_L, y_L, x_R, y_R]` of `posture` (the hot part of [`Self::forward`]).
    pub fn hands(&self, posture: &[f64; 4]) -> [f64; 4] {
        self.forward(posture).hands
    }

    /// Analytic inverse of one arm for `hand`, elbow angle sign `branch` (±1).
    fn arm_inverse(
        &self,
        shoulder: [f64; 2],
        hand: [f64; 2],
        branch: f64,
        arm: &'static str,
        row: usize,
    ) -> Result<[f64; 2]> {
        let (l1, l2) = (self.upper_arm, self.forearm);
        let (dx, dy) = (hand[0] - shoulder[0], hand[1] - shoulder[1]);
        let distance = dx.hypot(dy);
        let (min, max) = self.reach();
        let slack = REACH_SLACK * max;
        if distance > max + slack || distance < min - slack {
            return Err(SimError::Unreachable {
                arm,
                row,
                distance,
                min,
                max,
            });
        }
        let cos_q2 = ((distance * distance - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)).clamp(-1.0, 1.0);
        let q2 = branch * cos_q2.acos();
        let mut direction = dy.atan2(dx);
        let tau = std::f64::consts::TAU;
        while direction <= self.shoulder_cut {
            direction += tau;
        }
        while direction > self.shoulder_cut + tau {
            direction -= tau;
        }
        let q1 = direction - (l2 * q2.sin()).atan2(l1 + l2 * q2.cos());
        Ok([q1, q2])
    }

    /// Posture `[q1_L, q2_L, q1_R, q2_R]` that puts the hands at `hands` `[x_L, y_L, x_R, y_R]`,
    /// elbows outward; `row` only labels errors. Fails with [`SimError::Unreachable`].
    pub fn inverse(&self, hands: &[f64; 4], row: usize) -> Result<[f64; 4]> {
        let [q1l, q2l] = self.arm_inverse(self.left_shoulder, [hands[0], hands[1]], -1.0, "left", row)?;
        let [q1r, q2r] = self.arm_inverse(self.right_shoulder, [hands[2], hands[3]], 1.0, "right", row)?;
        Ok([q1l, q2l, q1r, q2r])
    }

    /// Forward kinematics of a row-major `(N, 4)` batch of postures → `(N, 4)` hands.
    pub fn forward_batch(&self, postures: &[f64]) -> Result<Vec<f64>> {
        check_rows("postures", postures)?;
        Ok(postures
            .chunks_exact(4)
            .flat_map(|p| self.hands(&[p[0], p[1], p[2], p[3]]))
            .collect())
    }

    /// Elbow positions of a row-major `(N, 4)` batch of postures → `(N, 4)` elbows.
    pub fn elbows_batch(&self, postures: &[f64]) -> Result<Vec<f64>> {
        check_rows("postures", postures)?;
        Ok(postures
            .chunks_exact(4)
            .flat_map(|p| self.forward(&[p[0], p[1], p[2], p[3]]).elbows)
            .collect())
    }

    /// Inverse kinematics of a row-major `(N, 4)` batch of hand targets → `(N, 4)` postures;
    /// the first unreachable row is the error.
    pub fn inverse_batch(&self, hands: &[f64]) -> Result<Vec<f64>> {
        check_rows("hands", hands)?;
        self.validate()?;
        let mut out = Vec::with_capacity(hands.len());
        for (row, h) in hands.chunks_exact(4).enumerate() {
            out.extend(self.inverse(&[h[0], h[1], h[2], h[3]], row)?);
        }
        Ok(out)
    }
}

/// Which distance [`grip_error`] measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GripTest {
    /// `| ‖hand_R − hand_L‖ − ‖GRIP‖ |` (the paper's Fig. 5: "distance between the
    /// end-effectors within 0.005 of 0.1").
    Distance,
    /// `‖(hand_R − hand_L) − GRIP‖` (Experiment 1's drop test, which also catches a rotated
    /// object).
    Vector,
}

impl GripTest {
    /// The test measured when none is named: the paper's distance test.
    pub const DEFAULT: Self = Self::Distance;

    /// The test's name, as [`GripTest::from_str`](std::str::FromStr) reads it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Distance => "distance",
            Self::Vector => "vector",
        }
    }
}

impl std::str::FromStr for GripTest {
    type Err = SimError;

    /// `"distance"` or `"vector"`.
    fn from_str(name: &str) -> Result<Self> {
        match name {
            "distance" => Ok(Self::Distance),
            "vector" => Ok(Self::Vector),
            _ => Err(SimError::Input(CoreError::Argument(format!(
                "test must be 'distance' or 'vector', got {name:?}"
            )))),
        }
    }
}

/// How far hands `[x_L, y_L, x_R, y_R]` are from holding the object (offset [`GRIP`]), in
/// metres, by `test`. Summed in NumPy's order (`sqrt(dx² + dy²)`, no `hypot`), so the NumPy
/// oracle gives the same bits.
pub fn grip_error(hands: &[f64; 4], test: GripTest) -> f64 {
    let norm = |x: f64, y: f64| (x * x + y * y).sqrt();
    let (dx, dy) = (hands[2] - hands[0], hands[3] - hands[1]);
    match test {
        GripTest::Distance => (norm(dx, dy) - norm(GRIP[0], GRIP[1])).abs(),
        GripTest::Vector => norm(dx - GRIP[0], dy - GRIP[1]),
    }
}

/// [`grip_error`] of each row of a row-major `(N, 4)` batch of hands.
pub fn grip_error_batch(hands: &[f64], test: GripTest) -> Result<Vec<f64>> {
    check_rows("hands", hands)?;
    Ok(hands
        .chunks_exact(4)
        .map(|h| grip_error(&[h[0], h[1], h[2], h[3]], test))
        .collect())
}

/// A flat row-major `(N, 4)` array: length a multiple of 4, N ≥ 1, all finite.
fn check_rows(what: &'static str, values: &[f64]) -> Result<()> {
    if values.is_empty() || !values.len().is_multiple_of(4) {
        return Err(SimError::Input(CoreError::Shape {
            what,
            expected: "(N, 4) with N >= 1".to_string(),
            got: format!("{} values", values.len()),
        }));
    }
    check_finite(what, values)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
    }

    #[test]
    fn known_poses() {
        let arms = PlanarArms::default();
        // Both arms straight along +x.
        let pose = arms.forward(&[0.0, 0.0, 0.0, 0.0]);
        assert!(close(&pose.hands, &[0.45, 0.0, 0.75, 0.0], 1e-12));
        assert!(close(&pose.elbows, &[0.15, 0.0, 0.45, 0.0], 1e-12));
        // Both arms straight up.
        let up = arms.forward(&[FRAC_PI_2, 0.0, FRAC_PI_2, 0.0]);
        assert!(close(&up.hands, &[-0.15, 0.6, 0.15, 0.6], 1e-12));
        // Upper arms out sideways, forearms bent up: hands above the elbows.
        let bent = arms.forward(&[PI, -FRAC_PI_2, 0.0, FRAC_PI_2]);
        assert!(close(&bent.elbows, &[-0.45, 0.0, 0.45, 0.0], 1e-12));
        assert!(close(&bent.hands, &[-0.45, 0.3, 0.45, 0.3], 1e-12));
        assert_eq!(
            arms.inverse(&bent.hands, 0)
                .map(|q| close(&q, &[PI, -FRAC_PI_2, 0.0, FRAC_PI_2], 1e-12)),
            Ok(true)
        );
    }

    #[test]
    fn forward_of_inverse_round_trip_and_branch() {
        let arms = PlanarArms::default();
        for i in 0..=40 {
            for j in 0..=40 {
                let left = [-0.6 + 0.025 * i as f64, -0.2 + 0.02 * j as f64];
                let hands = [left[0], left[1], left[0] + 0.1, left[1]];
                let Ok(q) = arms.inverse(&hands, 0) else { continue };
                assert!(q[1] <= 0.0 && q[3] >= 0.0, "elbows outward: {q:?}");
                assert!(close(&arms.hands(&q), &hands, 1e-12), "{hands:?} -> {q:?}");
            }
        }
    }

    #[test]
    fn inverse_of_forward_on_the_outward_branch() {
        let arms = PlanarArms::default();
        for k in 0..200 {
            let t = k as f64 / 200.0;
            let q = [0.4 + 2.0 * t, -0.1 - 2.5 * t, 2.6 - 2.2 * t, 0.2 + 2.4 * t];
            let back = arms.inverse(&arms.hands(&q), k).unwrap();
            assert!(close(&back, &q, 1e-9), "{q:?} -> {back:?}");
        }
    }

    #[test]
    fn continuous_across_shoulder_height() {
        // Left hand sweeping from above to below shoulder height on the left: atan2 crosses
        // ±π there, the reported shoulder angle must not jump.
        let arms = PlanarArms::default();
        let mut previous: Option<[f64; 4]> = None;
        for k in 0..=100 {
            let y = 0.2 - 0.004 * k as f64;
            let q = arms.inverse(&[-0.45, y, -0.35, y], k).unwrap();
            if let Some(p) = previous {
                assert!(close(&q, &p, 0.05), "jump at y = {y}: {p:?} -> {q:?}");
            }
            previous = Some(q);
        }
    }

    #[test]
    fn unreachable_and_bad_input() {
        let arms = PlanarArms::default();
        let far = arms.inverse(&[-0.15, 0.7, 0.0, 0.3], 3);
        assert!(
            matches!(
                far,
                Err(SimError::Unreachable {
                    arm: "left",
                    row: 3,
                    ..
                })
            ),
            "{far:?}"
        );
        let far_right = arms.inverse_batch(&[0.0, 0.3, 0.1, 0.3, 0.0, 0.3, 0.9, 0.0]);
        assert!(
            matches!(
                far_right,
                Err(SimError::Unreachable {
                    arm: "right",
                    row: 1,
                    ..
                })
            ),
            "{far_right:?}"
        );
        // Exactly at full stretch is reachable (rounding slack).
        assert!(arms.inverse(&[-0.15, 0.6, 0.15, 0.6], 0).is_ok());
        assert!(matches!(
            arms.forward_batch(&[0.0; 5]),
            Err(SimError::Input(CoreError::Shape { .. }))
        ));
        assert!(matches!(
            arms.forward_batch(&[]),
            Err(SimError::Input(CoreError::Shape { .. }))
        ));
        assert!(matches!(
            arms.inverse_batch(&[0.0, 0.3, f64::NAN, 0.3]),
            Err(SimError::Input(CoreError::NonFinite { index: 2, .. }))
        ));
        let bad = PlanarArms {
            forearm: 0.0,
            ..PlanarArms::default()
        };
        assert!(matches!(
            bad.validate(),
            Err(SimError::Input(CoreError::InvalidParameter { name: "forearm", .. }))
        ));
    }

    #[test]
    fn grip_errors() {
        let hands = [0.0, 0.0, 0.103, 0.004, 0.0, 0.0, 0.0, 0.1];
        let vector = grip_error_batch(&hands, GripTest::Vector).unwrap();
        assert!(close(&vector, &[0.005, 0.02_f64.sqrt()], 1e-12), "{vector:?}");
        let distance = grip_error_batch(&hands, GripTest::Distance).unwrap();
        assert!(
            close(&distance, &[0.103_f64.hypot(0.004) - 0.1, 0.0], 1e-12),
            "{distance:?}"
        );
        assert_eq!(
            grip_error(&[1.0, 2.0, 1.1, 2.0], GripTest::Distance),
            grip_error(&[1.0, 2.0, 1.0, 2.1], GripTest::Distance)
        );
        assert!(matches!(
            "angle".parse::<GripTest>(),
            Err(SimError::Input(CoreError::Argument(_)))
        ));
        assert!(matches!(
            grip_error_batch(&[0.0; 3], GripTest::Vector),
            Err(SimError::Input(CoreError::Shape { .. }))
        ));
    }

    #[test]
    fn batches_match_single_calls() {
        let arms = PlanarArms::default();
        let postures = [1.2, -0.8, 1.9, 0.7, 2.0, -1.5, 1.0, 1.4];
        let hands = arms.forward_batch(&postures).unwrap();
        let elbows = arms.elbows_batch(&postures).unwrap();
        for r in 0..2 {
            let p = [
                postures[4 * r],
                postures[4 * r + 1],
                postures[4 * r + 2],
                postures[4 * r + 3],
            ];
            let pose = arms.forward(&p);
            assert_eq!(&hands[4 * r..4 * r + 4], &pose.hands);
            assert_eq!(&elbows[4 * r..4 * r + 4], &pose.elbows);
        }
        let back = arms.inverse_batch(&hands).unwrap();
        assert!(close(&back, &postures, 1e-9), "{back:?}");
    }
}
