//! Evaluating one resolved case into a [`Row`]: build the vehicle (cached per worker), record
//! the design columns, run the static TCM analysis and the closed-loop scenario as the study
//! asks. A panic, an invalid design or a failed run becomes the row's status and reason; it
//! never aborts the sweep.
//!
//! A worker may carry a per-case wall-clock budget ([`Worker::with_budget`]): it is checked
//! cooperatively (before every control period of a closed-loop run, after every chunk of
//! static samples), and a case past it ends `failed` with a reason starting `timeout`. No
//! thread is ever killed.

use super::cases::Resolved;
use super::doe::Case;
use super::records::{pack_metrics, CaseStatus, Row, DESIGN_COLUMNS, TCM_COLUMNS};
use super::runner;
use super::schema::Study;
use super::static_table::{static_spec, STATIC_TABLE};
use crate::model::design::parse_design_table;
use crate::model::Vehicle;
use crate::report::Table;
use crate::sampling::derive_seed;
use crate::statics::{analyse, Distribution, StaticError, StaticSummary};
use std::time::{Duration, Instant};

/// Per-worker state of a sweep (one per rayon worker): a one-entry vehicle cache keyed by
/// the design hash, so consecutive cases of one design build it once.
#[derive(Default)]
pub struct Worker {
    cache: Option<(String, Vehicle)>,
    /// Wall-clock budget of one case (`None`: unlimited).
    pub budget: Option<Duration>,
}

impl Worker {
    /// A fresh worker without a time budget.
    pub fn new() -> Self {
        Self::default()
    }

    /// A fresh worker giving every case at most `budget` of wall-clock time (`None`:
    /// unlimited).
    pub fn with_budget(budget: Option<Duration>) -> Self {
        Self {
            cache: None,
            budget,
        }
    }

    /// Evaluate a resolved case; returns the row and (with `log`) the trajectory.
    pub fn evaluate(
        &mut self,
        study: &Study,
        case: &Case,
        r: &Resolved,
        log: bool,
    ) -> (Row, Option<Table>) {
        let deadline = self.budget.map(|b| Instant::now() + b);
        self.evaluate_until(study, case, r, log, deadline)
    }

    /// [`Worker::evaluate`] within a deadline set by the caller (per-case tuning spends part
    /// of the case's budget before the case is scored).
    pub fn evaluate_until(
        &mut self,
        study: &Study,
        case: &Case,
        r: &Resolved,
        log: bool,
        deadline: Option<Instant>,
    ) -> (Row, Option<Table>) {
        let mut row = Row::new(study, case.id, r.hash.clone(), case.values.clone());
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            self.evaluate_phases(study, case, r, log, deadline, &mut row)
        }));
        match result {
            Ok(traj) => (row, traj),
            Err(p) => {
                let msg = p
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| p.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "unknown panic".into());
                row.end(CaseStatus::Failed, &format!("panic: {msg}"));
                self.cache = None;
                (row, None)
            }
        }
    }

    fn evaluate_phases(
        &mut self,
        study: &Study,
        case: &Case,
        r: &Resolved,
        log: bool,
        deadline: Option<Instant>,
        row: &mut Row,
    ) -> Option<Table> {
        let v = self.vehicle(case, r, row)?;
        row.metrics[..DESIGN_COLUMNS.len()].copy_from_slice(&design_metrics(v));
        if study.static_enabled {
            static_phase(v, r, deadline, row)?;
        }
        if study.mode.is_dynamic() {
            return dynamic_phase(v, r, log, deadline, row);
        }
        None
    }

    /// The case's vehicle, built unless cached; `None` (the row skipped) for an invalid design.
    fn vehicle(&mut self, case: &Case, r: &Resolved, row: &mut Row) -> Option<&Vehicle> {
        let cached = matches!(&self.cache, Some((h, _)) if *h == r.design_hash);
        if !cached {
            match parse_design_table(&r.design, &format!("case {} design", case.id)) {
                Ok(v) => self.cache = Some((r.design_hash.clone(), v)),
                Err(e) => {
                    row.end(CaseStatus::Skipped, &format!("invalid design: {e}"));
                    return None;
                }
            }
        }
        self.cache.as_ref().map(|(_, v)| v)
    }
}

/// The [`DESIGN_COLUMNS`] of a vehicle.
pub fn design_metrics(v: &Vehicle) -> [f64; 5] {
    [
        v.bodies.len() as f64,
        v.n_joints() as f64,
        v.n_thrusters() as f64,
        v.total_length(),
        v.total_mass(),
    ]
}

/// The static TCM analysis into the [`TCM_COLUMNS`]; `None` when the row ended (a `timeout`
/// when `deadline` passed: it is checked for every sample handed over, so after each chunk).
fn static_phase(v: &Vehicle, r: &Resolved, deadline: Option<Instant>, row: &mut Row) -> Option<()> {
    let spec = match static_spec(&r.scenario, derive_seed(r.seed, 1)) {
        Ok(s) => s,
        Err(m) => {
            row.end(CaseStatus::Skipped, &m);
            return None;
        }
    };
    let mut on_time = |_: usize, _: &[f64], _: &_| match deadline {
        Some(d) if Instant::now() >= d => Err(runner::TIMEOUT.into()),
        _ => Ok(()),
    };
    match analyse(v, &spec, 1, &mut on_time, &|_| {}) {
        Ok(s) => {
            let d = DESIGN_COLUMNS.len();
            row.metrics[d..d + TCM_COLUMNS.len()].copy_from_slice(&tcm_metrics(&s));
            Some(())
        }
        Err(StaticError::Sink(_)) => {
            let reason = format!(
                "{}: the case's wall-clock budget ran out in the static analysis",
                runner::TIMEOUT
            );
            row.end(CaseStatus::Failed, &reason);
            None
        }
        Err(e) => {
            row.end(CaseStatus::Failed, &e.to_string());
            None
        }
    }
}

/// The [`TCM_COLUMNS`] of a static summary.
pub fn tcm_metrics(s: &StaticSummary) -> [f64; TCM_COLUMNS.len()] {
    let q = |d: &Distribution, p: f64| d.quantile(p).unwrap_or(f64::NAN);
    let lost = |k: usize| s.lost_axes[k].fraction;
    [
        s.singular_fraction,
        s.rank_deficient_fraction,
        s.sigma_min.min,
        q(&s.sigma_min, 0.05),
        q(&s.sigma_min, 0.5),
        s.sigma_min.mean,
        q(&s.kappa, 0.5),
        q(&s.kappa, 0.95),
        s.straight.metrics.sigma_min,
        lost(0),
        lost(1),
        lost(2),
        lost(3),
        lost(4),
        lost(5),
        s.singular_fraction_commanded,
        s.sigma_min_commanded.min,
        q(&s.sigma_min_commanded, 0.05),
        q(&s.sigma_min_commanded, 0.5),
        q(&s.kappa_commanded, 0.5),
        s.straight.metrics.sigma_min_commanded,
    ]
}

/// The closed-loop run into the packed scenario metrics; returns the trajectory (with `log`).
fn dynamic_phase(
    v: &Vehicle,
    r: &Resolved,
    log: bool,
    deadline: Option<Instant>,
    row: &mut Row,
) -> Option<Table> {
    let mut sc = r.scenario.clone();
    sc.remove(STATIC_TABLE);
    match runner::run_case_until(v, &sc, r.seed, log, deadline) {
        Ok(out) => {
            if let Some(f) = &out.failure {
                row.end(CaseStatus::Failed, f);
            } else if let Some(m) = &out.missed {
                row.end(CaseStatus::Unsuccessful, m);
            }
            row.scenario = pack_metrics(&out.metrics);
            out.trajectory
        }
        Err(m) => {
            row.end(CaseStatus::Failed, &m);
            None
        }
    }
}
