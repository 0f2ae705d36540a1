//! Antonelli & Chiaverini's case 3 (docs/model.md §8): the NPS AUV II with its full 6-DOF dynamic
//! model ([`crate::paper::nps_auv2`], through the crate's floating-base dynamics) under the
//! constant irrotational current `ν_c = (0.1√2, 0.1√2, 0)` m/s, driven by the sliding-mode
//! law of [`crate::paper::sliding`], for 100 s:
//!
//! - **3a**: the vehicle holds its initial pose (0, 0, ψ = 0): the control forces only
//!   compensate the current;
//! - **3b**: the vehicle follows the vehicle motion of case 1 (re-orientation to
//!   ψ = 0.78 rad into the current within 10 s, position held by the secondary task), then
//!   holds the final pose.
//!
//! The paper's Table I is `∫‖f‖dt` and `∫‖m‖dt` of the generalised control forces `τ_r`
//! (AC-2) over the run: [`DynamicHistory::force_integral`], [`DynamicHistory::moment_integral`]
//! (the control wrench is held over each control period, so the sums are exact).
//!
//! Inferred (the paper does not say; overridable in [`DynamicCase`]): the vehicle alone (the
//! arm's parameters are unknown, docs/model.md §8), starting at rest; depth, roll and pitch references
//! zero; control at 100 Hz with fixed RK4 steps of 10 ms; samples logged at 5 Hz.

use super::KinematicHistory;
use crate::dynamics::{
    restoring_generalized, ActuatorCommand, DynWorkspace, Integrator, SimConfig, SimState,
    Simulator,
};
use crate::kinematics::BasePose;
use crate::paper::nps_auv2::{actuator_thrusts, nps_auv2};
use crate::paper::sliding::{
    sliding_mode_wrench, sliding_variable, PoseReference, SlidingModeGains,
};
use crate::scenario::ScenarioError;
use crate::spatial::{euler_zyx, Vec3, Vec6};
use nalgebra::UnitQuaternion;
use serde::Serialize;

/// A planar vehicle reference `(x, y, ψ)` and its inertial rates, sampled in time; held at
/// its last sample afterwards (and at its first before).
#[derive(Clone, Debug, PartialEq)]
pub struct BaseTrajectory {
    /// Sample times [s], increasing.
    pub t: Vec<f64>,
    /// `x, y` [m], `ψ` [rad] per sample.
    pub pose: [Vec<f64>; 3],
    /// `ẋ, ẏ` [m/s], `ψ̇` [rad/s] per sample (inertial).
    pub rate: [Vec<f64>; 3],
}

impl BaseTrajectory {
    /// Hold the pose `(x, y, ψ)` forever.
    pub fn hold(pose: [f64; 3]) -> Self {
        Self {
            t: vec![0.0],
            pose: pose.map(|x| vec![x]),
            rate: [vec![0.0], vec![0.0], vec![0.0]],
        }
    }

    /// The vehicle motion of a kinematic case (its `base` and `base_rate`); after its end the
    /// final pose is held with zero rates.
    pub fn from_kinematic(h: &KinematicHistory) -> Self {
        let mut r = Self {
            t: h.t.clone(),
            pose: h.base.clone(),
            rate: h.base_rate.clone(),
        };
        // Past the end the pose is held: the rate of the last sample is zero.
        for k in 0..3 {
            if let Some(x) = r.rate[k].last_mut() {
                *x = 0.0;
            }
        }
        r
    }

    /// The reference at time `t` (linear interpolation between samples): pose and rates.
    pub fn sample(&self, t: f64) -> ([f64; 3], [f64; 3]) {
        let n = self.t.len();
        let i = self.t.partition_point(|&s| s <= t);
        let lerp = |x: &[f64]| -> f64 {
            if i == 0 {
                x[0]
            } else if i >= n {
                x[n - 1]
            } else {
                let a = (t - self.t[i - 1]) / (self.t[i] - self.t[i - 1]);
                x[i - 1] + a * (x[i] - x[i - 1])
            }
        };
        let rate = |x: &[f64]| if i >= n { 0.0 } else { lerp(x) };
        (
            [
                lerp(&self.pose[0]),
                lerp(&self.pose[1]),
                lerp(&self.pose[2]),
            ],
            [
                rate(&self.rate[0]),
                rate(&self.rate[1]),
                rate(&self.rate[2]),
            ],
        )
    }

    /// The 6-DOF reference at time `t` (depth, roll and pitch zero).
    fn reference(&self, t: f64) -> PoseReference {
        let (p, r) = self.sample(t);
        PoseReference {
            position: Vec3::new(p[0], p[1], 0.0),
            orientation: UnitQuaternion::from_axis_angle(&Vec3::z_axis(), p[2]),
            velocity: Vec3::new(r[0], r[1], 0.0),
            angular_velocity: Vec3::new(0.0, 0.0, r[2]),
        }
    }
}

/// Settings of a case-3 run.
#[derive(Clone, Debug, PartialEq)]
pub struct DynamicCase {
    /// Name used for outputs (`case3a`, `case3b`).
    pub name: String,
    /// Simulated time [s] (paper: 100).
    pub duration: f64,
    /// Control period [s] (inferred: 0.01); the physics takes one RK4 step per period.
    pub control_dt: f64,
    /// Log every this many control periods (default 20: 5 Hz).
    pub log_every: usize,
    /// Constant irrotational current in the inertial frame [m/s] (paper:
    /// `(0.1√2, 0.1√2, 0)`).
    pub current: Vec3,
    /// Sliding-mode gains.
    pub gains: SlidingModeGains,
    /// Add Fossen's added-mass Coriolis `C_A(ν_r) ν_r` to the derivative table
    /// ([`crate::model::manoeuvring::Manoeuvring::kirchhoff`]). The paper's set-up: `true`
    /// (AC-3 writes `C(q, ζ_r) ζ_r` after Fossen [5], whose `C` holds `C_A`); `false` is
    /// MSS `npsauv.m`.
    pub added_mass_coriolis: bool,
}

impl DynamicCase {
    /// The paper's set-up named `name`.
    pub fn paper(name: &str) -> Self {
        let c = 0.1 * std::f64::consts::SQRT_2;
        Self {
            name: name.into(),
            duration: 100.0,
            control_dt: 0.01,
            log_every: 20,
            current: Vec3::new(c, c, 0.0),
            gains: SlidingModeGains::default(),
            added_mass_coriolis: true,
        }
    }

    /// Positive finite times, `log_every ≥ 1`, finite current, valid gains.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        let bad = |e: ScenarioError| Err(e.in_case(&self.name));
        if ![self.duration, self.control_dt]
            .iter()
            .all(|x| x.is_finite() && *x > 0.0)
            || self.log_every == 0
        {
            return bad(ScenarioError::Rule(
                "duration, control_dt and log_every must be > 0",
            ));
        }
        if !self.current.iter().all(|x| x.is_finite()) {
            return bad(ScenarioError::Rule("current must be finite"));
        }
        self.gains
            .validate()
            .map_err(|e| ScenarioError::from(e).in_case(&self.name))
    }
}

/// Logged time histories of a case-3 run (SI units, rad). Body quantities are in `F_b` at the
/// hull centre `CO` with the crate's axes (x forward, y port, z up).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct DynamicHistory {
    /// Case name.
    pub name: String,
    /// Time [s].
    pub t: Vec<f64>,
    /// Position `x, y, z` [m] (inertial).
    pub position: [Vec<f64>; 3],
    /// Roll, pitch, yaw (ZYX) [rad].
    pub attitude: [Vec<f64>; 3],
    /// Base twist `u, v, w` [m/s], `p, q, r` [rad/s].
    pub twist: [Vec<f64>; 6],
    /// Reference `x_d, y_d` [m], `ψ_d` [rad].
    pub reference: [Vec<f64>; 3],
    /// Control wrench `f_x, f_y, f_z` [N], `m_x, m_y, m_z` [N·m].
    pub wrench: [Vec<f64>; 6],
    /// `‖f‖` [N].
    pub force_norm: Vec<f64>,
    /// `‖m‖` [N·m].
    pub moment_norm: Vec<f64>,
    /// `∫‖f‖dt` over the run [N·s] (Table I).
    pub force_integral: f64,
    /// `∫‖m‖dt` over the run [N·m·s] (Table I).
    pub moment_integral: f64,
}

impl DynamicHistory {
    /// Every sampled series as `(column name, values)`, time first.
    pub fn columns(&self) -> Vec<(String, &[f64])> {
        let mut c: Vec<(String, &[f64])> = vec![("t".into(), &self.t)];
        let groups: [(&[&str], &[Vec<f64>]); 5] = [
            (&["x", "y", "z"], &self.position),
            (&["roll", "pitch", "yaw"], &self.attitude),
            (&["u", "v", "w", "p", "q", "r"], &self.twist),
            (&["x_d", "y_d", "psi_d"], &self.reference),
            (&["f_x", "f_y", "f_z", "m_x", "m_y", "m_z"], &self.wrench),
        ];
        for (names, series) in groups {
            for (n, s) in names.iter().zip(series) {
                c.push((n.to_string(), s));
            }
        }
        c.push(("f_norm".into(), &self.force_norm));
        c.push(("m_norm".into(), &self.moment_norm));
        c
    }

    /// Largest distance between the vehicle and its reference position [m].
    pub fn max_position_error(&self) -> f64 {
        (0..self.t.len())
            .map(|i| {
                (self.position[0][i] - self.reference[0][i])
                    .hypot(self.position[1][i] - self.reference[1][i])
            })
            .fold(0.0, f64::max)
    }

    /// Largest `|ψ_d − ψ|` (wrapped) [rad].
    pub fn max_yaw_error(&self) -> f64 {
        (0..self.t.len())
            .map(|i| crate::spatial::wrap_angle(self.reference[2][i] - self.attitude[2][i]).abs())
            .fold(0.0, f64::max)
    }

    fn log(&mut self, t: f64, s: &SimState, r: &PoseReference, tau: &Vec6) {
        self.t.push(t);
        let rpy = euler_zyx(s.pose.orientation.to_rotation_matrix().matrix());
        for k in 0..3 {
            self.position[k].push(s.pose.position[k]);
            self.attitude[k].push(rpy[k]);
        }
        for k in 0..6 {
            self.twist[k].push(s.base_twist[k]);
            self.wrench[k].push(tau[k]);
        }
        self.reference[0].push(r.position.x);
        self.reference[1].push(r.position.y);
        self.reference[2].push(crate::spatial::heading(
            r.orientation.to_rotation_matrix().matrix(),
        ));
        self.force_norm.push(tau.fixed_rows::<3>(0).norm());
        self.moment_norm.push(tau.fixed_rows::<3>(3).norm());
    }
}

/// Run case 3 with reference `reference` (3a: [`BaseTrajectory::hold`] of the initial pose;
/// 3b: [`BaseTrajectory::from_kinematic`] of case 1). The vehicle starts at rest at the
/// reference's initial pose. Errors on invalid settings; a numerical failure of the
/// simulation is reported as an error naming the quantity and time.
pub fn run_dynamic_case(
    case: &DynamicCase,
    reference: &BaseTrajectory,
) -> Result<DynamicHistory, ScenarioError> {
    case.validate()?;
    let mut v = nps_auv2();
    v.fluid.current = case.current;
    if let crate::model::Hydro::Manoeuvring(m) = &mut v.bodies[0].hydro {
        m.kirchhoff = case.added_mass_coriolis;
    }
    let cfg = SimConfig {
        integrator: Integrator::Rk4 {
            dt: case.control_dt,
        },
        ..SimConfig::default()
    };
    let sim_err = |e: crate::dynamics::SimError| ScenarioError::Sim(e).in_case(&case.name);
    let mut sim = Simulator::new(&v, cfg).map_err(sim_err)?;
    let r0 = reference.reference(0.0);
    let mut state = SimState::rest(&v);
    state.pose = BasePose {
        orientation: r0.orientation,
        position: r0.position,
    };
    sim.set_state(state).map_err(sim_err)?;
    let mut ws = DynWorkspace::new(&v);
    let mut restoring = [0.0; 6];
    let mut h = DynamicHistory {
        name: case.name.clone(),
        ..DynamicHistory::default()
    };
    let steps = (case.duration / case.control_dt).round() as usize;
    for step in 0..=steps {
        let t = step as f64 * case.control_dt;
        let r = reference.reference(t);
        let s = sim.state();
        restoring_generalized(&v, &mut ws, &s.pose, &[], &mut restoring);
        let sv = sliding_variable(&case.gains, &s.pose, &s.base_twist, &r);
        let tau = sliding_mode_wrench(&case.gains, &sv, &Vec6::from_column_slice(&restoring));
        if step % case.log_every == 0 || step == steps {
            h.log(t, s, &r, &tau);
        }
        if step == steps {
            break;
        }
        h.force_integral += tau.fixed_rows::<3>(0).norm() * case.control_dt;
        h.moment_integral += tau.fixed_rows::<3>(3).norm() * case.control_dt;
        let thrust = actuator_thrusts(&tau);
        let cmd = ActuatorCommand {
            thrust: &thrust,
            joint_ref: &[],
            joint_rate_ref: &[],
        };
        sim.advance(case.control_dt, &cmd).map_err(sim_err)?;
    }
    Ok(h)
}
