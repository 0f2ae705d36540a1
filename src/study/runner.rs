//! The ONE adapter between the batch engine and the scenario module's settings
//! (`crate::scenario`); running a case is the evaluator's ([`crate::evaluate`]).
//!
//! - [`StudyMode`]: the scenario modes a study may name.
//! - [`default_table`]: every scenario-side key with its default for a mode, shaped like the
//!   scenario side of a study file — a table with the sub-tables `scenario`, `control`,
//!   `allocation` and `metrics` (the batch engine adds `static` itself). Used for the list of
//!   valid axis names and to reject unknown keys before anything runs.
//! - [`check_success`]: validate the `[success]` criteria of a scenario-side table.
//! - [`check_case`]: validate a resolved table against a vehicle without running it.
//! - [`method_control`]: the full `[control]` table of a transport method.

use std::fmt;
use std::str::FromStr;

use crate::input::document::deserialize_table;
use crate::input::located::KeyError;
use crate::model::Vehicle;
use crate::scenario::criteria::SuccessSpec;
use crate::scenario::Mode as ScenarioMode;

/// Why the scenario side's defaults or a method's gains could not be produced.
#[derive(Debug, thiserror::Error)]
pub enum SettingsError {
    /// A scenario mode that does not exist.
    #[error("unknown scenario mode '{name}'; valid: {valid}")]
    UnknownMode {
        /// The name given.
        name: String,
        /// The valid names, comma separated.
        valid: String,
    },
    /// The scenario module's defaults.
    #[error(transparent)]
    Scenario(#[from] crate::scenario::ScenarioError),
    /// Parsing the static mode's table.
    #[error(transparent)]
    Toml(#[from] toml::de::Error),
    /// Writing gains back as a table.
    #[error(transparent)]
    TomlWrite(#[from] toml::ser::Error),
    /// Gains that do not parse or validate.
    #[error(transparent)]
    Gains(#[from] KeyError),
}

/// Callers inside fallible steps that report a reason as text (a skipped case's reason).
impl From<SettingsError> for String {
    fn from(e: SettingsError) -> String {
        e.to_string()
    }
}

/// Top-level tables of the scenario side of a study file (besides the batch engine's own
/// `[static]`); must cover the top-level keys of [`default_table`].
pub const SCENARIO_TABLES: [&str; 17] = [
    "scenario",
    "hydro",
    "control",
    "base_control",
    "allocation",
    "metrics",
    "physics",
    "initial",
    "path",
    "setpoint",
    "reference",
    "servo",
    "thrusters",
    "success",
    "mission",
    "fault",
    "secondary",
];

/// The mode of a study (`scenario.mode`; written as lower-case text in study files and
/// manifests): the static analysis alone, or one of the closed-loop scenario modes
/// ([`ScenarioMode`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StudyMode {
    /// Only the static TCM analysis (the default).
    #[default]
    Static,
    /// Closed-loop transport along a path.
    Transport,
    /// Closed-loop work at a set point.
    Work,
}

impl StudyMode {
    /// Every mode, in the order listed in messages.
    pub const ALL: [StudyMode; 3] = [StudyMode::Static, StudyMode::Transport, StudyMode::Work];

    /// The name as written in study files.
    pub fn as_str(self) -> &'static str {
        match self {
            StudyMode::Static => "static",
            StudyMode::Transport => "transport",
            StudyMode::Work => "work",
        }
    }

    /// Whether the mode runs a closed-loop scenario (as opposed to the static analysis).
    pub fn is_dynamic(self) -> bool {
        self != StudyMode::Static
    }
}

impl fmt::Display for StudyMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for StudyMode {
    type Err = SettingsError;
    fn from_str(s: &str) -> Result<Self, SettingsError> {
        StudyMode::ALL
            .into_iter()
            .find(|m| m.as_str() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = StudyMode::ALL.iter().map(|m| m.as_str()).collect();
                SettingsError::UnknownMode {
                    name: s.to_string(),
                    valid: names.join(", "),
                }
            })
    }
}

/// Check a resolved scenario-side table of a dynamic mode against `vehicle` without running
/// it (schema, settings, gains against the design, log size); the error names the key.
pub fn check_case(vehicle: &Vehicle, scenario: &toml::Table) -> Result<(), KeyError> {
    crate::scenario::check_table(vehicle, scenario)
}

/// Every scenario-side key with its default for `mode` (see the module docs for the shape):
/// `crate::scenario::default_table` for the dynamic modes.
pub fn default_table(mode: StudyMode) -> Result<toml::Table, SettingsError> {
    Ok(match mode {
        StudyMode::Static => toml::from_str("[scenario]\nmode = \"static\"\n")?,
        StudyMode::Transport => crate::scenario::default_table(ScenarioMode::Transport)?,
        StudyMode::Work => crate::scenario::default_table(ScenarioMode::Work)?,
    })
}

/// The full `[control]` table of a transport case whose own `control` table (the study's,
/// with the case's overrides) names a `method`: that method's USM Table III row with every
/// key the table gives on top, written out in full — so `method = "method1"` brings Method
/// 1's Δ, k_6p, k_6d and end-effector surge unless the file sets them. `None` when the mode
/// is not transport or no method is named (the defaults, Method 2, stand); `Some(Err)` for
/// gains that do not parse or validate.
pub fn method_control(
    mode: StudyMode,
    control: Option<&toml::Value>,
) -> Option<Result<toml::Table, SettingsError>> {
    let control = control?.as_table()?;
    if mode != StudyMode::Transport || !control.contains_key("method") {
        return None;
    }
    Some(
        deserialize_table::<crate::control::TransportGains>(control, "control")
            .map_err(SettingsError::from)
            .and_then(|g| Ok(toml::Table::try_from(&g)?)),
    )
}

/// Check the `[success]` table of a resolved scenario-side table (absent: the defaults), so
/// that a bad success definition is reported with its key before any case runs.
pub fn check_success(scenario: &toml::Table) -> Result<(), KeyError> {
    let spec: SuccessSpec = match scenario.get("success") {
        Some(toml::Value::Table(t)) => deserialize_table(t, "success")?,
        Some(_) => return Err(KeyError::new("success", "must be a table")),
        None => SuccessSpec::default(),
    };
    spec.validate()
}
