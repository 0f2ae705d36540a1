//! The report step of a sweep, a merge or `usm-study report`: rerun the best and worst cases of
//! dynamic studies for their trajectories, then write `summary.md` and the plots.

use std::path::Path;

use super::cases::resolve_case;
use super::doe::expand;
use super::error::StudyError;
use super::manifest::{read_manifest, Manifest};
use super::records::{final_table, Extreme, CASES_PARQUET, CASE_ID, PARTIAL_FILE};
use super::schema::Study;
use super::selection::Selection;
use super::summary::write_report;
use super::tune::Tuner;
use super::worker::Worker;
use crate::report::{read_csv_typed, write_csv, Table};

/// Write the report, rerunning the best and worst cases of dynamic studies for their
/// trajectories when the study is available. Returns non-fatal warnings.
pub fn finish_report(
    out: &Path,
    table: &Table,
    manifest: &Manifest,
    study: Option<&Study>,
) -> Vec<String> {
    let mut warnings = Vec::new();
    if let Some(study) = study {
        if study.mode.is_dynamic() {
            if let Err(e) = rerun_extremes(out, table, manifest, study) {
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
) -> Result<(), String> {
    let sel = Selection::new(table, manifest);
    let Some((best, worst)) = sel.extremes(table) else {
        return Ok(());
    };
    let ids = table.i64(CASE_ID).map_err(|e| e.to_string())?;
    let all = expand(study, None)?;
    let tuner = Tuner::new(study).map_err(|e| e.to_string())?;
    let params = study.tune_columns();
    let tuned = params[..params.len().saturating_sub(2)]
        .iter()
        .map(|c| table.f64(c))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| e.to_string())?;
    // The two reruns are independent: run them side by side.
    let rerun = |which: Extreme, row: usize| -> Result<(), String> {
        let id = ids[row] as usize;
        let case = all.get(id).ok_or("case id out of range")?;
        let mut r = resolve_case(study, case)?;
        if let Some(t) = &tuner {
            // Rerun at the case's tuned values, as scored.
            let x: Vec<f64> = tuned.iter().map(|c| c[row]).collect();
            r = t.at(study, case, &r, &x)?;
        }
        let (_, traj) = Worker::new().evaluate(study, case, &r, true);
        if let Some(t) = traj {
            write_csv(&t, &out.join(which.trajectory_file())).map_err(|e| e.to_string())?;
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
/// `cases.csv`) and `manifest.json`.
pub fn report(dir: &Path) -> Result<Vec<String>, StudyError> {
    let m = read_manifest(dir)?;
    let pq = dir.join(CASES_PARQUET);
    let table = if pq.is_file() {
        crate::report::read_parquet(&pq)?
    } else {
        // Reconstruct from the raw rows (typed) when the Parquet file is missing.
        let schema = m.schema()?;
        final_table(read_csv_typed(&dir.join(PARTIAL_FILE), &schema)?)?
    };
    Ok(write_report(dir, &table, &m))
}
