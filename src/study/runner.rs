//! The ONE adapter between the batch engine and the scenario module (`crate::scenario`).
//!
//! Everything the sweep needs from the closed-loop scenarios goes through this file:
//!
//! - [`StudyMode`]: the scenario modes a study may name.
//! - [`default_table`]: every scenario-side key with its default for a mode, shaped like the
//!   scenario side of a study file — a table with the sub-tables `scenario`, `control`,
//!   `allocation` and `metrics` (the batch engine adds `static` itself). Used for the list of
//!   valid axis names and to reject unknown keys before anything runs.
//! - [`check_success`]: validate the `[success]` criteria of a scenario-side table.
//! - [`check_case`]: validate a resolved table against a vehicle without running it.
//! - [`run_case`] / [`run_case_until`]: run one case of a dynamic mode (`transport`, `work`)
//!   on a vehicle with the case's fully resolved scenario-side table (same shape, overrides
//!   applied) and the case seed (the latter within a wall-clock deadline); returns named
//!   scalar metrics and, when `log` is set, a trajectory table.
//!
//! Both delegate to `crate::scenario` (`default_table`, `run_case`); trajectories are turned
//! into report tables here so that the scenario module stays free of polars.

use std::fmt;
use std::str::FromStr;
use std::time::Instant;

use crate::input::document::deserialize_table;
use crate::input::located::KeyError;
use crate::model::Vehicle;
use crate::report::Table;
use crate::scenario::success::SuccessSpec;
use crate::scenario::Mode as ScenarioMode;

/// The result of one dynamic case.
#[derive(Clone, Debug, Default)]
pub struct CaseOutcome {
    /// Named scalar metrics, in a stable order. Names must not contain `=` or `;`.
    pub metrics: Vec<(String, f64)>,
    /// The trajectory (one row per logged step; a time column named `t` or `time` first),
    /// when logging was requested.
    pub trajectory: Option<Table>,
    /// Why the run stopped early (diverged, …): the case is recorded as `failed` with this
    /// reason, its metrics are kept.
    pub failure: Option<String>,
    /// The first `[success]` criterion a completed run missed, as `criterion: detail` (the
    /// criterion id first): the case is recorded as `unsuccessful` with this reason.
    pub missed: Option<String>,
}

/// Top-level tables of the scenario side of a study file (besides the batch engine's own
/// `[static]`); must cover the top-level keys of [`default_table`].
pub const SCENARIO_TABLES: [&str; 13] = [
    "scenario",
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
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        StudyMode::ALL
            .into_iter()
            .find(|m| m.as_str() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = StudyMode::ALL.iter().map(|m| m.as_str()).collect();
                format!("unknown scenario mode '{s}'; valid: {}", names.join(", "))
            })
    }
}

/// Check a resolved scenario-side table of a dynamic mode against `vehicle` without running
/// it (schema, settings, gains against the design, log size): `Err((key, message))`.
pub fn check_case(vehicle: &Vehicle, scenario: &toml::Table) -> Result<(), (String, String)> {
    crate::scenario::check_table(vehicle, scenario).map_err(|e| (e.key.clone(), e.message.clone()))
}

/// The reason of a case stopped by its wall-clock budget starts with this word.
pub const TIMEOUT: &str = crate::scenario::TIMEOUT;

/// Every scenario-side key with its default for `mode` (see the module docs for the shape):
/// `crate::scenario::default_table` for the dynamic modes.
pub fn default_table(mode: StudyMode) -> Result<toml::Table, String> {
    match mode {
        StudyMode::Static => {
            toml::from_str("[scenario]\nmode = \"static\"\n").map_err(|e| e.to_string())
        }
        StudyMode::Transport => {
            crate::scenario::default_table(ScenarioMode::Transport).map_err(|e| e.to_string())
        }
        StudyMode::Work => {
            crate::scenario::default_table(ScenarioMode::Work).map_err(|e| e.to_string())
        }
    }
}

/// Run one dynamic case without a time budget: [`run_case_until`] with no deadline.
pub fn run_case(
    vehicle: &Vehicle,
    scenario: &toml::Table,
    seed: u64,
    log: bool,
) -> Result<CaseOutcome, String> {
    run_case_until(vehicle, scenario, seed, log, None)
}

/// Run one dynamic case: `scenario` is the resolved scenario-side table, `seed` the case seed,
/// `log` asks for the trajectory, `deadline` is the case's wall-clock budget (checked before
/// every control period). An `Err` (invalid settings) is recorded as a failed case with
/// the message as its reason; a run that stops early (diverges, NaN, the deadline: a
/// `timeout: …` failure) returns its metrics with `failure` naming the time and the cause.
pub fn run_case_until(
    vehicle: &Vehicle,
    scenario: &toml::Table,
    seed: u64,
    log: bool,
    deadline: Option<Instant>,
) -> Result<CaseOutcome, String> {
    let run = crate::outcome::run_case(vehicle, scenario, seed, log, deadline)
        .map_err(|e| e.to_string())?;
    let trajectory = match run.trajectory {
        Some(t) => Some(crate::report::figures::trajectory_table(&t).map_err(|e| e.to_string())?),
        None => None,
    };
    Ok(CaseOutcome {
        metrics: run.metrics,
        trajectory,
        failure: run.failure,
        missed: run.missed,
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
) -> Option<Result<toml::Table, String>> {
    let control = control?.as_table()?;
    if mode != StudyMode::Transport || !control.contains_key("method") {
        return None;
    }
    Some(
        deserialize_table::<crate::control::TransportGains>(control, "control")
            .map_err(|e| e.to_string())
            .and_then(|g| toml::Table::try_from(&g).map_err(|e| e.to_string())),
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
