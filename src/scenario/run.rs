//! The closed loop of the USM paper's Fig. 5: guidance → kinematic control → dynamic control
//! (USM-33) → thrust allocation (USM-36/37) → vehicle (SPEC §4), with logging and metrics.
//!
//! Rates: the physics advances with RK4 steps of `dt`; the controllers and the allocator run
//! every `control_dt` with the actuator commands held in between (zero-order hold); the log
//! samples every `log_dt`. Nothing allocates inside the loop: the log columns are reserved for
//! the whole run up front.

use super::config::{Mode, ModeGains, ScenarioFile};
use crate::allocation::{AllocStatus, Allocation, Allocator};
use crate::control::dynamic::DynamicController;
use crate::control::transport::{measure_transport, TransportController};
use crate::control::work::{WorkController, WorkTarget};
use crate::dynamics::{ActuatorCommand, SimError, SimState, Simulator};
use crate::kinematics::{forward_kinematics, thruster_matrix, KinWorkspace};
use crate::metrics::singularity::sigma_min_scaled_gram;
use crate::metrics::trajectory::{
    energy_metrics, segment_tracking, settling_time, singularity_exposure,
};
use crate::model::Vehicle;
use crate::spatial::{ang, euler_zyx, lin, Vec3, Vec6};
use nalgebra::{Matrix6xX, UnitQuaternion, Vector3};
use serde::Serialize;
use std::time::Instant;
use thiserror::Error;

/// A problem with a scenario: bad settings (before running) or a failed run.
#[derive(Debug, Error)]
pub enum ScenarioError {
    /// The scenario or its design is invalid; nothing ran.
    #[error("{0}")]
    Invalid(String),
    /// The run stopped early; what was simulated up to then is in the partial result.
    #[error("run stopped at t = {time:.3} s: {cause}")]
    Stopped {
        /// Simulation time of the failure [s].
        time: f64,
        /// What went wrong (the offending quantity).
        cause: String,
    },
}

/// Column-oriented time series of one run: named f64 channels of equal length.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trajectory {
    /// Channel names (SI units; angles in rad).
    pub names: Vec<String>,
    /// One vector per channel.
    pub columns: Vec<Vec<f64>>,
}

impl Trajectory {
    fn with_names(names: Vec<String>, capacity: usize) -> Self {
        let columns = names.iter().map(|_| Vec::with_capacity(capacity)).collect();
        Self { names, columns }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.columns.first().map_or(0, |c| c.len())
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// A channel by name.
    pub fn col(&self, name: &str) -> Option<&[f64]> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|i| self.columns[i].as_slice())
    }

    /// Channels whose names start with `prefix`, in order (e.g. `u_` for the thrusts).
    pub fn cols_with_prefix(&self, prefix: &str) -> Vec<&[f64]> {
        self.names
            .iter()
            .zip(&self.columns)
            .filter(|(n, _)| n.starts_with(prefix))
            .map(|(_, c)| c.as_slice())
            .collect()
    }

    fn push_row(&mut self, row: &[f64]) {
        for (c, x) in self.columns.iter_mut().zip(row) {
            c.push(*x);
        }
    }
}

/// Wall-clock breakdown of a run (not deterministic; never part of result tables).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Timing {
    /// Total wall time [s].
    pub total_s: f64,
    /// Time in the physics (RK4 steps and the base-control dynamics terms) [s].
    pub dynamics_s: f64,
    /// Time in thrust allocation [s].
    pub allocation_s: f64,
    /// Time in kinematics, guidance and control laws [s].
    pub control_s: f64,
    /// Time logging (including σ_min of T(q)) [s].
    pub logging_s: f64,
    /// Real-time factor: simulated seconds per wall second.
    pub realtime_factor: f64,
}

/// The outcome of one run: the trajectory up to the end (or the failure), the metrics, and
/// the failure if the run stopped early.
#[derive(Clone, Debug)]
pub struct RunResult {
    /// Scenario name.
    pub name: String,
    /// Mode.
    pub mode: Mode,
    /// Logged time series.
    pub trajectory: Trajectory,
    /// Metrics (name, value), in a fixed order for the mode; SI units.
    pub metrics: Vec<(String, f64)>,
    /// Why the run stopped early, if it did.
    pub failure: Option<(f64, String)>,
    /// Allocation outcomes: steps, slack-active steps, solver failures.
    pub allocation_counts: [u64; 3],
    /// Wall-clock breakdown.
    pub timing: Timing,
}

impl RunResult {
    /// A metric by name.
    pub fn metric(&self, name: &str) -> Option<f64> {
        self.metrics.iter().find(|(n, _)| n == name).map(|m| m.1)
    }
}

const AXES6: [&str; 6] = ["u", "v", "w", "p", "q", "r"];

fn channel_names(v: &Vehicle, mode: Mode) -> Vec<String> {
    let mut n: Vec<String> = vec!["t".into()];
    for p in ["base", "ee"] {
        for s in ["x", "y", "z", "roll", "pitch", "yaw"] {
            n.push(format!("{p}_{s}"));
        }
        for s in AXES6 {
            n.push(format!("{p}_{s}"));
        }
    }
    match mode {
        Mode::Transport => {
            for s in [
                "psi",
                "psi_r",
                "cross_track",
                "along_track",
                "segment",
                "heading_error",
                "surge_error",
                "base_cross_track",
                "path_y",
            ] {
                n.push(s.into());
            }
        }
        Mode::Work => {
            for s in ["x", "y", "z", "roll", "pitch", "yaw"] {
                n.push(format!("sp_{s}"));
            }
            n.push("ee_position_error".into());
            n.push("ee_orientation_error".into());
            for s in AXES6 {
                n.push(format!("ref_{s}"));
            }
        }
    }
    for (k, j) in v.joints.iter().enumerate() {
        let _ = j;
        n.push(format!("q_{k}"));
    }
    for k in 0..v.n_joints() {
        n.push(format!("qref_{k}"));
    }
    for k in 0..v.n_joints() {
        n.push(format!("qd_{k}"));
    }
    for k in 0..v.n_joints() {
        n.push(format!("tau_{k}"));
    }
    for j in 0..v.n_thrusters() {
        n.push(format!("ucmd_{j}"));
    }
    for j in 0..v.n_thrusters() {
        n.push(format!("u_{j}"));
    }
    for j in 0..v.n_thrusters() {
        n.push(format!("power_{j}"));
    }
    n.push("sigma_min".into());
    n.push("slack_norm".into());
    n.push("alloc_status".into());
    n
}

fn status_code(s: &AllocStatus) -> f64 {
    match s {
        AllocStatus::Solved => 0.0,
        AllocStatus::SlackActive { .. } => 1.0,
        AllocStatus::BoundsViolated { .. } => 2.0,
        _ => 3.0,
    }
}

/// Signed lateral offset of `p` from the line of a segment (positive left), for the base's
/// "tail follows the head" measure.
fn lateral_offset(p: &Vec3, from: [f64; 2], to: [f64; 2]) -> f64 {
    let d = [to[0] - from[0], to[1] - from[1]];
    let l = (d[0] * d[0] + d[1] * d[1]).sqrt();
    if l == 0.0 {
        return 0.0;
    }
    (d[0] * (p.y - from[1]) - d[1] * (p.x - from[0])) / l
}

/// Run a scenario on a vehicle. Never panics on bad input: settings problems return
/// [`ScenarioError::Invalid`] before anything runs; a run that fails (diverges, NaN,
/// singular mass matrix) returns `Ok` with `failure` set and the trajectory up to then.
pub fn run_scenario(v: &Vehicle, file: &ScenarioFile) -> Result<RunResult, ScenarioError> {
    let started = Instant::now();
    file.validate()
        .map_err(|e| ScenarioError::Invalid(e.to_string()))?;
    let s = &file.scenario;
    let mut vehicle = v.clone();
    vehicle.fluid.current = Vec3::from(file.physics.current);
    let v = &vehicle;
    let n = v.n_joints();
    let m = v.n_thrusters();
    if m == 0 {
        return Err(ScenarioError::Invalid(
            "design: a closed-loop scenario needs at least one thruster".into(),
        ));
    }
    let mut sim = Simulator::new(
        v,
        file.sim_config()
            .map_err(|e| ScenarioError::Invalid(e.to_string()))?,
    )
    .map_err(|e| ScenarioError::Invalid(e.to_string()))?;
    // Initial state.
    let mut st = SimState::rest(v);
    st.pose.position = Vec3::from(file.initial.position);
    st.pose.orientation =
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), file.initial.yaw_deg.to_radians());
    if !file.initial.joint_angles_deg.is_empty() {
        if file.initial.joint_angles_deg.len() != n {
            return Err(ScenarioError::Invalid(format!(
                "initial.joint_angles_deg has {} entries, the design has {n} joints",
                file.initial.joint_angles_deg.len()
            )));
        }
        for (q, d) in st
            .joint_angles
            .iter_mut()
            .zip(&file.initial.joint_angles_deg)
        {
            *q = d.to_radians();
        }
    }
    sim.set_state(st)
        .map_err(|e| ScenarioError::Invalid(e.to_string()))?;

    // Controllers.
    let gains = file
        .mode_gains()
        .map_err(|e| ScenarioError::Invalid(e.to_string()))?;
    let mut base_ctl = DynamicController::new(file.base_gains())
        .map_err(|e| ScenarioError::Invalid(format!("base_control.{e}")))?;
    let mut transport = None;
    let mut work = None;
    let mut work_target = None;
    match (&gains, s.mode) {
        (ModeGains::Transport(g), _) => {
            let path = file.path.as_ref().ok_or_else(|| {
                ScenarioError::Invalid("path: transport mode needs a [path] table".into())
            })?;
            transport = Some(
                TransportController::new(v, g.clone(), path)
                    .map_err(|e| ScenarioError::Invalid(format!("control.{e}")))?,
            );
        }
        (ModeGains::Work(g), _) => {
            let sp = file.setpoint.as_ref().ok_or_else(|| {
                ScenarioError::Invalid("setpoint: work mode needs a [setpoint] table".into())
            })?;
            let mut c = WorkController::new(v, g)
                .map_err(|e| ScenarioError::Invalid(format!("control.{e}")))?;
            c.reset(&sim.state().joint_angles);
            work = Some(c);
            let r = sp.rpy_deg.map(f64::to_radians);
            work_target = Some(WorkTarget {
                ee_position: Vec3::from(sp.position),
                ee_orientation: UnitQuaternion::from_euler_angles(r[0], r[1], r[2]),
                ee_twist: Vec6::zeros(),
                base_position: Vec3::from(sp.base_position.unwrap_or(file.initial.position)),
            });
        }
    }
    let u_min: Vec<f64> = v.thrusters.iter().map(|t| t.u_min).collect();
    let u_max: Vec<f64> = v.thrusters.iter().map(|t| t.u_max).collect();
    let alloc_spec = &file.allocation;
    let mut allocator = Allocator::new(
        alloc_spec.method,
        m,
        &u_min,
        &u_max,
        &alloc_spec.weights_for(m),
        alloc_spec.settings(m),
    )
    .map_err(|e| ScenarioError::Invalid(format!("allocation: {e}")))?;
    let char_length = if file.metrics.char_length > 0.0 {
        file.metrics.char_length
    } else {
        v.characteristic_length()
    };
    let power = file.power_model(v.fluid.rho);

    // Buffers, all sized once.
    let mut ws = KinWorkspace::new(v);
    let mut t_mat = Matrix6xX::<f64>::zeros(m);
    let mut alloc = Allocation::new(m);
    let mut q_ref = sim.state().joint_angles.clone();
    let mut qd_ref = vec![0.0; n];
    let mut qd_meas = vec![0.0; n];
    let names = channel_names(v, s.mode);
    let n_log = (s.duration / s.log_dt).floor() as usize + 2;
    let mut traj = Trajectory::with_names(names, n_log);
    let mut row = vec![0.0; traj.names.len()];
    let sub = (s.control_dt / s.dt).round() as usize;
    let log_every = (s.log_dt / s.control_dt).round() as usize;
    let n_control = (s.duration / s.control_dt).round() as usize;
    let mut timing = Timing::default();
    let mut failure: Option<(f64, String)> = None;
    let mut counts = [0u64; 3];
    let mut tau_c = Vec6::zeros();
    let mut aux = [0.0f64; 14];

    for k in 0..=n_control {
        let t = k as f64 * s.control_dt;
        let t0 = Instant::now();
        // Measure.
        let state = sim.state();
        let base = state.pose;
        forward_kinematics(v, &state.joint_angles, &mut ws);
        let v_b = state.base_twist;
        qd_meas.copy_from_slice(&state.joint_rates);
        // Divergence guard.
        let dist = base.position.norm();
        if dist.is_nan() || dist > file.metrics.divergence_distance {
            failure = Some((
                t,
                format!(
                    "diverged: base position |p| = {dist:.3e} m exceeds metrics.divergence_distance"
                ),
            ));
            break;
        }
        // Kinematic and dynamic control.
        let t1 = Instant::now();
        timing.control_s += (t1 - t0).as_secs_f64();
        let (m11, nvec) = match sim.base_control_terms() {
            Ok(x) => x,
            Err(e) => {
                failure = Some((t, e.to_string()));
                break;
            }
        };
        let t2 = Instant::now();
        timing.dynamics_s += (t2 - t1).as_secs_f64();
        if let Some(c) = transport.as_mut() {
            let meas = measure_transport(&base, &ws, &v_b, &qd_meas);
            let out = c.step(t, &meas, s.control_dt);
            q_ref.copy_from_slice(c.q_ref());
            qd_ref.fill(0.0);
            tau_c = base_ctl.transport_control(&m11, &nvec, &out.a_b, &v_b).0;
            let path = file.path.as_ref().map(|p| (p, out.los.segment));
            let base_ct = match path {
                Some((p, seg)) if !p.segments.is_empty() => {
                    let sg = &p.segments[seg.min(p.segments.len() - 1)];
                    lateral_offset(&base.position, sg.from, sg.to)
                }
                Some((p, seg)) if p.waypoints.len() >= 2 => {
                    let i = seg.min(p.waypoints.len() - 2);
                    lateral_offset(&base.position, p.waypoints[i], p.waypoints[i + 1])
                }
                _ => f64::NAN,
            };
            aux[..9].copy_from_slice(&[
                meas.psi,
                out.los.psi_r,
                out.los.cross_track,
                out.los.along_track,
                out.los.segment as f64,
                out.heading_error,
                out.surge_error,
                base_ct,
                // y of the path point nearest the end-effector: p_ee − e_y n, n the left normal.
                meas.ee_position.y - out.los.cross_track * out.los.alpha.cos(),
            ]);
        }
        if let (Some(c), Some(target)) = (work.as_mut(), work_target.as_ref()) {
            let out = c.step(&base, &ws, target, s.control_dt);
            q_ref.copy_from_slice(c.q_ref());
            qd_ref.copy_from_slice(c.qd_ref());
            let d = base_ctl.velocity_control(&m11, &nvec, &v_b, &out.v_r, s.control_dt);
            tau_c = d.tau_c;
            let g_ie = base.to_se3().compose(&ws.g_be);
            let e_pos = (g_ie.p - target.ee_position).norm();
            // Orientation error with roll excluded: the angle between the desired and the
            // actual end-effector x axes (the pointing direction).
            let x_d = target.ee_orientation * Vec3::x();
            let x_e = g_ie.r * Vec3::x();
            let e_ang = x_d.dot(&x_e).clamp(-1.0, 1.0).acos();
            let sp = euler_zyx(target.ee_orientation.to_rotation_matrix().matrix());
            aux[..14].copy_from_slice(&[
                target.ee_position.x,
                target.ee_position.y,
                target.ee_position.z,
                sp.x,
                sp.y,
                sp.z,
                e_pos,
                e_ang,
                out.v_r[0],
                out.v_r[1],
                out.v_r[2],
                out.v_r[3],
                out.v_r[4],
                out.v_r[5],
            ]);
        }
        // Allocation.
        thruster_matrix(v, &ws, &mut t_mat);
        let t3 = Instant::now();
        timing.control_s += (t3 - t2).as_secs_f64();
        if let Err(e) = allocator.allocate_into(&t_mat, &tau_c, &mut alloc) {
            failure = Some((t, format!("allocation: {e}")));
            break;
        }
        counts[0] += 1;
        match alloc.status {
            AllocStatus::SlackActive { .. } => counts[1] += 1,
            AllocStatus::Solved | AllocStatus::BoundsViolated { .. } => {}
            _ => counts[2] += 1,
        }
        let t4 = Instant::now();
        timing.allocation_s += (t4 - t3).as_secs_f64();

        // Log (the state at t with the commands decided at t).
        if k % log_every == 0 {
            let state = sim.state();
            let g_ib = state.pose.to_se3();
            let g_ie = g_ib.compose(&ws.g_be);
            let mut v_in_b = state.base_twist;
            for (x, r) in ws.joint_twist_b.iter().zip(&state.joint_rates) {
                v_in_b += x * *r;
            }
            let v_e = ws.g_be.twist_to_child(&v_in_b);
            let mut i = 0;
            let mut put = |x: f64| {
                row[i] = x;
                i += 1;
            };
            put(t);
            let eb = euler_zyx(&g_ib.r);
            for x in [g_ib.p.x, g_ib.p.y, g_ib.p.z, eb.x, eb.y, eb.z] {
                put(x);
            }
            for x in state.base_twist.iter() {
                put(*x);
            }
            let ee = euler_zyx(&g_ie.r);
            for x in [g_ie.p.x, g_ie.p.y, g_ie.p.z, ee.x, ee.y, ee.z] {
                put(x);
            }
            for x in lin(&v_e).iter().chain(ang(&v_e).iter()) {
                put(*x);
            }
            let n_aux = if s.mode == Mode::Transport { 9 } else { 14 };
            for x in &aux[..n_aux] {
                put(*x);
            }
            for x in &state.joint_angles {
                put(*x);
            }
            for x in &q_ref {
                put(*x);
            }
            for x in &state.joint_rates {
                put(*x);
            }
            for x in sim.last_joint_torque() {
                put(*x);
            }
            for x in &alloc.u {
                put(*x);
            }
            // Actual thrust: the thruster states clamped to their limits.
            for (x, th) in state.thrust.iter().zip(&v.thrusters) {
                put(x.clamp(th.u_min, th.u_max));
            }
            for (x, th) in state.thrust.iter().zip(&v.thrusters) {
                put(power.power(x.clamp(th.u_min, th.u_max)));
            }
            put(sigma_min_scaled_gram(&t_mat, char_length));
            put(alloc.s.norm());
            put(status_code(&alloc.status));
            traj.push_row(&row);
        }
        let t5 = Instant::now();
        timing.logging_s += (t5 - t4).as_secs_f64();
        if k == n_control {
            break;
        }
        // Physics over one control period.
        let cmd = ActuatorCommand {
            thrust: &alloc.u,
            joint_ref: &q_ref,
            joint_rate_ref: &qd_ref,
        };
        let mut stop: Option<SimError> = None;
        for _ in 0..sub {
            if let Err(e) = sim.step(s.dt, &cmd) {
                stop = Some(e);
                break;
            }
        }
        timing.dynamics_s += t5.elapsed().as_secs_f64();
        if let Some(e) = stop {
            failure = Some((e.time, e.to_string()));
            break;
        }
    }
    timing.total_s = started.elapsed().as_secs_f64();
    let simulated = traj.col("t").and_then(|c| c.last().copied()).unwrap_or(0.0);
    timing.realtime_factor = if timing.total_s > 0.0 {
        simulated / timing.total_s
    } else {
        f64::INFINITY
    };
    let metrics = summarise(v, file, &traj, failure.is_some(), counts);
    Ok(RunResult {
        name: s.name.clone(),
        mode: s.mode,
        trajectory: traj,
        metrics,
        failure,
        allocation_counts: counts,
        timing,
    })
}

/// Metrics of a run (SPEC §6) from its trajectory, in a fixed order for the mode.
fn summarise(
    v: &Vehicle,
    file: &ScenarioFile,
    traj: &Trajectory,
    failed: bool,
    counts: [u64; 3],
) -> Vec<(String, f64)> {
    let mut out: Vec<(String, f64)> = Vec::new();
    let mut add = |k: &str, x: f64| out.push((k.to_string(), x));
    let empty: [f64; 0] = [];
    let t = traj.col("t").unwrap_or(&empty);
    let thrust: Vec<Vec<f64>> = traj
        .cols_with_prefix("u_")
        .iter()
        .map(|c| c.to_vec())
        .collect();
    let torque: Vec<Vec<f64>> = traj
        .cols_with_prefix("tau_")
        .iter()
        .map(|c| c.to_vec())
        .collect();
    let rate: Vec<Vec<f64>> = traj
        .cols_with_prefix("qd_")
        .iter()
        .map(|c| c.to_vec())
        .collect();
    let limits: Vec<(f64, f64)> = v.thrusters.iter().map(|t| (t.u_min, t.u_max)).collect();
    let e = energy_metrics(
        t,
        &thrust,
        &limits,
        &torque,
        &rate,
        &file.power_model(v.fluid.rho),
        file.metrics.saturation_tolerance,
    );
    add("completed", if failed { 0.0 } else { 1.0 });
    add("simulated_time", t.last().copied().unwrap_or(0.0));
    add("thruster_energy", e.thruster_energy);
    add("effort_sq", e.effort_sq);
    add("effort_abs", e.effort_abs);
    add("joint_energy", e.joint_energy);
    add("peak_thrust", e.peak_thrust);
    add("saturation_fraction", e.saturation_fraction);
    let sig = traj.col("sigma_min").unwrap_or(&empty);
    add(
        "singularity_exposure",
        singularity_exposure(t, sig, file.metrics.threshold),
    );
    add(
        "sigma_min_min",
        sig.iter().copied().fold(f64::INFINITY, f64::min),
    );
    add(
        "sigma_min_mean",
        if sig.is_empty() {
            f64::NAN
        } else {
            sig.iter().sum::<f64>() / sig.len() as f64
        },
    );
    let steps = counts[0].max(1) as f64;
    add("slack_fraction", counts[1] as f64 / steps);
    add("allocation_failures", counts[2] as f64);
    match file.scenario.mode {
        Mode::Transport => {
            let ey = traj.col("cross_track").unwrap_or(&empty);
            let seg = traj.col("segment").unwrap_or(&empty);
            let base_ct = traj.col("base_cross_track").unwrap_or(&empty);
            let band = file.metrics.band;
            // Split by active segment (contiguous runs).
            let mut runs: Vec<(usize, usize)> = Vec::new();
            let mut a = 0;
            for i in 1..=seg.len() {
                if i == seg.len() || seg[i] != seg[a] {
                    runs.push((a, i));
                    a = i;
                }
            }
            let mut conv_max: f64 = 0.0;
            let mut overshoot_max: f64 = 0.0;
            let mut rms_sq = 0.0;
            let mut rms_t = 0.0;
            let mut base_sq = 0.0;
            let mut all_converged = !runs.is_empty();
            for (k, &(a, b)) in runs.iter().enumerate() {
                let st = segment_tracking(&t[a..b], &ey[a..b], band);
                add(&format!("seg{k}_convergence_time"), st.convergence_time);
                add(&format!("seg{k}_overshoot"), st.overshoot);
                add(&format!("seg{k}_cross_track_rms"), st.rms_after);
                if st.convergence_time.is_nan() {
                    all_converged = false;
                } else {
                    conv_max = conv_max.max(st.convergence_time);
                    let c0 = a + t[a..b]
                        .iter()
                        .position(|x| *x >= st.start + st.convergence_time)
                        .unwrap_or(0);
                    let span = t[b - 1] - t[c0];
                    rms_sq += st.rms_after * st.rms_after * span;
                    rms_t += span;
                    let bs: f64 = (c0 + 1..b)
                        .map(|i| {
                            0.5 * (t[i] - t[i - 1])
                                * (base_ct[i] * base_ct[i] + base_ct[i - 1] * base_ct[i - 1])
                        })
                        .sum();
                    base_sq += bs;
                }
                overshoot_max = overshoot_max.max(st.overshoot);
            }
            add("segments_reached", runs.len() as f64);
            add("converged", if all_converged { 1.0 } else { 0.0 });
            add(
                "convergence_time",
                if all_converged { conv_max } else { f64::NAN },
            );
            add("overshoot", overshoot_max);
            add(
                "cross_track_rms",
                if rms_t > 0.0 {
                    (rms_sq / rms_t).sqrt()
                } else {
                    f64::NAN
                },
            );
            add(
                "base_cross_track_rms",
                if rms_t > 0.0 {
                    (base_sq / rms_t).sqrt()
                } else {
                    f64::NAN
                },
            );
            add("final_cross_track", ey.last().copied().unwrap_or(f64::NAN));
        }
        Mode::Work => {
            let ep = traj.col("ee_position_error").unwrap_or(&empty);
            let ea = traj.col("ee_orientation_error").unwrap_or(&empty);
            add(
                "final_position_error",
                ep.last().copied().unwrap_or(f64::NAN),
            );
            add(
                "final_orientation_error_deg",
                ea.last().copied().unwrap_or(f64::NAN).to_degrees(),
            );
            add(
                "settling_time_position",
                settling_time(t, ep, file.metrics.position_tolerance),
            );
            add(
                "settling_time_orientation",
                settling_time(t, ea, file.metrics.orientation_tolerance_deg.to_radians()),
            );
            let bx = traj.col("base_x").unwrap_or(&empty);
            let by = traj.col("base_y").unwrap_or(&empty);
            let bz = traj.col("base_z").unwrap_or(&empty);
            let drift = if bx.is_empty() {
                f64::NAN
            } else {
                let l = bx.len() - 1;
                ((bx[l] - bx[0]).powi(2) + (by[l] - by[0]).powi(2) + (bz[l] - bz[0]).powi(2)).sqrt()
            };
            add("base_drift", drift);
            // Roll of the end-effector about its setpoint over the second half of the run.
            let er = traj.col("ee_roll").unwrap_or(&empty);
            let sr = traj.col("sp_roll").unwrap_or(&empty);
            let half = er.len() / 2;
            let dev: Vec<f64> = er[half..]
                .iter()
                .zip(&sr[half..])
                .map(|(a, b)| crate::control::wrap_angle(a - b))
                .collect();
            let mean = dev.iter().sum::<f64>() / dev.len().max(1) as f64;
            let var = dev.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / dev.len().max(1) as f64;
            add("ee_roll_std_deg", var.sqrt().to_degrees());
            add(
                "ee_roll_max_deg",
                dev.iter().fold(0.0f64, |m, d| m.max(d.abs())).to_degrees(),
            );
        }
    }
    out
}
