//! The error of a scenario: invalid settings, found before anything runs. A run that stops
//! early is not an error: it is a result with its failure (`RunResult::failure`).
//!
//! Each variant keeps the error it was built from as its `source`, so that a caller can
//! tell a bad key from a design the generator cannot build or a simulator that refuses its
//! settings; the text shown to the user is the one the source prints (with the key prefix or
//! case name the scenario adds), on one line.

use thiserror::Error;

use crate::allocation::AllocError;
use crate::control::ControlError;
use crate::dynamics::SimError;
use crate::input::located::{InputError, KeyError};
use crate::model::design::DesignError;

/// A problem with a scenario's settings or its design; nothing ran.
#[derive(Debug, Error)]
pub enum ScenarioError {
    /// A key of the scenario file is invalid or its text does not parse, placed in its
    /// document (`file:line:col: key: message`).
    #[error("{0}")]
    Input(#[source] InputError),
    /// A setting is invalid at a key of a table that was never a file (checks of the parsed
    /// settings at run time: `key: message`).
    #[error("{0}")]
    Key(#[source] KeyError),
    /// The scenario's design could not be loaded or built.
    #[error("{0}")]
    Design(#[source] DesignError),
    /// The scenario file exists but could not be read.
    #[error("{origin}: {source}")]
    Read {
        /// The file as the user named it.
        origin: String,
        /// The file-system error.
        #[source]
        source: std::io::Error,
    },
    /// The argument is neither a file nor the name of a preset.
    #[error(
        "{name}: no such scenario file, and not a preset (presets: {})",
        .presets.join(", ")
    )]
    NotFound {
        /// The argument as given.
        name: String,
        /// The presets there are.
        presets: Vec<&'static str>,
    },
    /// A table could not be written out as TOML (a value TOML cannot hold).
    #[error("{0}")]
    Serialize(#[source] toml::ser::Error),
    /// The trajectory file of `[reference] file` cannot be a reference (file, line, column).
    #[error("reference.file: {0}")]
    Reference(#[from] crate::control::ReferenceFileError),
    /// A control law refused its settings; the message is the law's key path under `prefix`.
    #[error("{prefix}{source}")]
    Control {
        /// The scenario-file section the law's keys live in, with its dot (`control.`,
        /// `base_control.`), or empty when the law's key is already a file key.
        prefix: &'static str,
        /// The control law's error.
        #[source]
        source: ControlError,
    },
    /// The simulator refused the design or the initial state.
    #[error("{0}")]
    Sim(#[source] SimError),
    /// The allocator refused the `[allocation]` settings for the design's thrusters.
    #[error("allocation: {0}")]
    Allocation(#[source] AllocError),
    /// The design has no thruster, so the closed loop has nothing to allocate to.
    #[error("design: a closed-loop scenario needs at least one thruster")]
    NoThrusters,
    /// The mode needs a table the file does not have.
    #[error("{table}: {mode} mode needs a [{table}] table")]
    MissingTable {
        /// The missing table (`path`, `setpoint`).
        table: &'static str,
        /// The mode needing it (`transport`, `work`).
        mode: &'static str,
    },
    /// A list of joint angles does not have one entry per joint of the design.
    #[error("{key} has {found} entries, the design has {joints} joints")]
    JointCount {
        /// The list's key (`initial.joint_angles_deg`, `q0`).
        key: &'static str,
        /// Entries given.
        found: usize,
        /// Joints of the design.
        joints: usize,
    },
    /// A rule on a group of settings of a built-in case is broken; the text names the keys
    /// and the rule (`duration, control_dt and log_every must be > 0`).
    #[error("{0}")]
    Rule(&'static str),
    /// A problem of a named built-in case (the paper reproductions), with the case's name.
    #[error("{case}: {source}")]
    Case {
        /// The case's name.
        case: String,
        /// What is wrong with it.
        #[source]
        source: Box<ScenarioError>,
    },
}

impl ScenarioError {
    /// This error as a problem of the case named `case`.
    pub fn in_case(self, case: &str) -> ScenarioError {
        ScenarioError::Case {
            case: case.to_string(),
            source: Box::new(self),
        }
    }
}

impl From<ControlError> for ScenarioError {
    /// A control law's error whose key is already a scenario-file key (no prefix).
    fn from(source: ControlError) -> Self {
        ScenarioError::Control { prefix: "", source }
    }
}

impl From<SimError> for ScenarioError {
    fn from(e: SimError) -> Self {
        ScenarioError::Sim(e)
    }
}

impl From<KeyError> for ScenarioError {
    /// A key error not placed in a file (`Source::invalid` in this room places it).
    fn from(e: KeyError) -> Self {
        ScenarioError::Key(e)
    }
}
