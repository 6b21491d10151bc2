//! What the fuzz targets run on one URDF document, and the structured mutation of the
//! shipped URDFs. The property: [`exercise`] never panics, aborts or hangs; an `Err` from
//! parsing, building or resetting is fine, a non-finite posture after stepping is not.

use sim::{PhysicsConfig, RootMode, UrdfModel, World, WorldConfig};

/// Physics steps run per built world (a few are enough to reach the solver and contacts).
pub const STEPS: usize = 4;

/// The shipped URDFs, the seeds of the structured target.
pub const SEEDS: [&str; 2] = [
    include_str!("../../python/latentrl/data/two_arms.urdf"),
    include_str!("../../python/latentrl/data/khr1hv.urdf"),
];

/// Parses `xml`; on success builds a fixed-root and a floating-root world (the latter over
/// a ground plane), resets to the start posture, servos towards the middle of the limits,
/// steps [`STEPS`] times and checks that the posture, velocities and root pose are finite.
///
/// Panics (the fuzzer's "crash") on a non-finite state or if resetting to the start
/// posture that `World::new` accepted fails.
pub fn exercise(xml: &str) {
    let Ok(model) = UrdfModel::parse(xml) else {
        return;
    };
    for (root, floor) in [(RootMode::Fixed, None), (RootMode::Floating, Some(-1.0))] {
        let options = WorldConfig {
            root,
            floor,
            physics: PhysicsConfig {
                substeps: 2,
                ..PhysicsConfig::default()
            },
            ..WorldConfig::default()
        };
        let Ok(mut sim) = World::new(model.clone(), options) else {
            continue;
        };
        let joints = model.joints();
        let start: Vec<f64> = joints.iter().map(|j| 0.0_f64.clamp(j.lower, j.upper)).collect();
        sim.reset(&start)
            .expect("the start posture accepted by World::new resets");
        let zeros = vec![0.0; joints.len()];
        let _ = sim.reset(&zeros);
        let middle: Vec<f64> = joints
            .iter()
            .map(|j| {
                if j.lower.is_finite() {
                    0.5 * j.lower + 0.5 * j.upper
                } else {
                    1.0
                }
            })
            .collect();
        sim.set_targets(&middle).expect("finite targets are accepted");
        sim.step(STEPS);
        let q = sim.joint_positions();
        let v = sim.joint_velocities();
        let base = sim.base_pose();
        let pose = base.translation.vector.iter().chain(base.rotation.coords.iter());
        assert!(
            q.iter().chain(&v).chain(pose).all(|x| x.is_finite()),
            "non-finite state after {STEPS} steps ({root:?} root): q = {q:?}, v = {v:?}, base = {base:?}"
        );
        let _ = sim.contacts();
    }
}

/// Byte ranges of the numbers inside attribute values of `xml` (comments skipped).
pub fn number_spans(xml: &str) -> Vec<(usize, usize)> {
    let bytes = xml.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    let mut in_value = false;
    while i < bytes.len() {
        if !in_value && xml[i..].starts_with("<!--") {
            i = xml[i..].find("-->").map_or(bytes.len(), |end| i + end + 3);
            continue;
        }
        match bytes[i] {
            b'"' => in_value = !in_value,
            c if in_value && !c.is_ascii_whitespace() => {
                let end = (i..bytes.len())
                    .find(|&k| bytes[k] == b'"' || bytes[k].is_ascii_whitespace())
                    .unwrap_or(bytes.len());
                if xml[i..end].parse::<f64>().is_ok() {
                    spans.push((i, end));
                }
                i = end;
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    spans
}

/// Values that sit on the edges of what rapier (f32) and the checks accept.
const EDGES: [&str; 22] = [
    "0",
    "-0",
    "1",
    "-1",
    "1e-45",
    "1e-38",
    "1e-12",
    "1e12",
    "1e20",
    "3.4e38",
    "3.5e38",
    "-3.5e38",
    "1e39",
    "1e300",
    "-1e300",
    "5e-324",
    "1.7976931348623157e308",
    "NaN",
    "inf",
    "-inf",
    "3.14159265",
    "1e-300",
];

/// One of [`SEEDS`] with up to eight of its attribute numbers replaced by edge values or
/// arbitrary floats chosen from `data`.
pub fn mutate_seed(data: &[u8]) -> String {
    let mut u = libfuzzer_sys::arbitrary::Unstructured::new(data);
    let seed = SEEDS[usize::from(u.arbitrary::<bool>().unwrap_or(false))];
    let spans = number_spans(seed);
    let mut edits: Vec<(usize, String)> = Vec::new();
    let n = u.int_in_range(1..=8).unwrap_or(1);
    for _ in 0..n {
        let Ok(k) = u.choose_index(spans.len()) else { break };
        let value = match u.int_in_range(0..=3).unwrap_or(0) {
            0 | 1 => EDGES[u.choose_index(EDGES.len()).unwrap_or(0)].to_string(),
            2 => format!("{:e}", u.arbitrary::<f64>().unwrap_or(0.0)),
            _ => format!("{}", f64::from(u.arbitrary::<i16>().unwrap_or(0)) / 100.0),
        };
        edits.retain(|(j, _)| *j != k);
        edits.push((k, value));
    }
    edits.sort_by_key(|(k, _)| std::cmp::Reverse(*k));
    let mut xml = seed.to_string();
    for (k, value) in edits {
        let (start, end) = spans[k];
        xml.replace_range(start..end, &value);
    }
    xml
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seeds_load_and_step() {
        for seed in SEEDS {
            assert!(UrdfModel::parse(seed).is_ok());
            exercise(seed);
        }
    }

    #[test]
    fn number_spans_skip_comments_and_names() {
        let xml = r#"<!-- "1" --><a b="x 2" c="-3.5e1 4"/>"#;
        let found: Vec<&str> = number_spans(xml).iter().map(|&(s, e)| &xml[s..e]).collect();
        assert_eq!(found, ["2", "-3.5e1", "4"]);
    }
}
