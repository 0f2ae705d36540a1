//! The batch engine: resolving cases, running them in parallel, streaming rows, resuming,
//! sharding, merging and writing the final tables.
//!
//! Files in the output directory:
//! - `cases.partial.csv`: one raw row per finished case, appended and flushed as cases complete
//!   (in completion order; scenario metrics packed in one `scenario_metrics` column as
//!   `name=value;…`). `--resume` reads it; at the end it is compacted (sorted by case id,
//!   deduplicated by hash, rows of other study versions dropped). `merge` reads it.
//! - `cases.csv`, `cases.parquet`: the final table, sorted by case id: `case_id`, `hash`, one
//!   column per axis, the metrics, `status` (`ok`, `failed`, `skipped`), `reason`. No times.
//! - `manifest.json`: provenance, counts, timings, the raw schema and the report settings.
//! - `study.toml`: a copy of the study file.
//!
//! Determinism: a case's row depends only on the study and the case id (per-case seed
//! `derive_seed(study_seed, case_id)`, no parallel reductions), and rows are sorted by id,
//! so `cases.csv` is bit-identical for any `--jobs` and any sharding.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::Instant;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use super::doe::{case_count, expand, Case};
use super::runner::{self, Worker};
use super::schema::{hex, ReportSettings, Study, Target};
use super::static_tcm::{analyse, StaticSpec};
use super::StudyError;
use crate::input::keypath::{set, Seg};
use crate::metrics::singularity::AXIS_NAMES;
use crate::model::design::{design_to_toml, parse_design_table};
use crate::model::Vehicle;
use crate::report::{
    read_csv_typed, write_csv, write_parquet, Column, ColumnData, ColumnKind, CsvAppender, Table,
    Value,
};
use crate::sampling::{derive_seed, Sampling};

/// Columns describing the built design (always present).
pub const DESIGN_COLUMNS: [&str; 5] = [
    "design_bodies",
    "design_joints",
    "design_thrusters",
    "design_length_m",
    "design_mass_kg",
];

/// Static TCM metric columns (present when the static analysis runs).
pub const TCM_COLUMNS: [&str; 15] = [
    "tcm_singular_fraction",
    "tcm_rank_deficient_fraction",
    "tcm_sigma_min_min",
    "tcm_sigma_min_p05",
    "tcm_sigma_min_p50",
    "tcm_sigma_min_mean",
    "tcm_kappa_p50",
    "tcm_kappa_p95",
    "tcm_straight_sigma_min",
    "tcm_lost_surge",
    "tcm_lost_sway",
    "tcm_lost_heave",
    "tcm_lost_roll",
    "tcm_lost_pitch",
    "tcm_lost_yaw",
];

/// Raw column packing the scenario metrics of dynamic modes.
pub const SCENARIO_METRICS_COLUMN: &str = "scenario_metrics";

/// Fixed leading columns of the raw (partial) table.
const RAW_HEAD: [&str; 4] = ["case_id", "hash", "status", "reason"];

/// A case with every override applied.
#[derive(Clone, Debug, PartialEq)]
pub struct Resolved {
    /// Design table.
    pub design: toml::Table,
    /// Scenario-side table (defaults filled in).
    pub scenario: toml::Table,
    /// Case seed `derive_seed(study_seed, case_id)`.
    pub seed: u64,
    /// Stable case hash (hex, 128 bits).
    pub hash: String,
    /// Hash of the design table alone (vehicle cache key).
    pub design_hash: String,
}

/// Canonical text of a table: keys sorted, floats by their bits; stable across runs and
/// platforms and independent of map ordering.
pub fn canonical_table(t: &toml::Table, out: &mut String) {
    let mut keys: Vec<&String> = t.keys().collect();
    keys.sort();
    out.push('{');
    for k in keys {
        out.push_str(&format!("{k:?}="));
        canonical_value(&t[k], out);
        out.push(';');
    }
    out.push('}');
}

fn canonical_value(v: &toml::Value, out: &mut String) {
    match v {
        toml::Value::String(s) => out.push_str(&format!("s{s:?}")),
        toml::Value::Integer(i) => out.push_str(&format!("i{i}")),
        toml::Value::Float(f) => out.push_str(&format!("f{:016x}", f.to_bits())),
        toml::Value::Boolean(b) => out.push_str(if *b { "T" } else { "F" }),
        toml::Value::Datetime(d) => out.push_str(&format!("d{d}")),
        toml::Value::Array(a) => {
            out.push('[');
            for x in a {
                canonical_value(x, out);
                out.push(',');
            }
            out.push(']');
        }
        toml::Value::Table(t) => canonical_table(t, out),
    }
}

fn sha_hex(parts: &[&[u8]]) -> String {
    let mut h = Sha256::new();
    for p in parts {
        h.update(p);
        h.update([0]);
    }
    hex(&h.finalize()[..16])
}

/// Apply a case's overrides to the study's tables. `Err` is the reason the case is skipped
/// (an index beyond an array, a design the generator cannot build for thruster overrides).
pub fn resolve_case(study: &Study, case: &Case) -> Result<Resolved, String> {
    let mut design = study.design.clone();
    let mut scenario = study.scenario_full.clone();
    let mut thruster_edits = Vec::new();
    for (a, v) in study.axes.iter().zip(&case.values) {
        match &a.target {
            Target::Design(p) => {
                if matches!(p.0.first(), Some(Seg::Key(k)) if k == "thruster") {
                    thruster_edits.push((a, p, v));
                } else {
                    set(&mut design, &p.0, v.clone(), &a.name)?;
                }
            }
            Target::Scenario(p) => set(&mut scenario, &p.0, v.clone(), &a.name)?,
        }
    }
    if !thruster_edits.is_empty() && study.generator && !design.contains_key("thruster") {
        // Write the generated thrusters out so that they can be edited one by one.
        let v = parse_design_table(&design, "generated design").map_err(|e| e.to_string())?;
        let explicit: toml::Table =
            toml::from_str(&design_to_toml(&v)).map_err(|e| e.to_string())?;
        if let Some(t) = explicit.get("thruster") {
            design.insert("thruster".into(), t.clone());
        } else {
            design.insert("thruster".into(), toml::Value::Array(Vec::new()));
        }
    }
    for (a, p, v) in thruster_edits {
        set(&mut design, &p.0, v.clone(), &a.name)?;
    }
    let seed = derive_seed(study.seed, case.id as u64);
    let mut d = String::new();
    canonical_table(&design, &mut d);
    let mut s = String::new();
    canonical_table(&scenario, &mut s);
    let version = env!("CARGO_PKG_VERSION").as_bytes();
    let hash = sha_hex(&[
        b"usm-study case v1",
        version,
        d.as_bytes(),
        s.as_bytes(),
        &seed.to_le_bytes(),
    ]);
    let design_hash = sha_hex(&[b"design", d.as_bytes()]);
    Ok(Resolved {
        design,
        scenario,
        seed,
        hash,
        design_hash,
    })
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StaticFile {
    samples: Option<usize>,
    threshold: Option<f64>,
    sampling: Option<String>,
    char_length: Option<f64>,
    rank_rel_tol: Option<f64>,
}

/// The static-analysis settings of a resolved scenario-side table (`[static]`, with
/// `metrics.char_length` as the fallback characteristic length), seeded with `seed`.
pub fn static_spec(scenario: &toml::Table, seed: u64) -> Result<StaticSpec, String> {
    let t = scenario
        .get("static")
        .cloned()
        .unwrap_or(toml::Value::Table(toml::Table::new()));
    let f = StaticFile::deserialize(t).map_err(|e| format!("[static]: {}", e.message().trim()))?;
    let d = StaticSpec::default();
    let sampling: Sampling = match &f.sampling {
        Some(s) => s.parse().map_err(|m| format!("static.sampling: {m}"))?,
        None => Sampling::Sobol,
    };
    let metrics_l = scenario
        .get("metrics")
        .and_then(|m| m.get("char_length"))
        .and_then(|v| v.as_float().or(v.as_integer().map(|i| i as f64)))
        .filter(|l| *l > 0.0);
    let char_length = match f.char_length {
        Some(l) if l != 0.0 => Some(l),
        _ => metrics_l,
    };
    let spec = StaticSpec {
        samples: f.samples.unwrap_or(256),
        seed,
        threshold: f.threshold.unwrap_or(d.threshold),
        sampling,
        char_length,
        rank_rel_tol: f.rank_rel_tol.unwrap_or(d.rank_rel_tol),
        worst: 0,
    };
    spec.validate().map_err(|e| e.to_string())?;
    Ok(spec)
}

/// The raw (partial-file) schema of a study.
pub fn raw_schema(study: &Study) -> Vec<(String, ColumnKind)> {
    let mut s: Vec<(String, ColumnKind)> = vec![
        ("case_id".into(), ColumnKind::I64),
        ("hash".into(), ColumnKind::Str),
        ("status".into(), ColumnKind::Str),
        ("reason".into(), ColumnKind::Str),
    ];
    for a in &study.axes {
        let k = if a.numeric {
            ColumnKind::F64
        } else {
            ColumnKind::Str
        };
        s.push((a.name.clone(), k));
    }
    s.extend(
        DESIGN_COLUMNS
            .iter()
            .map(|c| (c.to_string(), ColumnKind::F64)),
    );
    if study.static_enabled {
        s.extend(TCM_COLUMNS.iter().map(|c| (c.to_string(), ColumnKind::F64)));
    }
    if runner::is_dynamic(&study.mode) {
        s.push((SCENARIO_METRICS_COLUMN.into(), ColumnKind::Str));
    }
    s
}

/// Text of a non-numeric axis value.
pub fn axis_text(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

fn axis_number(v: &toml::Value) -> f64 {
    match v {
        toml::Value::Float(f) => *f,
        toml::Value::Integer(i) => *i as f64,
        _ => f64::NAN,
    }
}

/// One finished case, as written to the partial file.
#[derive(Clone, Debug)]
pub struct Row {
    /// Case id.
    pub id: usize,
    /// Case hash.
    pub hash: String,
    /// `ok`, `failed` or `skipped`.
    pub status: &'static str,
    /// Why it failed or was skipped (single line).
    pub reason: String,
    /// Axis values.
    pub axes: Vec<toml::Value>,
    /// Design and TCM metrics, in raw-schema order (NaN when not computed).
    pub metrics: Vec<f64>,
    /// Packed scenario metrics.
    pub scenario: String,
}

impl Row {
    fn values<'a>(&'a self, study: &Study, texts: &'a [String]) -> Vec<Value<'a>> {
        let mut v: Vec<Value<'a>> = vec![
            Value::I64(self.id as i64),
            Value::Str(&self.hash),
            Value::Str(self.status),
            Value::Str(&self.reason),
        ];
        for ((a, x), t) in study.axes.iter().zip(&self.axes).zip(texts) {
            v.push(if a.numeric {
                Value::F64(axis_number(x))
            } else {
                Value::Str(t)
            });
        }
        v.extend(self.metrics.iter().map(|m| Value::F64(*m)));
        if runner::is_dynamic(&study.mode) {
            v.push(Value::Str(&self.scenario));
        }
        v
    }
}

fn one_line(s: &str) -> String {
    s.replace(['\n', '\r'], " ")
}

/// Per-worker state: the scenario worker and a one-entry vehicle cache.
pub struct WorkerState {
    runner: Worker,
    cache: Option<(String, Vehicle)>,
}

impl WorkerState {
    /// A fresh worker.
    pub fn new() -> Self {
        Self {
            runner: Worker::new(),
            cache: None,
        }
    }
}

impl Default for WorkerState {
    fn default() -> Self {
        Self::new()
    }
}

/// Evaluate a resolved case; returns the row and (with `log`) the trajectory.
pub fn evaluate(
    study: &Study,
    case: &Case,
    r: &Resolved,
    w: &mut WorkerState,
    log: bool,
) -> (Row, Option<Table>) {
    let n_metrics = DESIGN_COLUMNS.len()
        + if study.static_enabled {
            TCM_COLUMNS.len()
        } else {
            0
        };
    let mut row = Row {
        id: case.id,
        hash: r.hash.clone(),
        status: "ok",
        reason: String::new(),
        axes: case.values.clone(),
        metrics: vec![f64::NAN; n_metrics],
        scenario: String::new(),
    };
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        evaluate_inner(study, case, r, w, log, &mut row)
    }));
    match result {
        Ok(traj) => (row, traj),
        Err(p) => {
            let msg = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            row.status = "failed";
            row.reason = one_line(&format!("panic: {msg}"));
            w.cache = None;
            (row, None)
        }
    }
}

fn evaluate_inner(
    study: &Study,
    case: &Case,
    r: &Resolved,
    w: &mut WorkerState,
    log: bool,
    row: &mut Row,
) -> Option<Table> {
    let cached = matches!(&w.cache, Some((h, _)) if *h == r.design_hash);
    if !cached {
        match parse_design_table(&r.design, &format!("case {} design", case.id)) {
            Ok(v) => w.cache = Some((r.design_hash.clone(), v)),
            Err(e) => {
                row.status = "skipped";
                row.reason = one_line(&format!("invalid design: {e}"));
                return None;
            }
        }
    }
    let v = &w.cache.as_ref()?.1;
    row.metrics[..5].copy_from_slice(&[
        v.bodies.len() as f64,
        v.n_joints() as f64,
        v.n_thrusters() as f64,
        v.total_length(),
        v.total_mass(),
    ]);
    if study.static_enabled {
        let spec = match static_spec(&r.scenario, derive_seed(r.seed, 1)) {
            Ok(s) => s,
            Err(m) => {
                row.status = "skipped";
                row.reason = one_line(&m);
                return None;
            }
        };
        match analyse(v, &spec, 1, &mut |_| Ok(()), &|_| {}) {
            Ok(s) => {
                let q = |p| s.sigma_min_quantile(p).unwrap_or(f64::NAN);
                let kq = |p: f64| {
                    s.kappa
                        .quantiles
                        .iter()
                        .find(|(l, _)| *l == p)
                        .map_or(f64::NAN, |x| x.1)
                };
                let mut m = vec![
                    s.singular_fraction,
                    s.rank_deficient_fraction,
                    s.sigma_min.min,
                    q(0.05),
                    q(0.5),
                    s.sigma_min.mean,
                    kq(0.5),
                    kq(0.95),
                    s.straight.sigma_min,
                ];
                m.extend(s.lost_axes.iter().map(|a| a.fraction));
                debug_assert_eq!(m.len(), TCM_COLUMNS.len());
                debug_assert_eq!(AXIS_NAMES.len(), 6);
                row.metrics[5..].copy_from_slice(&m);
            }
            Err(e) => {
                row.status = "failed";
                row.reason = one_line(&e.to_string());
                return None;
            }
        }
    }
    if runner::is_dynamic(&study.mode) {
        let mut sc = r.scenario.clone();
        sc.remove("static");
        match w.runner.run(v, &sc, r.seed, log) {
            Ok(out) => {
                if let Some(f) = &out.failure {
                    row.status = "failed";
                    row.reason = one_line(f);
                }
                let mut packed = String::new();
                for (name, x) in &out.metrics {
                    let clean: String = name
                        .chars()
                        .map(|c| {
                            if c == '=' || c == ';' || c.is_whitespace() {
                                '_'
                            } else {
                                c
                            }
                        })
                        .collect();
                    if !packed.is_empty() {
                        packed.push(';');
                    }
                    packed.push_str(&clean);
                    packed.push('=');
                    packed.push_str(&crate::report::format_f64(*x));
                }
                row.scenario = packed;
                return out.trajectory;
            }
            Err(m) => {
                row.status = "failed";
                row.reason = one_line(&m);
            }
        }
    }
    None
}

/// Options of a sweep run.
#[derive(Clone, Debug, Default)]
pub struct SweepOptions {
    /// Worker threads (0: all cores).
    pub jobs: usize,
    /// Skip cases already in the partial file.
    pub resume: bool,
    /// Run only case ids `≡ index (mod count)`: `(index, count)`.
    pub shard: Option<(usize, usize)>,
    /// Output directory (default: the study's, with `shard-I-of-N` appended for shards).
    pub out: Option<PathBuf>,
    /// Stop after running this many cases (testing interruptions; no final outputs).
    pub max_cases: Option<usize>,
}

/// Progress of a sweep, reported after every finished case.
#[derive(Clone, Copy, Debug)]
pub struct ProgressEvent {
    /// Cases finished, including resumed ones.
    pub finished: usize,
    /// Cases of this run (shard).
    pub total: usize,
    /// Cases actually run.
    pub ran: usize,
    /// Cases taken from a previous run.
    pub resumed: usize,
}

/// The outcome of a sweep.
#[derive(Clone, Debug, Default)]
pub struct SweepOutcome {
    /// Output directory.
    pub out: PathBuf,
    /// Cases of the study.
    pub planned: usize,
    /// Cases of this shard.
    pub in_shard: usize,
    /// Counts by status.
    pub ok: usize,
    /// Failed cases.
    pub failed: usize,
    /// Skipped cases.
    pub skipped: usize,
    /// Cases taken from a previous run.
    pub resumed: usize,
    /// Cases run now.
    pub ran: usize,
    /// Stopped early by `max_cases` (no final outputs written).
    pub interrupted: bool,
    /// Wall time [s].
    pub elapsed_s: f64,
    /// Problems with the report (plots etc.), not fatal.
    pub warnings: Vec<String>,
}

/// Column kinds as text in the manifest.
fn kind_name(k: ColumnKind) -> String {
    k.to_string()
}

fn kind_of(s: &str) -> Option<ColumnKind> {
    Some(match s {
        "f64" => ColumnKind::F64,
        "i64" => ColumnKind::I64,
        "str" => ColumnKind::Str,
        "bool" => ColumnKind::Bool,
        _ => return None,
    })
}

/// An axis as recorded in the manifest.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct AxisInfo {
    /// Name (column).
    pub name: String,
    /// Numeric column.
    pub numeric: bool,
}

/// Case counts of a manifest.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, Default)]
pub struct Counts {
    /// Cases of the study.
    pub planned: usize,
    /// Cases in this output (shard or merge).
    pub in_output: usize,
    /// `ok` rows.
    pub ok: usize,
    /// `failed` rows.
    pub failed: usize,
    /// `skipped` rows.
    pub skipped: usize,
    /// Cases taken from a previous run.
    pub resumed: usize,
    /// Cases run by this invocation.
    pub ran: usize,
}

/// `manifest.json`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Manifest {
    /// Tool name.
    pub tool: String,
    /// Tool version.
    pub tool_version: String,
    /// `git rev-parse HEAD` of the working directory, when available.
    pub git_commit: Option<String>,
    /// Study name.
    pub study_name: String,
    /// Description.
    pub description: String,
    /// Study file (absolute when known).
    pub study_file: String,
    /// Study hash.
    pub study_hash: String,
    /// Study seed.
    pub seed: u64,
    /// Scenario mode.
    pub mode: String,
    /// Whether the static analysis ran.
    pub static_analysis: bool,
    /// Design of experiments (`grid`, `sobol`, …).
    pub doe: String,
    /// Start time (UTC, RFC 3339).
    pub start_time: String,
    /// End time (UTC, RFC 3339).
    pub end_time: String,
    /// Wall time [s].
    pub elapsed_s: f64,
    /// Cases run per second of wall time.
    pub throughput_cases_per_s: f64,
    /// Worker threads.
    pub jobs: usize,
    /// `[index, count]` for a shard.
    pub shard: Option<[usize; 2]>,
    /// Merged output directories (for `merge`).
    pub merged_from: Vec<String>,
    /// Case counts.
    pub cases: Counts,
    /// Raw (partial-file) schema: `[name, kind]`.
    pub columns: Vec<[String; 2]>,
    /// Axes.
    pub axes: Vec<AxisInfo>,
    /// Report settings.
    pub report: ReportSettings,
}

impl Manifest {
    /// The raw schema.
    pub fn schema(&self) -> Result<Vec<(String, ColumnKind)>, String> {
        self.columns
            .iter()
            .map(|[n, k]| {
                kind_of(k)
                    .map(|k| (n.clone(), k))
                    .ok_or_else(|| format!("unknown column kind `{k}`"))
            })
            .collect()
    }
}

/// Current UTC time as RFC 3339 (seconds).
pub fn now_rfc3339() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs() as i64);
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    // Civil from days (H. Hinnant).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem / 60 % 60,
        rem % 60
    )
}

fn git_commit() -> Option<String> {
    let out = std::process::Command::new("git")
        .args(["rev-parse", "HEAD"])
        .stderr(std::process::Stdio::null())
        .output()
        .ok()?;
    let s = String::from_utf8(out.stdout).ok()?.trim().to_string();
    (out.status.success() && s.len() >= 7).then_some(s)
}

fn io_err(path: &Path, e: std::io::Error) -> StudyError {
    StudyError::Io {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// The output directory of a sweep.
pub fn output_dir(study: &Study, opts: &SweepOptions) -> PathBuf {
    match (&opts.out, opts.shard) {
        (Some(o), _) => o.clone(),
        (None, Some((i, n))) => study.output.join(format!("shard-{i}-of-{n}")),
        (None, None) => study.output.clone(),
    }
}

enum Msg {
    Resumed(String),
    Row(Box<Row>),
    NotRun,
}

/// Run a sweep: every case of the study (or shard) in parallel, streaming rows to
/// `cases.partial.csv`, then the final tables, the manifest and (unless sharded) the report.
pub fn run_sweep(
    study: &Study,
    opts: &SweepOptions,
    progress: &mut dyn FnMut(&ProgressEvent),
) -> Result<SweepOutcome, StudyError> {
    let t0 = Instant::now();
    let start_time = now_rfc3339();
    if let Some((i, n)) = opts.shard {
        if n == 0 || i >= n {
            return Err(StudyError::Input(format!(
                "--shard {i}/{n}: need 0 <= I < N"
            )));
        }
    }
    let cases = expand(study, opts.shard).map_err(StudyError::Input)?;
    let out = output_dir(study, opts);
    std::fs::create_dir_all(&out).map_err(|e| io_err(&out, e))?;
    std::fs::write(out.join("study.toml"), &study.text).map_err(|e| io_err(&out, e))?;
    let schema = raw_schema(study);
    let partial = out.join("cases.partial.csv");
    let mut done: HashSet<String> = HashSet::new();
    let mut appender = if opts.resume {
        let app = CsvAppender::open_or_create(&partial, &schema).map_err(|e| {
            StudyError::Input(format!(
                "cannot resume from {}: {e} (the study's axes or mode changed? run without --resume or use another --out)",
                partial.display()
            ))
        })?;
        if app.rows_written() > 0 {
            let t = read_csv_typed(&partial, &schema)?;
            done.extend(t.str("hash")?.iter().cloned());
        }
        app
    } else {
        CsvAppender::create(&partial, &schema)?
    };
    let jobs = if opts.jobs == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        opts.jobs
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .map_err(|e| StudyError::Other(format!("thread pool: {e}")))?;
    let total = cases.len();
    let cancel = AtomicBool::new(false);
    let started = AtomicUsize::new(0);
    let max = opts.max_cases.unwrap_or(usize::MAX);
    let mut plan_hashes: HashSet<String> = HashSet::with_capacity(total);
    let mut ev = ProgressEvent {
        finished: 0,
        total,
        ran: 0,
        resumed: 0,
    };
    let mut not_run = 0usize;
    let mut write_error: Option<StudyError> = None;
    let (mut ok, mut failed, mut skipped) = (0, 0, 0);
    std::thread::scope(|s| {
        let (tx, rx) = mpsc::channel::<Msg>();
        let (cases, done, cancel, started) = (&cases, &done, &cancel, &started);
        let pool = &pool;
        s.spawn(move || {
            pool.install(|| {
                cases.par_iter().for_each_init(
                    || (tx.clone(), WorkerState::new()),
                    |(tx, w), case| {
                        let msg = process(study, case, w, done, cancel, started, max);
                        let _ = tx.send(msg);
                    },
                );
            });
            drop(tx);
        });
        for msg in rx {
            match msg {
                Msg::Resumed(h) => {
                    plan_hashes.insert(h);
                    ev.resumed += 1;
                }
                Msg::Row(row) => {
                    plan_hashes.insert(row.hash.clone());
                    ev.ran += 1;
                    match row.status {
                        "ok" => ok += 1,
                        "failed" => failed += 1,
                        _ => skipped += 1,
                    }
                    if write_error.is_none() {
                        let texts: Vec<String> = row.axes.iter().map(axis_text).collect();
                        if let Err(e) = appender.append(&row.values(study, &texts)) {
                            write_error = Some(e.into());
                            cancel.store(true, Ordering::Relaxed);
                        }
                    }
                }
                Msg::NotRun => {
                    not_run += 1;
                    continue;
                }
            }
            ev.finished = ev.ran + ev.resumed;
            progress(&ev);
        }
    });
    if let Some(e) = write_error {
        return Err(e);
    }
    let _ = appender.sync();
    drop(appender);
    let mut outcome = SweepOutcome {
        out: out.clone(),
        planned: case_count(study),
        in_shard: total,
        resumed: ev.resumed,
        ran: ev.ran,
        interrupted: not_run > 0,
        ..Default::default()
    };
    if outcome.interrupted {
        outcome.ok = ok;
        outcome.failed = failed;
        outcome.skipped = skipped;
        outcome.elapsed_s = t0.elapsed().as_secs_f64();
        return Ok(outcome);
    }
    // Final tables from the partial file.
    let raw = read_csv_typed(&partial, &schema)?;
    let raw = compact(&raw, Some(&plan_hashes))?;
    write_csv(&raw, &partial)?;
    let table = final_table(&raw)?;
    write_csv(&table, &out.join("cases.csv"))?;
    write_parquet(&table, &out.join("cases.parquet"))?;
    let status = table.str("status")?;
    outcome.ok = status.iter().filter(|s| *s == "ok").count();
    outcome.failed = status.iter().filter(|s| *s == "failed").count();
    outcome.skipped = status.iter().filter(|s| *s == "skipped").count();
    let elapsed = t0.elapsed().as_secs_f64();
    outcome.elapsed_s = elapsed;
    let manifest = Manifest {
        tool: "usm-study".into(),
        tool_version: env!("CARGO_PKG_VERSION").into(),
        git_commit: git_commit(),
        study_name: study.name.clone(),
        description: study.description.clone(),
        study_file: std::fs::canonicalize(&study.path)
            .unwrap_or_else(|_| study.path.clone())
            .display()
            .to_string(),
        study_hash: study.hash.clone(),
        seed: study.seed,
        mode: study.mode.clone(),
        static_analysis: study.static_enabled,
        doe: match study.doe {
            super::schema::Doe::Grid => "grid".into(),
            super::schema::Doe::Sampled { kind, .. } => kind.to_string(),
        },
        start_time,
        end_time: now_rfc3339(),
        elapsed_s: elapsed,
        throughput_cases_per_s: if elapsed > 0.0 {
            ev.ran as f64 / elapsed
        } else {
            0.0
        },
        jobs,
        shard: opts.shard.map(|(i, n)| [i, n]),
        merged_from: Vec::new(),
        cases: Counts {
            planned: outcome.planned,
            in_output: table.n_rows(),
            ok: outcome.ok,
            failed: outcome.failed,
            skipped: outcome.skipped,
            resumed: ev.resumed,
            ran: ev.ran,
        },
        columns: schema
            .iter()
            .map(|(n, k)| [n.clone(), kind_name(*k)])
            .collect(),
        axes: study
            .axes
            .iter()
            .map(|a| AxisInfo {
                name: a.name.clone(),
                numeric: a.numeric,
            })
            .collect(),
        report: study.report.clone(),
    };
    write_manifest(&out, &manifest)?;
    if opts.shard.is_none() {
        // Inside the sweep's pool, so the best/worst reruns respect --jobs.
        outcome.warnings = pool.install(|| finish_report(&out, &table, &manifest, Some(study)));
    }
    Ok(outcome)
}

fn process(
    study: &Study,
    case: &Case,
    w: &mut WorkerState,
    done: &HashSet<String>,
    cancel: &AtomicBool,
    started: &AtomicUsize,
    max: usize,
) -> Msg {
    if cancel.load(Ordering::Relaxed) {
        return Msg::NotRun;
    }
    let resolved = resolve_case(study, case);
    let hash = match &resolved {
        Ok(r) => r.hash.clone(),
        Err(_) => unresolved_hash(study, case),
    };
    if done.contains(&hash) {
        return Msg::Resumed(hash);
    }
    if started.fetch_add(1, Ordering::Relaxed) >= max {
        return Msg::NotRun;
    }
    let row = match resolved {
        Ok(r) => evaluate(study, case, &r, w, false).0,
        Err(reason) => {
            let n = DESIGN_COLUMNS.len()
                + if study.static_enabled {
                    TCM_COLUMNS.len()
                } else {
                    0
                };
            Row {
                id: case.id,
                hash,
                status: "skipped",
                reason: one_line(&reason),
                axes: case.values.clone(),
                metrics: vec![f64::NAN; n],
                scenario: String::new(),
            }
        }
    };
    Msg::Row(Box::new(row))
}

/// Hash of a case whose overrides could not be applied: the study hash, the id and the
/// axis values.
fn unresolved_hash(study: &Study, case: &Case) -> String {
    let mut s = String::new();
    for v in &case.values {
        canonical_value(v, &mut s);
    }
    sha_hex(&[
        b"usm-study unresolved case v1",
        study.hash.as_bytes(),
        &(case.id as u64).to_le_bytes(),
        s.as_bytes(),
    ])
}

fn write_manifest(dir: &Path, m: &Manifest) -> Result<(), StudyError> {
    let text = serde_json::to_string_pretty(m).map_err(|e| StudyError::Other(e.to_string()))?;
    let p = dir.join("manifest.json");
    std::fs::write(&p, text + "\n").map_err(|e| io_err(&p, e))
}

/// Read `manifest.json` of an output directory.
pub fn read_manifest(dir: &Path) -> Result<Manifest, StudyError> {
    let p = dir.join("manifest.json");
    let text = std::fs::read_to_string(&p).map_err(|e| {
        StudyError::Input(format!(
            "{}: {e} (is {} a finished sweep output? an unfinished one can be completed with --resume)",
            p.display(),
            dir.display()
        ))
    })?;
    serde_json::from_str(&text).map_err(|e| StudyError::Input(format!("{}: {e}", p.display())))
}

/// Sort raw rows by case id, drop duplicates (by hash, first kept) and, when `keep` is
/// given, rows whose hash is not in it.
pub fn compact(raw: &Table, keep: Option<&HashSet<String>>) -> Result<Table, StudyError> {
    let ids = raw.i64("case_id")?;
    let hashes = raw.str("hash")?;
    let mut order: Vec<usize> = (0..raw.n_rows())
        .filter(|&i| keep.is_none_or(|k| k.contains(&hashes[i])))
        .collect();
    order.sort_by(|&a, &b| {
        ids[a]
            .cmp(&ids[b])
            .then(hashes[a].cmp(&hashes[b]))
            .then(a.cmp(&b))
    });
    let mut seen = HashSet::new();
    order.retain(|&i| seen.insert(hashes[i].as_str()));
    Ok(raw.select_rows(&order)?)
}

/// The final table from compacted raw rows: `case_id`, `hash`, axes and metrics (scenario
/// metrics unpacked into columns in order of first appearance), `status`, `reason`.
pub fn final_table(raw: &Table) -> Result<Table, StudyError> {
    let mut cols: Vec<Column> = Vec::new();
    let get = |n: &str| raw.column(n).cloned();
    for n in ["case_id", "hash"] {
        cols.extend(get(n));
    }
    let mut packed: Option<&[String]> = None;
    for c in &raw.columns {
        if RAW_HEAD.contains(&c.name.as_str()) {
            continue;
        }
        if c.name == SCENARIO_METRICS_COLUMN {
            packed = Some(raw.str(&c.name)?);
            continue;
        }
        cols.push(c.clone());
    }
    if let Some(p) = packed {
        let mut names: Vec<String> = Vec::new();
        let mut index: HashMap<String, usize> = HashMap::new();
        let parsed: Vec<Vec<(usize, f64)>> = p
            .iter()
            .map(|s| {
                s.split(';')
                    .filter(|x| !x.is_empty())
                    .filter_map(|kv| {
                        let (k, v) = kv.split_once('=')?;
                        let i = *index.entry(k.to_string()).or_insert_with(|| {
                            names.push(k.to_string());
                            names.len() - 1
                        });
                        Some((i, v.parse::<f64>().unwrap_or(f64::NAN)))
                    })
                    .collect()
            })
            .collect();
        let mut data = vec![vec![f64::NAN; p.len()]; names.len()];
        for (r, kvs) in parsed.iter().enumerate() {
            for &(i, x) in kvs {
                data[i][r] = x;
            }
        }
        for (n, d) in names.into_iter().zip(data) {
            if raw.column(&n).is_some() || cols.iter().any(|c| c.name == n) {
                continue;
            }
            cols.push(Column {
                name: n,
                data: ColumnData::F64(d),
            });
        }
    }
    for n in ["status", "reason"] {
        cols.extend(get(n));
    }
    Ok(Table::from_columns(cols)?)
}

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
        if runner::is_dynamic(&study.mode) {
            if let Err(e) = rerun_extremes(out, table, manifest, study) {
                warnings.push(format!("time series of the best/worst case: {e}"));
            }
        }
    }
    warnings.extend(super::summary::write_report(out, table, manifest));
    warnings
}

fn rerun_extremes(
    out: &Path,
    table: &Table,
    manifest: &Manifest,
    study: &Study,
) -> Result<(), String> {
    let sel = super::summary::Selection::new(table, manifest);
    let Some((best, worst)) = sel.extremes(table) else {
        return Ok(());
    };
    let ids = table.i64("case_id").map_err(|e| e.to_string())?;
    let all = expand(study, None)?;
    // The two reruns are independent: run them side by side.
    let rerun = |label: &str, row: usize| -> Result<(), String> {
        let id = ids[row] as usize;
        let case = all.get(id).ok_or("case id out of range")?;
        let r = resolve_case(study, case)?;
        let (_, traj) = evaluate(study, case, &r, &mut WorkerState::new(), true);
        if let Some(t) = traj {
            write_csv(&t, &out.join(format!("trajectory_{label}.csv")))
                .map_err(|e| e.to_string())?;
        }
        Ok(())
    };
    let (a, b) = rayon::join(|| rerun("best", best), || rerun("worst", worst));
    a.and(b)
}

/// Merge shard outputs into `out`: check they come from the same study, concatenate their raw
/// rows, sort by case id, deduplicate by hash, and write the final tables, manifest and report.
pub fn merge(dirs: &[PathBuf], out: &Path) -> Result<(Manifest, Vec<String>), StudyError> {
    let t0 = Instant::now();
    let start_time = now_rfc3339();
    let first_dir = dirs
        .first()
        .ok_or_else(|| StudyError::Input("merge needs at least one directory".into()))?;
    let manifests: Vec<Manifest> = dirs
        .iter()
        .map(|d| read_manifest(d))
        .collect::<Result<_, _>>()?;
    let m0 = &manifests[0];
    for (d, m) in dirs.iter().zip(&manifests) {
        if m.study_hash != m0.study_hash {
            return Err(StudyError::Input(format!(
                "{} comes from another study (hash {}…) than {} ({}…)",
                d.display(),
                &m.study_hash[..12.min(m.study_hash.len())],
                first_dir.display(),
                &m0.study_hash[..12.min(m0.study_hash.len())]
            )));
        }
        if m.columns != m0.columns {
            return Err(StudyError::Input(format!(
                "{}: columns differ from {}",
                d.display(),
                first_dir.display()
            )));
        }
    }
    let schema = m0.schema().map_err(StudyError::Input)?;
    let mut tables = Vec::new();
    for d in dirs {
        tables.push(read_csv_typed(&d.join("cases.partial.csv"), &schema)?);
    }
    let raw = compact(&Table::concat(&tables)?, None)?;
    std::fs::create_dir_all(out).map_err(|e| io_err(out, e))?;
    write_csv(&raw, &out.join("cases.partial.csv"))?;
    let table = final_table(&raw)?;
    write_csv(&table, &out.join("cases.csv"))?;
    write_parquet(&table, &out.join("cases.parquet"))?;
    if let Ok(text) = std::fs::read_to_string(first_dir.join("study.toml")) {
        std::fs::write(out.join("study.toml"), text).map_err(|e| io_err(out, e))?;
    }
    let status = table.str("status")?;
    let count = |s: &str| status.iter().filter(|x| *x == s).count();
    let mut m = m0.clone();
    m.start_time = start_time;
    m.end_time = now_rfc3339();
    m.elapsed_s = t0.elapsed().as_secs_f64();
    m.shard = None;
    m.merged_from = dirs.iter().map(|d| d.display().to_string()).collect();
    m.cases = Counts {
        planned: m0.cases.planned,
        in_output: table.n_rows(),
        ok: count("ok"),
        failed: count("failed"),
        skipped: count("skipped"),
        resumed: manifests.iter().map(|m| m.cases.resumed).sum(),
        ran: manifests.iter().map(|m| m.cases.ran).sum(),
    };
    m.elapsed_s = manifests.iter().map(|m| m.elapsed_s).fold(0.0, f64::max);
    m.throughput_cases_per_s = manifests.iter().map(|m| m.throughput_cases_per_s).sum();
    write_manifest(out, &m)?;
    let mut warnings = Vec::new();
    if table.n_rows() < m.cases.planned {
        warnings.push(format!(
            "merged {} of {} cases: some shards are missing or unfinished",
            table.n_rows(),
            m.cases.planned
        ));
    }
    // The study itself (for reruns of the best/worst case), when it is still where it was.
    let study = super::schema::load_study(Path::new(&m.study_file))
        .ok()
        .filter(|s| s.hash == m.study_hash);
    warnings.extend(finish_report(out, &table, &m, study.as_ref()));
    Ok((m, warnings))
}

/// Regenerate `summary.md` and the plots of an output directory from `cases.parquet` (or
/// `cases.csv`) and `manifest.json`.
pub fn report(dir: &Path) -> Result<Vec<String>, StudyError> {
    let m = read_manifest(dir)?;
    let pq = dir.join("cases.parquet");
    let table = if pq.is_file() {
        crate::report::read_parquet(&pq)?
    } else {
        // Reconstruct from the raw rows (typed) when the Parquet file is missing.
        let schema = m.schema().map_err(StudyError::Input)?;
        final_table(&read_csv_typed(&dir.join("cases.partial.csv"), &schema)?)?
    };
    Ok(super::summary::write_report(dir, &table, &m))
}
