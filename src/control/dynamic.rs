//! Dynamic (base) control (docs/model.md §5, USM section IV-B, USM-33/34): feedback-linearising
//! tracking of the base reference twist from the kinematic controller,
//!
//! `τ_c = M_11(q) a^b + n(R_Ib, q, ζ)` (USM-33),
//! `a^b = V̇_r − K_p Ṽ − K_i ∫Ṽ dt`, `Ṽ = V_b − V_r` (USM-34),
//!
//! with `M_11` the 6×6 upper-left block of the mass matrix (whole-body inertia about the base,
//! rigid + added, in `F_b`), `n = C_11 ζ + D_11 ζ + N_1` the upper-left blocks of the bias terms
//! (USM-35), both supplied by the caller (the dynamics module), `V_b`, `V_r` twists in `F_b`
//! [m/s, rad/s], `τ_c` the commanded base wrench `[f; m]` in `F_b` [N, N·m] for the thrust
//! allocation. The nonlinear term is used only when [`DynamicGains::nonlinear`] is set (the
//! paper's work mode drops it). In transport mode the surge and yaw accelerations come directly
//! from USM-40/41 and the other axes get USM-34 with a zero reference
//! ([`DynamicController::transport_control`]).

use super::error::{check_nonneg, ControlError};
use crate::spatial::Vec6;
use nalgebra::Matrix6;
use serde::{Deserialize, Serialize};

/// Gains of USM-33/34. Defaults ([`DynamicGains::work_mode`], given on each field) are the
/// paper's work-mode values; [`DynamicGains::validate`] checks the ranges.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DynamicGains {
    /// Diagonal of `K_p` [1/s], `[surge, sway, heave, roll, pitch, yaw]`. Default
    /// `[1, 1, 1, 0, 1, 1]` (roll not controlled).
    pub kp: [f64; 6],
    /// Diagonal of `K_i` [1/s²]. Default 0.
    pub ki: [f64; 6],
    /// Whether `τ_c` includes the nonlinear term `n` (USM-33/35). Default false.
    pub nonlinear: bool,
    /// Whether `a^b` includes the reference acceleration `V̇_r`, estimated by a first-order
    /// filtered backward difference of `V_r` (unless given explicitly, see
    /// [`DynamicController::velocity_control_with_rate`]). Default true.
    pub feedforward: bool,
    /// Time constant [s] of that filter (0 = raw backward difference). Default 0.1 s.
    pub feedforward_time_constant: f64,
    /// Bound on each component of `|∫Ṽ dt|` (anti-windup; `None` = unbounded). Default
    /// `None`.
    pub integral_limit: Option<f64>,
    /// Transport mode only: whether the axes transport does not command (sway, heave, roll,
    /// pitch) get USM-34 with a zero reference, `a_i = −K_p,i v_b,i` (true), or the paper's
    /// literal "remaining acceleration components are set to zero", `a_i = 0` (false)
    /// ([`DynamicController::transport_control`]). Default true.
    pub uncommanded_feedback: bool,
}

impl Default for DynamicGains {
    fn default() -> Self {
        Self::work_mode()
    }
}

impl DynamicGains {
    /// The paper's work-mode setting (USM section VI-C): `K_p = diag(1,1,1,0,1,1)`, no integral,
    /// no nonlinear term; `V̇_r` feed-forward by a filtered difference (τ = 0.1 s).
    pub fn work_mode() -> Self {
        Self {
            kp: [1.0, 1.0, 1.0, 0.0, 1.0, 1.0],
            ki: [0.0; 6],
            nonlinear: false,
            feedforward: true,
            feedforward_time_constant: 0.1,
            integral_limit: None,
            uncommanded_feedback: true,
        }
    }

    /// Transport mode (interpretation, see [`super::transport`]): USM-33 **without** the
    /// nonlinear term, as in the paper's own work-mode simulation, and the paper's
    /// `K_p = diag(1, 1, 1, 0, 1, 1)` used on the axes transport does not command (sway 1,
    /// heave 1, roll 0, pitch 1: [`DynamicController::transport_control`]); surge and yaw come
    /// from USM-40/41, so `K_p,0`, `K_p,5` and `K_i` are unused. The paper-literal form is
    /// `nonlinear = true, uncommanded_feedback = false`; the readings comparison
    /// (`usm-study paper readings`) runs every combination and keeps this one as the default
    /// because it is the only one under which both Table III methods converge.
    pub fn transport() -> Self {
        Self::work_mode()
    }

    /// Tracking of a full-state reference (`[reference] file`, [`super::tracking`]): the
    /// work-mode gains with the nonlinear term `n` of USM-33 (drag, restoring, Coriolis
    /// cancelled by the model, so a moving reference leaves no steady lag) and without the
    /// `V̇_r` feed-forward. Inferred from runs: `M_11 V̇_r` ignores the joints' reaction on the
    /// base (`M_12 q̈`, already in the reference's base motion), so feeding it forward fights
    /// that reaction — replaying `transport-method1` with it peaks at 2839 N sway and fails one
    /// allocation (0.45 m largest base error), without it 487 N and none (0.38 m); tracking the
    /// `studies/ocp_usm_paper.toml` optimum costs an effort of 8.57 with it and 1.21 without.
    pub fn tracking() -> Self {
        Self {
            nonlinear: true,
            feedforward: false,
            ..Self::work_mode()
        }
    }

    /// Check the values; errors name `dynamic.<key>`.
    pub fn validate(&self) -> Result<(), ControlError> {
        for i in 0..6 {
            check_nonneg(&format!("dynamic.kp[{i}]"), self.kp[i])?;
            check_nonneg(&format!("dynamic.ki[{i}]"), self.ki[i])?;
        }
        check_nonneg(
            "dynamic.feedforward_time_constant",
            self.feedforward_time_constant,
        )?;
        if let Some(l) = self.integral_limit {
            check_nonneg("dynamic.integral_limit", l)?;
        }
        Ok(())
    }
}

/// Result of one dynamic-control step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DynamicOutput {
    /// Commanded base wrench `τ_c = [f; m]` in `F_b` [N, N·m].
    pub tau_c: Vec6,
    /// Commanded base acceleration `a^b` in `F_b` [m/s², rad/s²].
    pub a_b: Vec6,
    /// Velocity error `Ṽ = V_b − V_r` [m/s, rad/s].
    pub error: Vec6,
}

/// USM-33/34 with its state: the error integral and the reference-rate filter.
#[derive(Clone, Debug)]
pub struct DynamicController {
    gains: DynamicGains,
    integral: Vec6,
    prev_v_r: Option<Vec6>,
    v_r_dot: Vec6,
}

impl DynamicController {
    /// A controller with zero state.
    pub fn new(gains: DynamicGains) -> Result<Self, ControlError> {
        gains.validate()?;
        Ok(Self {
            gains,
            integral: Vec6::zeros(),
            prev_v_r: None,
            v_r_dot: Vec6::zeros(),
        })
    }

    /// The gains.
    pub fn gains(&self) -> &DynamicGains {
        &self.gains
    }

    /// The error integral `∫Ṽ dt`.
    pub fn integral(&self) -> &Vec6 {
        &self.integral
    }

    /// Clear the integral and the reference-rate filter.
    pub fn reset(&mut self) {
        self.integral = Vec6::zeros();
        self.prev_v_r = None;
        self.v_r_dot = Vec6::zeros();
    }

    /// USM-33: `τ_c = M_11 a^b + n` (`n` added only if [`DynamicGains::nonlinear`]; pass zeros
    /// when it is not computed). `m11` in `F_b` [kg, kg·m, kg·m²], `n` [N, N·m], `a_b`
    /// [m/s², rad/s²].
    pub fn acceleration_control(&self, m11: &Matrix6<f64>, n: &Vec6, a_b: &Vec6) -> Vec6 {
        let tau = m11 * a_b;
        if self.gains.nonlinear {
            tau + n
        } else {
            tau
        }
    }

    /// Transport mode (USM section V-A): USM-33 with `a^b` from USM-40/41 on surge and yaw and,
    /// if [`DynamicGains::uncommanded_feedback`], USM-34 with `V_r = V̇_r = 0` on the axes
    /// transport does not command (sway, heave, roll, pitch): `a_i = −K_p,i v_b,i` for
    /// `i ∈ {1, 2, 3, 4}`; `K_p,0` and `K_p,5` are not used (see the transport-mode module docs,
    /// [`super::transport`], for why the paper's "remaining acceleration components are set to
    /// zero" is read this way). Without it (or with `K_p = 0` on those axes) `a_i = 0`, the
    /// literal reading. `v_b` is the measured base twist in `F_b`. Returns `τ_c` and the `a^b`
    /// actually used.
    pub fn transport_control(
        &self,
        m11: &Matrix6<f64>,
        n: &Vec6,
        a_cmd: &Vec6,
        v_b: &Vec6,
    ) -> (Vec6, Vec6) {
        let mut a = *a_cmd;
        if self.gains.uncommanded_feedback {
            for i in 1..5 {
                a[i] -= self.gains.kp[i] * v_b[i];
            }
        }
        (self.acceleration_control(m11, n, &a), a)
    }

    /// USM-33/34 with `V̇_r` estimated internally (if [`DynamicGains::feedforward`]): advances the
    /// integral and the filter over `dt` [s] (no state change unless `dt` is positive and
    /// finite). `v_b` measured and `v_r` reference base twists in `F_b`.
    pub fn velocity_control(
        &mut self,
        m11: &Matrix6<f64>,
        n: &Vec6,
        v_b: &Vec6,
        v_r: &Vec6,
        dt: f64,
    ) -> DynamicOutput {
        let ok = dt.is_finite() && dt > 0.0;
        if ok && v_r.iter().all(|x| x.is_finite()) {
            if let Some(prev) = self.prev_v_r {
                let raw = (v_r - prev) / dt;
                let alpha = dt / (self.gains.feedforward_time_constant + dt);
                self.v_r_dot += (raw - self.v_r_dot) * alpha;
            }
            self.prev_v_r = Some(*v_r);
        }
        let v_r_dot = if self.gains.feedforward {
            self.v_r_dot
        } else {
            Vec6::zeros()
        };
        self.velocity_control_with_rate(m11, n, v_b, v_r, &v_r_dot, if ok { dt } else { 0.0 })
    }

    /// USM-33/34 with an explicit reference acceleration `v_r_dot` (in `F_b`); advances the
    /// integral over `dt` [s] (0: no change).
    pub fn velocity_control_with_rate(
        &mut self,
        m11: &Matrix6<f64>,
        n: &Vec6,
        v_b: &Vec6,
        v_r: &Vec6,
        v_r_dot: &Vec6,
        dt: f64,
    ) -> DynamicOutput {
        let err = v_b - v_r;
        if dt.is_finite() && dt > 0.0 && err.iter().all(|x| x.is_finite()) {
            self.integral += err * dt;
            if let Some(l) = self.gains.integral_limit {
                self.integral.apply(|x| *x = x.clamp(-l, l));
            }
        }
        let mut a_b = *v_r_dot;
        for i in 0..6 {
            a_b[i] -= self.gains.kp[i] * err[i] + self.gains.ki[i] * self.integral[i];
        }
        DynamicOutput {
            tau_c: self.acceleration_control(m11, n, &a_b),
            a_b,
            error: err,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m11() -> Matrix6<f64> {
        let a = Matrix6::from_fn(|i, j| ((i * 7 + j * 3) % 5) as f64 * 0.1);
        a * a.transpose() + Matrix6::identity() * 80.0
    }

    #[test]
    fn feedback_linearisation_closes_a_linear_loop() {
        // Plant M_11 V̇ + n = τ with n a state-dependent bias; with the nonlinear term the
        // closed loop is V̇ = V̇_r − K_p Ṽ − K_i ∫Ṽ: errors decay for a constant reference.
        let m = m11();
        let lu = m.lu();
        let gains = DynamicGains {
            kp: [1.0; 6],
            ki: [0.2; 6],
            nonlinear: true,
            ..DynamicGains::work_mode()
        };
        let mut ctl = DynamicController::new(gains).unwrap();
        let v_r = Vec6::new(0.3, -0.1, 0.05, 0.0, 0.02, -0.1);
        let mut v = Vec6::zeros();
        let dt = 0.01;
        for _ in 0..3000 {
            let n = v.component_mul(&v.abs()) * 30.0 + Vec6::repeat(1.0);
            let out = ctl.velocity_control(&m, &n, &v, &v_r, dt);
            let vdot = lu.solve(&(out.tau_c - n)).unwrap();
            // The plant acceleration is exactly the commanded one (exact linearisation).
            assert!((vdot - out.a_b).norm() < 1e-9);
            v += vdot * dt;
        }
        assert!((v - v_r).norm() < 1e-4, "{}", (v - v_r).norm());
    }

    #[test]
    fn paper_work_mode_gains_ignore_roll_and_n() {
        let mut ctl = DynamicController::new(DynamicGains::default()).unwrap();
        let m = Matrix6::identity() * 2.0;
        let n = Vec6::repeat(5.0);
        let v_b = Vec6::new(0.0, 0.0, 0.0, 1.0, 0.0, 0.0);
        let out = ctl.velocity_control(&m, &n, &v_b, &Vec6::zeros(), 0.1);
        assert_eq!(out.tau_c, Vec6::zeros());
        let v_b = Vec6::new(0.5, 0.0, 0.0, 0.0, 0.0, 0.0);
        let out = ctl.velocity_control(&m, &n, &v_b, &Vec6::zeros(), 0.1);
        assert_eq!(out.tau_c, Vec6::new(-1.0, 0.0, 0.0, 0.0, 0.0, 0.0));
        // With the nonlinear term: τ = M a + n.
        let t = DynamicController::new(DynamicGains {
            nonlinear: true,
            ..DynamicGains::transport()
        })
        .unwrap();
        let a = Vec6::new(0.1, 0.0, 0.0, 0.0, 0.0, -0.2);
        assert_eq!(t.acceleration_control(&m, &n, &a), m * a + n);
    }

    #[test]
    fn transport_control_damps_only_the_free_axes() {
        // Surge and yaw pass through from USM-40/41; sway, heave, pitch get −K_p v (K_p = 1),
        // roll nothing (K_p = 0); no n by default.
        let t = DynamicController::new(DynamicGains::transport()).unwrap();
        let m = Matrix6::identity() * 2.0;
        let n = Vec6::repeat(5.0);
        let a = Vec6::new(0.1, 0.0, 0.0, 0.0, 0.0, -0.2);
        let v = Vec6::new(0.5, 0.2, -0.1, 0.3, 0.05, 0.4);
        let (tau, used) = t.transport_control(&m, &n, &a, &v);
        let expect = Vec6::new(0.1, -0.2, 0.1, 0.0, -0.05, -0.2);
        assert!((used - expect).norm() < 1e-15, "{used}");
        assert!((tau - m * expect).norm() < 1e-15);
        // The literal reading (no feedback on the free axes, with n) is τ = M a + n, and so is
        // K_p = 0 on those axes.
        for lit in [
            DynamicGains {
                uncommanded_feedback: false,
                nonlinear: true,
                ..DynamicGains::transport()
            },
            DynamicGains {
                kp: [0.0; 6],
                nonlinear: true,
                ..DynamicGains::transport()
            },
        ] {
            let lit = DynamicController::new(lit).unwrap();
            assert_eq!(lit.transport_control(&m, &n, &a, &v).0, m * a + n);
        }
    }

    #[test]
    fn reference_rate_feedforward() {
        let gains = DynamicGains {
            kp: [0.0; 6],
            feedforward_time_constant: 0.0,
            ..DynamicGains::work_mode()
        };
        let mut ctl = DynamicController::new(gains).unwrap();
        let m = Matrix6::identity();
        let z = Vec6::zeros();
        ctl.velocity_control(&m, &z, &z, &Vec6::repeat(1.0), 0.1);
        let out = ctl.velocity_control(&m, &z, &z, &Vec6::repeat(1.2), 0.1);
        assert!((out.a_b - Vec6::repeat(2.0)).norm() < 1e-12);
    }

    #[test]
    fn gains_from_toml() {
        let g: DynamicGains = toml::from_str("nonlinear = true").unwrap();
        assert_eq!(g.kp, [1.0, 1.0, 1.0, 0.0, 1.0, 1.0]);
        assert!(toml::from_str::<DynamicGains>("k_p = [1,1,1,1,1,1]").is_err());
        let bad = DynamicGains {
            kp: [1.0, -1.0, 0.0, 0.0, 0.0, 0.0],
            ..Default::default()
        };
        assert_eq!(
            DynamicController::new(bad).unwrap_err().key,
            "dynamic.kp[1]"
        );
    }
}
