//! The summary metrics of one closed-loop run (docs/model.md §6): pure functions of its trajectory,
//! looked up by [`Channel`], and of the effort and energy integrals the loop accumulated
//! (at the control and physics rates, not from the log), in a fixed order for the mode — the common effort, energy,
//! singularity and allocation metrics, then the transport tracking or the work regulation
//! metrics; [`add_success`] appends the verdict on the scenario's success criteria.

use super::judge::{judge, success_margin};
use crate::metrics::trajectory::{
    integrate, segment_tracking, settling_time, singularity_exposure, EnergyMetrics,
};
use crate::scenario::channels::{Channel, Pose, Trajectory};
use crate::scenario::config::{MetricsSpec, Mode, ModeGains, ScenarioFile};
use crate::scenario::criteria::Missed;
use crate::scenario::recorder::AllocationCounts;
use crate::spatial::wrap_angle;

/// A run's metrics as (name, value) pairs in order, before the evaluator files them into its one
/// `crate::evaluate::Metrics` row (named apart from it: this is not the row type).
type RunValues = Vec<(String, f64)>;

/// The metrics of every mode, in the order [`run_summary`] adds them (documented at
/// [`common_metrics`]). Each name list below is the one declaration of its metrics: the code
/// that computes them adds values in this order, and [`metric_catalogue`] lists them so that
/// callers (the optimiser) can check names before anything runs.
pub const COMMON_METRICS: [&str; 28] = [
    "completed",
    "simulated_time",
    "stopped_at",
    "thruster_energy",
    "thruster_energy_static",
    "effort_sq",
    "effort_abs",
    "joint_energy",
    "joint_torque_peak",
    "peak_thrust",
    "saturation_fraction",
    "singularity_exposure",
    "singularity_exposure_full",
    "sigma_min_min",
    "sigma_min_mean",
    "sigma_min_commanded_min",
    "sigma_min_commanded_mean",
    "slack_fraction",
    "allocation_failures",
    "allocation_residual_fraction",
    "total_energy",
    "reach",
    "wrench_peak_surge",
    "wrench_peak_sway",
    "wrench_peak_heave",
    "wrench_peak_roll",
    "wrench_peak_pitch",
    "wrench_peak_yaw",
];

/// Per-segment transport metrics, each named `seg{k}_{name}` for segment `k` (0-based).
pub const SEGMENT_METRICS: [&str; 3] = ["convergence_time", "overshoot", "cross_track_rms"];

/// Transport metrics over the whole run (after the per-segment ones).
pub const TRANSPORT_METRICS: [&str; 16] = [
    "segments_reached",
    "converged",
    "convergence_time",
    "overshoot",
    "cross_track_rms",
    "base_cross_track_rms",
    "final_cross_track",
    "path_progress",
    "energy_per_metre",
    "total_energy_per_metre",
    "cross_track_iae",
    "mission_cost",
    "max_abs_roll_deg",
    "max_abs_pitch_deg",
    "max_vertical_error",
    "roll_commanded_fraction",
];

/// Work-mode regulation metrics (then [`ROLL_METRICS`]).
pub const WORK_METRICS: [&str; 7] = [
    "final_position_error",
    "final_orientation_error_deg",
    "settling_time_position",
    "settling_time_orientation",
    "base_drift",
    "ee_damped_fraction",
    "ee_damping_max",
];

/// The last metric of every run: 1 when it met its `[success]` criteria, else 0 (see
/// [`add_success`]).
pub const SUCCESS_METRIC: &str = "success";

/// Work-mode end-effector roll metrics (see [`roll_metrics`]).
pub const ROLL_METRICS: [&str; 3] = [
    "ee_roll_max_deg",
    "ee_roll_max_settled_deg",
    "ee_roll_std_deg",
];

/// Every metric name a run of `mode` reports, in order, with the per-segment transport
/// metrics written as `seg{k}_…` patterns (see [`is_run_metric`]).
pub fn metric_catalogue(mode: Mode) -> Vec<String> {
    let mut names: Vec<String> = COMMON_METRICS.iter().map(|s| s.to_string()).collect();
    match mode {
        Mode::Transport => {
            names.extend(SEGMENT_METRICS.iter().map(|s| format!("seg{{k}}_{s}")));
            names.extend(TRANSPORT_METRICS.iter().map(|s| s.to_string()));
        }
        Mode::Work => {
            names.extend(
                WORK_METRICS
                    .iter()
                    .chain(&ROLL_METRICS)
                    .map(|s| s.to_string()),
            );
        }
    }
    names.push(SUCCESS_MARGIN.to_string());
    names.push(SUCCESS_METRIC.to_string());
    names
}

/// Whether `name` is a metric a run of `mode` reports: a catalogue name, or for transport
/// `seg{k}_{name}` with `k` a segment index.
pub fn is_run_metric(mode: Mode, name: &str) -> bool {
    if COMMON_METRICS.contains(&name) || name == SUCCESS_METRIC || name == SUCCESS_MARGIN {
        return true;
    }
    match mode {
        Mode::Transport => {
            TRANSPORT_METRICS.contains(&name)
                || name
                    .strip_prefix("seg")
                    .and_then(|r| r.split_once('_'))
                    .is_some_and(|(k, m)| {
                        !k.is_empty()
                            && k.bytes().all(|b| b.is_ascii_digit())
                            && SEGMENT_METRICS.contains(&m)
                    })
        }
        Mode::Work => WORK_METRICS.contains(&name) || ROLL_METRICS.contains(&name),
    }
}

/// Append `values` under the declared `names` (same length by construction).
fn add_all<const N: usize>(out: &mut RunValues, names: &[&str; N], values: [f64; N]) {
    out.extend(names.iter().zip(values).map(|(n, x)| (n.to_string(), x)));
}

/// A channel's samples, empty if the run did not log it.
fn channel(traj: &Trajectory, c: Channel) -> &[f64] {
    traj.get(c).unwrap_or(&[])
}

/// What a run's summary needs besides its trajectory and integrals.
#[derive(Clone, Copy, Debug)]
pub struct RunFacts {
    /// Whether the run stopped early.
    pub failed: bool,
    /// The time a run stopped on a certain `[success]` miss was ended at [s]
    /// (`scenario::LoopRun::stopped`; metric `stopped_at`); NaN when it was not.
    pub stopped_at: f64,
    /// The design's reach [m] (`kinematics::straight_reach`, metric `reach`).
    pub reach: f64,
}

/// The metrics of a run of `file` from its trajectory: the common ones, then the
/// mode's. `run` says whether the run stopped early and gives the design's reach; `counts` are its allocation outcomes;
/// `energy` its effort and energy integrals, accumulated at every control step (not from
/// the log).
pub fn run_summary(
    file: &ScenarioFile,
    run: RunFacts,
    traj: &Trajectory,
    counts: &AllocationCounts,
    energy: &EnergyMetrics,
) -> Vec<(String, f64)> {
    let mut out = RunValues::new();
    common_metrics(&mut out, file, run, traj, counts, energy);
    match file.scenario.mode {
        Mode::Transport => transport_metrics(&mut out, file, traj, energy),
        Mode::Work => work_metrics(&mut out, &file.metrics, traj),
    }
    out
}

/// The run's signed, normalised distance to its success bounds ([`success_margin`]).
pub const SUCCESS_MARGIN: &str = "success_margin";

/// Judge the run by its `metrics` against `file`'s `[success]` criteria
/// ([`super::judge::judge`]) and append `success_margin` and `success` (1 = every criterion
/// met, 0 = not); returns the first criterion missed.
pub fn add_success(metrics: &mut Vec<(String, f64)>, file: &ScenarioFile) -> Option<Missed> {
    let margin = success_margin(&file.success, &file.mission, file.scenario.mode, metrics);
    metrics.push((SUCCESS_MARGIN.to_string(), margin));
    let missed = judge(&file.success, &file.mission, file.scenario.mode, metrics);
    let met = if missed.is_none() { 1.0 } else { 0.0 };
    metrics.push((SUCCESS_METRIC.to_string(), met));
    missed
}

/// Completion, energy and effort (docs/model.md §6, integrated along the run, not from the log: see
/// [`EnergyMetrics`]), σ_min of T(q) and allocation outcomes:
/// - `thruster_energy` [J]: thruster shaft energy by actuator-disk momentum theory with each
///   thruster's axial inflow; `thruster_energy_static` [J] the same thrusts at zero inflow
///   (the figure before inflow was modelled);
/// - `effort_sq` [N²·s] `∫‖u‖²dt`, `effort_abs` [N·s] `∫Σ|u_j|dt`, of the thrust held over
///   each control interval (rectangle rule on the zero-order hold, at the control rate);
/// - `joint_energy` [J] `∫Σ|τ_q,i q̇_i|dt` from the simulator's joint motor torques and the
///   joint rates at the start of every physics step; `joint_torque_peak` [N·m] the largest
///   |τ_q,i| among them;
/// - `stopped_at` [s]: with `[success] stop_on_failure`, the time the run was ended at because
///   the criterion its verdict names was already certain to be missed (NaN for a run that
///   went to its end or failed; `completed` stays 1: nothing failed numerically);
/// - `peak_thrust` [N] at a control tick, `saturation_fraction` of the control intervals;
/// - `singularity_exposure`, the fraction of time σ_min of the commanded rows `S·T_L` is below
///   `[metrics] threshold` (the controller's commanded axes, docs/model.md §6), and
///   `singularity_exposure_full` the same for all six rows (a straight USM has lost roll, which
///   neither of the paper's modes commands, so the full figure measures straightness);
///   `sigma_min_min`/`_mean` (all rows) and `sigma_min_commanded_min`/`_mean` over the log;
/// - `slack_fraction` of allocations whose slack was active, `allocation_failures`, and
///   `allocation_residual_fraction`, the fraction of control steps whose allocation left the
///   commanded wrench undelivered beyond `[metrics] residual_tolerance`;
/// - `total_energy` [J]: `thruster_energy + joint_energy / η_j`, the thruster shaft energy plus
///   the joint drives' electrical energy (`[metrics] joint_efficiency` η_j);
/// - `reach` [m]: the design's distance from the base frame's origin to the end effector at
///   `q = 0` (a `[mission] reach` requirement is judged on it);
/// - `wrench_peak_<axis>` [N or N·m]: the largest `|τ_c|` the base controller commanded
///   along each base axis at a control tick (base frame, USM-33): the required wrench of
///   `authority_margin`.
fn common_metrics(
    out: &mut RunValues,
    file: &ScenarioFile,
    run: RunFacts,
    traj: &Trajectory,
    counts: &AllocationCounts,
    e: &EnergyMetrics,
) {
    let t = channel(traj, Channel::T);
    let threshold = file.metrics.threshold;
    let full = channel(traj, Channel::SigmaMin);
    let cmd = channel(traj, Channel::SigmaMinCommanded);
    let min = |x: &[f64]| x.iter().copied().fold(f64::INFINITY, f64::min);
    let mean = |x: &[f64]| {
        if x.is_empty() {
            f64::NAN
        } else {
            x.iter().sum::<f64>() / x.len() as f64
        }
    };
    let steps = counts.steps.max(1) as f64;
    let values = [
        if run.failed { 0.0 } else { 1.0 },
        t.last().copied().unwrap_or(0.0),
        run.stopped_at,
        e.thruster_energy,
        e.thruster_energy_static,
        e.effort_sq,
        e.effort_abs,
        e.joint_energy,
        e.joint_torque_peak,
        e.peak_thrust,
        e.saturation_fraction,
        singularity_exposure(t, cmd, threshold),
        singularity_exposure(t, full, threshold),
        min(full),
        mean(full),
        min(cmd),
        mean(cmd),
        counts.slack_active as f64 / steps,
        counts.solver_failures as f64,
        counts.residual as f64 / steps,
        total_energy(e, &file.metrics),
        run.reach,
        e.wrench_peak[0],
        e.wrench_peak[1],
        e.wrench_peak[2],
        e.wrench_peak[3],
        e.wrench_peak[4],
        e.wrench_peak[5],
    ];
    add_all(out, &COMMON_METRICS, values);
}

/// `thruster_energy + joint_energy / η_j` [J] (docs/model.md §6 "Missions").
fn total_energy(e: &EnergyMetrics, spec: &MetricsSpec) -> f64 {
    e.thruster_energy + e.joint_energy / spec.joint_efficiency
}

/// `energy / progress`, NaN without progress (as `EnergyMetrics::energy_per_metre`).
fn per_metre(energy: f64, progress: f64) -> f64 {
    if progress > 0.0 {
        energy / progress
    } else {
        f64::NAN
    }
}

/// `∫|e_y| dt` [m·s] over the logged run (trapezoid rule): the tracking term of a transport
/// mission, so that arriving late on the path is not free.
fn integral_abs(t: &[f64], y: &[f64]) -> f64 {
    let abs: Vec<f64> = y.iter().map(|x| x.abs()).collect();
    integrate(t, &abs)
}

/// Index ranges `[a, b)` of the contiguous runs of equal values in `seg` (the samples during
/// which one path segment was active).
fn segment_runs(seg: &[f64]) -> Vec<(usize, usize)> {
    let mut runs = Vec::new();
    let mut a = 0;
    for i in 1..=seg.len() {
        if i == seg.len() || seg[i] != seg[a] {
            runs.push((a, i));
            a = i;
        }
    }
    runs
}

/// Transport: convergence, overshoot and cross-track RMS per segment (after convergence)
/// and over the run, the base's cross-track RMS, the final cross-track error; the distance
/// the end-effector covered along the path (`path_progress` [m], at the control rate) and
/// the thruster shaft energy per metre of it (`energy_per_metre` [J/m]); `total_energy` per
/// metre (`total_energy_per_metre` [J/m], thrusters and joint drives) and the integrated
/// absolute cross-track error `cross_track_iae` [m·s] over the whole run; the mission's
/// score `mission_cost = total_energy_per_metre + w · cross_track_iae` [J/m] (`w` =
/// `[mission] tracking_weight`, J/m per m·s); the attitude and depth of the run
/// ([`attitude_metrics`]).
fn transport_metrics(
    out: &mut RunValues,
    file: &ScenarioFile,
    traj: &Trajectory,
    energy: &EnergyMetrics,
) {
    let spec = &file.metrics;
    let t = channel(traj, Channel::T);
    let ey = channel(traj, Channel::CrossTrack);
    let base_ct = channel(traj, Channel::BaseCrossTrack);
    let runs = segment_runs(channel(traj, Channel::Segment));
    let mut conv_max: f64 = 0.0;
    let mut overshoot_max: f64 = 0.0;
    let mut rms_sq = 0.0;
    let mut rms_t = 0.0;
    let mut base_sq = 0.0;
    let mut all_converged = !runs.is_empty();
    for (k, &(a, b)) in runs.iter().enumerate() {
        let st = segment_tracking(&t[a..b], &ey[a..b], spec.band);
        let values = [st.convergence_time, st.overshoot, st.rms_after];
        out.extend(
            SEGMENT_METRICS
                .iter()
                .zip(values)
                .map(|(n, x)| (format!("seg{k}_{n}"), x)),
        );
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
    let rms = |sq: f64| {
        if rms_t > 0.0 {
            (sq / rms_t).sqrt()
        } else {
            f64::NAN
        }
    };
    let total_per_metre = per_metre(total_energy(energy, spec), energy.path_progress);
    let iae = integral_abs(t, ey);
    let values = [
        runs.len() as f64,
        if all_converged { 1.0 } else { 0.0 },
        if all_converged { conv_max } else { f64::NAN },
        overshoot_max,
        rms(rms_sq),
        rms(base_sq),
        ey.last().copied().unwrap_or(f64::NAN),
        energy.path_progress,
        energy.energy_per_metre(),
        total_per_metre,
        iae,
        total_per_metre + file.mission.tracking_weight * iae,
    ];
    let [roll, pitch, vertical] = attitude_metrics(traj);
    let mut all = [0.0; 16];
    all[..12].copy_from_slice(&values);
    all[12..].copy_from_slice(&[roll, pitch, vertical, roll_commanded_fraction(file, traj)]);
    add_all(out, &TRANSPORT_METRICS, all);
}

/// `roll_commanded_fraction`: the fraction of the logged control periods in which the
/// transport autopilot commanded roll (docs/model.md §5 "Autopilot": σ_min of all six rows
/// of the scaled T(q), the logged `sigma_min`, at or above `[metrics] threshold`); 0 without
/// the autopilot (`control.autopilot = false`, the paper's laws), NaN without a log.
fn roll_commanded_fraction(file: &ScenarioFile, traj: &Trajectory) -> f64 {
    let on = matches!(file.mode_gains(), Ok(ModeGains::Transport(g)) if g.autopilot);
    let sigma = channel(traj, Channel::SigmaMin);
    if sigma.is_empty() {
        return f64::NAN;
    }
    if !on {
        return 0.0;
    }
    let threshold = file.metrics.threshold;
    sigma.iter().filter(|s| **s >= threshold).count() as f64 / sigma.len() as f64
}

/// Transport attitude and depth over the whole logged run (the `[success]` bounds
/// `max_roll_deg`, `max_pitch_deg`, `max_vertical_error` judge them):
/// - `max_abs_roll_deg`, `max_abs_pitch_deg` [deg]: the largest |roll| and |pitch| of the base
///   frame (its ZYX Euler angles in `I`, roll wrapped into (−180°, 180°]) — the deviation from
///   transport's level reference (a horizontal path, every pitch-joint reference 0);
/// - `max_vertical_error` [m]: the largest `|z − z(0)|` of the base origin and of the end
///   effector (the "front" of the cross-track error): the depth deviation from the path, which
///   lies at the depth the vehicle starts at.
///
/// NaN when the run logged no sample.
fn attitude_metrics(traj: &Trajectory) -> [f64; 3] {
    let peak = |c: Channel| {
        let x = channel(traj, c);
        if x.is_empty() {
            return f64::NAN;
        }
        x.iter().fold(0.0f64, |m, a| m.max(wrap_angle(*a).abs()))
    };
    let depth = |c: Channel| {
        let z = channel(traj, c);
        match z.first() {
            None => f64::NAN,
            Some(z0) => z.iter().fold(0.0f64, |m, z| m.max((z - z0).abs())),
        }
    };
    [
        peak(Channel::BasePose(Pose::Roll)).to_degrees(),
        peak(Channel::BasePose(Pose::Pitch)).to_degrees(),
        depth(Channel::BasePose(Pose::Z)).max(depth(Channel::EePose(Pose::Z))),
    ]
}

/// Work: final errors and settling times of the end-effector, the base's drift, the
/// end-effector roll about its setpoint over the whole run and after settling
/// ([`roll_metrics`]), and how much the singularity-robust damping of `J_e^#` acted:
/// `ee_damped_fraction` of the logged samples with λ > 0 and its largest value
/// `ee_damping_max`.
fn work_metrics(out: &mut RunValues, spec: &MetricsSpec, traj: &Trajectory) {
    let t = channel(traj, Channel::T);
    let ep = channel(traj, Channel::EePositionError);
    let ea = channel(traj, Channel::EeOrientationError);
    let last = |x: &[f64]| x.last().copied().unwrap_or(f64::NAN);
    let settle_p = settling_time(t, ep, spec.position_tolerance);
    let settle_a = settling_time(t, ea, spec.orientation_tolerance_deg.to_radians());
    let bx = channel(traj, Channel::BasePose(Pose::X));
    let by = channel(traj, Channel::BasePose(Pose::Y));
    let bz = channel(traj, Channel::BasePose(Pose::Z));
    let drift = if bx.is_empty() {
        f64::NAN
    } else {
        let l = bx.len() - 1;
        ((bx[l] - bx[0]).powi(2) + (by[l] - by[0]).powi(2) + (bz[l] - bz[0]).powi(2)).sqrt()
    };
    let damp = channel(traj, Channel::EeDamping);
    let damped = damp.iter().filter(|l| **l > 0.0).count();
    let values = [
        last(ep),
        last(ea).to_degrees(),
        settle_p,
        settle_a,
        drift,
        damped as f64 / damp.len().max(1) as f64,
        damp.iter().fold(0.0, |m: f64, l| m.max(*l)),
    ];
    add_all(out, &WORK_METRICS, values);
    roll_metrics(out, traj, settle_p.max(settle_a));
}

/// Roll of the end effector about its setpoint (uncontrolled in the paper's work mode):
/// `ee_roll_max_deg`, the largest |deviation| over the whole logged run;
/// `ee_roll_max_settled_deg` and `ee_roll_std_deg`, its largest |deviation| and its standard
/// deviation after the pose has settled (`settled` [s] from the start: the later of the
/// position and orientation settling times; NaN when the pose never settles).
fn roll_metrics(out: &mut RunValues, traj: &Trajectory, settled: f64) {
    let t = channel(traj, Channel::T);
    let er = channel(traj, Channel::EePose(Pose::Roll));
    let sr = channel(traj, Channel::Setpoint(Pose::Roll));
    let dev: Vec<f64> = er.iter().zip(sr).map(|(a, b)| wrap_angle(a - b)).collect();
    let peak = |d: &[f64]| d.iter().fold(0.0f64, |m, x| m.max(x.abs())).to_degrees();
    let whole = peak(&dev);
    let t0 = t.first().copied().unwrap_or(0.0);
    let after: Vec<f64> = t
        .iter()
        .zip(&dev)
        .filter(|(ti, _)| settled.is_finite() && **ti - t0 >= settled)
        .map(|(_, d)| *d)
        .collect();
    let (settled_peak, std) = if after.is_empty() {
        (f64::NAN, f64::NAN)
    } else {
        let mean = after.iter().sum::<f64>() / after.len() as f64;
        let var = after.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / after.len() as f64;
        (peak(&after), var.sqrt().to_degrees())
    };
    add_all(out, &ROLL_METRICS, [whole, settled_peak, std]);
}

#[cfg(test)]
mod tests {
    use super::segment_runs;

    #[test]
    fn segment_runs_split_at_every_change() {
        assert_eq!(segment_runs(&[]), vec![]);
        assert_eq!(segment_runs(&[0.0]), vec![(0, 1)]);
        assert_eq!(
            segment_runs(&[0.0, 0.0, 1.0, 1.0, 1.0, 0.0]),
            vec![(0, 2), (2, 5), (5, 6)]
        );
    }
}
