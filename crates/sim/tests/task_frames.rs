//! Where a floating robot stands and where its target is measured from: `fall.stance` puts the
//! first sole at a fixed spot for every start posture, `target.relative_to` measures h and h*
//! from a link's origin so that the target moves with the feet (docs/tasks.md, docs/exp3.md).
mod common;

use std::sync::Arc;

use latent_core::Plant;
use sim::{Task, TaskPlant};

/// The humanoid lift task with `edit` applied to its configuration.
fn lift(edit: impl FnOnce(&mut sim::TaskConfig)) -> sim::error::Result<Arc<Task>> {
    let shipped = common::task("humanoid_lift");
    let mut config = shipped.config().clone();
    edit(&mut config);
    Task::new(config, shipped.model().clone(), "test").map(Arc::new)
}

fn sole_xy(p: &TaskPlant) -> [f64; 2] {
    let foot = p.world().link_pose("l_foot").unwrap().translation;
    [foot.x, foot.y]
}

#[test]
fn a_stance_stands_every_posture_on_the_same_spot() {
    let demos = common::lift_demos();
    let free = lift(|_| {}).unwrap();
    let mut p = TaskPlant::new(free, Some(&demos)).unwrap();
    let spots: Vec<[f64; 2]> = demos.iter().map(|q| (p.reset(q), sole_xy(&p)).1).collect();
    assert!(
        (spots[0][0] - spots[6][0]).abs() > 0.05,
        "without a stance the hinge stands its feet ahead of the squat: {spots:?}"
    );
    let fixed = lift(|c| c.fall.as_mut().unwrap().stance = Some([0.05, -0.02])).unwrap();
    let mut p = TaskPlant::new(fixed, Some(&demos)).unwrap();
    for q in &demos {
        p.reset(q);
        let [x, y] = sole_xy(&p);
        assert!((x - 0.05).abs() < 1e-6 && (y + 0.02).abs() < 1e-6, "sole at ({x}, {y})");
    }
}

#[test]
fn a_relative_target_moves_with_the_feet() {
    let demos = common::lift_demos();
    let shipped = lift(|_| {}).unwrap();
    assert_eq!(shipped.config().target.relative_to.as_deref(), Some("l_foot"));
    // The shipped h* is demo 6's hands measured from its left sole; `target_position` is it in
    // the world, the sole's origin plus `target.position`.
    let mut p = TaskPlant::new(shipped.clone(), Some(&demos)).unwrap();
    p.reset(&demos[6]);
    assert!(p.reached_target(), "the shipped h* is demo 6's hands");
    let sole = p.world().link_pose("l_foot").unwrap().translation.vector;
    let world_target: Vec<[f64; 3]> = p
        .target_position()
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    for (t, w) in shipped.config().target.position.iter().zip(&world_target) {
        for k in 0..3 {
            assert!(
                (w[k] - t[k] - sole[k]).abs() < 1e-12,
                "world target {w:?} = {t:?} + sole {sole:?}"
            );
        }
    }
    for (stance, moved) in [(None, false), (Some([sole.x + 0.04, sole.y]), true)] {
        let relative = lift(|c| c.fall.as_mut().unwrap().stance = stance).unwrap();
        let absolute = lift(|c| {
            c.fall.as_mut().unwrap().stance = stance;
            c.target.relative_to = None;
            c.target.position = world_target.clone();
        })
        .unwrap();
        let mut rel = TaskPlant::new(relative, Some(&demos)).unwrap();
        let mut abs = TaskPlant::new(absolute, Some(&demos)).unwrap();
        rel.reset(&demos[6]);
        abs.reset(&demos[6]);
        assert!(
            rel.reached_target(),
            "relative target reached with the feet at {stance:?}"
        );
        assert_eq!(abs.reached_target(), !moved, "world target with the feet at {stance:?}");
        let shift = rel.target_position()[0] - world_target[0][0];
        assert!(
            (shift - if moved { 0.04 } else { 0.0 }).abs() < 1e-6,
            "h* moved {shift} m with the feet"
        );
        if !moved {
            assert!((rel.reward() - abs.reward()).abs() < 1e-9, "same feet, same reward");
        }
    }
}

#[test]
fn an_unknown_origin_link_is_named() {
    let err = lift(|c| c.target.relative_to = Some("l_sole".into()))
        .unwrap_err()
        .to_string();
    assert!(err.contains("target.relative_to") && err.contains("l_sole"), "{err}");
}
