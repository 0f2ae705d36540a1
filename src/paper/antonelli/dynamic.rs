//! Antonelli & Chiaverini's case 3 (docs/model.md §8): the NPS AUV II with its full 6-DOF dynamic
//! model ([`crate::paper::nps_auv2`], through the crate's floating-base dynamics) under the
//! constant irrotational current `ν_c = (0.1√2, 0.1√2, 0)` m/s, driven by the sliding-mode
//! law of [`crate::paper::sliding`], for 100 s:
//!
//! - **3a**: the vehicle holds its initial pose (0, 0, ψ = 0): the control forces only
//!   compensate the current;
//! - **3b**: the vehicle "moves according to the results of the first simulation in the first
//!   case study" (the paper): it re-orients to ψ = 0.78 rad into the current within 10 s
//!   along case 1's heading, then holds the final pose.
//!
//! The paper's Table I is `∫‖f‖dt` and `∫‖m‖dt` of the generalised control forces `τ_r`
//! (AC-2) over the run: [`DynamicHistory::force_integral`], [`DynamicHistory::moment_integral`]
//! (the control wrench is held over each control period, so the sums are exact).
//!
//! **Readings.** The text leaves four choices to interpretation; a [`Case3Reading`] fixes them.
//! The default, [`Case3Reading::AS_WRITTEN`], takes the text literally:
//! - 3b holds the vehicle's position, as case 1 does ("the end-effector location and vehicle
//!   position are held while the vehicle body is re-oriented"), and follows case 1's heading
//!   only;
//! - a current along x̂ produces no force ("an ocean current parallel to the x̂ axis is not
//!   even modelled"): the surge resistance `Cd0 ½ρL² |u|u` is off
//!   ([`DynamicCase::surge_resistance`]);
//! - the regulation law of the paper's reference [1], without feed-forward
//!   ([`SlidingLaw::Regulation`]);
//! - one account of the Munk moment: Healey's empirical derivatives alone, without Fossen's
//!   added-mass Coriolis `C_A` on top ([`DynamicCase::added_mass_coriolis`] = false; the
//!   free-body check of `tests/kirchhoff.rs` shows that a table which carries the Munk moment
//!   plus `C_A` counts it twice).
//!
//! [`Case3Reading::PREVIOUS`] is the project's earlier reading (3b follows case 1's vehicle
//! translation too, surge resistance on, tracking with feed-forward, `C_A` on top);
//! [`CASE3_READINGS`] lists every named reading that `paper antonelli` reports.
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
use crate::model::{Hydro, Vehicle};
use crate::paper::nps_auv2::{actuator_thrusts, nps_auv2};
use crate::paper::sliding::{
    sliding_mode_wrench, sliding_variable, PoseReference, SlidingLaw, SlidingModeGains,
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
    /// The form of the sliding variable: [`SlidingLaw::Regulation`] (as written: the
    /// paper's reference [1] is a regulation law) or [`SlidingLaw::Tracking`].
    pub law: SlidingLaw,
    /// Add Fossen's added-mass Coriolis `C_A(ν_r) ν_r` to the derivative table
    /// ([`crate::model::manoeuvring::Manoeuvring::kirchhoff`]). As written: `false` — Healey's
    /// empirical derivatives already hold the Munk moment (their `N_uv`), as in MSS
    /// `npsauv.m`; `true` counts it twice (AC-3's `C(q, ζ_r) ζ_r` after Fossen [5] taken
    /// literally beside the empirical table).
    pub added_mass_coriolis: bool,
    /// Keep the surge resistance `Cd0 ½ρL² |u|u`, the only force a current along x̂ produces
    /// in the model. As written: `false` (the paper: "an ocean current parallel to the x̂
    /// axis is not even modelled").
    pub surge_resistance: bool,
}

/// One reading of case 3's set-up (module doc): which of the text's open choices a run
/// makes. Turned into settings by [`DynamicCase::from_reading`] and 3b's reference by
/// [`Case3Reading::reference_b`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Case3Reading {
    /// Short name (`as_written`, `previous`, …): the key in `summary.json`.
    pub name: &'static str,
    /// What the reading is, in words.
    pub what: &'static str,
    /// 3b follows case 1's vehicle translation as well as its heading (`false`: the
    /// position is held at its start, as case 1's text says it is).
    pub follow_case1_translation: bool,
    /// [`DynamicCase::surge_resistance`].
    pub surge_resistance: bool,
    /// Feed the reference's velocity forward ([`SlidingLaw::Tracking`]; `false`:
    /// [`SlidingLaw::Regulation`]).
    pub feed_forward: bool,
    /// [`DynamicCase::added_mass_coriolis`].
    pub added_mass_coriolis: bool,
    /// The paper's current (`false`: still water).
    pub current: bool,
    /// `K_D` ×4 and `Λ` = 1 1/s instead of the default gains.
    pub stiff_gains: bool,
}

impl Case3Reading {
    /// The text taken literally (the default; module doc).
    pub const AS_WRITTEN: Case3Reading = Case3Reading {
        name: "as_written",
        what: "as written: position held in 3b, no force from a current along x, \
               regulation law (no feed-forward), Healey's derivatives alone (Munk moment once)",
        follow_case1_translation: false,
        surge_resistance: false,
        feed_forward: false,
        added_mass_coriolis: false,
        current: true,
        stiff_gains: false,
    };

    /// The project's earlier default: 3b follows case 1's translation and heading, surge
    /// resistance on, tracking with feed-forward, Fossen's `C_A` on top of Healey's table.
    pub const PREVIOUS: Case3Reading = Case3Reading {
        name: "previous",
        what: "earlier default: 3b follows case 1's translation and heading, surge resistance, \
               tracking with feed-forward, C_A on top of Healey's derivatives",
        follow_case1_translation: true,
        surge_resistance: true,
        feed_forward: true,
        added_mass_coriolis: true,
        current: true,
        stiff_gains: false,
    };

    /// 3b's reference under this reading, from case 1's vehicle motion `case1`
    /// ([`BaseTrajectory::from_kinematic`]): as it is, or with the position held at the
    /// start (`x, y` and their rates from the first sample).
    pub fn reference_b(&self, case1: &BaseTrajectory) -> BaseTrajectory {
        let mut r = case1.clone();
        if !self.follow_case1_translation {
            for k in 0..2 {
                let x0 = r.pose[k].first().copied().unwrap_or(0.0);
                r.pose[k].iter_mut().for_each(|x| *x = x0);
                r.rate[k].iter_mut().for_each(|x| *x = 0.0);
            }
        }
        r
    }
}

/// Every named reading `paper antonelli` reports, the default first: the as-written one, the
/// earlier default, each of the four choices flipped alone from the as-written one, its gain
/// and still-water checks, and the earlier diagnostic variants of the previous default.
pub const CASE3_READINGS: [Case3Reading; 12] = [
    Case3Reading::AS_WRITTEN,
    Case3Reading::PREVIOUS,
    Case3Reading {
        name: "as_written_with_c_a",
        what: "as written, plus Fossen's C_A on top of Healey's derivatives (Munk moment twice)",
        added_mass_coriolis: true,
        ..Case3Reading::AS_WRITTEN
    },
    Case3Reading {
        name: "as_written_with_surge_resistance",
        what: "as written, plus the surge resistance Cd0 (a current along x pushes)",
        surge_resistance: true,
        ..Case3Reading::AS_WRITTEN
    },
    Case3Reading {
        name: "as_written_with_feed_forward",
        what: "as written, but tracking: the reference's velocity fed forward",
        feed_forward: true,
        ..Case3Reading::AS_WRITTEN
    },
    Case3Reading {
        name: "as_written_with_case1_translation",
        what: "as written, but 3b follows case 1's vehicle translation as well",
        follow_case1_translation: true,
        ..Case3Reading::AS_WRITTEN
    },
    Case3Reading {
        name: "as_written_gains_x4",
        what: "as written, with K_D x4 and Lambda = 1 1/s",
        stiff_gains: true,
        ..Case3Reading::AS_WRITTEN
    },
    Case3Reading {
        name: "as_written_still_water",
        what: "as written, without current (a: nothing to do; b: the re-orientation alone)",
        current: false,
        ..Case3Reading::AS_WRITTEN
    },
    Case3Reading {
        name: "previous_without_c_a",
        what: "previous, without C_A (the MSS npsauv.m form)",
        added_mass_coriolis: false,
        ..Case3Reading::PREVIOUS
    },
    Case3Reading {
        name: "previous_in_place",
        what: "previous, but 3b holds the position (case 1's heading only)",
        follow_case1_translation: false,
        ..Case3Reading::PREVIOUS
    },
    Case3Reading {
        name: "previous_in_place_still_water",
        what: "previous, 3b holding the position, without current",
        follow_case1_translation: false,
        current: false,
        ..Case3Reading::PREVIOUS
    },
    Case3Reading {
        name: "previous_gains_x4",
        what: "previous, with K_D x4 and Lambda = 1 1/s",
        stiff_gains: true,
        ..Case3Reading::PREVIOUS
    },
];

impl DynamicCase {
    /// The paper's set-up named `name`, as written ([`Case3Reading::AS_WRITTEN`]).
    pub fn paper(name: &str) -> Self {
        Self::from_reading(name, &Case3Reading::AS_WRITTEN)
    }

    /// The set-up named `name` under `reading`.
    pub fn from_reading(name: &str, reading: &Case3Reading) -> Self {
        let c = if reading.current {
            0.1 * std::f64::consts::SQRT_2
        } else {
            0.0
        };
        let mut gains = SlidingModeGains::default();
        if reading.stiff_gains {
            gains.k_d.iter_mut().for_each(|k| *k *= 4.0);
            gains.lambda = [1.0; 6];
        }
        Self {
            name: name.into(),
            duration: 100.0,
            control_dt: 0.01,
            log_every: 20,
            current: Vec3::new(c, c, 0.0),
            gains,
            law: if reading.feed_forward {
                SlidingLaw::Tracking
            } else {
                SlidingLaw::Regulation
            },
            added_mass_coriolis: reading.added_mass_coriolis,
            surge_resistance: reading.surge_resistance,
        }
    }

    /// The vehicle this case simulates: the NPS AUV II ([`nps_auv2`]) in the case's current,
    /// with `C_A` and the surge resistance as the case says.
    pub fn vehicle(&self) -> Vehicle {
        let mut v = nps_auv2();
        v.fluid.current = self.current;
        if let Hydro::Manoeuvring(m) = &mut v.bodies[0].hydro {
            m.kirchhoff = self.added_mass_coriolis;
            if !self.surge_resistance {
                m.quadratic[0] = 0.0;
            }
        }
        v
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
/// 3b: [`Case3Reading::reference_b`] of case 1's [`BaseTrajectory::from_kinematic`]) on the
/// case's vehicle ([`DynamicCase::vehicle`]). The vehicle starts at rest at the reference's
/// initial pose. Errors on invalid settings; a numerical failure of the simulation is
/// reported as an error naming the quantity and time.
pub fn run_dynamic_case(
    case: &DynamicCase,
    reference: &BaseTrajectory,
) -> Result<DynamicHistory, ScenarioError> {
    run_dynamic_case_on(&case.vehicle(), case, reference)
}

/// [`run_dynamic_case`] on a given vehicle `v` (for sensitivity studies: [`DynamicCase::vehicle`]
/// with some coefficients changed). `v` must have six base actuators laid out as
/// [`nps_auv2`]'s ([`actuator_thrusts`]); its `fluid.current` is used as it is.
pub fn run_dynamic_case_on(
    v: &Vehicle,
    case: &DynamicCase,
    reference: &BaseTrajectory,
) -> Result<DynamicHistory, ScenarioError> {
    case.validate()?;
    if v.thrusters.len() != 6 || v.n_joints() != 0 {
        return Err(ScenarioError::Rule(
            "case 3 needs a jointless vehicle with the six base actuators of nps_auv2",
        )
        .in_case(&case.name));
    }
    let cfg = SimConfig {
        integrator: Integrator::Rk4 {
            dt: case.control_dt,
        },
        ..SimConfig::default()
    };
    let sim_err = |e: crate::dynamics::SimError| ScenarioError::Sim(e).in_case(&case.name);
    let mut sim = Simulator::new(v, cfg).map_err(sim_err)?;
    let r0 = reference.reference(0.0);
    let mut state = SimState::rest(v);
    state.pose = BasePose {
        orientation: r0.orientation,
        position: r0.position,
    };
    sim.set_state(state).map_err(sim_err)?;
    let mut ws = DynWorkspace::new(v);
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
        restoring_generalized(v, &mut ws, &s.pose, &[], &mut restoring);
        let sv = sliding_variable(&case.gains, case.law, &s.pose, &s.base_twist, &r);
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
