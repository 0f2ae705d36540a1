//! Evaluating one resolved case of a sweep into a [`Row`] through the one case evaluator
//! ([`crate::evaluate`]): the study says which phases run, the case gives the tables, the
//! seed and (with `[tune]`) its tuned values. A panic, an invalid design or a failed run
//! becomes the row's status and reason; it never aborts the sweep.
//!
//! A worker may carry a per-case wall-clock budget ([`Worker::with_budget`]): one
//! [`Deadline`] per case covers tuning and scoring, checked cooperatively (before every control
//! period of a closed-loop run, after every chunk of static samples); a case past it ends
//! `failed` with a reason starting `timeout`. No thread is ever killed.

use std::time::Duration;

use super::bound_hook::{record_efficiency, CaseBound};
use super::faults::score_faults;
use super::records::Row;
use super::tuning_hook::CaseTuner;
use super::worlds::{evaluate_phases, score_worlds};
use crate::evaluate::{out_of_reach, CaseEnd, CaseResult, CaseStatus, Deadline, Evaluator, Phases};
use crate::study::cases::Resolved;
use crate::study::doe::Case;
use crate::study::schema::Study;

/// Per-worker state of a sweep (one per rayon worker): the evaluator (its vehicle cache keyed
/// by the design hash, so consecutive cases of one design build it once) and the budget.
#[derive(Default)]
pub struct Worker {
    evaluator: Evaluator,
    /// Wall-clock budget of one case (`None`: unlimited).
    pub budget: Option<Duration>,
}

/// The phases a case of `study` runs.
pub fn study_phases(study: &Study) -> Phases {
    Phases {
        static_analysis: study.static_enabled,
        closed_loop: study.mode.is_dynamic(),
    }
}

/// Evaluate resolved case `r` of `study` with `evaluator` within `deadline`.
pub fn evaluate_resolved(
    evaluator: &mut Evaluator,
    study: &Study,
    id: usize,
    r: &Resolved,
    log: bool,
    deadline: Deadline,
) -> CaseResult {
    evaluate_phases(evaluator, r, id, study_phases(study), log, deadline)
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
            evaluator: Evaluator::new(),
            budget,
        }
    }

    /// Score a case that ran (at its tuned values `r`) in the study's worlds and validation
    /// variants ([`score_worlds`]); a timeout there fails the case.
    fn robust(
        &mut self,
        study: &Study,
        id: usize,
        r: &Resolved,
        deadline: Deadline,
        res: &mut CaseResult,
    ) {
        let robust =
            study.uncertainty.is_some() || !study.validate.is_empty() || study.faults.is_some();
        if !robust
            || matches!(res.status(), CaseStatus::Failed | CaseStatus::Skipped)
            || res.end.disqualified()
        {
            return;
        }
        let worlds = study
            .uncertainty
            .as_ref()
            .map(|u| u.sample(study.seed))
            .unwrap_or_default();
        if let Err(e) = score_worlds(
            &mut self.evaluator,
            study,
            &worlds,
            id,
            r,
            deadline,
            &mut res.metrics,
        )
        .and_then(|()| score_faults(study, id, r, deadline, &mut res.metrics))
        {
            res.finish(CaseEnd::Timeout, e.to_string());
        }
    }

    /// Evaluate a resolved case into its row (no trajectory is logged: the report's best and
    /// worst reruns log theirs, `finish::rerun_extremes`). With a `tuner`, the case is tuned
    /// first and scored at its tuned values (a tuning that cannot run makes the case `failed`
    /// with a reason starting `tune:`). With a `bounder` (`[ocp]`), a case that ran gets its
    /// design's optimal-control bound and `controller_efficiency`.
    pub fn evaluate(
        &mut self,
        study: &Study,
        case: &Case,
        r: &Resolved,
        tuner: Option<&dyn CaseTuner>,
        bounder: Option<&dyn CaseBound>,
    ) -> Row {
        let deadline = Deadline::after(self.budget);
        // A design that cannot reach the mission is not tuned nor put in worlds: no gain
        // changes its reach; one untuned evaluation records its static columns and the miss.
        let unreachable = out_of_reach(&r.design, &r.scenario, &study.name);
        // With `[ocp]`, a case that ran gets its design's bound and the controller's
        // efficiency against it (the bound depends on the design only: its gains are not
        // an input, so a tuned case is bounded by its own design's solve). A design that
        // cannot reach the mission gets no bound (NaN columns): it cannot do the mission.
        let bounded = |mut res: CaseResult| {
            if let Some(b) = bounder.filter(|_| !unreachable) {
                if !matches!(res.status(), CaseStatus::Failed | CaseStatus::Skipped) {
                    b.bound(study, r, &mut res.metrics);
                    let tol = study.ocp.as_ref().map_or(0.0, |o| o.tolerance);
                    record_efficiency(&mut res.metrics, tol);
                }
            }
            res
        };
        let row = |res: CaseResult| {
            Row::from_result(case.id, r.hash.clone(), case.values.clone(), bounded(res))
        };
        let Some(t) = tuner.filter(|_| !unreachable) else {
            let mut res =
                evaluate_resolved(&mut self.evaluator, study, case.id, r, false, deadline);
            if !unreachable {
                self.robust(study, case.id, r, deadline, &mut res);
            }
            return row(res);
        };
        match t.tune(study, case, r, deadline) {
            Ok(tuned) => {
                let mut res = evaluate_resolved(
                    &mut self.evaluator,
                    study,
                    case.id,
                    &tuned.resolved,
                    false,
                    deadline,
                );
                tuned.record(study, &mut res.metrics);
                self.robust(study, case.id, &tuned.resolved, deadline, &mut res);
                row(res)
            }
            Err(e) => {
                let mut failed = Row::new(case.id, r.hash.clone(), case.values.clone());
                failed.end(CaseEnd::Error, &e.to_string());
                failed
            }
        }
    }
}
