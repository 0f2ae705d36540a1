//! The optimal-control bound hook of a sweep (`[ocp]`, issue 41, docs/ocp.md §6). The solver
//! lives in the `ocp` room (`crate::ocp::study_bound`); the sweep engine only knows this
//! interface, handed in by the caller ([`BoundHook`] in `SweepOptions::bound`), so running a
//! study never imports the optimal control.
//!
//! A case's row gets the bound of its design ([`crate::study::schema::OCP_COLUMNS`]), set by
//! name, and `controller_efficiency`: the bound's energy per metre over the closed loop's
//! `(thruster_energy_static + joint_energy) / path_progress` in the nominal world.

use std::fmt;

use crate::evaluate::Metrics;
use crate::study::cases::Resolved;
use crate::study::error::StudyError;
use crate::study::schema::{
    Study, CONTROLLER_EFFICIENCY, OCP_ENERGY_PER_METRE, OCP_PRIMAL, OCP_WORK_ERROR,
    OCP_WORK_TRUSTED,
};

/// Solves the bound of the cases of one study.
pub trait CaseBound: Sync {
    /// Write the bound columns of case `r`'s design into `metrics` (a design solved before
    /// is taken from the cache: same numbers, `ocp_time_s` 0). A design the solver cannot
    /// build writes NaN and never fails the case (the closed loop's row stands).
    fn bound(&self, study: &Study, r: &Resolved, metrics: &mut Metrics);
}

/// The bound solver of a study (`None` without `[ocp]`).
pub type BoundFactory = fn(&Study) -> Option<Box<dyn CaseBound>>;

/// How a sweep bounds its cases: the factory the caller wires in (the `ocp` room's).
#[derive(Clone, Copy)]
pub struct BoundHook(pub BoundFactory);

impl fmt::Debug for BoundHook {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("BoundHook")
    }
}

/// The bound solver of `study` through `hook`; `None` without `[ocp]`. A study with `[ocp]`
/// but no hook cannot be run as written: refused.
pub fn case_bound(
    study: &Study,
    hook: Option<BoundHook>,
) -> Result<Option<Box<dyn CaseBound>>, StudyError> {
    match hook {
        Some(h) => Ok((h.0)(study)),
        None if study.ocp.is_some() => Err(StudyError::NoBounder),
        None => Ok(None),
    }
}

/// `controller_efficiency` of a row: `ocp_energy_per_metre` over the closed loop's
/// `(thruster_energy_static + joint_energy) / path_progress`; NaN when either is missing, the
/// run made no progress, or the bound's trajectory is not feasible (`ocp_primal` above
/// `tolerance`, the section's KKT tolerance: not a trajectory the model can fly, so no bound)
/// or not trusted on its grid (`ocp_work_error` above [`OCP_WORK_TRUSTED`]: it swims on energy
/// the integration supplies).
/// Set by name.
pub fn record_efficiency(metrics: &mut Metrics, tolerance: f64) {
    let get = |m: &Metrics, k: &str| m.get(k).unwrap_or(f64::NAN);
    let progress = get(metrics, "path_progress");
    let closed = (get(metrics, "thruster_energy_static") + get(metrics, "joint_energy")) / progress;
    let bound = get(metrics, OCP_ENERGY_PER_METRE);
    let feasible =
        get(metrics, OCP_PRIMAL) <= tolerance && get(metrics, OCP_WORK_ERROR) <= OCP_WORK_TRUSTED;
    let eff = if feasible && progress > 0.0 && closed > 0.0 {
        bound / closed
    } else {
        f64::NAN
    };
    metrics.set(CONTROLLER_EFFICIENCY, eff);
}
