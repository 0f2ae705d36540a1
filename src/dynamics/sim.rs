//! Actuator models and the fixed-step Lie-group RK4 integrator (SPEC §4).
//!
//! State: base pose (inertial position, unit quaternion `R_Ib`), joint angles, base twist
//! `V_b` in `F_b`, joint rates, and one thrust state per thruster. Joint servos are either
//! ideal second-order reference filters (hybrid dynamics: the joints follow
//! `q̈ = ω_n²(q_r − q) − 2ζ_n ω_n q̇`, the base obeys `M_11 V̇_b = τ_b − M_12 q̈ − h_1`,
//! joint torques recovered), torque-level PD servos with torque limits (full forward
//! dynamics), or passive (torque-free) joints.
//!
//! # Integrator
//! Classical RK4 on the quaternion kinematics `Q̇ = ½ Q ⊗ [0; ω]` together with
//! `ṗ = R_Ib v`, `q̇`, `ζ̇`: every stage uses the normalised stage quaternion, and the
//! quaternion is renormalised at the end of each step (a projection onto the unit sphere
//! that changes it by `O(dt⁵)`). Chosen over RKMK for simplicity; it keeps fourth-order
//! accuracy and the quaternion unit to machine precision.
//!
//! # Thrusters
//! The commanded thrust is held over a step (zero-order hold) and first saturated to
//! `[u_min, u_max]`. Each thruster's thrust state then follows, exactly (closed form,
//! evaluated at every RK4 stage time), `u̇ = clamp((u_c − u)/T, −r, r)` — a first-order lag
//! with time constant `T` and rate limit `r`, either of which may be absent (absent lag:
//! `u̇ = r sign(u_c − u)` until it arrives; neither: `u = u_c`). The actual thrust is the
//! state saturated to `[u_min, u_max]` in every model. Thrust enters as the generalised force
//! `J_g,iᵀ F_j` of each thruster's wrench on its body (base rows `T(q) u`, USM-25/26).

use super::algorithms::{
    dynamics_terms, kinetic_energy, solve_forward, solve_hybrid, spatial_momentum,
};
use super::config::{config_err, ServoModel, SimConfig, ThrusterModel};
use super::{check_finite, DynError, DynWorkspace, SimError};
use crate::kinematics::{generalized_thrust_map, BasePose};
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

/// Lag and rate limit of one thruster, resolved from the model and the config.
#[derive(Clone, Copy, Debug)]
struct ThrusterDyn {
    time_constant: Option<f64>,
    rate_limit: Option<f64>,
    u_min: f64,
    u_max: f64,
}

impl ThrusterDyn {
    /// Exact solution after `s` seconds of `u̇ = clamp((u_c − u)/T, −r, r)` from `u0`
    /// towards the (saturated) command `u_c`.
    fn evolve(&self, u0: f64, u_c: f64, s: f64) -> f64 {
        let e0 = u_c - u0;
        match (self.time_constant, self.rate_limit) {
            (None, None) => u_c,
            (Some(t), None) => u_c - e0 * (-s / t).exp(),
            (None, Some(r)) => {
                if e0.abs() <= r * s {
                    u_c
                } else {
                    u0 + r * s * e0.signum()
                }
            }
            (Some(t), Some(r)) => {
                // Rate-limited while |e| > r T, then the exponential lag.
                let e_lin = r * t;
                if e0.abs() <= e_lin {
                    u_c - e0 * (-s / t).exp()
                } else {
                    let t1 = (e0.abs() - e_lin) / r;
                    if s <= t1 {
                        u0 + r * s * e0.signum()
                    } else {
                        u_c - e_lin * e0.signum() * (-(s - t1) / t).exp()
                    }
                }
            }
        }
    }

    fn saturate(&self, u: f64) -> f64 {
        u.clamp(self.u_min, self.u_max)
    }
}

/// Offsets in the flat integration vector `[p (3), Q (4: w,i,j,k), q (n), V_b (6), q̇ (n)]`.
const P: usize = 0;
const QUAT: usize = 3;
const JOINTS: usize = 7;

/// A fixed-step simulator of one vehicle (SPEC §4): owns a copy of the vehicle, its
/// [`DynWorkspace`], the state and the actuator models; [`Simulator::step`] allocates
/// nothing.
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
        let nx = JOINTS + n + 6 + n;
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
        Ok(())
    }

    /// Simulation time [s].
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Set the simulation time [s].
    pub fn set_time(&mut self, t: f64) {
        self.time = t;
    }

    /// Actual thrust per thruster [N] at the start of the last step (RK4 stage 1: the
    /// saturated thrust state under that step's command).
    pub fn last_thrust(&self) -> &[f64] {
        &self.last_thrust
    }

    /// Joint motor torques [N·m] at the start of the last step: recovered by the hybrid
    /// dynamics for ideal servos, the saturated PD torque for PD servos, zero if passive.
    pub fn last_joint_torque(&self) -> &[f64] {
        &self.last_joint_torque
    }

    /// Generalised acceleration `ζ̇ = [V̇_b; q̈]` at the start of the last step.
    pub fn last_acceleration(&self) -> &[f64] {
        &self.last_accel
    }

    /// The dynamics workspace (holds `M` and `h` of the last evaluation).
    pub fn workspace(&self) -> &DynWorkspace {
        &self.ws
    }

    /// `M_11(q)` and `h_1 = n(R_Ib, q, ζ)` (USM-33/34: the base block of the mass matrix and
    /// the base rows of the bias forces, both in `F_b`) at the current state, with the
    /// simulator's options.
    pub fn base_control_terms(&mut self) -> Result<(Matrix6<f64>, Vector6<f64>), SimError> {
        self.check_state()?;
        self.load_zeta();
        dynamics_terms(
            &self.vehicle,
            &mut self.ws,
            &self.state.pose,
            &self.state.joint_angles,
            &self.zeta,
            &self.cfg.options,
        );
        check_finite("bias", &self.ws.bias).map_err(|e| e.at(self.time))?;
        Ok((self.ws.mass_base_block(), self.ws.bias_base()))
    }

    /// Kinetic energy `½ζᵀMζ` [J] of the current state (USM-22 `M`, with added mass when the
    /// options have it).
    pub fn kinetic_energy(&mut self) -> f64 {
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

    /// Advance the state by one RK4 step of `dt` [s] under `cmd` (held over the step).
    ///
    /// On error (bad `dt` or command, a non-finite state or acceleration, a singular mass
    /// matrix) the state and time are left unchanged and the error names the quantity and
    /// the simulation time at which it was detected.
    pub fn step(&mut self, dt: f64, cmd: &ActuatorCommand) -> Result<(), SimError> {
        let t0 = self.time;
        let n = self.vehicle.n_joints();
        let m = self.vehicle.n_thrusters();
        if !(dt.is_finite() && dt > 0.0) {
            return Err(DynError::new("dt", format!("must be finite and > 0, got {dt}")).at(t0));
        }
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
        self.check_state()?;

        for (j, th) in self.thr.iter().enumerate() {
            self.u_cmd[j] = th.saturate(cmd.thrust[j]);
        }
        // Pack x0.
        let s = &self.state;
        let x0 = &mut self.x0;
        x0[P..P + 3].copy_from_slice(s.pose.position.as_slice());
        let qc = s.pose.orientation.quaternion();
        x0[QUAT..QUAT + 4].copy_from_slice(&[qc.w, qc.i, qc.j, qc.k]);
        x0[JOINTS..JOINTS + n].copy_from_slice(&s.joint_angles);
        x0[JOINTS + n..JOINTS + n + 6].copy_from_slice(s.base_twist.as_slice());
        x0[JOINTS + n + 6..].copy_from_slice(&s.joint_rates);

        const C: [f64; 4] = [0.0, 0.5, 0.5, 1.0];
        for (stage, c) in C.iter().enumerate() {
            let h = c * dt;
            if stage == 0 {
                self.xs.copy_from_slice(&self.x0);
            } else {
                let kp = &self.k[stage - 1];
                for ((xs, x0), k) in self.xs.iter_mut().zip(&self.x0).zip(kp) {
                    *xs = x0 + h * k;
                }
            }
            for (j, th) in self.thr.iter().enumerate() {
                let u = th.evolve(self.state.thrust[j], self.u_cmd[j], h);
                self.u_act[j] = th.saturate(u);
            }
            eval_stage(
                &self.vehicle,
                &self.cfg,
                &mut self.ws,
                &self.xs,
                &self.u_act,
                cmd,
                &mut self.q_gen,
                &mut self.qdd,
                &mut self.k[stage],
            )
            .map_err(|e| e.at(t0 + h))?;
            if stage == 0 {
                self.last_thrust.copy_from_slice(&self.u_act);
                self.last_joint_torque
                    .copy_from_slice(&self.ws.joint_torque);
                self.last_accel.copy_from_slice(&self.ws.zeta_dot);
            }
        }
        // Combine.
        let [k1, k2, k3, k4] = &self.k;
        for i in 0..self.xs.len() {
            self.xs[i] = self.x0[i] + dt / 6.0 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]);
        }
        let t1 = t0 + dt;
        let x = &self.xs;
        let names: [(&str, std::ops::Range<usize>); 5] = [
            ("base_position", P..P + 3),
            ("base_orientation", QUAT..QUAT + 4),
            ("joint_angles", JOINTS..JOINTS + n),
            ("base_twist", JOINTS + n..JOINTS + n + 6),
            ("joint_rates", JOINTS + n + 6..x.len()),
        ];
        for (name, r) in names {
            check_finite(name, &x[r]).map_err(|e| e.at(t1))?;
        }
        let quat = Quaternion::new(x[QUAT], x[QUAT + 1], x[QUAT + 2], x[QUAT + 3]);
        let norm = quat.norm();
        if norm == 0.0 {
            return Err(DynError::new("base_orientation", "quaternion has zero norm").at(t1));
        }
        let s = &mut self.state;
        s.pose.position = Vec3::new(x[P], x[P + 1], x[P + 2]);
        s.pose.orientation = UnitQuaternion::new_unchecked(quat / norm);
        s.joint_angles.copy_from_slice(&x[JOINTS..JOINTS + n]);
        s.base_twist = Vec6::from_column_slice(&x[JOINTS + n..JOINTS + n + 6]);
        s.joint_rates.copy_from_slice(&x[JOINTS + n + 6..]);
        for (j, th) in self.thr.iter().enumerate() {
            s.thrust[j] = th.evolve(s.thrust[j], self.u_cmd[j], dt);
        }
        self.time = t1;
        Ok(())
    }
}

/// One RK4 stage: the time derivative `dx` of the flat state `x` with actual thrust
/// `u_act` (SPEC §4 dynamics + the servo model).
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
    let zeta = &x[JOINTS + n..];
    check_finite("joint_angles", q)?;
    check_finite("generalized_velocity", zeta)?;
    dynamics_terms(v, ws, &pose, q, zeta, &cfg.options);

    // Generalised thrust force Q = Σ_j (J_g,iᵀ F_j) u_j.
    q_gen.fill(0.0);
    if !u_act.is_empty() {
        generalized_thrust_map(v, &ws.kin, &mut ws.thrust_map);
        for (j, u) in u_act.iter().enumerate() {
            for (r, g) in q_gen.iter_mut().enumerate() {
                *g += ws.thrust_map[(r, j)] * u;
            }
        }
    }
    let qd = &zeta[6..];
    match cfg.servo {
        ServoModel::SecondOrder { omega_n, zeta: z } => {
            let w2 = omega_n * omega_n;
            for k in 0..n {
                qdd[k] = w2 * (cmd.joint_ref[k] - q[k]) - 2.0 * z * omega_n * qd[k];
            }
            solve_hybrid(ws, q_gen, qdd)?;
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
            solve_forward(ws, q_gen)?;
        }
        ServoModel::Passive => {
            ws.joint_torque.fill(0.0);
            solve_forward(ws, q_gen)?;
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
    dx[JOINTS + n..].copy_from_slice(&ws.zeta_dot);
    Ok(())
}
