//! The task file's tables (docs/tasks.md): every key declared once with its doc, default
//! and rule ([`latent_core::params!`]); a TOML task file and a Python dict deserialize into
//! [`TaskConfig`] and [`TaskConfig::validate`] checks it (names, shapes and ranges; the
//! robot's links and joints are checked by [`crate::task::Task::new`]).

use latent_core::params::{ParamError, Params, Rule, join};
use latent_core::{LearnerConfig, RunConfig, choice, params};

use crate::urdf::RootMode;
use crate::world::{PhysicsConfig, ServoConfig};

choice! {
    /// A world axis.
    pub enum Axis {
        /// x.
        X = "x",
        /// y.
        Y = "y",
        /// z.
        Z = "z",
    }
}

impl Axis {
    /// 0, 1 or 2.
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }
}

choice! {
    /// What an obstacle is tested against.
    pub enum ObstacleTest {
        /// The effector points: a point in the closed box touches it (Exp. 2's walls, which
        /// the links cross). The box is not a body in the physics.
        Effectors = "effectors",
        /// Every collision shape of the robot: within `physics.contact_margin` touches it
        /// (Exp. 3's block).
        Links = "links",
    }
}

choice! {
    /// The kind of a constraint that ends an episode when broken (a drop, code 3).
    pub enum ConstraintKind {
        /// `| ‖p_b − p_a‖ − value | ≤ tolerance` for the two `links` (a held object's width).
        Distance = "distance",
        /// `‖(p_b − p_a) − offset‖ ≤ tolerance` for the two `links` (a held object, no rotation).
        Offset = "offset",
        /// The `axis` of `link` (in its frame) within `max_angle` of the world `direction`
        /// (a full glass upright).
        Orientation = "orientation",
        /// The world `coordinate` of `link`'s origin within [`min`, `max`].
        Plane = "plane",
    }
}

choice! {
    /// Where training episodes start.
    pub enum StartRule {
        /// Uniform over the latent box, redrawn while the decoded posture at rest breaks a rule
        /// (outside the joint limits, touching an obstacle, a constraint broken, fallen or
        /// outside its support).
        Uniform = "uniform",
        /// The demonstration `start_demo` plus uniform noise of ±`start_noise` per joint,
        /// encoded; redrawn while it breaks a rule.
        Demo = "demo",
    }
}

choice! {
    /// Which admissible starts may also start a frozen test episode.
    pub enum TestStart {
        /// Every admissible start.
        Any = "any",
        /// Every effector below the waypoint's `below` (Exp. 2: the hands under the walls).
        BelowWaypoint = "below_waypoint",
    }
}

choice! {
    /// When a step tests the rules that end an episode (obstacles, falls, constraints).
    pub enum RuleCheck {
        /// Once, after the RL step's last physics step (docs/method.md §RL loop: the reached
        /// state).
        RlStep = "rl_step",
        /// After every physics step of the RL step: a touch in between ends it too (the
        /// RL step still runs all its physics steps).
        PhysicsStep = "physics_step",
    }
}

params! {
    /// A floor under a floating robot.
    pub struct FloorConfig {
        /// Height of the floor half-space (m), normal +z.
        height: f64 = 0.0 => Rule::closed(-1000.0, 1000.0),
    }
}

params! {
    /// The target of the reward `R = exp(−θ ‖(h − h*)/ℓ‖²)` over the effector positions h
    /// (paper Eq. 12 with a length unit ℓ).
    pub struct TargetConfig {
        /// h*: one [x, y, z] row per effector (m), in the order of `effectors`.
        position: Vec<[f64; 3]> = Vec::new() => Rule::closed(-1000.0, 1000.0),
        /// The reward's length unit ℓ (m): with metres alone θ = 0.35 is nearly flat.
        width: f64 = 1.0 => Rule::closed(1e-6, 1000.0),
        /// θ of the reward (paper: 0.35 in Exp. 2).
        theta: f64 = 0.35 => Rule::Positive,
        /// "Reached the target": RMS per-effector distance to h* at most this (m).
        reach_radius: f64 = 0.05 => Rule::Positive,
        /// Success: an episode ends as `success` (code 6) once the effectors have stayed within
        /// `reach_radius` for this many RL steps in a row (a place, not a pass); 0: never (the
        /// paper's rule: episodes run on at the target to `episode.max_steps`). A success is not
        /// a terminal state: its update bootstraps, so V keeps valuing the target.
        hold_steps: usize = 0 => Rule::count(0, 1_000_000),
        /// A link from whose origin h and h* are measured (world axes), e.g. the standing sole:
        /// the target moves with the feet. Absent: world positions.
        relative_to: Option<String> = None => Rule::NonEmpty,
    }
}

params! {
    /// A constraint of the task: broken, it ends the episode with the penalty (code 3, drop).
    /// Each kind takes its own keys.
    pub struct ConstraintConfig {
        /// "distance", "offset", "orientation" or "plane".
        kind: ConstraintKind = ConstraintKind::Distance => Rule::Any,
        /// distance, offset: the two links (or frames) [a, b].
        links: Vec<String> = Vec::new() => Rule::Any,
        /// orientation, plane: the link (or frame).
        link: Option<String> = None => Rule::Any,
        /// distance: ‖p_b − p_a‖ to keep (m).
        value: Option<f64> = None => Rule::closed(0.0, 1000.0),
        /// offset: p_b − p_a to keep, [x, y, z] (m).
        offset: Option<[f64; 3]> = None => Rule::closed(-1000.0, 1000.0),
        /// distance, offset: the largest error allowed (m); orientation: unused.
        tolerance: Option<f64> = None => Rule::Positive,
        /// orientation: the link's axis in its own frame, [x, y, z].
        axis: Option<[f64; 3]> = None => Rule::Finite,
        /// orientation: the world direction the axis must point along, [x, y, z].
        direction: Option<[f64; 3]> = None => Rule::Finite,
        /// orientation: the largest angle between them (rad).
        max_angle: Option<f64> = None => Rule::open_closed(0.0, std::f64::consts::PI),
        /// plane: the world coordinate tested ("x", "y" or "z").
        coordinate: Option<Axis> = None => Rule::Any,
        /// plane: its lower bound (m); none for no bound.
        min: Option<f64> = None => Rule::Finite,
        /// plane: its upper bound (m); none for no bound.
        max: Option<f64> = None => Rule::Finite,
    }
    check = constraint_keys;
}

fn constraint_keys(c: &ConstraintConfig, path: &str) -> Result<(), ParamError> {
    let given = [
        ("links", !c.links.is_empty()),
        ("link", c.link.is_some()),
        ("value", c.value.is_some()),
        ("offset", c.offset.is_some()),
        ("tolerance", c.tolerance.is_some()),
        ("axis", c.axis.is_some()),
        ("direction", c.direction.is_some()),
        ("max_angle", c.max_angle.is_some()),
        ("coordinate", c.coordinate.is_some()),
        ("min", c.min.is_some()),
        ("max", c.max.is_some()),
    ];
    let (needs, allows): (&[&str], &[&str]) = match c.kind {
        ConstraintKind::Distance => (&["links", "value", "tolerance"], &[]),
        ConstraintKind::Offset => (&["links", "offset", "tolerance"], &[]),
        ConstraintKind::Orientation => (&["link", "axis", "direction", "max_angle"], &[]),
        ConstraintKind::Plane => (&["link", "coordinate"], &["min", "max"]),
    };
    let kind = c.kind.as_str();
    for (key, present) in given {
        if needs.contains(&key) && !present {
            return Err(ParamError::new(
                &join(path, key),
                format!("is required for kind = \"{kind}\" (it takes {})", needs.join(", ")),
            ));
        }
        if present && !needs.contains(&key) && !allows.contains(&key) {
            let takes = needs.iter().chain(allows).copied().collect::<Vec<_>>().join(", ");
            return Err(ParamError::new(
                &join(path, key),
                format!("is not a key of kind = \"{kind}\" (it takes {takes})"),
            ));
        }
    }
    if needs.contains(&"links") && c.links.len() != 2 {
        return Err(ParamError::new(
            &join(path, "links"),
            format!("must name two links, got {}", c.links.len()),
        ));
    }
    if needs.contains(&"links") && c.links[0] == c.links[1] {
        return Err(ParamError::new(
            &join(path, "links"),
            format!("must name two different links, got \"{}\" twice", c.links[0]),
        ));
    }
    for (key, v) in [("axis", c.axis), ("direction", c.direction)] {
        if v.is_some_and(|v| v.iter().map(|x| x * x).sum::<f64>() < 1e-12) {
            return Err(ParamError::new(&join(path, key), "must not be the zero vector"));
        }
    }
    if c.kind == ConstraintKind::Plane {
        match (c.min, c.max) {
            (None, None) => return Err(ParamError::new(path, "kind = \"plane\" needs min, max or both")),
            (Some(lo), Some(hi)) if lo > hi => {
                return Err(ParamError::new(
                    &join(path, "max"),
                    format!("must be >= min = {lo}, got {hi}"),
                ));
            }
            _ => {}
        }
    }
    Ok(())
}

params! {
    /// A static box obstacle, axis-aligned: `center` and `half_extents`, or `min` and `max`
    /// corners. Touching it ends the episode with the penalty (code 1).
    pub struct ObstacleConfig {
        /// Name in reports.
        name: String = "box".to_string() => Rule::Any,
        /// Centre of the box, [x, y, z] (m).
        center: Option<[f64; 3]> = None => Rule::closed(-1000.0, 1000.0),
        /// Half-extents of the box along x, y, z (m).
        half_extents: Option<[f64; 3]> = None => Rule::closed(1e-6, 1000.0),
        /// Lower corner, [x, y, z] (m), instead of center and half_extents.
        min: Option<[f64; 3]> = None => Rule::closed(-1000.0, 1000.0),
        /// Upper corner, [x, y, z] (m).
        max: Option<[f64; 3]> = None => Rule::closed(-1000.0, 1000.0),
        /// A sensor the robot passes through (true) or a solid the robot collides with (false);
        /// either way touching it ends the episode. Effector-tested boxes are never solid.
        sensor: bool = true => Rule::Any,
        /// "links" (every collision shape of the robot) or "effectors" (the effector points).
        test: ObstacleTest = ObstacleTest::Links => Rule::Any,
    }
    check = obstacle_keys;
}

fn obstacle_keys(o: &ObstacleConfig, path: &str) -> Result<(), ParamError> {
    match (o.center, o.half_extents, o.min, o.max) {
        (Some(_), Some(_), None, None) => Ok(()),
        (None, None, Some(lo), Some(hi)) => match (0..3).find(|&k| hi[k] <= lo[k]) {
            Some(k) => Err(ParamError::new(
                &format!("{}[{k}]", join(path, "max")),
                format!("must exceed min[{k}] = {}, got {}", lo[k], hi[k]),
            )),
            None => Ok(()),
        },
        _ => Err(ParamError::new(
            path,
            "needs center and half_extents, or min and max (not both)",
        )),
    }
}

impl ObstacleConfig {
    /// Lower and upper corners.
    pub fn corners(&self) -> ([f64; 3], [f64; 3]) {
        match (self.min, self.max, self.center, self.half_extents) {
            (Some(lo), Some(hi), _, _) => (lo, hi),
            (_, _, Some(c), Some(h)) => (
                [c[0] - h[0], c[1] - h[1], c[2] - h[2]],
                [c[0] + h[0], c[1] + h[1], c[2] + h[2]],
            ),
            _ => ([0.0; 3], [0.0; 3]),
        }
    }

    /// Centre and half-extents.
    pub fn center_half_extents(&self) -> ([f64; 3], [f64; 3]) {
        match (self.center, self.half_extents, self.min, self.max) {
            (Some(c), Some(h), _, _) => (c, h),
            (_, _, Some(lo), Some(hi)) => {
                let c = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
                (c, [0, 1, 2].map(|k| 0.5 * (hi[k] - lo[k])))
            }
            _ => ([0.0; 3], [0.0; 3]),
        }
    }
}

params! {
    /// A waypoint the effectors should pass: "passed" = every effector's `axis` coordinate
    /// below `below` at the start and above `above` at some later step (Exp. 2: under the walls,
    /// then over them).
    pub struct WaypointConfig {
        /// The world coordinate tested.
        axis: Axis = Axis::Y => Rule::Any,
        /// Start side: below this (m).
        below: f64 = 0.0 => Rule::Finite,
        /// Far side: above this (m).
        above: f64 = 0.0 => Rule::Finite,
    }
    check = waypoint_order;
}

fn waypoint_order(w: &WaypointConfig, path: &str) -> Result<(), ParamError> {
    if w.above < w.below {
        return Err(ParamError::new(
            &join(path, "above"),
            format!("must be >= below = {}, got {}", w.below, w.above),
        ));
    }
    Ok(())
}

params! {
    /// The fall rule of a floating robot: ends the episode (code 4) when a sole tilts too far,
    /// a non-sole link touches the floor or the base sinks.
    pub struct FallConfig {
        /// The links allowed to touch the floor; their collision shapes make the support polygon.
        /// At a reset the first stands flat if it has a box shape; else (sphere feet) the robot
        /// stands upright on its lowest point.
        soles: Vec<String> = Vec::new() => Rule::NonEmpty,
        /// A sole with a box shape leaning more than this from the vertical is a fall (rad;
        /// Experiment 3: 20°); a sole without one has no plane to lean.
        max_tilt: f64 = crate::fall::MAX_SOLE_TILT => Rule::open_closed(0.0, std::f64::consts::PI),
        /// The base below this share of its height above the floor at the reset is a fall
        /// (Experiment 3: half).
        base_height_fraction: f64 = 0.5 => Rule::open(0.0, 1.0),
        /// A start is refused unless the centre of mass lies at least this far (m) inside the
        /// support polygon (negative: outside allowed).
        min_start_margin: f64 = 0.0 => Rule::closed(-1.0, 1.0),
        /// Where the first sole stands at every reset, [x, y] on the floor (m); absent: where
        /// the posture puts it with the base over the origin, so the feet move with the posture.
        stance: Option<[f64; 2]> = None => Rule::closed(-1000.0, 1000.0),
    }
}

params! {
    /// How episodes run and start.
    pub struct EpisodeConfig {
        /// Steps per episode before a time-out (paper: 1000 in Exp. 2, 200 in Exp. 3).
        max_steps: usize = 1000 => Rule::count(1, 1_000_000),
        /// Penalty R_p added when a step ends the episode, and of a box exit (paper: −1).
        penalty: f64 = -1.0 => Rule::closed(-1e6, 1e6),
        /// Where training episodes start: "uniform" or "demo".
        start: StartRule = StartRule::Uniform => Rule::Any,
        /// The demonstration (row of the demo file) a "demo" start uses.
        start_demo: usize = 0 => Rule::count(0, 1_000_000),
        /// Uniform noise of a "demo" start, ± this per joint (rad or m).
        start_noise: f64 = 0.0 => Rule::closed(0.0, 10.0),
        /// Draws allowed to find an admissible start.
        max_start_draws: usize = 1000 => Rule::count(1, 1_000_000_000),
        /// Ours, not the paper's: stop a training trial once `stop_patience` windows of this many
        /// episodes in a row raised neither its reach count nor its mean return by 1 % (the
        /// episode budget is then a ceiling; `latentrl train` derives it where silent); 0: run
        /// every episode (the paper's).
        stop_window: usize = 0 => Rule::count(0, 1_000_000_000),
        /// Windows without improvement before a trial stops (with `stop_window`).
        stop_patience: usize = 3 => Rule::count(1, 1_000_000),
        /// Which admissible starts may start a frozen test episode: "any" or "below_waypoint".
        test_start: TestStart = TestStart::Any => Rule::Any,
        /// When a step tests the end rules: "rl_step" (once, at its end) or "physics_step"
        /// (after each of its physics steps; ours, issue #18).
        check_rules: RuleCheck = RuleCheck::RlStep => Rule::Any,
    }
}

params! {
    /// A task: the robot, its servos and physics, the effectors and their target, the rules that
    /// end an episode, the episodes and the learner (docs/tasks.md).
    pub struct TaskConfig {
        /// Name of the task (results and policy files).
        name: String = "task".to_string() => Rule::NonEmpty,
        /// The robot's URDF file, relative to the task file.
        urdf: String = String::new() => Rule::NonEmpty,
        /// Repair inertias the physics cannot take (all zero, or breaking the triangle
        /// inequality), each repaired link named in the task's warnings (`latentrl urdf-info
        /// --balance-inertia` shows them; docs/robots.md).
        balance_inertia: bool = false => Rule::Any,
        /// "fixed" (the root link welded to the world) or "floating" (6 free DoF; needs a floor).
        root: RootMode = RootMode::Fixed => Rule::Any,
        /// A floor (`[floor]`, with its height); a floating robot needs one.
        floor: Option<FloorConfig> = None => Rule::Nested,
        /// The links (or frames) whose world positions the reward, the target and the recorded
        /// paths use.
        effectors: Vec<String> = Vec::new() => Rule::NonEmpty,
        /// The servos (`[servo]`).
        servo: ServoConfig = ServoConfig::default() => Rule::Nested,
        /// The physics (`[physics]`).
        physics: PhysicsConfig = PhysicsConfig::default() => Rule::Nested,
        /// The reward's target (`[target]`).
        target: TargetConfig = TargetConfig::default() => Rule::Nested,
        /// Constraints that end an episode when broken (`[[constraints]]`).
        constraints: Vec<ConstraintConfig> = Vec::new() => Rule::Nested,
        /// Static box obstacles (`[[obstacles]]`).
        obstacles: Vec<ObstacleConfig> = Vec::new() => Rule::Nested,
        /// A waypoint to pass (`[waypoint]`), for the "passed" record.
        waypoint: Option<WaypointConfig> = None => Rule::Nested,
        /// The fall rule of a floating robot (`[fall]`); none for no falls (a reset then rests
        /// the robot's lowest point on the floor).
        fall: Option<FallConfig> = None => Rule::Nested,
        /// How episodes run and start (`[episode]`).
        episode: EpisodeConfig = EpisodeConfig::default() => Rule::Nested,
        /// The learner (`[learner]`).
        learner: LearnerConfig = LearnerConfig::default() => Rule::Nested,
        /// The run's settings (`[run]`): trials, episodes, seed, GPLVM fit, encoder, latent
        /// box. They replace the preset's; a flag or an API argument replaces them.
        run: RunConfig = RunConfig::default() => Rule::Nested,
    }
    check = task_rules;
}

fn task_rules(t: &TaskConfig, path: &str) -> Result<(), ParamError> {
    let key = |k: &str| join(path, k);
    if t.target.position.len() != t.effectors.len() {
        return Err(ParamError::new(
            &key("target.position"),
            format!(
                "needs one [x, y, z] row per effector ({} effectors: {}), got {} rows",
                t.effectors.len(),
                t.effectors.join(", "),
                t.target.position.len()
            ),
        ));
    }
    match (t.root, &t.floor, &t.fall) {
        (RootMode::Floating, None, _) => Err(ParamError::new(
            &key("floor"),
            "is required with root = \"floating\" (a [floor] table)",
        )),
        (RootMode::Fixed, _, Some(_)) => Err(ParamError::new(&key("fall"), "applies to root = \"floating\" only")),
        _ if t.episode.test_start == TestStart::BelowWaypoint && t.waypoint.is_none() => Err(ParamError::new(
            &key("episode.test_start"),
            "\"below_waypoint\" needs a [waypoint] table",
        )),
        _ => Ok(()),
    }
}

impl TaskConfig {
    /// Every key of a task file with its doc, rule, type and default, table by table: the
    /// source of docs/tasks.md and of the CLI's flags. A key's default is its table's: the
    /// optional and repeated tables' own, the others' as in the default task.
    pub fn schema_tables() -> Vec<SchemaTable> {
        let top = TaskConfig::default();
        vec![
            SchemaTable::of("", &top),
            SchemaTable::of("floor", &FloorConfig::default()),
            SchemaTable::of("servo", &top.servo),
            SchemaTable::of("servo.joints.NAME", &crate::world::JointServo::default()),
            SchemaTable::of("physics", &top.physics),
            SchemaTable::of("target", &top.target),
            SchemaTable::of("constraints[]", &ConstraintConfig::default()),
            SchemaTable::of("obstacles[]", &ObstacleConfig::default()),
            SchemaTable::of("waypoint", &WaypointConfig::default()),
            SchemaTable::of("fall", &FallConfig::default()),
            SchemaTable::of("episode", &top.episode),
            SchemaTable::of("learner", &top.learner),
            SchemaTable::of("run", &top.run),
        ]
    }
}

/// One table of settings: its keys, each with its default.
#[derive(Debug, Clone)]
pub struct SchemaTable {
    /// The table's key path (`""` for the top, `constraints[]` for a repeated table).
    pub prefix: String,
    /// Its keys, in declaration order.
    pub entries: Vec<SchemaEntry>,
}

impl SchemaTable {
    /// The table of `T`'s fields below `prefix`, each with its value in `defaults`.
    pub fn of<T: Params + serde::Serialize>(prefix: &str, defaults: &T) -> Self {
        let values = match toml::Value::try_from(defaults) {
            Ok(toml::Value::Table(table)) => table,
            _ => toml::Table::new(),
        };
        let entries = T::fields().into_iter().map(|f| {
            let default = values.get(f.name).cloned();
            SchemaEntry::new(join(prefix, f.name), f, default)
        });
        Self {
            prefix: prefix.to_string(),
            entries: entries.collect(),
        }
    }
}

/// One settable key: what `_native.task_schema()` lists (each as a dict of these fields but its
/// name, which its key path ends with).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SchemaEntry {
    /// Its key path (`learner.gamma`, `constraints[].kind`).
    pub key: String,
    /// Its name in its table.
    #[serde(skip)]
    pub name: &'static str,
    /// Its meaning.
    pub doc: String,
    /// The rule its value must satisfy, in words.
    pub rule: String,
    /// Its type as the CLI names it.
    pub kind: String,
    /// Its default as a task file writes it (none: absent by default).
    pub default: Option<toml::Value>,
}

impl SchemaEntry {
    /// The entry of `field` at `key` with `default`.
    pub fn new(key: String, field: latent_core::FieldInfo, default: Option<toml::Value>) -> Self {
        Self {
            key,
            name: field.name,
            doc: field.doc,
            rule: field.rule.to_string(),
            kind: field.kind,
            default,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_key_carries_its_default_and_the_run_is_a_table() {
        let tables = TaskConfig::schema_tables();
        let entry = |key: &str| tables.iter().flat_map(|t| &t.entries).find(|e| e.key == key).cloned();
        let default = |key: &str| entry(key).expect("a schema key").default;
        assert_eq!(default("learner.gamma"), Some(toml::Value::Float(0.95)));
        assert_eq!(default("run.trials"), Some(toml::Value::Integer(4)));
        assert_eq!(default("run.encoder"), Some(toml::Value::String("gp".into())));
        assert_eq!(default("target.relative_to"), None);
        assert_eq!(
            entry("run.encoder").unwrap().kind,
            "gp | projection | back_constrained | tracking"
        );
        let config: TaskConfig =
            toml::from_str("urdf = \"a.urdf\"\n[run]\nepisodes = 7\nencoder = \"tracking\"\n").unwrap();
        assert_eq!((config.run.episodes, config.run.trials), (7, 4));
        assert_eq!(config.run.encoder, latent_core::Encoder::Tracking);
    }
}
