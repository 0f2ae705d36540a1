//! The files of one closed-loop scenario run (`simulate`, and each run of `paper`):
//! `summary.json`, and optionally `timeseries.csv`, `timeseries.parquet` and the paper-style
//! `figure.svg`, and the drawings of the body along the run (`shapes.svg`, `animation.svg`).

use std::path::Path;

use serde_json::json;

use super::error::PipelineError;
use super::run_figure::run_figure;
use crate::allocation::Method;
use crate::control::transport::yaw_joint_mask;
use crate::evaluate::trajectory_table;
use crate::model::Vehicle;
use crate::outcome::RunResult;
use crate::report::{atomic_write, write_csv, write_parquet_with};

/// Sets `allocation.method` in a scenario table (the `--allocation` override, and the paper's
/// allocator comparison).
pub fn set_allocation_method(table: &mut toml::Table, m: Method) {
    if let Some(t) = table
        .entry("allocation")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()))
        .as_table_mut()
    {
        t.insert("method".into(), toml::Value::String(m.name().into()));
    }
}

/// The `summary.json` of a run of `design`: scenario, mode, status, failure, the success
/// verdict (`met`, and the first missed `criterion` with its `detail`, or null), metrics
/// (non-finite values as strings; `success` among them), allocation counts and timing.
fn summary_json(r: &RunResult, design: &str) -> serde_json::Value {
    let metrics: serde_json::Map<String, serde_json::Value> = r
        .metrics
        .iter()
        .map(|(k, v)| {
            (
                k.clone(),
                if v.is_finite() {
                    json!(v)
                } else {
                    json!(v.to_string())
                },
            )
        })
        .collect();
    json!({
        "scenario": r.name,
        "mode": r.mode.to_string(),
        "design": design,
        "status": if r.failure.is_some() { "failed" } else { "ok" },
        "failure": r.failure.as_ref().map(|(t, c)| json!({"time": t, "cause": c})),
        "success": {
            "met": r.missed.is_none(),
            "criterion": r.missed.as_ref().map(|m| m.criterion.as_str()),
            "detail": r.missed.as_ref().map(|m| m.detail.as_str()),
        },
        "metrics": metrics,
        "allocation": r.allocation_counts,
        "timing": r.timing,
    })
}

/// Which optional files of a run to write (`summary.json` is always written).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RunFiles {
    /// `timeseries.csv` and `timeseries.parquet` (about 2 MB per paper run).
    pub timeseries: bool,
    /// The paper-style figure `figure.svg` (only when the run logged samples).
    pub figure: bool,
    /// The body along the run, `shapes.svg` and `animation.svg` ([`super::shapes`]; only
    /// when the run logged samples).
    pub shapes: bool,
}

/// Writes `summary.json` and the chosen `files` of a run of `vehicle` into `out`, which must
/// exist.
pub fn write_run_outputs(
    r: &RunResult,
    out: &Path,
    vehicle: &Vehicle,
    files: RunFiles,
) -> Result<(), PipelineError> {
    let table = trajectory_table(&r.trajectory)?;
    if files.timeseries {
        write_csv(&table, &out.join("timeseries.csv"))?;
        // The channels' units and meanings travel with the Parquet file.
        let meta = crate::study::dictionary::parquet_metadata(&table, &[]);
        write_parquet_with(&table, &out.join("timeseries.parquet"), &meta)?;
    }
    let text = serde_json::to_string_pretty(&summary_json(r, &vehicle.name))?;
    atomic_write(&out.join("summary.json"), text.as_bytes())?;
    if files.figure && table.n_rows() > 0 {
        let yaw_joints: Vec<usize> = yaw_joint_mask(vehicle)
            .iter()
            .enumerate()
            .filter(|(_, y)| **y)
            .map(|(i, _)| i)
            .collect();
        let fig = run_figure(
            &table,
            r.mode,
            &yaw_joints,
            &format!("{} ({} mode)", r.name, r.mode),
        )?;
        fig.write_svg(&out.join("figure.svg"))?;
    }
    if files.shapes {
        super::shapes::write_shapes(r, vehicle, out)?;
    }
    Ok(())
}
