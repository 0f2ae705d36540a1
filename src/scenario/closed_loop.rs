//! The closed loop of the USM paper's Fig. 5: guidance → kinematic control → dynamic control
//! (USM-33) → thrust allocation (USM-36/37) → vehicle (docs/model.md §4), observed by a recorder.
//!
//! Rates: the physics advances with the `[physics] integrator` (RK4 steps of `dt`, or
//! adaptive Dormand–Prince steps) over each control period; the controllers and the allocator run
//! every `control_dt` with the actuator commands held in between (zero-order hold); the
//! recorder samples the thrusters at every control tick for the energy integrals (the
//! simulator integrates the joint work), and logs every `log_dt`. Each control period is a fixed sequence
//! of named phases (`measure`, `control`, `allocate`, the recorder's `sample` and `observe`,
//! `advance`), timed by phase; nothing allocates inside the loop.

use super::channels::Trajectory;
use super::config::ScenarioFile;
use super::controller::Measurement;
use super::criteria::Criterion;
use super::error::ScenarioError;
use super::recorder::{timed, AllocationCounts, Recorder, Timing};
use super::setup::ClosedLoop;
use super::watch::FailureWatch;
use crate::dynamics::ActuatorCommand;
use crate::kinematics::{forward_kinematics, thruster_matrix, BasePose};
use crate::metrics::singularity::{commanded_sigma_with, CommandedDofs, ScaledGram};
use crate::metrics::trajectory::EnergyMetrics;
use crate::model::Vehicle;
use crate::spatial::Vec6;
use nalgebra::Matrix6;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// One closed-loop run before its metrics: the trajectory up to the end (or the failure), the
/// allocation counts, the energy integrals and the timings. [`crate::outcome`] turns it into a
/// run's summary metrics and success.
#[derive(Clone, Debug)]
pub struct LoopRun {
    /// Logged time series.
    pub trajectory: Trajectory,
    /// Why the run stopped early, if it did: (simulation time [s], cause).
    pub failure: Option<(f64, String)>,
    /// With `[success] stop_on_failure`: the run was ended at this time [s] (the end of the
    /// last control period it ran) because this criterion was certain to be missed
    /// (`super::watch`); `None` when it ran to its end or failed.
    pub stopped: Option<(f64, Criterion)>,
    /// Allocation outcomes.
    pub allocation_counts: AllocationCounts,
    /// Energy integrals (thrusters at the control rate, joints from the simulator).
    pub energy: EnergyMetrics,
    /// Wall-clock breakdown.
    pub timing: Timing,
    /// With a `[fault]`: the simulation time it struck [s] (NaN if the run ended before);
    /// `None` without one.
    pub fault_time: Option<f64>,
}

/// Why a control period ended the run: (simulation time [s], cause).
type Failure = (f64, String);

/// The state a control period measures, copied out of the simulator so the dynamics can be
/// evaluated next: base pose and twist (base frame).
struct Measured {
    base: BasePose,
    v_b: Vec6,
}

impl ClosedLoop<'_> {
    /// Measure: forward kinematics of the current joint angles, the base pose, twist and the
    /// joint rates; the divergence guard.
    fn measure(&mut self, t: f64) -> Result<Measured, Failure> {
        let state = self.sim.state();
        let base = state.pose;
        forward_kinematics(&self.vehicle, &state.joint_angles, &mut self.ws);
        let v_b = state.base_twist;
        self.qd_meas.copy_from_slice(&state.joint_rates);
        let dist = base.position.norm();
        if dist.is_nan() || dist > self.file.metrics.divergence_distance {
            return Err((
                t,
                format!(
                    "diverged: base position |p| = {dist:.3e} m exceeds metrics.divergence_distance"
                ),
            ));
        }
        Ok(Measured { base, v_b })
    }

    /// Control: T(q) for the allocator (and, with the transport autopilot, whether it can
    /// command roll: σ_min of all six rows of the scaled T(q) at or above `[metrics]
    /// threshold`, docs/model.md §5 "Autopilot"), then the mode's law and the base's dynamic
    /// control (USM-33) from the measurement and the base-control terms (M11, n).
    fn control(&mut self, t: f64, measured: &Measured, terms: &(Matrix6<f64>, Vec6)) {
        thruster_matrix(&self.vehicle, &self.ws, &mut self.t_mat);
        let roll_authority = self.mode.wants_roll_authority() && {
            let g = ScaledGram::new(&self.t_mat, self.file.char_length(&self.vehicle));
            let s = commanded_sigma_with(&g, &self.t_mat, CommandedDofs::ALL).sigma_min;
            s >= self.file.metrics.threshold
        };
        let meas = Measurement {
            base: &measured.base,
            v_b: &measured.v_b,
            ws: &self.ws,
            qd: &self.qd_meas,
            m11: &terms.0,
            nvec: &terms.1,
            roll_authority,
        };
        let dt = self.file.scenario.control_dt;
        self.mode
            .step(t, dt, &meas, &mut self.base_ctl, &mut self.cmd);
    }

    /// Allocate: thrusts for τ_c (USM-36/37). With a `[fault]` that has struck, the informed
    /// allocator sees the reconfigured T(q) and τ, and the thrusts become the ones the
    /// thrusters produce, with the slack `s = T u − τ_c` of those (`scenario::fault`).
    fn allocate(&mut self, t: f64) -> Result<(), Failure> {
        let tau_c = self.cmd.tau_c;
        if let Some(f) = self.fault.as_mut() {
            f.update(t, self.alloc.u[f.thruster()]);
        }
        let result = match self.fault.as_mut() {
            Some(f) if f.reconfigures() => {
                let (t_alloc, tau) = f.reconfigured(&self.t_mat, &tau_c);
                self.allocator.allocate_into(t_alloc, &tau, &mut self.alloc)
            }
            _ => (self.allocator).allocate_into(&self.t_mat, &tau_c, &mut self.alloc),
        };
        result.map_err(|e| (t, format!("allocation: {e}")))?;
        if let Some(f) = self.fault.as_ref().filter(|f| f.struck_at.is_some()) {
            f.produce(&mut self.alloc.u);
            self.alloc.s = -tau_c;
            for (col, u) in self.t_mat.column_iter().zip(&self.alloc.u) {
                self.alloc.s += col * *u;
            }
        }
        Ok(())
    }

    /// Advance the physics over one control period with the commands held; the recorder sees
    /// each physics step (joint power).
    fn advance(&mut self) -> Result<(), Failure> {
        let cmd = ActuatorCommand {
            thrust: &self.alloc.u,
            joint_ref: &self.cmd.q_ref,
            joint_rate_ref: &self.cmd.qd_ref,
        };
        self.sim
            .advance(self.file.scenario.control_dt, &cmd)
            .map_err(|e| (e.time, e.to_string()))
    }

    /// Control period `k`: measure, control, allocate, sample the thrusters and record, then
    /// advance the physics (except after the last period) and integrate the thruster sample
    /// over the period just simulated (docs/model.md §6 energy: rectangle rule on the zero-order hold,
    /// at the control rate; the joint work is integrated by the simulator with the motion; the
    /// thrusters of a period that fails are not counted).
    fn period(&mut self, k: usize, rec: &mut Recorder) -> Result<(), Failure> {
        let t = k as f64 * self.file.scenario.control_dt;
        let measured = timed!(rec.timing.control_s, self.measure(t))?;
        let mut terms = timed!(rec.timing.dynamics_s, self.sim.base_control_terms())
            .map_err(|e| (t, e.to_string()))?;
        if let Some(nominal) = self.nominal.as_mut() {
            terms = timed!(rec.timing.dynamics_s, nominal.terms(self.sim.state()));
        }
        timed!(rec.timing.control_s, self.control(t, &measured, &terms));
        timed!(
            rec.timing.allocation_s,
            rec.allocation_steps,
            self.allocate(t)
        )?;
        rec.counts.count(&self.alloc);
        let sample = timed!(rec.timing.logging_s, rec.sample(self));
        timed!(rec.timing.logging_s, rec.observe(k, t, self));
        if k == self.n_control {
            rec.energy.add(&sample, 0.0);
            return Ok(());
        }
        timed!(rec.timing.dynamics_s, self.advance())?;
        rec.energy.add(&sample, self.file.scenario.control_dt);
        Ok(())
    }
}

/// The failure cause of a run stopped by its wall-clock deadline ([`run_loop`]).
pub const TIMEOUT: &str = "timeout";

/// The failure cause of a run stopped by its interrupt flag ([`Stop::on_flag`]; `simulate`
/// on Ctrl-C).
pub const INTERRUPTED: &str = "interrupted";

/// When a closed-loop run must stop early: at a wall-clock instant, when a flag is raised
/// (an interrupt), or never. [`run_loop`] checks it cooperatively before every control period;
/// a run still going when it is [`due`](Stop::due) stops there with the failure cause
/// [`TIMEOUT`] (or [`INTERRUPTED`]) and keeps its trajectory up to then. A case's
/// `crate::evaluate::Deadline` hands one out (`Deadline::stop`), so that the loop does not
/// depend on the evaluator that budgets it.
#[derive(Clone, Copy, Debug, Default)]
pub struct Stop {
    at: Option<Instant>,
    flag: Option<&'static AtomicBool>,
}

impl PartialEq for Stop {
    fn eq(&self, other: &Stop) -> bool {
        self.at == other.at
            && match (self.flag, other.flag) {
                (None, None) => true,
                (Some(a), Some(b)) => std::ptr::eq(a, b),
                _ => false,
            }
    }
}

impl Eq for Stop {}

impl Stop {
    /// Never stop early: the run goes to the end of the scenario (or its failure).
    pub const NEVER: Stop = Stop {
        at: None,
        flag: None,
    };

    /// Stop at `instant`.
    pub fn at(instant: Instant) -> Stop {
        Stop {
            at: Some(instant),
            flag: None,
        }
    }

    /// This stop, and also as soon as `flag` is set (e.g. by a SIGINT handler).
    pub fn on_flag(self, flag: &'static AtomicBool) -> Stop {
        Stop {
            flag: Some(flag),
            ..self
        }
    }

    /// Why the run must stop now, if it must: [`INTERRUPTED`] when the flag is set, else
    /// [`TIMEOUT`] when the stop time has passed.
    pub fn cause(self) -> Option<&'static str> {
        if self.flag.is_some_and(|f| f.load(Ordering::Relaxed)) {
            Some(INTERRUPTED)
        } else if self.at.is_some_and(|d| Instant::now() >= d) {
            Some(TIMEOUT)
        } else {
            None
        }
    }

    /// Whether the run must stop now (never for [`Stop::NEVER`]).
    pub fn due(self) -> bool {
        self.cause().is_some()
    }
}

/// Run the closed loop of a scenario on a vehicle. Never panics on bad input: settings
/// problems return a [`ScenarioError`] before anything runs; a run that fails (diverges,
/// NaN, singular mass matrix) returns `Ok` with `failure` set and the trajectory up to then.
///
/// The [`Stop`] is checked cooperatively before every control period: a run still going when
/// it is due stops there with the failure cause [`TIMEOUT`] or [`INTERRUPTED`] (the trajectory
/// up to then is kept, as for any failure). A control period is bounded in work: at most
/// `MAX_SUBSTEPS` (1e5) RK4 steps (`scenario.control_dt / dt`, checked by validation) or
/// `MAX_STEPS_PER_SPAN` (1e5) Dormand–Prince trials.
pub fn run_loop(v: &Vehicle, file: &ScenarioFile, stop: Stop) -> Result<LoopRun, ScenarioError> {
    let started = Instant::now();
    let mut lp = ClosedLoop::new(v, file)?;
    let mut rec = Recorder::new(&lp);
    let mut watch = FailureWatch::new(v, &lp.vehicle, file, lp.n_control);
    let dt = file.scenario.control_dt;
    let (mut failure, mut stopped) = (None, None);
    for k in 0..=lp.n_control {
        if let Some(cause) = stop.cause() {
            failure = Some((k as f64 * dt, cause.to_string()));
            break;
        }
        let period_started = Instant::now();
        let result = lp.period(k, &mut rec);
        rec.control_periods
            .push(period_started.elapsed().as_secs_f64());
        if let Err(f) = result {
            failure = Some(f);
            break;
        }
        if k < lp.n_control {
            if let Some(c) = watch.check(rec.trajectory(), &rec.energy) {
                stopped = Some(((k + 1) as f64 * dt, c));
                break;
            }
        }
    }
    let stats = lp.sim.step_stats();
    rec.timing.physics_steps = stats.steps;
    rec.timing.physics_rejected = stats.rejected;
    rec.timing.physics_evaluations = stats.evaluations;
    rec.energy
        .set_joints(lp.sim.joint_work(), lp.sim.joint_torque_peak());
    let fault_time = (lp.fault.as_ref()).map(|f| f.struck_at.unwrap_or(f64::NAN));
    let (trajectory, allocation_counts, energy, timing) = rec.finish(started);
    Ok(LoopRun {
        trajectory,
        failure,
        stopped,
        allocation_counts,
        energy,
        timing,
        fault_time,
    })
}
