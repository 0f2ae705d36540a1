//! One closed-loop run and its outcome: the loop of [`crate::scenario::run_loop`], then the
//! run's summary metrics ([`super::run_summary`]) and its `[success]` judgement
//! ([`super::judge`]).

use super::run_summary::{add_success, run_summary, RunFacts};
use crate::kinematics::straight_reach;
use crate::model::Vehicle;
use crate::scenario::channels::Trajectory;
use crate::scenario::config::{Mode, ScenarioFile};
use crate::scenario::criteria::Missed;
use crate::scenario::{
    parse_table, run_loop, AllocationCounts, ScenarioError, Source, Stop, Timing, TIMEOUT,
};

/// The metric a run with a `[fault]` adds before `success`: the simulation time the fault
/// struck [s] (NaN when the run ended before `fault.at`).
pub const FAULT_TIME_METRIC: &str = "fault_time";

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
    /// Why the run stopped early, if it did: (simulation time [s], cause).
    pub failure: Option<(f64, String)>,
    /// The first `[success]` criterion the run missed; `None` for a successful run (metric
    /// `success` = 1).
    pub missed: Option<Missed>,
    /// Allocation outcomes.
    pub allocation_counts: AllocationCounts,
    /// Wall-clock breakdown.
    pub timing: Timing,
}

impl RunResult {
    /// A metric by name.
    pub fn metric(&self, name: &str) -> Option<f64> {
        self.metrics
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, x)| *x)
    }
}

/// Run a scenario on a vehicle. Never panics on bad input: settings problems return
/// a [`ScenarioError`] before anything runs; a run that fails (diverges, NaN,
/// singular mass matrix) returns `Ok` with `failure` set and the trajectory up to then.
pub fn run_scenario(v: &Vehicle, file: &ScenarioFile) -> Result<RunResult, ScenarioError> {
    run_scenario_until(v, file, Stop::NEVER)
}

/// [`run_scenario`] with a wall-clock [`Stop`] ([`crate::scenario::run_loop`]): a run still
/// going when it is due stops there with the failure cause [`TIMEOUT`] (the metrics and
/// trajectory up to then are kept, as for any failure).
pub fn run_scenario_until(
    v: &Vehicle,
    file: &ScenarioFile,
    stop: Stop,
) -> Result<RunResult, ScenarioError> {
    let run = run_loop(v, file, stop)?;
    let facts = RunFacts {
        failed: run.failure.is_some(),
        stopped_at: run.stopped.map_or(f64::NAN, |(t, _)| t),
        reach: straight_reach(v),
    };
    let mut metrics = run_summary(
        file,
        facts,
        &run.trajectory,
        &run.allocation_counts,
        &run.energy,
    );
    if let Some(t) = run.fault_time {
        metrics.push((FAULT_TIME_METRIC.to_string(), t));
    }
    let mut missed = add_success(&mut metrics, file);
    if let (Some(m), Some((t, c))) = (missed.as_mut(), run.stopped) {
        // The watch stops only on the criterion the verdict names first (scenario::watch).
        debug_assert_eq!(m.criterion, c, "a run stopped on {c} was judged {m}");
        m.detail.push_str(&format!(
            " (run stopped at t = {t:.3} s: this bound can no longer be met)"
        ));
    }
    Ok(RunResult {
        name: file.scenario.name.clone(),
        mode: file.scenario.mode,
        trajectory: run.trajectory,
        metrics,
        failure: run.failure,
        missed,
        allocation_counts: run.allocation_counts,
        timing: run.timing,
    })
}

/// One case of a sweep: the scenario-side table (overrides applied) run on `vehicle`.
#[derive(Clone, Debug)]
pub struct CaseRun {
    /// Named metrics in a fixed order (see [`RunResult::metrics`]); a run that stopped
    /// early has `completed = 0`.
    pub metrics: Vec<(String, f64)>,
    /// The trajectory, when asked for.
    pub trajectory: Option<Trajectory>,
    /// Why the run stopped early, if it did.
    pub failure: Option<RunStopped>,
    /// The first success criterion the run missed (`no_failure` for a run that stopped
    /// early); `None` when it met them all.
    pub missed: Option<Missed>,
}

/// The text the reason of a run that stopped early (not at its deadline) starts with
/// (`run stopped at t = … s: cause`).
pub const RUN_STOPPED: &str = "run stopped at t = ";

/// Why a case's run stopped early.
#[derive(Clone, Debug, PartialEq)]
pub struct RunStopped {
    /// Simulation time it stopped at [s].
    pub at: f64,
    /// Whether the case's wall-clock budget ran out (else the run failed: non-finite state,
    /// singular mass matrix, …).
    pub timeout: bool,
    /// The reason, one line (`timeout: …` or `run stopped at t = … s: cause`).
    pub reason: String,
}

/// Run one sweep case. `seed` is accepted for scenarios with random elements (none yet: the
/// runs are deterministic). A run still going when `stop` is due stops with a failure
/// starting with [`TIMEOUT`] (`timeout: …`).
pub fn run_case(
    vehicle: &Vehicle,
    scenario: &toml::Table,
    seed: u64,
    log: bool,
    stop: Stop,
) -> Result<CaseRun, ScenarioError> {
    let _ = seed;
    let f = parse_table(scenario, &Source::unplaced("scenario"))?;
    let r = run_scenario_until(vehicle, &f, stop)?;
    Ok(CaseRun {
        metrics: r.metrics,
        trajectory: if log { Some(r.trajectory) } else { None },
        failure: r.failure.map(|(t, c)| {
            let timeout = c == TIMEOUT;
            let reason = if timeout {
                format!(
                    "{TIMEOUT}: the case's wall-clock budget ran out at t = {} s",
                    crate::input::located::fmt_fixed(t, 3)
                )
            } else {
                format!(
                    "{RUN_STOPPED}{} s: {c}",
                    crate::input::located::fmt_fixed(t, 3)
                )
            };
            RunStopped {
                at: t,
                timeout,
                reason,
            }
        }),
        missed: r.missed,
    })
}
