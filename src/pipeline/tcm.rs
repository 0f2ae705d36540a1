//! The `tcm` pipeline: static configuration-space analysis of the thruster configuration
//! matrix (docs/model.md §6) — how often `T(q)` is singular over the joint space — and its files.
//!
//! Writes to the output directory:
//! - `samples.csv`: one row per sample (streamed; memory stays bounded for any N):
//!   `index`, `q1_rad … qn_rad`, `sigma_min` (scaled σ_min, N per N), `kappa`, `rank`,
//!   `lost_axis` (empty unless σ_min < threshold or rank < 6), then `sigma_min_commanded`
//!   and `kappa_commanded` of the rows the mode's controller commands (docs/model.md §6);
//! - `samples.parquet`: the same table, only when N ≤ [`PARQUET_MAX_ROWS`] (larger tables stay
//!   CSV only);
//! - `summary.json`: the [`StaticSummary`] plus the slice joints and the files written;
//! - `sigma_min_hist.svg`, `sigma_min_commanded_hist.svg`: histograms of the full and the
//!   commanded σ_min; `sigma_min_slice.svg`: σ_min over a 2-D slice
//!   of joint space (the two most influential yaw joints, or the given pair; others 0).
//!
//! Complete or clearly incomplete: a previous `summary.json` is removed first; `samples.csv`
//! is streamed into a temporary file (`.samples.csv.tmp-TOKEN`, removed on an error) and
//! renamed into place when complete; the other files are written atomically; `summary.json`,
//! written last, marks a complete output. A run killed or failing part-way leaves no
//! `summary.json` (and never a `samples.csv` with a row cut in half or rows of two runs).

use std::path::{Path, PathBuf};

use serde::Serialize;

use super::error::{create_dir, PipelineError};
use crate::model::Vehicle;
use crate::report::{
    atomic_write, heatmap, histogram, push_csv_row, read_csv_typed, write_parquet, ColourScale,
    ColumnKind, CsvAppender, Value,
};
use crate::statics::slice::{influential_joints, slice_grid};
use crate::statics::{analyse_text, SampleMetrics, StaticSpec, StaticSummary};

/// Largest sample count for which `samples.parquet` is written.
pub const PARQUET_MAX_ROWS: usize = 200_000;

/// What to analyse and where to write it (validated by the caller against the vehicle:
/// `slice` holds two different joint indices below `n_joints`).
#[derive(Clone, Debug)]
pub struct TcmConfig {
    /// Settings of the static analysis.
    pub spec: StaticSpec,
    /// Output directory (created if missing).
    pub out: PathBuf,
    /// Worker threads (0: all cores). Results do not depend on it.
    pub jobs: usize,
    /// Joints of the 2-D slice plot (0-based); `None`: the two most influential yaw joints.
    pub slice: Option<(usize, usize)>,
    /// Grid resolution of the slice plot per joint.
    pub resolution: usize,
}

#[derive(Serialize)]
struct SummaryFile<'a> {
    #[serde(flatten)]
    summary: &'a StaticSummary,
    slice_joints: Option<[String; 2]>,
    files: Vec<String>,
}

/// The `samples.csv` schema for `n` joints.
fn sample_schema(n: usize) -> Vec<(String, ColumnKind)> {
    let mut schema: Vec<(String, ColumnKind)> = vec![("index".into(), ColumnKind::I64)];
    schema.extend((1..=n).map(|k| (format!("q{k}_rad"), ColumnKind::F64)));
    schema.extend([
        ("sigma_min".to_string(), ColumnKind::F64),
        ("kappa".to_string(), ColumnKind::F64),
        ("rank".to_string(), ColumnKind::I64),
        ("lost_axis".to_string(), ColumnKind::Str),
        ("sigma_min_commanded".to_string(), ColumnKind::F64),
        ("kappa_commanded".to_string(), ColumnKind::F64),
    ]);
    schema
}

/// Runs the static analysis of `vehicle` and writes its files into `config.out` (see the module
/// documentation). `progress` receives the number of samples done. Returns the summary.
pub fn run_tcm(
    vehicle: &Vehicle,
    config: &TcmConfig,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<StaticSummary, PipelineError> {
    if vehicle.n_thrusters() == 0 {
        return Err(PipelineError::NoThrusters {
            design: vehicle.name.clone(),
        });
    }
    let spec = &config.spec;
    spec.validate()?;
    let out = &config.out;
    create_dir(out)?;
    let schema = sample_schema(vehicle.n_joints());
    let summary_path = out.join("summary.json");
    match std::fs::remove_file(&summary_path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
            return Err(crate::report::ReportError::Io {
                path: summary_path,
                action: "removing",
                source: e,
            }
            .into())
        }
        _ => {}
    }
    let csv_path = out.join("samples.csv");
    let tmp_path = out.join(format!(".samples.csv{}", crate::report::temporary_suffix()));
    let result = write_samples(vehicle, config, &schema, &tmp_path, progress);
    let (summary, sigmas, commanded) = match result {
        Ok(r) => r,
        Err(e) => {
            let _ = std::fs::remove_file(&tmp_path);
            return Err(e);
        }
    };
    if let Err(source) = std::fs::rename(&tmp_path, &csv_path) {
        let _ = std::fs::remove_file(&tmp_path);
        return Err(crate::report::ReportError::Io {
            path: csv_path,
            action: "renaming into place",
            source,
        }
        .into());
    }
    write_rest(vehicle, config, &schema, &summary, sigmas, commanded)?;
    Ok(summary)
}

/// The σ_min columns kept for the histograms: the full and the commanded ones.
type Kept = (StaticSummary, Vec<f64>, Vec<f64>);

/// Streams the samples into `path` (flushed) and returns the summary and the kept σ_min columns.
fn write_samples(
    vehicle: &Vehicle,
    config: &TcmConfig,
    schema: &[(String, ColumnKind)],
    path: &Path,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<Kept, PipelineError> {
    let spec = &config.spec;
    let mut app = CsvAppender::create(path, schema)?.batched();
    let mut sigmas: Vec<f64> = Vec::with_capacity(spec.samples);
    let mut commanded: Vec<f64> = Vec::with_capacity(spec.samples);
    // Each worker formats its samples' rows (the bytes `CsvAppender::append` would write);
    // this thread keeps the σ_min columns for the histograms and writes the text in order.
    let format = |index: usize, q: &[f64], m: &SampleMetrics, text: &mut String| {
        let metrics = [
            Value::F64(m.sigma_min),
            Value::F64(m.kappa),
            Value::I64(m.rank as i64),
            Value::Str(m.lost_axis.unwrap_or("")),
            Value::F64(m.sigma_min_commanded),
            Value::F64(m.kappa_commanded),
        ];
        let angles = q.iter().map(|q| Value::F64(*q));
        push_csv_row(
            text,
            [Value::I64(index as i64)]
                .into_iter()
                .chain(angles)
                .chain(metrics),
        );
    };
    let summary = analyse_text(
        vehicle,
        spec,
        config.jobs,
        &format,
        &mut |text| app.append_lines(text).map_err(Into::into),
        &mut |_, _, m| {
            sigmas.push(m.sigma_min);
            commanded.push(m.sigma_min_commanded);
            Ok(())
        },
        progress,
    )?;
    // summary.json, written last (atomically), marks a complete output: no fsync of a file
    // of up to hundreds of MB here.
    app.flush()?;
    drop(app);
    Ok((summary, sigmas, commanded))
}

/// Writes the Parquet table, the plots and, last, `summary.json`.
fn write_rest(
    vehicle: &Vehicle,
    config: &TcmConfig,
    schema: &[(String, ColumnKind)],
    summary: &StaticSummary,
    sigmas: Vec<f64>,
    commanded: Vec<f64>,
) -> Result<(), PipelineError> {
    let (spec, out) = (&config.spec, &config.out);
    let csv_path = out.join("samples.csv");
    let mut files = vec!["samples.csv".to_string()];
    if spec.samples <= PARQUET_MAX_ROWS {
        let t = read_csv_typed(&csv_path, schema)?;
        write_parquet(&t, &out.join("samples.parquet"))?;
        files.push("samples.parquet".into());
    } else {
        // Not written for this many samples: a previous run's table must not stay beside.
        let _ = std::fs::remove_file(out.join("samples.parquet"));
    }
    for (values, file, what) in [
        (sigmas, "sigma_min_hist.svg", "scaled σ_min of T(q)"),
        (
            commanded,
            "sigma_min_commanded_hist.svg",
            &format!(
                "σ_min of the {} rows ({})",
                summary.mode, summary.commanded_axes
            ),
        ),
    ] {
        histogram(
            &values,
            50,
            &format!("{}: {what}, {} samples", vehicle.name, spec.samples),
            "σ_min [N/N]",
        )
        .write_svg(&out.join(file))?;
        files.push(file.into());
    }
    let slice_joints = write_slice(vehicle, config, out, &mut files)?;
    files.push("summary.json".into());
    let json = serde_json::to_string_pretty(&SummaryFile {
        summary,
        slice_joints,
        files,
    })?;
    atomic_write(&out.join("summary.json"), (json + "\n").as_bytes())?;
    Ok(())
}

/// Writes `sigma_min_slice.svg` over the configured (or most influential) pair of joints and
/// returns the pair's names; `None` when the vehicle has fewer than two joints.
fn write_slice(
    vehicle: &Vehicle,
    config: &TcmConfig,
    out: &Path,
    files: &mut Vec<String>,
) -> Result<Option<[String; 2]>, PipelineError> {
    let pair = match config.slice {
        Some(p) => Some(p),
        None => influential_joints(vehicle, &config.spec)?,
    };
    let Some((i, j)) = pair else {
        return Ok(None);
    };
    let g = slice_grid(vehicle, &config.spec, i, j, config.resolution, config.jobs)?;
    let deg = |v: &[f64]| v.iter().map(|x| x.to_degrees()).collect::<Vec<_>>();
    let (ni, nj) = (&vehicle.joints[i].name, &vehicle.joints[j].name);
    heatmap(
        deg(&g.x),
        deg(&g.y),
        g.sigma_min,
        &format!(
            "{}: σ_min over joints {i} ({ni}) and {j} ({nj}), others 0",
            vehicle.name
        ),
        &format!("joint {i} ({ni}) [deg]"),
        &format!("joint {j} ({nj}) [deg]"),
        "σ_min [N/N]",
        ColourScale::Viridis,
    )?
    .write_svg(&out.join("sigma_min_slice.svg"))?;
    files.push("sigma_min_slice.svg".into());
    Ok(Some([ni.clone(), nj.clone()]))
}
