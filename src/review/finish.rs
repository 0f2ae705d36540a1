//! The report step of a sweep, a merge or `usm-study report`: rerun the best and worst cases of
//! dynamic studies for their trajectories, then write `summary.md` and the plots.

use std::path::Path;

use super::rerank::Rerank;
use super::selection::Selection;
use super::summary::write_report;
use crate::batch::manifest::{read_manifest, Manifest};
use crate::batch::records::{final_table, Extreme, CASES_PARQUET, CASE_ID, PARTIAL_FILE};
use crate::batch::report_hook::ReportHook;
use crate::batch::tuning_hook::{case_tuner, tuned_columns, TuneError, TuningHook};
use crate::batch::worker::evaluate_resolved;
use crate::evaluate::{trajectory_table, Deadline, Evaluator};
use crate::report::{read_csv_typed, write_csv, ReportError, Table};
use crate::study::cases::{resolve_case, CaseError};
use crate::study::doe::expand;
use crate::study::error::{Notes, StudyError};
use crate::study::schema::Study;

/// Why the best or worst case could not be rerun (a warning of the report, not fatal).
#[derive(Debug, thiserror::Error)]
pub enum RerunError {
    /// Reading the table or writing the trajectory.
    #[error(transparent)]
    Report(#[from] ReportError),
    /// The tuner could not be set up.
    #[error(transparent)]
    Study(Box<StudyError>),
    /// The study's cases could not be planned.
    #[error("{0}")]
    Plan(#[source] crate::sampling::SamplerError),
    /// The table names a case the study does not have.
    #[error("case id out of range")]
    CaseId,
    /// The case's overrides do not apply.
    #[error("{0}")]
    Resolve(#[source] CaseError),
    /// The case's tuned values do not apply.
    #[error(transparent)]
    Tune(#[from] TuneError),
    /// The rerun ran out of the case's `--case-timeout`.
    #[error("the rerun ran out of the case's --case-timeout ({0}); no time series written")]
    Timeout(String),
}

/// [`finish_report`] as the hook a caller hands to a sweep or a merge
/// ([`crate::batch::SweepOptions::report`], [`crate::batch::merge`]).
pub const HOOK: ReportHook = ReportHook(finish_report);

/// Write the report, rerunning the best and worst cases of dynamic studies for their
/// trajectories when the study is available (at their tuned values through `tuning` for a
/// study with `[tune]`). Returns non-fatal warnings.
pub fn finish_report(
    out: &Path,
    table: &Table,
    manifest: &Manifest,
    study: Option<&Study>,
    tuning: Option<TuningHook>,
) -> Vec<String> {
    let mut warnings = Vec::new();
    if let Some(study) = study {
        if study.mode.is_dynamic() {
            if let Err(e) = rerun_extremes(out, table, manifest, study, tuning) {
                warnings.push(format!("time series of the best/worst case: {e}"));
            }
        }
    }
    warnings.extend(write_report(out, table, manifest));
    warnings
}

/// Rerun the best and worst case by the objective with logging and write their trajectories
/// (`trajectory_best.csv`, `trajectory_worst.csv`).
fn rerun_extremes(
    out: &Path,
    table: &Table,
    manifest: &Manifest,
    study: &Study,
    tuning: Option<TuningHook>,
) -> Result<(), RerunError> {
    let sel = Selection::new(table, manifest);
    let Some((best, worst)) = sel.extremes(table) else {
        return Ok(());
    };
    let ids = table.i64(CASE_ID)?;
    let all = expand(study, None).map_err(RerunError::Plan)?;
    let tuner = case_tuner(study, tuning).map_err(|e| RerunError::Study(Box::new(e)))?;
    let tuned = tuned_columns(study)
        .iter()
        .map(|c| table.f64(c))
        .collect::<Result<Vec<_>, _>>()?;
    // The two reruns are independent: run them side by side.
    let rerun = |which: Extreme, row: usize| -> Result<(), RerunError> {
        let id = ids[row] as usize;
        let case = all.get(id).ok_or(RerunError::CaseId)?;
        let mut r = resolve_case(study, case).map_err(RerunError::Resolve)?;
        if let Some(t) = &tuner {
            // Rerun at the case's tuned values, as scored.
            let x: Vec<f64> = tuned.iter().map(|c| c[row]).collect();
            r = t.at(study, case, &r, &x)?;
        }
        let mut ev = Evaluator::new();
        // The case's own budget (`--case-timeout`, recorded in the manifest) bounds the rerun.
        let budget = manifest
            .case_timeout_s
            .filter(|s| s.is_finite() && *s > 0.0)
            .map(std::time::Duration::from_secs_f64);
        let res = evaluate_resolved(&mut ev, study, case.id, &r, true, Deadline::after(budget));
        if res.end.timed_out() {
            return Err(RerunError::Timeout(res.reason));
        }
        if let Some(t) = res.trajectory {
            write_csv(&trajectory_table(&t)?, &out.join(which.trajectory_file()))?;
        }
        Ok(())
    };
    let (a, b) = rayon::join(
        || rerun(Extreme::Best, best),
        || rerun(Extreme::Worst, worst),
    );
    a.and(b)
}

/// Regenerate `summary.md` and the plots of an output directory from `cases.parquet` (or
/// `cases.csv`) and `manifest.json`; returns non-fatal warnings.
pub fn report(dir: &Path) -> Result<Notes, StudyError> {
    Ok(report_ranked(dir, &Rerank::default())?.warnings)
}

/// What [`report_ranked`] wrote besides the report.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Reported {
    /// Outputs that could not be written.
    pub warnings: Notes,
    /// What the re-ranking changed (see [`super::rerank`]).
    pub notes: Notes,
}

/// [`report`] re-ranked by `rerank` (`usm-study report DIR --objective M --pareto A,B`): an
/// unknown metric is refused (bad input, with the closest name) before anything is written.
pub fn report_ranked(dir: &Path, rerank: &Rerank) -> Result<Reported, StudyError> {
    let mut m = read_manifest(dir)?;
    let pq = dir.join(CASES_PARQUET);
    let mut table = if pq.is_file() {
        crate::report::read_parquet(&pq)?
    } else {
        // Reconstruct from the raw rows (typed) when the Parquet file is missing.
        let schema = m.schema()?;
        final_table(read_csv_typed(&dir.join(PARTIAL_FILE), &schema)?)?
    };
    crate::study::dictionary::integers_for_files(&mut table, false);
    let notes = if rerank.is_empty() {
        Notes::new()
    } else {
        super::rerank::apply(dir, &mut m, &mut table, rerank)?
    };
    Ok(Reported {
        warnings: write_report(dir, &table, &m),
        notes,
    })
}

/// The terminal's one-line answer of a study output without uncertain worlds (which have a
/// verdict line instead): the best successful case by the objective, its design and value,
/// e.g. "best by `mission_cost` (min): #41 (distributed/9/0.14) at 1.2345"; `None` when
/// no case is ranked or the files cannot be read.
pub fn best_case_line(dir: &Path) -> Option<String> {
    let m = read_manifest(dir).ok()?;
    let mut table = crate::report::read_parquet(&dir.join(CASES_PARQUET)).ok()?;
    crate::study::dictionary::integers_for_files(&mut table, false);
    let sel = Selection::new(&table, &m);
    let o = sel.objective.as_deref()?;
    let row = sel.best_row(&table, o, false)?;
    let id = table.i64(CASE_ID).ok()?.get(row).copied()?;
    let axes: Vec<&str> = m.axes.iter().map(|a| a.name.as_str()).collect();
    Some(format!(
        "best by `{o}` ({}): #{id} ({}) at {}",
        sel.goal(o),
        super::plots::case_name(&table, &axes, row),
        super::selection::cell_text(&table, o, row)
    ))
}
