//! The physical sections of a scenario file: `[servo]` (joint servos, docs/model.md §4), `[thrusters]`
//! (thruster dynamics) and `[physics]` (which effects act, the current, the time integrator).
//! Re-exported by [`super`]; their translation into a [`crate::dynamics::SimConfig`] stays
//! there.

use crate::dynamics::{Integrator, ServoModel};
use serde::{Deserialize, Serialize};

/// `[servo]`: joint servo model (docs/model.md §4).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ServoSpec {
    /// `second_order` (ideal reference filter, hybrid dynamics) or `torque_pd`.
    pub kind: String,
    /// Natural frequency ω_n [rad/s] of the reference filter.
    pub omega_n: f64,
    /// Damping ratio of the reference filter.
    pub zeta: f64,
    /// PD proportional gain [N·m/rad].
    pub kp: f64,
    /// PD derivative gain [N·m·s/rad].
    pub kd: f64,
    /// PD torque limit [N·m].
    pub torque_limit: f64,
}

impl Default for ServoSpec {
    fn default() -> Self {
        Self {
            kind: "second_order".into(),
            omega_n: ServoModel::DEFAULT_OMEGA_N,
            zeta: ServoModel::DEFAULT_ZETA,
            kp: 200.0,
            kd: 40.0,
            torque_limit: 100.0,
        }
    }
}

/// `[thrusters]`: thruster dynamics.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ThrusterSpec {
    /// `ideal`, `lag`, `rate` or `model` (each thruster's own lag/rate from the design).
    pub model: String,
    /// Lag time constant [s] for `lag` (0 = each thruster's own).
    pub time_constant: f64,
    /// Rate limit [N/s] for `rate` (0 = each thruster's own).
    pub rate_limit: f64,
}

impl Default for ThrusterSpec {
    fn default() -> Self {
        Self {
            model: "ideal".into(),
            time_constant: 0.0,
            rate_limit: 0.0,
        }
    }
}

/// `(rtol, atol)` of [`Integrator::dopri5_default`].
const DOPRI5_DEFAULT: (f64, f64) = match Integrator::dopri5_default() {
    Integrator::Dopri5 { rtol, atol, .. } => (rtol, atol),
    Integrator::Rk4 { .. } => (0.0, 0.0),
};

/// `[physics]`: which effects act, the current, and the time integrator.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PhysicsSpec {
    /// Added mass (and its Kirchhoff term).
    pub added_mass: bool,
    /// Hydrodynamic damping.
    pub drag: bool,
    /// Weight and buoyancy.
    pub restoring: bool,
    /// Constant irrotational current, inertial frame [m/s].
    pub current: [f64; 3],
    /// Time integrator: `"dopri5"` (adaptive Dormand–Prince 5(4), the default) or `"rk4"`
    /// (fixed steps of `scenario.dt`); see [`Integrator`].
    pub integrator: String,
    /// Relative tolerance of `dopri5` (> 0). Default from [`Integrator::dopri5_default`].
    pub rtol: f64,
    /// Absolute tolerance of `dopri5` (> 0). Default from [`Integrator::dopri5_default`].
    pub atol: f64,
}

impl Default for PhysicsSpec {
    fn default() -> Self {
        Self {
            added_mass: true,
            drag: true,
            restoring: true,
            current: [0.0; 3],
            integrator: "dopri5".into(),
            rtol: DOPRI5_DEFAULT.0,
            atol: DOPRI5_DEFAULT.1,
        }
    }
}
