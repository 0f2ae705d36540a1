//! The report hook: what a finished sweep writes about itself (`summary.md`, its plots, the
//! best and worst cases' time series) belongs to the review room ([`crate::review`]), which
//! sits above this one. The caller hands the review's finish to the sweep through a
//! [`ReportHook`], as it hands the optimiser's tuner through a
//! [`super::tuning_hook::TuningHook`], so that running a study never imports how it is
//! reviewed (issue 37 item 1).

use std::fmt;
use std::path::Path;

use super::manifest::Manifest;
use super::tuning_hook::TuningHook;
use crate::report::Table;
use crate::study::schema::Study;

/// Write the report of a finished output directory `out` from its final case table `table`
/// and manifest, rerunning cases of `study` (when given) at their tuned values through
/// `tuning`; returns non-fatal warnings.
pub type ReportFn = fn(&Path, &Table, &Manifest, Option<&Study>, Option<TuningHook>) -> Vec<String>;

/// How a sweep or a merge writes its report: the function the caller wires in (the review
/// room's `finish_report`). Without one, the final tables and the manifest are written and
/// no `summary.md`.
#[derive(Clone, Copy)]
pub struct ReportHook(pub ReportFn);

impl ReportHook {
    /// Write the report of `out` (see [`ReportFn`]); returns non-fatal warnings.
    pub fn write(
        &self,
        out: &Path,
        table: &Table,
        manifest: &Manifest,
        study: Option<&Study>,
        tuning: Option<TuningHook>,
    ) -> Vec<String> {
        (self.0)(out, table, manifest, study, tuning)
    }
}

impl fmt::Debug for ReportHook {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("ReportHook")
    }
}
