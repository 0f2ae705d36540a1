//! A run's outcome, above the closed loop: the summary metrics of a trajectory (common,
//! transport and work metrics, their names declared once), the judgement of a run against its
//! `[success]` criteria, and the one call that runs a scenario and returns both
//! ([`run_scenario`], [`run_case`]). The pure kernels these use live below the control laws in
//! [`crate::metrics`].

mod case_run;
pub mod judge;
pub mod run_summary;

pub use case_run::{
    run_case, run_scenario, run_scenario_until, CaseRun, RunResult, RunStopped, FAULT_TIME_METRIC,
    RUN_STOPPED,
};
