//! Actuator models, the Lie-group time integrators and the [`Simulator`] (docs/model.md §4).
//!
//! State: base pose (inertial position, unit quaternion `R_Ib`), joint angles, base twist
//! `V_b` in `F_b`, joint rates, and one thrust state per thruster. Joint servos are either
//! ideal second-order reference filters (hybrid dynamics: the joints follow
//! `q̈ = ω_n²(q_r − q) − 2ζ_n ω_n q̇`, the base obeys `M_11 V̇_b = τ_b − M_12 q̈ − h_1`,
//! joint torques recovered), torque-level PD servos with torque limits (full forward
//! dynamics), or passive (torque-free) joints.
//!
//! # Integrators
//! The flat state `x = [p, Q, q, V_b, q̇, S]` with the quaternion kinematics
//! `Q̇ = ½ Q ⊗ [0; ω]`, `ṗ = R_Ib v`, `q̇`, `ζ̇` and each joint's signed work
//! `Ṡ_k = τ_k q̇_k`, a quadrature state outside the error control: the joint work
//! `W = Σ_k ∫ |τ_k q̇_k| dt` (the joint-energy metric, docs/model.md §6) is integrated with the
//! motion instead of from logged samples, by folding each step's `ΔS_k` at the sign changes
//! of `τ_k q̇_k` (`integrator::abs_increment`), so the kinks of `|τ_k q̇_k|` neither cost
//! accuracy nor force small steps. Every stage uses the normalised stage
//! quaternion, and the quaternion is projected back onto the unit sphere after each step
//! (a change of the order of the local error). Chosen over RKMK for simplicity; it keeps
//! the order of the method and the quaternion unit to machine precision.
//!
//! [`Simulator::step`] is one classical RK4 step. [`Simulator::advance`] integrates over a
//! span (a control period, commands held) with the configured [`Integrator`]: fixed RK4
//! steps, or Dormand–Prince 5(4) with error control (`integrator`), restarted at each span
//! start because the held command jumps there.
//!
//! # Dynamics per stage (O(n))
//! Ideal servos evaluate the O(n) hybrid dynamics of [`super::aba`]: composite inertias,
//! `M_11`, the columns `Ic_{k+1} S_k` and the bias `h` by Newton–Euler
//! ([`hybrid_terms`](super::hybrid_terms)), then the base acceleration and the recovered
//! torques through the composite inertias ([`solve_hybrid_on`](super::solve_hybrid_on));
//! no joint block of `M`, no dense solve. PD servos and passive joints evaluate the
//! articulated-body forward dynamics ([`forward_dynamics_aba`](super::forward_dynamics_aba),
//! the added mass in the articulated inertias). Both equal the CRBA + Cholesky route to
//! 1e-12 (tests). The generalised thrust is summed from the tip in O(n + m). After a
//! Dormand–Prince span with ideal servos, the hybrid terms of the last (FSAL) evaluation are
//! those of the end state, so [`Simulator::base_control_terms`] and the first stage of the
//! next span reuse them instead of recomputing them.
//!
//! # Thrusters
//! The commanded thrust is held over a step (zero-order hold) and first saturated to
//! `[u_min, u_max]`. Each thruster's thrust state then follows, exactly (closed form,
//! evaluated at every RK4 stage time), `u̇ = clamp((u_c − u)/T, −r, r)` — a first-order lag
//! with time constant `T` and rate limit `r`, either of which may be absent (absent lag:
//! `u̇ = r sign(u_c − u)` until it arrives; neither: `u = u_c`). The actual thrust is the
//! state saturated to `[u_min, u_max]` in every model. Thrust enters as the generalised force
//! `J_g,iᵀ F_j` of each thruster's wrench on its body (base rows `T(q) u`, USM-25/26).

use super::aba::{aba_after_position, hybrid_terms, solve_hybrid_on};
use super::algorithms::{kinetic_energy, spatial_momentum};
use super::config::{config_err, Integrator, ServoModel, SimConfig, ThrusterModel};
use super::error::{check_finite, DynError, SimError};
use super::integrator::{rk4_step, Dopri5, Quadrature, StepStats, Tolerance};
use super::thruster_lag::ThrusterDyn;
use super::DynWorkspace;
use crate::kinematics::{thruster_column, BasePose};
use crate::model::Vehicle;
use crate::spatial::{Vec3, Vec6};
use nalgebra::{Matrix6, Quaternion, UnitQuaternion, Vector6};

/// The integrated state of a [`Simulator`].
#[derive(Clone, Debug, PartialEq)]
pub struct SimState {
    /// Base pose `g_Ib` (inertial position [m], unit quaternion `R_Ib`).
    pub pose: BasePose,
    /// Joint angles `q` [rad] (n).
    pub joint_angles: Vec<f64>,
    /// Base twist `V_b = [v; ω]` in `F_b` [m/s, rad/s].
    pub base_twist: Vec6,
    /// Joint rates `q̇` [rad/s] (n).
    pub joint_rates: Vec<f64>,
    /// Thrust states [N] (m), one per thruster (the lag / rate-limit states; equal to the
    /// last actual thrust for ideal thrusters).
    pub thrust: Vec<f64>,
}

impl SimState {
    /// At rest at the inertial origin in the straight configuration, thrust zero (clamped
    /// into each thruster's limits).
    pub fn rest(v: &Vehicle) -> Self {
        Self {
            pose: BasePose::default(),
            joint_angles: vec![0.0; v.n_joints()],
            base_twist: Vec6::zeros(),
            joint_rates: vec![0.0; v.n_joints()],
            thrust: v
                .thrusters
                .iter()
                .map(|t| 0.0f64.clamp(t.u_min, t.u_max))
                .collect(),
        }
    }

    /// The generalised velocity `ζ = [V_b; q̇]` (allocates; for analysis code).
    pub fn zeta(&self) -> Vec<f64> {
        let mut z = Vec::with_capacity(6 + self.joint_rates.len());
        z.extend_from_slice(self.base_twist.as_slice());
        z.extend_from_slice(&self.joint_rates);
        z
    }

    /// Set `V_b` and `q̇` from `ζ` (length 6+n; panics otherwise — analysis helper).
    pub fn set_zeta(&mut self, zeta: &[f64]) {
        self.base_twist = Vec6::from_column_slice(&zeta[..6]);
        self.joint_rates.copy_from_slice(&zeta[6..]);
    }
}

/// The actuator commands held over one step.
#[derive(Clone, Copy, Debug)]
pub struct ActuatorCommand<'a> {
    /// Commanded thrust per thruster [N] (m); saturated to its limits.
    pub thrust: &'a [f64],
    /// Joint angle references `q_r` [rad] (n).
    pub joint_ref: &'a [f64],
    /// Joint rate references `q̇_r` [rad/s] (n); used by the PD servo.
    pub joint_rate_ref: &'a [f64],
}

/// Offsets in the flat integration vector
/// `[p (3), Q (4: w,i,j,k), q (n), V_b (6), q̇ (n), S (n)]`, `S_k = ∫ τ_k q̇_k dt` the signed
/// work of joint `k` over the current span (quadrature states, reset at every span start).
const P: usize = 0;
const QUAT: usize = 3;
const JOINTS: usize = 7;

/// Offset of the signed joint work `S` (the last `n` entries) for `n` joints.
const fn work_index(n: usize) -> usize {
    JOINTS + 2 * n + 6
}

/// A simulator of one vehicle (docs/model.md §4): owns a copy of the vehicle, its [`DynWorkspace`],
/// the state, the actuator models and the integrators' buffers; [`Simulator::step`] and
/// [`Simulator::advance`] allocate nothing.
#[derive(Clone, Debug)]
pub struct Simulator {
    vehicle: Vehicle,
    cfg: SimConfig,
    ws: DynWorkspace,
    state: SimState,
    time: f64,
    thr: Vec<ThrusterDyn>,
    x0: Vec<f64>,
    xs: Vec<f64>,
    k: [Vec<f64>; 4],
    dopri: Dopri5,
    stats: StepStats,
    joint_work: f64,
    /// Peak |τ_q| [N·m] over the step boundaries evaluated since the simulator was built.
    joint_torque_peak: f64,
    /// The workspace holds the hybrid terms ([`hybrid_terms`]: `M_11` in the base block of
    /// `ws.mass`, `h` in `ws.bias`, the composite inertias) of the current state.
    terms_fresh: bool,
    u_cmd: Vec<f64>,
    u_act: Vec<f64>,
    q_gen: Vec<f64>,
    qdd: Vec<f64>,
    zeta: Vec<f64>,
    last_thrust: Vec<f64>,
    last_joint_torque: Vec<f64>,
    last_accel: Vec<f64>,
}

impl Simulator {
    /// A simulator of `vehicle` (validated and copied) at [`SimState::rest`], `t = 0`.
    /// Errors (with `time = 0`) on an invalid vehicle or configuration.
    pub fn new(vehicle: &Vehicle, cfg: SimConfig) -> Result<Self, SimError> {
        vehicle
            .validate()
            .map_err(|e| config_err(&format!("vehicle.{}", e.key), e.message))?;
        cfg.validate()?;
        let (tc_override, rate_override, use_tc, use_rate) = match cfg.thruster {
            ThrusterModel::Ideal => (None, None, false, false),
            ThrusterModel::FirstOrder { time_constant } => (time_constant, None, true, false),
            ThrusterModel::RateLimited { rate_limit } => (None, rate_limit, false, true),
            ThrusterModel::FromModel => (None, None, true, true),
        };
        let thr = vehicle
            .thrusters
            .iter()
            .map(|t| ThrusterDyn {
                time_constant: if use_tc {
                    tc_override.or(t.time_constant)
                } else {
                    None
                },
                rate_limit: if use_rate {
                    rate_override.or(t.rate_limit)
                } else {
                    None
                },
                u_min: t.u_min,
                u_max: t.u_max,
            })
            .collect();
        let n = vehicle.n_joints();
        let m = vehicle.n_thrusters();
        let nx = work_index(n) + n;
        let first_step = match cfg.integrator {
            Integrator::Dopri5 { first_step, .. } => first_step,
            Integrator::Rk4 { dt } => dt,
        };
        Ok(Self {
            vehicle: vehicle.clone(),
            cfg,
            ws: DynWorkspace::new(vehicle),
            state: SimState::rest(vehicle),
            time: 0.0,
            thr,
            x0: vec![0.0; nx],
            xs: vec![0.0; nx],
            k: std::array::from_fn(|_| vec![0.0; nx]),
            dopri: Dopri5::new(nx, first_step),
            stats: StepStats::default(),
            joint_work: 0.0,
            joint_torque_peak: 0.0,
            terms_fresh: false,
            u_cmd: vec![0.0; m],
            u_act: vec![0.0; m],
            q_gen: vec![0.0; 6 + n],
            qdd: vec![0.0; n],
            zeta: vec![0.0; 6 + n],
            last_thrust: vec![0.0; m],
            last_joint_torque: vec![0.0; n],
            last_accel: vec![0.0; 6 + n],
        })
    }

    /// The vehicle being simulated.
    pub fn vehicle(&self) -> &Vehicle {
        &self.vehicle
    }

    /// The configuration.
    pub fn config(&self) -> &SimConfig {
        &self.cfg
    }

    /// The current state.
    pub fn state(&self) -> &SimState {
        &self.state
    }

    /// Replace the state (lengths and finiteness checked; the quaternion is kept as given,
    /// it is a `UnitQuaternion`).
    pub fn set_state(&mut self, state: SimState) -> Result<(), SimError> {
        let n = self.vehicle.n_joints();
        let m = self.vehicle.n_thrusters();
        for (name, len, want) in [
            ("joint_angles", state.joint_angles.len(), n),
            ("joint_rates", state.joint_rates.len(), n),
            ("thrust", state.thrust.len(), m),
        ] {
            if len != want {
                return Err(SimError {
                    time: self.time,
                    quantity: name.into(),
                    message: format!("has length {len}, expected {want}"),
                });
            }
        }
        self.state = state;
        self.terms_fresh = false;
        Ok(())
    }

    /// Simulation time [s].
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Actual thrust per thruster [N] at the last step boundary evaluated (RK4: the start
    /// of the last step; Dormand–Prince: the end of the last span, under its command): the
    /// saturated thrust state.
    pub fn last_thrust(&self) -> &[f64] {
        &self.last_thrust
    }

    /// Joint motor torques [N·m] at the last step boundary evaluated (as
    /// [`Simulator::last_thrust`]): recovered by the hybrid dynamics for ideal servos, the
    /// saturated PD torque for PD servos, zero if passive.
    pub fn last_joint_torque(&self) -> &[f64] {
        &self.last_joint_torque
    }

    /// Generalised acceleration `ζ̇ = [V̇_b; q̈]` at the last step boundary evaluated (as
    /// [`Simulator::last_thrust`]).
    pub fn last_acceleration(&self) -> &[f64] {
        &self.last_accel
    }

    /// Joint work `W = ∫ Σ_k |τ_k q̇_k| dt` [J] since the simulator was built: the joint
    /// energy of docs/model.md §6, integrated with the motion (same method and accuracy).
    pub fn joint_work(&self) -> f64 {
        self.joint_work
    }

    /// Peak joint motor torque |τ_q| [N·m] over every step boundary evaluated since the
    /// simulator was built (the recovered torques of ideal servos, the saturated PD torques).
    pub fn joint_torque_peak(&self) -> f64 {
        self.joint_torque_peak
    }

    /// Work done by the integrators since the simulator was built: accepted and rejected
    /// steps and derivative evaluations.
    pub fn step_stats(&self) -> StepStats {
        self.stats
    }

    /// The dynamics workspace (holds the quantities of the last evaluation: with ideal
    /// servos `M_11` in the base block of `ws.mass` and `h` in `ws.bias`; the full `M` is not
    /// formed).
    pub fn workspace(&self) -> &DynWorkspace {
        &self.ws
    }

    /// `M_11(q)` and `h_1 = n(R_Ib, q, ζ)` (USM-33/34: the base block of the mass matrix and
    /// the base rows of the bias forces, both in `F_b`) at the current state, with the
    /// simulator's options (O(n): [`hybrid_terms`], no joint block). Reuses them when the workspace already holds them for the
    /// current state (after a Dormand–Prince span or a previous call).
    pub fn base_control_terms(&mut self) -> Result<(Matrix6<f64>, Vector6<f64>), SimError> {
        self.check_state()?;
        if !self.terms_fresh {
            self.load_zeta();
            hybrid_terms(
                &self.vehicle,
                &mut self.ws,
                &self.state.pose,
                &self.state.joint_angles,
                &self.zeta,
                &self.cfg.options,
            );
            self.terms_fresh = true;
        }
        check_finite("bias", &self.ws.bias).map_err(|e| e.at(self.time))?;
        Ok((self.ws.mass_base_block(), self.ws.bias_base()))
    }

    /// Kinetic energy `½ζᵀMζ` [J] of the current state (USM-22 `M`, with added mass when the
    /// options have it).
    pub fn kinetic_energy(&mut self) -> f64 {
        self.terms_fresh = false;
        self.load_zeta();
        kinetic_energy(
            &self.vehicle,
            &mut self.ws,
            &self.state.joint_angles,
            &self.zeta,
            &self.cfg.options,
        )
    }

    /// Inertial-frame spatial momentum about the inertial origin of the current state (see
    /// [`spatial_momentum`]).
    pub fn spatial_momentum(&mut self) -> Vec6 {
        self.terms_fresh = false;
        self.load_zeta();
        spatial_momentum(
            &self.vehicle,
            &mut self.ws,
            &self.state.pose,
            &self.state.joint_angles,
            &self.zeta,
            &self.cfg.options,
        )
    }

    /// Copy `ζ = [V_b; q̇]` of the state into the scratch buffer.
    fn load_zeta(&mut self) {
        self.zeta[..6].copy_from_slice(self.state.base_twist.as_slice());
        self.zeta[6..].copy_from_slice(&self.state.joint_rates);
    }

    fn check_state(&self) -> Result<(), SimError> {
        let s = &self.state;
        let t = self.time;
        check_finite("base_position", s.pose.position.as_slice()).map_err(|e| e.at(t))?;
        check_finite("base_orientation", s.pose.orientation.coords.as_slice())
            .map_err(|e| e.at(t))?;
        check_finite("joint_angles", &s.joint_angles).map_err(|e| e.at(t))?;
        check_finite("base_twist", s.base_twist.as_slice()).map_err(|e| e.at(t))?;
        check_finite("joint_rates", &s.joint_rates).map_err(|e| e.at(t))?;
        check_finite("thrust", &s.thrust).map_err(|e| e.at(t))
    }

    /// Check the command's lengths and finiteness and the state's finiteness at `t0`.
    fn check_command(&self, cmd: &ActuatorCommand) -> Result<(), SimError> {
        let t0 = self.time;
        let n = self.vehicle.n_joints();
        let m = self.vehicle.n_thrusters();
        for (name, x, want) in [
            ("command.thrust", cmd.thrust, m),
            ("command.joint_ref", cmd.joint_ref, n),
            ("command.joint_rate_ref", cmd.joint_rate_ref, n),
        ] {
            if x.len() != want {
                return Err(DynError::new(
                    name,
                    format!("has length {}, expected {want}", x.len()),
                )
                .at(t0));
            }
            check_finite(name, x).map_err(|e| e.at(t0))?;
        }
        self.check_state()
    }

    /// Advance the state by one RK4 step of `dt` [s] under `cmd` (held over the step),
    /// whatever the configured [`Integrator`].
    ///
    /// On error (bad `dt` or command, a non-finite state or acceleration, a singular mass
    /// matrix) the state and time are left unchanged and the error names the quantity and
    /// the simulation time at which it was detected.
    pub fn step(&mut self, dt: f64, cmd: &ActuatorCommand) -> Result<(), SimError> {
        self.integrate(dt, Integrator::Rk4 { dt }, cmd)
    }

    /// Advance the state over `span` [s] under `cmd` (held: zero-order hold over a control
    /// period) with the configured [`Integrator`]: RK4 steps of `dt`, or Dormand–Prince
    /// steps sized by the error control. Errors as in [`Simulator::step`].
    pub fn advance(&mut self, span: f64, cmd: &ActuatorCommand) -> Result<(), SimError> {
        self.integrate(span, self.cfg.integrator, cmd)
    }

    /// Integrate over `span` with `method`, the thruster states exactly (closed form from
    /// the span start), the rest through the flat state.
    fn integrate(
        &mut self,
        span: f64,
        method: Integrator,
        cmd: &ActuatorCommand,
    ) -> Result<(), SimError> {
        let t0 = self.time;
        if !(span.is_finite() && span > 0.0) {
            return Err(DynError::new("dt", format!("must be finite and > 0, got {span}")).at(t0));
        }
        self.check_command(cmd)?;
        for (j, th) in self.thr.iter().enumerate() {
            self.u_cmd[j] = th.saturate(cmd.thrust[j]);
        }
        self.pack_state();
        let Self {
            vehicle,
            cfg,
            ws,
            state,
            thr,
            x0,
            xs,
            k,
            dopri,
            u_cmd,
            u_act,
            q_gen,
            qdd,
            last_thrust,
            last_joint_torque,
            last_accel,
            terms_fresh,
            stats,
            joint_torque_peak,
            ..
        } = self;
        let mut reuse = *terms_fresh;
        let mut f = |s: f64, x: &[f64], dx: &mut [f64], boundary: bool| {
            for (j, th) in thr.iter().enumerate() {
                u_act[j] = th.saturate(th.evolve(state.thrust[j], u_cmd[j], s));
            }
            eval_stage(vehicle, cfg, ws, x, u_act, cmd, q_gen, qdd, dx, reuse)?;
            reuse = false;
            stats.evaluations += 1;
            if boundary {
                last_thrust.copy_from_slice(u_act);
                last_joint_torque.copy_from_slice(&ws.joint_torque);
                last_accel.copy_from_slice(&ws.zeta_dot);
                let peak = ws.joint_torque.iter().fold(0.0_f64, |m, t| m.max(t.abs()));
                *joint_torque_peak = joint_torque_peak.max(peak);
            }
            Ok(())
        };
        let fail = |(s, e): (f64, DynError)| e.at(t0 + s);
        let start = work_index(vehicle.n_joints());
        let mut work = 0.0;
        match method {
            Integrator::Rk4 { dt } => {
                let steps = ((span / dt).round() as usize).max(1);
                let h = span / steps as f64;
                for i in 0..steps {
                    let quad = Quadrature {
                        quat: QUAT,
                        start,
                        abs: &mut work,
                    };
                    rk4_step(x0, i as f64 * h, h, k, xs, quad, &mut f).map_err(fail)?;
                }
                stats.steps += steps as u64;
                *terms_fresh = false;
            }
            Integrator::Dopri5 { rtol, atol, .. } => {
                let mut counts = StepStats::default();
                let tol = Tolerance { rtol, atol };
                let quad = Quadrature {
                    quat: QUAT,
                    start,
                    abs: &mut work,
                };
                dopri
                    .span(x0, span, tol, quad, &mut counts, &mut f)
                    .map_err(fail)?;
                stats.steps += counts.steps;
                stats.rejected += counts.rejected;
                // The last evaluation was at the end state: with ideal servos, the terms of
                // the hybrid dynamics (M_11, h) stay valid for it; the ABA forms none.
                *terms_fresh = matches!(cfg.servo, ServoModel::SecondOrder { .. });
            }
        }
        self.unpack_state(t0 + span, work)
    }

    /// Pack the state into the flat vector `x0`.
    fn pack_state(&mut self) {
        let n = self.vehicle.n_joints();
        let s = &self.state;
        let x0 = &mut self.x0;
        x0[P..P + 3].copy_from_slice(s.pose.position.as_slice());
        let qc = s.pose.orientation.quaternion();
        x0[QUAT..QUAT + 4].copy_from_slice(&[qc.w, qc.i, qc.j, qc.k]);
        x0[JOINTS..JOINTS + n].copy_from_slice(&s.joint_angles);
        x0[JOINTS + n..JOINTS + n + 6].copy_from_slice(s.base_twist.as_slice());
        x0[JOINTS + n + 6..work_index(n)].copy_from_slice(&s.joint_rates);
        x0[work_index(n)..].fill(0.0);
    }

    /// Check the flat vector `x0` at time `t1` and make it the state (thrust states evolved
    /// in closed form from the span start) and add the span's joint work `work` [J]; on
    /// error nothing changes.
    fn unpack_state(&mut self, t1: f64, work: f64) -> Result<(), SimError> {
        let n = self.vehicle.n_joints();
        let x = &self.x0;
        let names: [(&str, std::ops::Range<usize>); 6] = [
            ("base_position", P..P + 3),
            ("base_orientation", QUAT..QUAT + 4),
            ("joint_angles", JOINTS..JOINTS + n),
            ("base_twist", JOINTS + n..JOINTS + n + 6),
            ("joint_rates", JOINTS + n + 6..work_index(n)),
            ("joint_work", work_index(n)..x.len()),
        ];
        for (name, r) in names {
            check_finite(name, &x[r]).map_err(|e| e.at(t1))?;
        }
        let quat = Quaternion::new(x[QUAT], x[QUAT + 1], x[QUAT + 2], x[QUAT + 3]);
        if quat.norm() == 0.0 {
            return Err(DynError::new("base_orientation", "quaternion has zero norm").at(t1));
        }
        let span = t1 - self.time;
        let s = &mut self.state;
        s.pose.position = Vec3::new(x[P], x[P + 1], x[P + 2]);
        s.pose.orientation = UnitQuaternion::new_normalize(quat);
        s.joint_angles.copy_from_slice(&x[JOINTS..JOINTS + n]);
        s.base_twist = Vec6::from_column_slice(&x[JOINTS + n..JOINTS + n + 6]);
        s.joint_rates
            .copy_from_slice(&x[JOINTS + n + 6..work_index(n)]);
        for (j, th) in self.thr.iter().enumerate() {
            s.thrust[j] = th.evolve(s.thrust[j], self.u_cmd[j], span);
        }
        self.joint_work += work;
        self.time = t1;
        Ok(())
    }
}

/// One stage: the time derivative `dx` of the flat state `x` with actual thrust `u_act`
/// (docs/model.md §4 dynamics + the servo model, and the joint power `Σ|τ_k q̇_k|`). With
/// `terms_ready` the workspace already holds `M`, `h` and the kinematics of `x`.
#[allow(clippy::too_many_arguments)]
fn eval_stage(
    v: &Vehicle,
    cfg: &SimConfig,
    ws: &mut DynWorkspace,
    x: &[f64],
    u_act: &[f64],
    cmd: &ActuatorCommand,
    q_gen: &mut [f64],
    qdd: &mut [f64],
    dx: &mut [f64],
    terms_ready: bool,
) -> Result<(), DynError> {
    let n = v.n_joints();
    let quat = Quaternion::new(x[QUAT], x[QUAT + 1], x[QUAT + 2], x[QUAT + 3]);
    let norm = quat.norm();
    if !(norm > 0.0 && norm.is_finite()) {
        return Err(DynError::new(
            "base_orientation",
            "quaternion is degenerate",
        ));
    }
    let quat = quat / norm;
    let pose = BasePose {
        orientation: UnitQuaternion::new_unchecked(quat),
        position: Vec3::new(x[P], x[P + 1], x[P + 2]),
    };
    let q = &x[JOINTS..JOINTS + n];
    let zeta = &x[JOINTS + n..work_index(n)];
    check_finite("joint_angles", q)?;
    check_finite("generalized_velocity", zeta)?;
    let hybrid = matches!(cfg.servo, ServoModel::SecondOrder { .. });
    if hybrid && !terms_ready {
        hybrid_terms(v, ws, &pose, q, zeta, &cfg.options);
    } else if !hybrid {
        // The ABA runs the position pass itself; the thrust needs it first.
        crate::kinematics::forward_kinematics(v, q, &mut ws.kin);
    }
    generalized_thrust(v, ws, u_act, q_gen);
    let qd = &zeta[6..];
    match cfg.servo {
        ServoModel::SecondOrder { omega_n, zeta: z } => {
            let w2 = omega_n * omega_n;
            for k in 0..n {
                qdd[k] = w2 * (cmd.joint_ref[k] - q[k]) - 2.0 * z * omega_n * qd[k];
            }
            solve_hybrid_on(ws, q_gen, qdd)?;
        }
        ServoModel::TorquePd {
            kp,
            kd,
            torque_limit,
        } => {
            for k in 0..n {
                let tau = kp * (cmd.joint_ref[k] - q[k]) + kd * (cmd.joint_rate_ref[k] - qd[k]);
                let tau = tau.clamp(-torque_limit, torque_limit);
                ws.joint_torque[k] = tau;
                q_gen[6 + k] += tau;
            }
            aba_after_position(v, ws, &pose, zeta, q_gen, &cfg.options)?;
        }
        ServoModel::Passive => {
            ws.joint_torque.fill(0.0);
            aba_after_position(v, ws, &pose, zeta, q_gen, &cfg.options)?;
        }
    }

    // Kinematics of the state: ṗ = R_Ib v, Q̇ = ½ Q ⊗ [0; ω], q̇, ζ̇.
    let v_b = Vec3::new(zeta[0], zeta[1], zeta[2]);
    let w_b = Vec3::new(zeta[3], zeta[4], zeta[5]);
    let p_dot = pose.orientation * v_b;
    dx[P..P + 3].copy_from_slice(p_dot.as_slice());
    let (qw, qv) = (quat.w, Vec3::new(quat.i, quat.j, quat.k));
    let dw = -0.5 * qv.dot(&w_b);
    let dv = 0.5 * (w_b * qw + qv.cross(&w_b));
    dx[QUAT] = dw;
    dx[QUAT + 1] = dv.x;
    dx[QUAT + 2] = dv.y;
    dx[QUAT + 3] = dv.z;
    dx[JOINTS..JOINTS + n].copy_from_slice(qd);
    dx[JOINTS + n..work_index(n)].copy_from_slice(&ws.zeta_dot);
    for ((d, t), w) in dx[work_index(n)..].iter_mut().zip(&ws.joint_torque).zip(qd) {
        *d = t * w;
    }
    Ok(())
}

/// Generalised thrust force `Q = Σ_j J_g,iᵀ F_j u_j` (6+n) into `q_gen`, in O(n + m): the
/// base rows are `Σ_j B_j u_j` (`B_j` thruster `j`'s unit wrench in `F_b`, USM-25) and joint
/// `k`'s row is `S_k · Σ_{j on bodies > k} B_j u_j`, summed from the tip. Needs the position
/// pass in `ws.kin`.
fn generalized_thrust(v: &Vehicle, ws: &mut DynWorkspace, u_act: &[f64], q_gen: &mut [f64]) {
    let body = &mut ws.thrust_body;
    body.fill(Vec6::zeros());
    for (j, u) in u_act.iter().enumerate() {
        body[v.thrusters[j].body] += thruster_column(v, &ws.kin, j) * *u;
    }
    let n = v.n_joints();
    let mut sum = body[n];
    for k in (0..n).rev() {
        // Joint k moves bodies k+1 …: `sum` holds their thrust.
        q_gen[6 + k] = ws.kin.joint_twist_b[k].dot(&sum);
        sum += body[k];
    }
    q_gen[..6].copy_from_slice(sum.as_slice());
}
