//! A task (docs/tasks.md): a URDF robot, its servos and physics, effectors with a target and
//! a Gaussian reward, constraints, obstacles, a fall rule, start rules and episodes, written
//! once here and read from a TOML task file or a Python dict. Experiments 2 and 3 are task
//! files (`latentrl/tasks/*.toml`); [`TaskPlant`] is the one plant that runs any of them.

use std::path::{Path, PathBuf};

use latent_core::params::Params;
use latent_core::{EpisodeRules, StartMode};

use crate::error::{Result, SimError};
use crate::fall::FallCriteria;
use crate::urdf::{LoadOptions, UrdfModel};
use crate::world::WorldConfig;

mod config;
mod plant;
pub mod survey;
pub mod trials;
pub use config::{
    Axis, ConstraintConfig, ConstraintKind, EpisodeConfig, FallConfig, FloorConfig, ObstacleConfig, ObstacleTest,
    RuleCheck, SchemaEntry, SchemaTable, StartRule, TargetConfig, TaskConfig, TestStart, WaypointConfig,
};
pub use plant::{Classified, TaskPlant};
pub use trials::TaskTrials;

/// Largest task file read (bytes): a task is a page of text. A FIFO, a device or a directory
/// given as a task file is refused before it is read ([`crate::files`]).
pub const MAX_TASK_FILE: u64 = 1 << 20;

/// A checked task: its configuration and its robot, every name resolved against the URDF.
#[derive(Debug, Clone)]
pub struct Task {
    config: TaskConfig,
    model: UrdfModel,
    origin: String,
}

/// `Task("name", robot="robot", joints=N, effectors=[...])`: how a task shows itself.
impl std::fmt::Display for Task {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (config, model) = (&self.config, &self.model);
        write!(
            f,
            "Task({:?}, robot={:?}, joints={}, effectors={:?})",
            config.name,
            model.name(),
            model.joints().len(),
            config.effectors
        )
    }
}

impl Task {
    /// Reads a TOML task file: the URDF path is resolved against the file's folder. Errors
    /// name the file and the key path (`task.toml: learner.gamma must lie in [0, 1), got 1`).
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let origin = path.display().to_string();
        let failed = |reason: String| SimError::Task {
            origin: origin.clone(),
            reason,
        };
        let text = crate::files::read_text(path, MAX_TASK_FILE, "a task file").map_err(failed)?;
        let config = parse_toml(&text).map_err(failed)?;
        Self::from_config(config, path.parent().unwrap_or(Path::new(".")), &origin)
    }

    /// The folder a configuration's URDF path is resolved against when none is named.
    pub const CONFIG_BASE_DIR: &'static str = ".";

    /// What names a task made from a configuration in errors when nothing else does.
    pub const CONFIG_ORIGIN: &'static str = "<dict>";

    /// A task from a configuration (e.g. a Python dict); its URDF path is resolved against
    /// `base_dir` ([`Task::CONFIG_BASE_DIR`] by default), `origin` names it in errors
    /// ([`Task::CONFIG_ORIGIN`] by default).
    pub fn from_config(config: TaskConfig, base_dir: &Path, origin: &str) -> Result<Self> {
        let failed = |reason: String| SimError::Task {
            origin: origin.to_string(),
            reason,
        };
        config.validate().map_err(|e| failed(e.to_string()))?;
        let urdf: PathBuf = base_dir.join(&config.urdf);
        let options = LoadOptions {
            balance_inertia: config.balance_inertia,
        };
        let model = UrdfModel::from_file_with_options(&urdf, crate::urdf::cache::default_folder().as_deref(), options)
            .map_err(|e| failed(format!("urdf: {e}")))?;
        Self::new(config, model, origin)
    }

    /// A task on an already loaded robot (`config.urdf` is kept as given, not read).
    pub fn new(config: TaskConfig, model: UrdfModel, origin: &str) -> Result<Self> {
        let failed = |reason: String| SimError::Task {
            origin: origin.to_string(),
            reason,
        };
        config.validate().map_err(|e| failed(e.to_string()))?;
        let link = |key: String, name: &str| {
            model
                .link_index(name)
                .map(|_| ())
                .map_err(|e| failed(format!("{key}: {e}")))
        };
        for (i, e) in config.effectors.iter().enumerate() {
            link(format!("effectors[{i}]"), e)?;
        }
        for (i, c) in config.constraints.iter().enumerate() {
            for (j, l) in c.links.iter().enumerate() {
                link(format!("constraints[{i}].links[{j}]"), l)?;
            }
            if let Some(l) = &c.link {
                link(format!("constraints[{i}].link"), l)?;
            }
        }
        if let Some(l) = &config.target.relative_to {
            link("target.relative_to".to_string(), l)?;
        }
        for (i, pair) in config.physics.ignore_collisions.iter().enumerate() {
            for (j, l) in pair.iter().enumerate() {
                link(format!("physics.ignore_collisions[{i}][{j}]"), l)?;
            }
        }
        if let Some(fall) = &config.fall {
            for (i, s) in fall.soles.iter().enumerate() {
                link(format!("fall.soles[{i}]"), s)?;
                let shaped = model
                    .robot
                    .links
                    .iter()
                    .any(|l| &l.name == s && !l.collision.is_empty());
                if !shaped {
                    return Err(failed(format!(
                        "fall.soles[{i}]: link \"{s}\" has no collision shape (a sole's shapes make the support \
                         polygon and touch the floor)"
                    )));
                }
            }
        }
        if model.joints().is_empty() {
            return Err(failed(format!(
                "urdf: the robot \"{}\" has no actuated joint (every joint is fixed or a mimic): nothing to move",
                model.name()
            )));
        }
        if let Some(name) = config.servo.joints.keys().find(|n| !model.is_servoed(n)) {
            return Err(failed(format!(
                "servo.joints.{name}: no servoed joint of that name; servoed joints are: {}",
                model.servoed_names().join(", ")
            )));
        }
        Ok(Self {
            config,
            model,
            origin: origin.to_string(),
        })
    }

    /// The configuration.
    pub fn config(&self) -> &TaskConfig {
        &self.config
    }

    /// The robot.
    pub fn model(&self) -> &UrdfModel {
        &self.model
    }

    /// Where the task came from (a file path, or what the caller named it).
    pub fn origin(&self) -> &str {
        &self.origin
    }

    /// A [`SimError::Task`] of this task: `reason`, after where the task came from.
    pub fn error(&self, reason: impl Into<String>) -> SimError {
        SimError::Task {
            origin: self.origin.clone(),
            reason: reason.into(),
        }
    }

    /// The world every episode runs in.
    pub fn world_config(&self) -> WorldConfig {
        WorldConfig {
            root: self.config.root,
            floor: self.config.floor.as_ref().map(|f| f.height),
            physics: self.config.physics.clone(),
            servo: self.config.servo.clone(),
        }
    }

    /// The learner's episode rules: length, penalty, start and draws.
    pub fn episode_rules(&self) -> EpisodeRules {
        let e = &self.config.episode;
        EpisodeRules {
            max_steps: e.max_steps,
            penalty: e.penalty,
            start: match e.start {
                crate::task::StartRule::Uniform => StartMode::Uniform,
                crate::task::StartRule::Demo => StartMode::Plant,
            },
            max_start_draws: e.max_start_draws,
            stop: (e.stop_window > 0).then_some(latent_core::StopRule {
                window: e.stop_window,
                patience: e.stop_patience,
            }),
        }
    }

    /// The fall test (its base height is set at every reset), if the task has a fall rule.
    pub(crate) fn fall_criteria(&self) -> Option<FallCriteria> {
        self.config.fall.as_ref().map(|f| FallCriteria {
            min_base_height: 0.0,
            max_sole_tilt: f.max_tilt,
            soles: f.soles.clone(),
        })
    }

    /// Columns of a recorded row: 3 per effector, the base pose (7) and the joints.
    pub fn row_len(&self) -> usize {
        3 * self.config.effectors.len() + 7 + self.model.joints().len()
    }
}

/// A [`TaskConfig`] from TOML text; an error names the key path and the line
/// (`learner.gamma (line 54): invalid type: string "x", expected a number`).
pub fn parse_toml(text: &str) -> std::result::Result<TaskConfig, String> {
    let at = |span: Option<std::ops::Range<usize>>| {
        span.map_or(String::new(), |s| {
            format!(" (line {})", text[..s.start.min(text.len())].lines().count().max(1))
        })
    };
    let de = toml::Deserializer::parse(text).map_err(|e| format!("not valid TOML{}: {}", at(e.span()), e.message()))?;
    serde_path_to_error::deserialize(de).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner();
        let key = if path == "." || path.is_empty() {
            "task".to_string()
        } else {
            path
        };
        format!(
            "{key}{}: {}",
            at(inner.span()),
            latent_core::error::plain_types(inner.message())
        )
    })
}
