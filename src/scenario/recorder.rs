//! The recorder of a closed-loop run, an observer outside the step: it owns the trajectory
//! (one column per [`Channel`] of [`channel_layout`]), the allocation outcome counts and the
//! wall-clock timers. It samples the loop every `log_dt` (the state at t with the commands
//! decided at t) into a row sized once, so recording never allocates.

use super::channels::{channel_layout, Channel, Pose, Trajectory, Twist};
use super::controller::ModeController;
use super::setup::ClosedLoop;
use crate::allocation::AllocStatus;
use crate::metrics::singularity::sigma_min_scaled_gram;
use crate::metrics::trajectory::PowerModel;
use crate::spatial::{ang, euler_zyx, lin};
use serde::Serialize;
use std::time::Instant;

/// Add the wall time of an expression to a timer [s] and yield its value.
macro_rules! timed {
    ($timer:expr, $body:expr) => {{
        let started = std::time::Instant::now();
        let value = $body;
        $timer += started.elapsed().as_secs_f64();
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
    /// Time logging (including σ_min of T(q)) [s].
    pub logging_s: f64,
    /// Real-time factor: simulated seconds per wall second.
    pub realtime_factor: f64,
}

/// How the allocations of a run went, counted over control periods.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct AllocationCounts {
    /// Allocations made (one per control period reached).
    pub steps: u64,
    /// Allocations whose wrench slack was active (the demand was not met exactly).
    pub slack_active: u64,
    /// Allocations the solver did not solve (neither solved, slack-active nor bounds-violated).
    pub solver_failures: u64,
}

impl AllocationCounts {
    /// Count one allocation outcome.
    pub fn count(&mut self, status: &AllocStatus) {
        self.steps += 1;
        match status {
            AllocStatus::SlackActive { .. } => self.slack_active += 1,
            AllocStatus::Solved | AllocStatus::BoundsViolated { .. } => {}
            _ => self.solver_failures += 1,
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
    power: PowerModel,
    /// Allocation outcomes so far.
    pub counts: AllocationCounts,
    /// Wall-clock timers.
    pub timing: Timing,
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
            char_length: if file.metrics.char_length > 0.0 {
                file.metrics.char_length
            } else {
                v.characteristic_length()
            },
            power: file.power_model(v.fluid.rho),
            counts: AllocationCounts::default(),
            timing: Timing::default(),
        }
    }

    /// Observe control period `k` at time `t` [s]: log a row every `log_dt`.
    pub fn observe(&mut self, k: usize, t: f64, lp: &ClosedLoop) {
        if k % self.log_every != 0 {
            return;
        }
        let (v, ws, state) = (&lp.vehicle, &lp.ws, lp.sim.state());
        let g_ib = state.pose.to_se3();
        let g_ie = g_ib.compose(&ws.g_be);
        let mut v_in_b = state.base_twist;
        for (x, r) in ws.joint_twist_b.iter().zip(&state.joint_rates) {
            v_in_b += x * *r;
        }
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
            ModeController::Work { signals: s, .. } => {
                w.put_all(Pose::ALL.map(Channel::Setpoint).into_iter().zip(s.setpoint));
                w.put(Channel::EePositionError, s.position_error);
                w.put(Channel::EeOrientationError, s.orientation_error);
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
        w.put_all(actual.clone().enumerate().map(|(j, u)| (Channel::U(j), u)));
        let power = &self.power;
        w.put_all(
            actual
                .enumerate()
                .map(|(j, u)| (Channel::Power(j), power.power(u))),
        );
        w.put(
            Channel::SigmaMin,
            sigma_min_scaled_gram(&lp.t_mat, self.char_length),
        );
        w.put(Channel::SlackNorm, lp.alloc.s.norm());
        w.put(Channel::AllocStatus, status_code(&lp.alloc.status));
        self.traj.push_row(&self.row);
    }

    /// The trajectory, the allocation counts and the timers, with the total wall time since
    /// `started` and the real-time factor filled in.
    pub fn finish(mut self, started: Instant) -> (Trajectory, AllocationCounts, Timing) {
        let timing = &mut self.timing;
        timing.total_s = started.elapsed().as_secs_f64();
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
        (self.traj, self.counts, self.timing)
    }
}
