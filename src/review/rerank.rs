//! `usm-study report DIR --objective M --pareto A,B`: a finished study re-ranked without
//! re-running any case. The objective and the Pareto pair replace the study's `objective` and
//! `pareto` for the report (direction from [`crate::study::directions`]) and are recorded in
//! `manifest.json`, so that `summary.md`, the plots, `report.html` and later reports agree.
//!
//! With uncertain worlds the objective must be one of the metrics the worlds recorded
//! (`worlds.csv`): `p_best` and the rank quantiles are recomputed over the worlds by it and
//! `cases.csv` / `cases.parquet` rewritten with them. The best and worst cases' trajectories
//! of the previous objective (`trajectory_best.csv`, `trajectory_worst.csv`) are removed when
//! the best or worst case changes: they would name other cases.

use std::path::Path;

use super::selection::Selection;
use crate::batch::manifest::{write_manifest, Manifest};
use crate::batch::records::{Extreme, CASES_CSV, CASES_PARQUET};
use crate::batch::robust::{
    add_rank_columns, write_case_files, P_BEST, RANK_COLUMNS, SUCCESS_LOWER, WORLDS_CSV,
};
use crate::input::keypath::did_you_mean;
use crate::report::{read_csv, Table};
use crate::study::error::{Notes, StudyError};

/// A re-ranking: the objective and the Pareto pair `[x, y]` to report by (`None`: as the
/// study set them).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Rerank {
    /// The metric picking the best and worst case (and ranking over worlds).
    pub objective: Option<String>,
    /// The trade-off plotted as a Pareto front.
    pub pareto: Option<[String; 2]>,
}

impl Rerank {
    /// Whether it changes nothing.
    pub fn is_empty(&self) -> bool {
        self.objective.is_none() && self.pareto.is_none()
    }
}

/// The error for `name` given to `flag` that is not a rankable metric of the table: the
/// closest name, or the list of the metrics when none is close.
fn unknown(flag: &str, name: &str, metrics: &[String]) -> StudyError {
    let hint = did_you_mean(name, metrics.iter().map(String::as_str));
    let list = if hint.is_empty() {
        format!("; the study's metrics: {}", metrics.join(", "))
    } else {
        hint
    };
    StudyError::Input(format!(
        "{flag}: unknown metric `{name}` (not a ranked metric column of the case table){list}"
    ))
}

/// Apply `r` to the manifest `m` and the case table `table` of the study output `dir`
/// (see the module docs); returns what changed, for the user.
pub fn apply(
    dir: &Path,
    m: &mut Manifest,
    table: &mut Table,
    r: &Rerank,
) -> Result<Notes, StudyError> {
    let before = Selection::new(table, m);
    let check = |flag: &str, name: &str| {
        if before.metrics.iter().any(|x| x == name) {
            Ok(())
        } else {
            Err(unknown(flag, name, &before.metrics))
        }
    };
    if let Some(o) = &r.objective {
        check("--objective", o)?;
    }
    for x in r.pareto.iter().flatten() {
        check("--pareto", x)?;
    }
    let mut notes = Notes::new();
    if let (Some(o), Some(info)) = (&r.objective, m.robust.as_mut()) {
        if info.objective() != o {
            let Some(k) = info.metrics.iter().position(|x| x == o) else {
                return Err(StudyError::Input(format!(
                    "--objective: `{o}` was not recorded over the uncertain worlds, so designs \
                     cannot be ranked by it; the worlds recorded: {} (`[uncertainty] metrics`)",
                    info.metrics.join(", ")
                )));
            };
            // The new objective first, the other metrics in their order.
            info.metrics[..=k].rotate_right(1);
            let worlds = read_csv(&dir.join(WORLDS_CSV))?;
            table.columns.retain(|c| {
                c.name != P_BEST
                    && c.name != SUCCESS_LOWER
                    && !RANK_COLUMNS.contains(&c.name.as_str())
            });
            add_rank_columns(table, &worlds, info);
            let axes: Vec<&str> = m.axes.iter().map(|a| a.name.as_str()).collect();
            write_case_files(table, dir, &axes)?;
            notes.push(format!(
                "p_best and the rank quantiles recomputed over the worlds by `{o}`; \
                 {CASES_CSV} and {CASES_PARQUET} rewritten"
            ));
        }
    }
    if r.objective.is_some() {
        m.report.objective = r.objective.clone();
    }
    if r.pareto.is_some() {
        m.report.pareto = r.pareto.clone();
    }
    let after = Selection::new(table, m);
    if after.extremes(table) != before.extremes(table) {
        for e in Extreme::BOTH {
            let p = dir.join(e.trajectory_file());
            if p.is_file() {
                std::fs::remove_file(&p).map_err(|e| StudyError::io(&p, e))?;
                notes.push(format!(
                    "removed {} (a case of the previous objective; rerun the sweep with the \
                     new objective for the best/worst trajectories)",
                    e.trajectory_file()
                ));
            }
        }
        let ts = dir.join("plots").join("timeseries.svg");
        if ts.is_file() {
            std::fs::remove_file(&ts).map_err(|e| StudyError::io(&ts, e))?;
        }
    }
    write_manifest(dir, m)?;
    if let Some(o) = &after.objective {
        notes.push(format!(
            "ranked by `{o}` ({}){}; recorded in manifest.json",
            after.goal(o),
            after
                .pareto
                .as_ref()
                .map_or(String::new(), |(x, y)| format!(
                    ", Pareto front `{x}` vs `{y}`"
                ))
        ));
    }
    Ok(notes)
}
