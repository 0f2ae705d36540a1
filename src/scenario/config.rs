//! Scenario files (TOML): the design, the mode and its parameters, gains, allocation, physics
//! and control rates, duration and metric settings — everything one closed-loop run needs.
//!
//! ```toml
//! [scenario]
//! name = "transport-method2"
//! mode = "transport"          # transport | work
//! design = "usm-paper"        # preset name or design file (relative to this file)
//! duration = 140.0            # s
//! dt = 0.01                   # physics step (RK4; first trial step of dopri5) [s]
//! control_dt = 0.05           # control period [s]
//! log_dt = 0.1                # logging period [s]
//!
//! [initial]                   # base pose at t = 0
//! position = [0.0, -3.0, 0.0]
//! yaw_deg = 0.0
//!
//! [path]                      # transport: LOS path (control::guidance::PathSpec)
//! segments = [{ from = [0.0, 0.0], to = [200.0, 0.0] }]
//!
//! [setpoint]                  # work: end-effector pose in the inertial frame
//! position = [3.5, 0.5, -0.3]
//! rpy_deg = [0.0, 0.0, 20.0]
//! [reference]                 # work, optional: timed path to the setpoint (scenario::target)
//!
//! [control]                   # transport: TransportGains keys; work: WorkGains keys
//! [base_control]              # USM-33/34 gains (DynamicGains)
//! [secondary]                 # manipulability / controllability objectives (off by default)
//! [allocation]                # method, lambda, q, eps, weights, rate limits
//! [servo]                     # joint servos
//! [thrusters]                 # thruster dynamics
//! [physics]                   # which effects, current, integrator (rk4 | dopri5), rtol, atol
//! [metrics]                   # thresholds, power model
//! [success]                   # what counts as a successful run (scenario::criteria)
//! [mission]                   # payload, reach, convergence deadline (config::MissionSpec)
//! [fault]                     # optional: one thruster fault (scenario::fault)
//! ```
//!
//! A `[design]` table (design-file schema) may replace `scenario.design` (the sweep's route).

mod metrics;
mod mission;
mod physics;

use super::criteria::SuccessSpec;
pub use super::target::{ReferenceSpec, SetpointSpec, ViaSpec};
use crate::allocation::{AllocSettings, Method, RateSettings};
use crate::control::dynamic::DynamicGains;
use crate::control::guidance::PathSpec;
use crate::control::kinematic::SecondarySettings;
use crate::control::transport::TransportGains;
use crate::control::work::WorkGains;
use crate::control::ControlError;
use crate::dynamics::{DynOptions, Integrator, ServoModel, SimConfig, ThrusterModel};
use crate::input::document::deserialize_table;
use crate::input::located::{fmt_exact, KeyError};
use crate::metrics::singularity::CommandedDofs;
use crate::metrics::trajectory::PowerModel;
use crate::model::Vehicle;
pub use metrics::MetricsSpec;
pub use mission::MissionSpec;
pub use physics::{HydroScaleSpec, PhysicsSpec, ServoSpec, ThrusterSpec, SCALE_KEYS};
use serde::{Deserialize, Serialize};
use std::fmt;

/// The two closed-loop modes of the USM paper (section V).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// Path following along straight segments (USM-38…41).
    Transport,
    /// End-effector setpoint regulation with the base as secondary task (USM-42).
    Work,
}

impl Mode {
    /// The base axes the mode's default controller commands (docs/model.md §5), as
    /// [`ScenarioFile::commanded_dofs`] of a file without `[control]`/`[base_control]`: both
    /// of the paper's modes leave roll free (`K_p,roll = 0`; work: zero base-roll weight).
    pub fn default_commanded_dofs(self) -> CommandedDofs {
        match self {
            Mode::Transport => commanded_for(
                &ModeGains::Transport(Default::default()),
                &DynamicGains::transport(),
            ),
            Mode::Work => commanded_for(
                &ModeGains::Work(WorkGains::default()),
                &DynamicGains::work_mode(),
            ),
        }
    }
}

/// The axes commanded under the mode gains `mode` and the base gains `base` (see
/// [`CommandedDofs::transport`], [`CommandedDofs::work`]).
fn commanded_for(mode: &ModeGains, base: &DynamicGains) -> CommandedDofs {
    match mode {
        ModeGains::Transport(_) if base.uncommanded_feedback => CommandedDofs::transport(&base.kp),
        ModeGains::Transport(_) => CommandedDofs::transport(&[0.0; 6]),
        ModeGains::Work(g) => {
            let w = g.weights_for(0);
            let base_w = std::array::from_fn(|i| w.get(i).copied().unwrap_or(0.0));
            CommandedDofs::work(&base_w, &base.kp, &base.ki)
        }
    }
}

impl fmt::Display for Mode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Mode::Transport => "transport",
            Mode::Work => "work",
        })
    }
}

/// `[scenario]`: identity, mode, rates and duration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioSection {
    /// Scenario name (used in outputs).
    #[serde(default = "default_name")]
    pub name: String,
    /// Transport or work mode.
    pub mode: Mode,
    /// Preset name or design file path (relative to the scenario file). Ignored when a
    /// `[design]` table is present.
    #[serde(default = "default_design")]
    pub design: String,
    /// Simulated time [s].
    #[serde(default = "default_duration")]
    pub duration: f64,
    /// Physics (RK4) step [s].
    #[serde(default = "default_dt")]
    pub dt: f64,
    /// Control period [s]; a whole multiple of `dt`.
    #[serde(default = "default_control_dt")]
    pub control_dt: f64,
    /// Logging period [s]; a whole multiple of `control_dt`.
    #[serde(default = "default_log_dt")]
    pub log_dt: f64,
}

fn default_name() -> String {
    "scenario".into()
}
fn default_design() -> String {
    "usm-paper".into()
}
fn default_duration() -> f64 {
    140.0
}
fn default_dt() -> f64 {
    0.01
}
/// Default control period `scenario.control_dt` [s].
pub const DEFAULT_CONTROL_DT: f64 = 0.05;

fn default_control_dt() -> f64 {
    DEFAULT_CONTROL_DT
}
fn default_log_dt() -> f64 {
    0.1
}

/// `[initial]`: the state at t = 0 (at rest).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct InitialSpec {
    /// Base position in the inertial frame [m].
    pub position: [f64; 3],
    /// Base heading about inertial +z [deg].
    pub yaw_deg: f64,
    /// Joint angles [deg]; empty = straight.
    pub joint_angles_deg: Vec<f64>,
}

impl Default for InitialSpec {
    fn default() -> Self {
        Self {
            position: [0.0; 3],
            yaw_deg: 0.0,
            joint_angles_deg: Vec::new(),
        }
    }
}

/// `[allocation]`: the thrust allocation method and its settings (docs/model.md §5, USM-37).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AllocationSpec {
    /// pinv, qp, minimax or power.
    pub method: Method,
    /// Damping λ of the pseudoinverse.
    pub lambda: f64,
    /// Slack weight q.
    pub q: f64,
    /// Minimax regularisation ε.
    pub eps: f64,
    /// Usage weights w (W = diag(w)); empty = all ones.
    pub weights: Vec<f64>,
    /// Rate-change weights R (diag) of `‖u − u_prev‖²_R`; empty = none.
    pub rate_weights: Vec<f64>,
    /// Per-step change bound Δu [N]; 0 = none.
    pub max_step: f64,
}

impl Default for AllocationSpec {
    fn default() -> Self {
        let s = AllocSettings::default();
        Self {
            method: Method::Qp,
            lambda: s.lambda,
            q: s.q,
            eps: s.eps,
            weights: Vec::new(),
            rate_weights: Vec::new(),
            max_step: 0.0,
        }
    }
}

impl AllocationSpec {
    /// Solver settings for `m` thrusters.
    pub fn settings(&self, m: usize) -> AllocSettings {
        let rate = if self.rate_weights.is_empty() && self.max_step <= 0.0 {
            None
        } else {
            Some(RateSettings {
                weights: if self.rate_weights.is_empty() {
                    vec![0.0; m]
                } else {
                    self.rate_weights.clone()
                },
                max_step: vec![
                    if self.max_step > 0.0 {
                        self.max_step
                    } else {
                        f64::INFINITY
                    };
                    m
                ],
            })
        };
        AllocSettings {
            lambda: self.lambda,
            q: self.q,
            eps: self.eps,
            rate,
            ..AllocSettings::default()
        }
    }

    /// Usage weights for `m` thrusters.
    pub fn weights_for(&self, m: usize) -> Vec<f64> {
        if self.weights.is_empty() {
            vec![1.0; m]
        } else {
            self.weights.clone()
        }
    }
}

/// A parsed scenario file. `control` stays a table until the mode decides its schema.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScenarioFile {
    /// Identity, mode, rates.
    pub scenario: ScenarioSection,
    /// Inline design (design-file schema); overrides `scenario.design`.
    #[serde(default)]
    pub design: Option<toml::Table>,
    /// Initial state.
    #[serde(default)]
    pub initial: InitialSpec,
    /// Transport path.
    #[serde(default)]
    pub path: Option<PathSpec>,
    /// Work setpoint.
    #[serde(default)]
    pub setpoint: Option<SetpointSpec>,
    /// Work: timed end-effector path to the setpoint; `None` = a step at `t = 0`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference: Option<ReferenceSpec>,
    /// Mode gains (TransportGains or WorkGains keys).
    #[serde(default)]
    pub control: toml::Table,
    /// Base control gains (USM-33/34); defaults depend on the mode.
    #[serde(default)]
    pub base_control: Option<DynamicGains>,
    /// The paper's secondary objectives (USM section IV-A: manipulability, controllability),
    /// below the mode's tasks; off by default.
    #[serde(default)]
    pub secondary: SecondarySettings,
    /// Thrust allocation.
    #[serde(default)]
    pub allocation: AllocationSpec,
    /// Joint servos.
    #[serde(default)]
    pub servo: ServoSpec,
    /// Thruster dynamics.
    #[serde(default)]
    pub thrusters: ThrusterSpec,
    /// Physical effects.
    #[serde(default)]
    pub physics: PhysicsSpec,
    /// Whole-design hydrodynamic scale factors (uncertain worlds).
    #[serde(default)]
    pub hydro: HydroScaleSpec,
    /// Metric settings.
    #[serde(default)]
    pub metrics: MetricsSpec,
    /// Success criteria (docs/model.md §6).
    #[serde(default)]
    pub success: SuccessSpec,
    /// Mission requirements: payload, reach, deadline (docs/model.md §6 "Missions").
    #[serde(default)]
    pub mission: MissionSpec,
    /// One thruster fault during the run (`scenario::fault`); none by default.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fault: Option<super::fault::FaultSpec>,
}

/// Mode-specific gains, parsed from `[control]`.
#[derive(Clone, Debug, PartialEq)]
pub enum ModeGains {
    /// Transport (USM Table III and the choices of `control::transport`).
    Transport(TransportGains),
    /// Work mode (USM-42).
    Work(WorkGains),
}

impl ScenarioFile {
    /// Parse the `[control]` table for the mode; errors name the key.
    pub fn mode_gains(&self) -> Result<ModeGains, KeyError> {
        match self.scenario.mode {
            Mode::Transport => {
                deserialize_table(&self.control, "control").map(ModeGains::Transport)
            }
            Mode::Work => deserialize_table(&self.control, "control").map(ModeGains::Work),
        }
    }

    /// Check the gains against the design `v` they will drive (USM-33/34 and the mode's
    /// gains; work-mode weights need 6 + n entries); errors name the file key
    /// (`control.weights`, `base_control.kp[2]`).
    pub fn check_design(&self, v: &Vehicle) -> Result<(), KeyError> {
        match self.mode_gains()? {
            ModeGains::Transport(g) => g.validate(),
            ModeGains::Work(g) => g.validate(v.n_joints()),
        }
        .map_err(file_key_error)?;
        self.world_vehicle(v).map(|_| ())
    }

    /// The plant this file's world makes of the design `v`: the file's 3-D current, the
    /// `[hydro]` scale factors and centre-of-buoyancy shifts, the thrust derating and the
    /// mission payload (docs/model.md §4, §6). Errors name the key (a CB shifted out of a
    /// body, a payload wet weight above its weight).
    pub fn world_vehicle(&self, v: &Vehicle) -> Result<Vehicle, KeyError> {
        let mut w = v.clone();
        w.fluid.current = crate::spatial::Vec3::from(self.physics.total_current());
        let key = |e: crate::model::ModelError| KeyError::new(e.key, e.message);
        let scales = self.hydro.scales(self.thrusters.limit_scale);
        w.apply_scales(&scales, &SCALE_KEYS).map_err(key)?;
        let volume = self.mission.payload_volume_in(w.fluid.rho, w.fluid.g)?;
        w.add_payload(self.mission.payload_mass, volume)
            .map_err(key)?;
        Ok(w)
    }

    /// Base control gains: the file's, or the mode's default
    /// ([`DynamicGains::transport`], [`DynamicGains::work_mode`]). A partial `[base_control]`
    /// table fills the missing keys from the work-mode defaults (`nonlinear = false`).
    pub fn base_gains(&self) -> DynamicGains {
        self.base_control
            .clone()
            .unwrap_or(match self.scenario.mode {
                Mode::Transport => DynamicGains::transport(),
                Mode::Work if self.reference_file().is_some() => DynamicGains::tracking(),
                Mode::Work => DynamicGains::work_mode(),
            })
    }

    /// The base axes this scenario's controller commands (docs/model.md §5), from its mode, `[control]`
    /// and `[base_control]` gains: the selection `S` of `singularity_exposure` and
    /// `allocation_residual_fraction` ([`CommandedDofs::transport`] — surge, yaw and the axes
    /// with `K_p > 0` when the base control feeds back on the uncommanded axes —,
    /// [`CommandedDofs::work`]).
    pub fn commanded_dofs(&self) -> Result<CommandedDofs, KeyError> {
        Ok(commanded_for(&self.mode_gains()?, &self.base_gains()))
    }

    /// [`Self::commanded_dofs`], or the mode's default controller's
    /// ([`Mode::default_commanded_dofs`]) when the gains do not parse.
    pub fn commanded(&self) -> CommandedDofs {
        self.commanded_dofs()
            .unwrap_or_else(|_| self.scenario.mode.default_commanded_dofs())
    }

    /// The trajectory file of `[reference] file`, if the run follows one.
    pub fn reference_file(&self) -> Option<&str> {
        self.reference.as_ref().and_then(|r| r.file.as_deref())
    }

    /// The characteristic length L [m] of the scaled TCM: `metrics.char_length`, or half the
    /// length of `v` when that is 0 (docs/model.md §6).
    pub fn char_length(&self, v: &Vehicle) -> f64 {
        if self.metrics.char_length > 0.0 {
            self.metrics.char_length
        } else {
            v.characteristic_length()
        }
    }

    /// The simulator configuration.
    pub fn sim_config(&self) -> Result<SimConfig, KeyError> {
        let servo = match self.servo.kind.as_str() {
            "second_order" => ServoModel::SecondOrder {
                omega_n: self.servo.omega_n,
                zeta: self.servo.zeta,
            },
            "torque_pd" => ServoModel::TorquePd {
                kp: self.servo.kp,
                kd: self.servo.kd,
                torque_limit: self.servo.torque_limit,
            },
            other => {
                return Err(KeyError::new(
                    "servo.kind",
                    format!("unknown servo '{other}'; valid: second_order, torque_pd"),
                ))
            }
        };
        let opt = |x: f64| if x > 0.0 { Some(x) } else { None };
        let thruster = match self.thrusters.model.as_str() {
            "ideal" => ThrusterModel::Ideal,
            "lag" => ThrusterModel::FirstOrder {
                time_constant: opt(self.thrusters.time_constant),
            },
            "rate" => ThrusterModel::RateLimited {
                rate_limit: opt(self.thrusters.rate_limit),
            },
            "model" => ThrusterModel::FromModel,
            other => {
                return Err(KeyError::new(
                    "thrusters.model",
                    format!("unknown model '{other}'; valid: ideal, lag, rate, model"),
                ))
            }
        };
        let p = &self.physics;
        let integrator = match p.integrator.as_str() {
            "rk4" => Integrator::Rk4 {
                dt: self.scenario.dt,
            },
            "dopri5" => Integrator::Dopri5 {
                rtol: p.rtol,
                atol: p.atol,
                first_step: self.scenario.dt,
            },
            other => {
                return Err(KeyError::new(
                    "physics.integrator",
                    format!("unknown integrator '{other}'; valid: rk4, dopri5"),
                ))
            }
        };
        Ok(SimConfig {
            options: DynOptions {
                added_mass: p.added_mass,
                drag: p.drag,
                restoring: p.restoring,
                current: p.total_current().iter().any(|c| *c != 0.0),
            },
            servo,
            thruster,
            integrator,
        })
    }

    /// The power model of the metrics section for water of density `rho`.
    pub fn power_model(&self, rho: f64) -> PowerModel {
        PowerModel {
            propeller_diameter: self.metrics.propeller_diameter,
            efficiency: self.metrics.efficiency,
            rho,
        }
    }

    /// Check rates, durations and mode-specific sections; errors name the key.
    pub fn validate(&self) -> Result<(), KeyError> {
        self.validate_rates()?;
        let finite = |k: &str, xs: &[f64]| match xs.iter().find(|x| !x.is_finite()) {
            Some(x) => Err(KeyError::new(
                k,
                format!("must be finite, got {}", fmt_exact(*x)),
            )),
            None => Ok(()),
        };
        finite("initial.position", &self.initial.position)?;
        finite("initial.yaw_deg", &[self.initial.yaw_deg])?;
        finite("initial.joint_angles_deg", &self.initial.joint_angles_deg)?;
        self.physics.validate_current()?;
        finite("physics.current", &self.physics.total_current())?;
        let scales = self.hydro.scales(self.thrusters.limit_scale);
        scales
            .validate(&SCALE_KEYS)
            .map_err(|e| KeyError::new(e.key, e.message))?;
        match self.scenario.mode {
            Mode::Transport if self.path.is_none() => {
                return Err(KeyError::new("path", "transport mode needs a [path] table"))
            }
            Mode::Work if self.setpoint.is_none() && self.reference_file().is_none() => {
                return Err(KeyError::new(
                    "setpoint",
                    "work mode needs a [setpoint] table",
                ))
            }
            _ => {}
        }
        if let Some(sp) = &self.setpoint {
            finite("setpoint.position", &sp.position)?;
            finite("setpoint.rpy_deg", &sp.rpy_deg)?;
        }
        if let Some(r) = &self.reference {
            r.validate(self.scenario.mode == Mode::Work, self.scenario.duration)?;
        }
        self.validate_metrics()?;
        self.success.validate()?;
        self.mission.validate()?;
        self.mode_gains()?;
        self.base_gains().validate().map_err(file_key_error)?;
        self.secondary.validate().map_err(file_key_error)?;
        self.sim_config()?;
        Ok(())
    }

    /// `[scenario]`: positive durations, control and logging periods whole multiples.
    fn validate_rates(&self) -> Result<(), KeyError> {
        let s = &self.scenario;
        check_scenario_name(&s.name)?;
        for (k, v) in [
            ("scenario.duration", s.duration),
            ("scenario.dt", s.dt),
            ("scenario.control_dt", s.control_dt),
            ("scenario.log_dt", s.log_dt),
        ] {
            positive(k, v)?;
        }
        let ratio = |a: f64, b: f64| {
            let r = (a / b).round();
            r >= 1.0 && (a - r * b).abs() <= 1e-9 * a.max(1.0)
        };
        if !ratio(s.control_dt, s.dt) {
            return Err(KeyError::new(
                "scenario.control_dt",
                format!(
                    "{} must be a whole multiple of scenario.dt ({})",
                    fmt_exact(s.control_dt),
                    fmt_exact(s.dt)
                ),
            ));
        }
        if !ratio(s.log_dt, s.control_dt) {
            return Err(KeyError::new(
                "scenario.log_dt",
                format!(
                    "{} must be a whole multiple of scenario.control_dt ({})",
                    fmt_exact(s.log_dt),
                    fmt_exact(s.control_dt)
                ),
            ));
        }
        if s.duration < s.control_dt {
            return Err(KeyError::new(
                "scenario.duration",
                format!(
                    "{} s is shorter than one control period (scenario.control_dt = {} s): \
                     the run would have no step",
                    fmt_exact(s.duration),
                    fmt_exact(s.control_dt)
                ),
            ));
        }
        if s.control_dt / s.dt > MAX_SUBSTEPS {
            return Err(KeyError::new(
                "scenario.control_dt",
                format!(
                    "gives {} steps of scenario.dt per control period, more than {MAX_SUBSTEPS:e} \
                     (a run's time budget is checked once per control period)",
                    fmt_exact((s.control_dt / s.dt).round())
                ),
            ));
        }
        if s.duration / s.dt > 5.0e7 {
            return Err(KeyError::new(
                "scenario.duration",
                format!(
                    "gives {} steps of scenario.dt, more than 5e7",
                    fmt_exact((s.duration / s.dt).round())
                ),
            ));
        }
        Ok(())
    }

    /// `[metrics]`: positive thresholds and tolerances.
    fn validate_metrics(&self) -> Result<(), KeyError> {
        let m = &self.metrics;
        for (k, v) in [
            ("metrics.threshold", m.threshold),
            ("metrics.residual_tolerance", m.residual_tolerance),
            ("metrics.band", m.band),
            ("metrics.position_tolerance", m.position_tolerance),
            (
                "metrics.orientation_tolerance_deg",
                m.orientation_tolerance_deg,
            ),
            ("metrics.propeller_diameter", m.propeller_diameter),
            ("metrics.efficiency", m.efficiency),
            ("metrics.joint_efficiency", m.joint_efficiency),
            ("metrics.divergence_distance", m.divergence_distance),
        ] {
            positive(k, v)?;
        }
        if !m.char_length.is_finite() || m.char_length < 0.0 {
            return Err(KeyError::new(
                "metrics.char_length",
                format!("must be finite and >= 0, got {}", m.char_length),
            ));
        }
        Ok(())
    }
}

/// Most physics steps of `scenario.dt` in one control period.
pub const MAX_SUBSTEPS: f64 = 1.0e5;

/// Longest scenario name (it names `out/<name>` and appears in file names).
const MAX_NAME_CHARS: usize = 100;

/// `scenario.name` names the output directory (`out/<name>`): non-empty, at most
/// [`MAX_NAME_CHARS`] ASCII letters, digits, `_`, `-` and `.`, not starting with `.` — so that
/// `""`, `.`, `..` and `~` are refused rather than written into `out/` itself or mapped to one
/// shared name.
fn check_scenario_name(name: &str) -> Result<(), KeyError> {
    let ok = !name.is_empty()
        && name.len() <= MAX_NAME_CHARS
        && !name.starts_with('.')
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "_-.".contains(c));
    if ok {
        return Ok(());
    }
    Err(KeyError::new(
        "scenario.name",
        format!(
            "`{name}`: must be 1 to {MAX_NAME_CHARS} letters, digits, `_`, `-` and `.`, not \
             starting with `.` (it names the output directory out/<name>)"
        ),
    ))
}

fn positive(key: &str, v: f64) -> Result<(), KeyError> {
    if !v.is_finite() || v <= 0.0 {
        return Err(KeyError::new(
            key,
            format!("must be a finite number > 0, got {}", fmt_exact(v)),
        ));
    }
    Ok(())
}

/// A control-layer error keyed by the controller (`transport.k_psi`, `work.weights`,
/// `dynamic.kp[2]`) as an error keyed by the scenario file (`control.k_psi`,
/// `control.weights`, `base_control.kp[2]`).
fn file_key_error(e: ControlError) -> KeyError {
    let key = match e.key.split_once('.') {
        Some(("transport" | "work", rest)) => format!("control.{rest}"),
        Some(("dynamic", rest)) => format!("base_control.{rest}"),
        _ => e.key,
    };
    KeyError::new(key, e.message)
}
