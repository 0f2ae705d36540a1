//! The recorder of a closed-loop run, an observer outside the step: it owns the trajectory
//! (one column per [`Channel`] of [`channel_layout`]), the allocation outcome counts, the
//! energy integrals and the wall-clock timers. At every control tick it samples the
//! thrusters (thrust held over the coming interval, each thruster's axial inflow) and at every
//! physics step the joints (motor torque and rate) for the [`EnergyIntegrator`]; every
//! `log_dt` it logs the state at t with the commands decided at t into a row sized once.
//! Nothing here allocates after setup.

use super::channels::{channel_layout, Channel, Pose, Trajectory, Twist};
use super::controller::ModeController;
use super::setup::ClosedLoop;
use crate::allocation::{AllocPath, AllocStatus, Allocation};
use crate::dynamics::SimState;
use crate::kinematics::KinWorkspace;
use crate::metrics::singularity::{
    commanded_sigma_with, residual_exceeds, CommandedDofs, ScaledGram,
};
use crate::metrics::trajectory::{
    EnergyIntegrator, EnergyMetrics, PowerModel, PowerSample, ThrusterSample,
};
use crate::model::Vehicle;
use crate::spatial::{ang, euler_zyx, lin, Vec6};
use serde::Serialize;
use std::time::Instant;

/// Add the wall time of an expression to a timer [s] and yield its value.
/// With a third argument (a [`StepTimes`] series), also record the duration as one sample.
macro_rules! timed {
    ($timer:expr, $body:expr) => {{
        let started = std::time::Instant::now();
        let value = $body;
        $timer += started.elapsed().as_secs_f64();
        value
    }};
    ($timer:expr, $series:expr, $body:expr) => {{
        let started = std::time::Instant::now();
        let value = $body;
        let dt = started.elapsed().as_secs_f64();
        $timer += dt;
        $series.push(dt);
        value
    }};
}
pub(crate) use timed;

/// Wall-clock breakdown of a run (not deterministic; never part of result tables).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Timing {
    /// Total wall time [s].
    pub total_s: f64,
    /// Time in the physics (integrator steps and the base-control dynamics terms) [s].
    pub dynamics_s: f64,
    /// Physics steps accepted by the integrator (deterministic).
    pub physics_steps: u64,
    /// Physics steps rejected by the error control (Dormand–Prince; deterministic).
    pub physics_rejected: u64,
    /// Dynamics evaluations (one `M ζ̇ = τ − h` solve each; deterministic).
    pub physics_evaluations: u64,
    /// Time in thrust allocation [s].
    pub allocation_s: f64,
    /// Time in kinematics, guidance and control laws [s].
    pub control_s: f64,
    /// Time logging (including the σ_min of T(q)) [s].
    pub logging_s: f64,
    /// Real-time factor: simulated seconds per wall second.
    pub realtime_factor: f64,
    /// Median wall time of one allocation (one control step's thrust allocation) [µs].
    pub allocation_step_median_us: f64,
    /// Median wall time of one whole control period (measure, control, allocate, record and
    /// the physics up to the next tick) [µs].
    pub control_period_median_us: f64,
}

/// Per-step wall times of a run [s], one sample per control period, reserved for the whole
/// run at setup so that recording them never allocates.
pub(crate) struct StepTimes {
    samples: Vec<f64>,
}

impl StepTimes {
    /// Room for `n` samples.
    pub fn with_capacity(n: usize) -> Self {
        Self {
            samples: Vec::with_capacity(n),
        }
    }

    /// Record one duration [s] (dropped beyond the reserved capacity, so never allocates).
    pub fn push(&mut self, dt: f64) {
        if self.samples.len() < self.samples.capacity() {
            self.samples.push(dt);
        }
    }

    /// The median [µs] (the upper one of an even count); NaN without samples.
    fn median_us(&mut self) -> f64 {
        let n = self.samples.len();
        if n == 0 {
            return f64::NAN;
        }
        let (_, m, _) = self.samples.select_nth_unstable_by(n / 2, f64::total_cmp);
        *m * 1e6
    }
}

/// How the allocations of a run went, counted over control periods: outcomes, and which path
/// computed each step (`steps = pinv + fast_path + clarabel + solver_failures`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct AllocationCounts {
    /// Allocations made (one per control period reached).
    pub steps: u64,
    /// Allocations whose wrench slack was active (the demand was not met exactly).
    pub slack_active: u64,
    /// Allocations the solver did not solve (neither solved, slack-active nor bounds-violated);
    /// their `u` is the fallback ([`AllocPath::Fallback`]).
    pub solver_failures: u64,
    /// `qp` steps solved by the certified interior shortcut, without Clarabel
    /// ([`AllocPath::Interior`]).
    pub fast_path: u64,
    /// Steps solved by Clarabel ([`AllocPath::Clarabel`]).
    pub clarabel: u64,
    /// `pinv` steps ([`AllocPath::Pinv`]).
    pub pinv: u64,
    /// Allocations that did not deliver the commanded wrench: the commanded slack exceeds
    /// `[metrics] residual_tolerance` times the commanded wrench
    /// ([`residual_exceeds`]; `allocation_residual_fraction = residual / steps`).
    pub residual: u64,
}

impl AllocationCounts {
    /// Count one allocation: its outcome and its path.
    pub fn count(&mut self, a: &Allocation) {
        self.steps += 1;
        match a.status {
            AllocStatus::SlackActive { .. } => self.slack_active += 1,
            AllocStatus::Solved | AllocStatus::BoundsViolated { .. } => {}
            _ => self.solver_failures += 1,
        }
        match a.path {
            AllocPath::Interior => self.fast_path += 1,
            AllocPath::Clarabel => self.clarabel += 1,
            AllocPath::Pinv => self.pinv += 1,
            AllocPath::Fallback => {}
        }
    }
}

/// The [`Channel::AllocStatus`] code of an outcome.
fn status_code(s: &AllocStatus) -> f64 {
    match s {
        AllocStatus::Solved => 0.0,
        AllocStatus::SlackActive { .. } => 1.0,
        AllocStatus::BoundsViolated { .. } => 2.0,
        _ => 3.0,
    }
}

/// Twist of body `body` relative to the inertial frame, expressed in the base frame `F_b`
/// (linear part: the velocity of the body point at the base origin):
/// `V_b + Σ_{k < body} ξ_k q̇_k` with `ξ_k` the joint unit twists in `F_b` (USM-17: joint k
/// moves body k+1 and everything after it). `base_twist` is the base's body twist.
fn body_twist_in_base(ws: &KinWorkspace, base_twist: &Vec6, qd: &[f64], body: usize) -> Vec6 {
    let mut v = *base_twist;
    for (x, r) in ws.joint_twist_b.iter().zip(qd).take(body) {
        v += x * *r;
    }
    v
}

/// Axial inflow `V_a` of every thruster [m/s] (docs/model.md §6) for the thrusts `thrust` [N]: the
/// velocity of the thruster point relative to the water (the current `ν_c` rotated into
/// `F_b`) projected on the direction the thruster pushes the vehicle, `sign(u_j) d_j`. A
/// thruster pushing the vehicle forward while the vehicle moves forward sees a positive
/// inflow equal to that speed. `ws` must hold the forward kinematics of the current joint
/// angles. Writes `out` (one per thruster).
fn thruster_inflow(
    v: &Vehicle,
    ws: &KinWorkspace,
    state: &SimState,
    thrust: &[f64],
    out: &mut [f64],
) {
    let water_b = state
        .pose
        .orientation
        .inverse_transform_vector(&v.fluid.current);
    for ((th, u), o) in v.thrusters.iter().zip(thrust).zip(out.iter_mut()) {
        let g = &ws.g_b[th.body];
        let tw = body_twist_in_base(ws, &state.base_twist, &state.joint_rates, th.body);
        let p = g.act_point(&th.position);
        let d = g.act_vector(&th.direction);
        let v_rel = lin(&tw) + ang(&tw).cross(&p) - water_b;
        *o = u.signum() * d.dot(&v_rel);
    }
}

/// `(family(k), xs[k])` for every k: the samples of an indexed channel family.
fn indexed(family: fn(usize) -> Channel, xs: &[f64]) -> impl Iterator<Item = (Channel, f64)> + '_ {
    xs.iter().enumerate().map(move |(k, x)| (family(k), *x))
}

/// One row being written: each value is put with its channel, checked against the layout.
struct RowWriter<'a> {
    channels: &'a [Channel],
    row: &'a mut [f64],
    next: usize,
}

impl RowWriter<'_> {
    fn put(&mut self, channel: Channel, x: f64) {
        assert_eq!(
            self.channels[self.next], channel,
            "the recorder is out of step with the channel layout"
        );
        self.row[self.next] = x;
        self.next += 1;
    }

    fn put_all(&mut self, channels: impl IntoIterator<Item = (Channel, f64)>) {
        for (c, x) in channels {
            self.put(c, x);
        }
    }
}

/// The observer of a closed-loop run: trajectory, allocation counts and timers.
pub(crate) struct Recorder {
    traj: Trajectory,
    row: Vec<f64>,
    /// Log every this many control periods.
    log_every: usize,
    /// Characteristic length for the scaled σ_min of T(q) [m].
    char_length: f64,
    /// The base axes the controller commands (the rows of `S·T_L`).
    commanded: CommandedDofs,
    /// Relative tolerance of the commanded allocation residual.
    residual_tol: f64,
    power: PowerModel,
    /// Thruster limits `(u_min, u_max)` [N].
    limits: Vec<(f64, f64)>,
    /// Saturation tolerance [N].
    sat_tol: f64,
    /// Thrust held over the current control interval: the allocation saturated to the limits,
    /// as the simulator applies it [N].
    thrust: Vec<f64>,
    /// Axial inflow of each thruster at the current tick [m/s].
    inflow: Vec<f64>,
    /// Joint rates at the start of the current physics step [rad/s].
    /// Allocation outcomes so far.
    pub counts: AllocationCounts,
    /// Energy and effort integrals over the control intervals so far.
    pub energy: EnergyIntegrator,
    /// Wall-clock timers.
    pub timing: Timing,
    /// Wall time of each allocation.
    pub allocation_steps: StepTimes,
    /// Wall time of each control period.
    pub control_periods: StepTimes,
}

impl Recorder {
    /// A recorder for the run `lp` is set up for, with every column reserved for the run.
    pub fn new(lp: &ClosedLoop) -> Self {
        let (file, v) = (lp.file, &lp.vehicle);
        let s = &file.scenario;
        let channels = channel_layout(s.mode, v.n_joints(), v.n_thrusters());
        let n_log = (s.duration / s.log_dt).floor() as usize + 2;
        let row = vec![0.0; channels.len()];
        Self {
            traj: Trajectory::with_channels(channels, n_log),
            row,
            log_every: (s.log_dt / s.control_dt).round() as usize,
            char_length: file.char_length(v),
            commanded: file.commanded(),
            residual_tol: file.metrics.residual_tolerance,
            power: file.power_model(v.fluid.rho),
            limits: v.thrusters.iter().map(|t| (t.u_min, t.u_max)).collect(),
            sat_tol: file.metrics.saturation_tolerance,
            thrust: vec![0.0; v.n_thrusters()],
            inflow: vec![0.0; v.n_thrusters()],
            counts: AllocationCounts::default(),
            energy: EnergyIntegrator::default(),
            timing: Timing::default(),
            allocation_steps: StepTimes::with_capacity(lp.n_control + 1),
            control_periods: StepTimes::with_capacity(lp.n_control + 1),
        }
    }

    /// Sample the thrusters at a control tick, after allocation (`lp.ws` holds the forward
    /// kinematics of the tick): the thrust the simulator will hold over the coming interval
    /// (the allocation saturated to the limits; a thruster lag or rate limit, if configured,
    /// is not followed) and each thruster's axial inflow. Also tracks the guided point along
    /// the path (transport) and counts the tick's allocation if it left a commanded residual
    /// ([`AllocationCounts::residual`]). The sample is for [`EnergyIntegrator::add`] once the
    /// interval has been simulated.
    pub fn sample(&mut self, lp: &ClosedLoop) -> PowerSample {
        if residual_exceeds(
            &lp.alloc.s,
            &lp.cmd.tau_c,
            self.char_length,
            self.commanded,
            self.residual_tol,
        ) {
            self.counts.residual += 1;
        }
        let (v, state) = (&lp.vehicle, lp.sim.state());
        for ((u, a), th) in self.thrust.iter_mut().zip(&lp.alloc.u).zip(&v.thrusters) {
            *u = a.clamp(th.u_min, th.u_max);
        }
        thruster_inflow(v, &lp.ws, state, &self.thrust, &mut self.inflow);
        if let ModeController::Transport { signals: s, .. } = &lp.mode {
            self.energy.track_path(s.segment, s.along_track);
        }
        self.energy.track_wrench(&lp.cmd.tau_c.into());
        let thrusters = ThrusterSample {
            thrust: &self.thrust,
            inflow: &self.inflow,
            limits: &self.limits,
        };
        PowerSample::new(&self.power, &thrusters, self.sat_tol)
    }

    /// Observe control period `k` at time `t` [s] after [`Recorder::sample`]: log a row every
    /// `log_dt`.
    pub fn observe(&mut self, k: usize, t: f64, lp: &ClosedLoop) {
        if k % self.log_every != 0 {
            return;
        }
        let (v, ws, state) = (&lp.vehicle, &lp.ws, lp.sim.state());
        let g_ib = state.pose.to_se3();
        let g_ie = g_ib.compose(&ws.g_be);
        let last = ws.g_b.len() - 1;
        let v_in_b = body_twist_in_base(ws, &state.base_twist, &state.joint_rates, last);
        let v_e = ws.g_be.twist_to_child(&v_in_b);
        let eb = euler_zyx(&g_ib.r);
        let ee = euler_zyx(&g_ie.r);
        let mut w = RowWriter {
            channels: self.traj.channels(),
            row: &mut self.row,
            next: 0,
        };
        w.put(Channel::T, t);
        let base_pose = [g_ib.p.x, g_ib.p.y, g_ib.p.z, eb.x, eb.y, eb.z];
        w.put_all(Pose::ALL.map(Channel::BasePose).into_iter().zip(base_pose));
        let base_twist = state.base_twist.iter().copied();
        w.put_all(
            Twist::ALL
                .map(Channel::BaseTwist)
                .into_iter()
                .zip(base_twist),
        );
        let ee_pose = [g_ie.p.x, g_ie.p.y, g_ie.p.z, ee.x, ee.y, ee.z];
        w.put_all(Pose::ALL.map(Channel::EePose).into_iter().zip(ee_pose));
        let (v_lin, v_ang) = (lin(&v_e), ang(&v_e));
        let ee_twist = v_lin.iter().chain(v_ang.iter()).copied();
        w.put_all(Twist::ALL.map(Channel::EeTwist).into_iter().zip(ee_twist));
        match &lp.mode {
            ModeController::Transport { signals: s, .. } => w.put_all([
                (Channel::Psi, s.psi),
                (Channel::PsiR, s.psi_r),
                (Channel::CrossTrack, s.cross_track),
                (Channel::AlongTrack, s.along_track),
                (Channel::Segment, s.segment),
                (Channel::HeadingError, s.heading_error),
                (Channel::SurgeError, s.surge_error),
                (Channel::BaseCrossTrack, s.base_cross_track),
                (Channel::PathY, s.path_y),
            ]),
            ModeController::Work { signals: s, .. } | ModeController::Track { signals: s, .. } => {
                w.put_all(Pose::ALL.map(Channel::Setpoint).into_iter().zip(s.setpoint));
                w.put(Channel::EePositionError, s.position_error);
                w.put(Channel::EeOrientationError, s.orientation_error);
                w.put(Channel::EeDamping, s.damping);
                let twist_ref = s.twist_ref.iter().copied();
                w.put_all(Twist::ALL.map(Channel::TwistRef).into_iter().zip(twist_ref));
            }
        }
        w.put_all(indexed(Channel::Q, &state.joint_angles));
        w.put_all(indexed(Channel::QRef, &lp.cmd.q_ref));
        w.put_all(indexed(Channel::Qd, &state.joint_rates));
        w.put_all(indexed(Channel::Tau, lp.sim.last_joint_torque()));
        w.put(Channel::JointWork, lp.sim.joint_work());
        w.put_all(indexed(Channel::UCmd, &lp.alloc.u));
        // Actual thrust: the thruster states clamped to their limits.
        let actual = state
            .thrust
            .iter()
            .zip(&v.thrusters)
            .map(|(x, th)| x.clamp(th.u_min, th.u_max));
        w.put_all(actual.enumerate().map(|(j, u)| (Channel::U(j), u)));
        let power = &self.power;
        let held = self.thrust.iter().zip(&self.inflow);
        w.put_all(
            held.clone()
                .enumerate()
                .map(|(j, (u, v_a))| (Channel::Power(j), power.shaft_power(*u, *v_a))),
        );
        w.put_all(
            held.enumerate()
                .map(|(j, (_, v_a))| (Channel::Inflow(j), *v_a)),
        );
        let g = ScaledGram::new(&lp.t_mat, self.char_length);
        let sigma = |dofs| commanded_sigma_with(&g, &lp.t_mat, dofs).sigma_min;
        w.put(Channel::SigmaMin, sigma(CommandedDofs::ALL));
        w.put(Channel::SigmaMinCommanded, sigma(self.commanded));
        w.put(Channel::SlackNorm, lp.alloc.s.norm());
        w.put(Channel::AllocStatus, status_code(&lp.alloc.status));
        self.traj.push_row(&self.row);
    }

    /// The log so far.
    pub fn trajectory(&self) -> &Trajectory {
        &self.traj
    }

    /// The trajectory, the allocation counts, the energy integrals and the timers, with the
    /// total wall time since `started`, the real-time factor and the per-step medians filled
    /// in.
    pub fn finish(
        mut self,
        started: Instant,
    ) -> (Trajectory, AllocationCounts, EnergyMetrics, Timing) {
        let timing = &mut self.timing;
        timing.total_s = started.elapsed().as_secs_f64();
        timing.allocation_step_median_us = self.allocation_steps.median_us();
        timing.control_period_median_us = self.control_periods.median_us();
        let simulated = self
            .traj
            .get(Channel::T)
            .and_then(|c| c.last().copied())
            .unwrap_or(0.0);
        timing.realtime_factor = if timing.total_s > 0.0 {
            simulated / timing.total_s
        } else {
            f64::INFINITY
        };
        (self.traj, self.counts, self.energy.metrics(), self.timing)
    }
}

#[cfg(test)]
mod tests {
    use super::thruster_inflow;
    use crate::dynamics::SimState;
    use crate::kinematics::KinWorkspace;
    use crate::model::presets::usm_paper;
    use crate::spatial::{Vec3, Vec6};
    use nalgebra::{UnitQuaternion, Vector3};

    /// The straight paper design (T2, T6 sway; T3, T4 surge; T1, T5, T7 heave) with the
    /// given base twist, yaw and current.
    fn inflow(twist: [f64; 6], yaw: f64, current: Vec3, thrust: [f64; 7]) -> [f64; 7] {
        let mut v = usm_paper();
        v.fluid.current = current;
        let ws = KinWorkspace::new(&v);
        let mut s = SimState::rest(&v);
        s.base_twist = Vec6::from_row_slice(&twist);
        s.pose.orientation = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw);
        let mut out = [0.0; 7];
        thruster_inflow(&v, &ws, &s, &thrust, &mut out);
        out
    }

    #[test]
    fn inflow_is_the_speed_through_water_along_the_thrust() {
        let push = [10.0; 7];
        // Surging at 0.5 m/s in still water: the surge thrusters pushing forward see 0.5 m/s,
        // pushing backward −0.5 m/s (clamped to 0 by the power model); the others nothing.
        let a = inflow([0.5, 0.0, 0.0, 0.0, 0.0, 0.0], 0.0, Vec3::zeros(), push);
        let expect = [0.0, 0.0, 0.5, 0.5, 0.0, 0.0, 0.0];
        for (x, e) in a.iter().zip(expect) {
            assert!((x - e).abs() < 1e-12, "{a:?}");
        }
        let back = [-10.0; 7];
        let b = inflow([0.5, 0.0, 0.0, 0.0, 0.0, 0.0], 0.0, Vec3::zeros(), back);
        assert!((b[2] + 0.5).abs() < 1e-12 && (b[3] + 0.5).abs() < 1e-12);
        // Heading along inertial +y at 0.5 m/s, carried by a 0.5 m/s current along +y: at
        // rest relative to the water.
        let c = inflow(
            [0.5, 0.0, 0.0, 0.0, 0.0, 0.0],
            std::f64::consts::FRAC_PI_2,
            Vec3::new(0.0, 0.5, 0.0),
            push,
        );
        assert!(c.iter().all(|x| x.abs() < 1e-12), "{c:?}");
    }

    #[test]
    fn inflow_of_a_yawing_body_grows_with_the_lever_arm() {
        // Yaw rate r about the base origin (the tail face): a thruster at (x_b, y_b) moves at
        // (−r·y_b, r·x_b, 0), so a sway thruster sees r·x_b, a surge thruster −r·y_b (the
        // off-axis pair T3/T4 at y_b = ∓0.1 m: ±0.02 m/s), a heave thruster nothing.
        let r = 0.2;
        let a = inflow([0.0, 0.0, 0.0, 0.0, 0.0, r], 0.0, Vec3::zeros(), [10.0; 7]);
        let v = usm_paper();
        let ws = KinWorkspace::new(&v);
        for (j, th) in v.thrusters.iter().enumerate() {
            let p = ws.g_b[th.body].act_point(&th.position);
            let expect = th.direction.x * (-r * p.y) + th.direction.y * (r * p.x);
            assert!((a[j] - expect).abs() < 1e-12, "{j}: {a:?}");
        }
        assert!(a[5] > a[1] && a[1] > 0.0);
    }
}
