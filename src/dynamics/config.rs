//! Simulator configuration (docs/model.md §4 joint actuation, docs/model.md §2 thruster dynamics): the joint
//! [`ServoModel`], the [`ThrusterModel`], the time [`Integrator`] and the [`SimConfig`] that
//! bundles them with the [`DynOptions`], each default beside its field and a `validate()`.

use super::error::SimError;
use super::DynOptions;

/// Joint servo model (docs/model.md §4 joint actuation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ServoModel {
    /// Ideal servos: the joints follow the second-order reference filter
    /// `q̈ = ω_n²(q_r − q) − 2ζ_n ω_n q̇` exactly (hybrid dynamics); the torques needed are
    /// recovered for energy accounting.
    SecondOrder {
        /// Natural frequency ω_n [rad/s], > 0.
        omega_n: f64,
        /// Damping ratio ζ_n [-], ≥ 0.
        zeta: f64,
    },
    /// Torque-level PD servos, full forward dynamics:
    /// `τ_q = sat(K_p(q_r − q) + K_d(q̇_r − q̇), ±torque_limit)`.
    TorquePd {
        /// Proportional gain K_p [N·m/rad], ≥ 0.
        kp: f64,
        /// Derivative gain K_d [N·m·s/rad], ≥ 0.
        kd: f64,
        /// Torque limit [N·m], > 0 (may be `f64::INFINITY`).
        torque_limit: f64,
    },
    /// Torque-free joints (forward dynamics with zero joint torque): the free multibody.
    Passive,
}

impl ServoModel {
    /// Default natural frequency ω_n [rad/s] of the ideal servos' reference filter (inferred:
    /// well inside the joint modules' bandwidth).
    pub const DEFAULT_OMEGA_N: f64 = 5.0;
    /// Default damping ratio ζ_n [-] of the reference filter (critically damped).
    pub const DEFAULT_ZETA: f64 = 1.0;
}

/// Thruster dynamics model (docs/model.md §2: optional lag and rate limit per thruster).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ThrusterModel {
    /// Actual thrust = saturated command.
    Ideal,
    /// First-order lag; `Some(T)` [s] overrides every thruster's time constant, `None` uses
    /// each thruster's own `Thruster::time_constant` (thrusters without one are ideal).
    FirstOrder {
        /// Global time constant override [s].
        time_constant: Option<f64>,
    },
    /// Rate limit; `Some(r)` [N/s] overrides every thruster's, `None` uses each thruster's
    /// own `Thruster::rate_limit` (thrusters without one are ideal).
    RateLimited {
        /// Global rate limit override [N/s].
        rate_limit: Option<f64>,
    },
    /// Each thruster's own lag and rate limit from the model, whichever it has.
    FromModel,
}

/// How [`Simulator::advance`](super::Simulator::advance) integrates over a span with the
/// commands held (zero-order hold over a control period).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integrator {
    /// Classical Lie-group RK4 with a fixed step `dt` [s] (> 0); a span is cut into
    /// `round(span / dt)` (at least one) equal steps.
    Rk4 {
        /// Step [s].
        dt: f64,
    },
    /// Dormand–Prince 5(4) with FSAL and step-size control on the embedded error estimate:
    /// a step is accepted when `‖e‖ ≤ 1` in the RMS norm with per-component scale
    /// `atol + rtol·max(|x₀|, |x₁|)` over the integrated state (position, quaternion, joint
    /// angles, twist, joint rates, joint work). Each span restarts at its start (the held
    /// command jumps at a control tick); the step size carries over from span to span.
    Dopri5 {
        /// Relative tolerance [-], > 0.
        rtol: f64,
        /// Absolute tolerance [state units: m, -, rad, m/s, rad/s, J], > 0.
        atol: f64,
        /// First trial step [s] of the first span, > 0.
        first_step: f64,
    },
}

impl Integrator {
    /// The default adaptive integrator: Dormand–Prince 5(4) at `rtol = 1e-7`,
    /// `atol = 1e-8`, first trial step 10 ms — the loosest decade at which every metric of the
    /// presets stays within 1e-4 of the converged reference (Dormand–Prince at 1e-12, itself
    /// within 4e-10 of RK4 at 0.25 ms; issue 11: worst 3.1e-5, the final position error of
    /// `work-setpoint`). At `1e-6` a threshold count (`allocation_residual_fraction` of
    /// `work-setpoint`) flips one sample (9.5e-4). The joint work is integrated as each joint's
    /// smooth signed work with the sign changes of `τ_k q̇_k` located per step, so its kinks no
    /// longer drive the step size.
    pub const fn dopri5_default() -> Self {
        Self::Dopri5 {
            rtol: 1e-7,
            atol: 1e-8,
            first_step: 0.01,
        }
    }
}

/// Simulator configuration: physical effects, servo and thruster models. Each field's doc
/// gives its default ([`Default`]); [`SimConfig::validate`] checks the model parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SimConfig {
    /// Which effects enter the dynamics. Default [`DynOptions::full`].
    pub options: DynOptions,
    /// Joint servos. Default ideal second-order servos with ω_n = 5 rad/s and ζ_n = 1
    /// (inferred defaults: critically damped, well inside the joint modules' bandwidth).
    pub servo: ServoModel,
    /// Thruster dynamics. Default [`ThrusterModel::Ideal`].
    pub thruster: ThrusterModel,
    /// Time integration of [`Simulator::advance`](super::Simulator::advance). Default
    /// [`Integrator::dopri5_default`]. ([`Simulator::step`](super::Simulator::step) is
    /// always one RK4 step.)
    pub integrator: Integrator,
}

impl Default for SimConfig {
    fn default() -> Self {
        Self {
            options: DynOptions::full(),
            servo: ServoModel::SecondOrder {
                omega_n: ServoModel::DEFAULT_OMEGA_N,
                zeta: ServoModel::DEFAULT_ZETA,
            },
            thruster: ThrusterModel::Ideal,
            integrator: Integrator::dopri5_default(),
        }
    }
}

impl SimConfig {
    /// Check the servo and thruster parameters (ranges as documented on [`ServoModel`] and
    /// [`ThrusterModel`]); errors name `config.servo.<key>` / `config.thruster.<key>`, with
    /// `time = 0`.
    pub fn validate(&self) -> Result<(), SimError> {
        match self.servo {
            ServoModel::SecondOrder { omega_n, zeta } => {
                positive("config.servo.omega_n", omega_n)?;
                non_negative("config.servo.zeta", zeta)?;
            }
            ServoModel::TorquePd {
                kp,
                kd,
                torque_limit,
            } => {
                non_negative("config.servo.kp", kp)?;
                non_negative("config.servo.kd", kd)?;
                if torque_limit.is_nan() || torque_limit <= 0.0 {
                    return Err(config_err(
                        "config.servo.torque_limit",
                        format!("must be > 0, got {torque_limit}"),
                    ));
                }
            }
            ServoModel::Passive => {}
        }
        match self.thruster {
            ThrusterModel::FirstOrder {
                time_constant: Some(t),
            } => positive("config.thruster.time_constant", t)?,
            ThrusterModel::RateLimited {
                rate_limit: Some(r),
            } => positive("config.thruster.rate_limit", r)?,
            _ => {}
        }
        match self.integrator {
            Integrator::Rk4 { dt } => positive("config.integrator.dt", dt),
            Integrator::Dopri5 {
                rtol,
                atol,
                first_step,
            } => {
                positive("config.integrator.rtol", rtol)?;
                positive("config.integrator.atol", atol)?;
                positive("config.integrator.first_step", first_step)
            }
        }
    }
}

/// A configuration error, found before the run starts (`time = 0`).
pub(super) fn config_err(quantity: &str, message: String) -> SimError {
    SimError {
        time: 0.0,
        quantity: quantity.to_string(),
        message,
    }
}

/// `x` finite and > 0.
fn positive(quantity: &str, x: f64) -> Result<(), SimError> {
    if x.is_finite() && x > 0.0 {
        Ok(())
    } else {
        Err(config_err(
            quantity,
            format!("must be finite and > 0, got {x}"),
        ))
    }
}

/// `x` finite and ≥ 0.
fn non_negative(quantity: &str, x: f64) -> Result<(), SimError> {
    if x.is_finite() && x >= 0.0 {
        Ok(())
    } else {
        Err(config_err(
            quantity,
            format!("must be finite and >= 0, got {x}"),
        ))
    }
}
