//! `manifest.json`: provenance (tool, version, git commit, study file and hash), counts,
//! timings, the raw schema and the report settings of a sweep output; with the clock and git
//! helpers that fill it in.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::records::StatusCounts;
use crate::report::ColumnKind;
use crate::study::error::StudyError;
use crate::study::runner::StudyMode;
use crate::study::schema::{DoeKind, ReportSettings};

/// The manifest's file name in an output directory.
pub const MANIFEST_FILE: &str = "manifest.json";

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
    /// `unsuccessful` rows (ran, missed a success criterion); absent in older manifests.
    #[serde(default)]
    pub unsuccessful: usize,
    /// `failed` rows.
    pub failed: usize,
    /// `skipped` rows.
    pub skipped: usize,
    /// Cases taken from a previous run.
    pub resumed: usize,
    /// Cases run by this invocation.
    pub ran: usize,
}

impl Counts {
    /// Counts with the status counts `s`.
    pub fn with_status(self, s: StatusCounts) -> Self {
        Counts {
            ok: s.ok,
            unsuccessful: s.unsuccessful,
            failed: s.failed,
            skipped: s.skipped,
            ..self
        }
    }
}

/// `manifest.json`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Manifest {
    /// Tool name.
    pub tool: String,
    /// Tool version.
    pub tool_version: String,
    /// The build's identity ([`crate::study::hash::BUILD_ID`], a hash of the sources): part of the
    /// study hash, so another build's journal is not resumed. Absent in older manifests.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub build_id: Option<String>,
    /// `git rev-parse HEAD` of the working directory, when available.
    pub git_commit: Option<String>,
    /// Whether that checkout had uncommitted changes to tracked files (`git status
    /// --porcelain --untracked-files=no` not empty) when the run started; absent outside git.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub git_dirty: Option<bool>,
    /// `rustc --version` of the compiler that built this binary (recorded by `build.rs`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rustc: Option<String>,
    /// The CPU model of the machine that ran it (`model name` of `/proc/cpuinfo`, else the
    /// architecture), and its logical CPU count: the context of every time in the manifest.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cpu: Option<String>,
    /// Study name.
    pub study_name: String,
    /// Description.
    pub description: String,
    /// Study file, relative to the output directory that holds this manifest (e.g.
    /// `../../studies/thrusters.toml`; [`study_path`] resolves it), so that a results folder
    /// names no path of the machine that ran it. Older manifests: absolute.
    pub study_file: String,
    /// Study hash.
    pub study_hash: String,
    /// Study seed.
    pub seed: u64,
    /// Scenario mode.
    pub mode: StudyMode,
    /// Whether the static analysis ran.
    pub static_analysis: bool,
    /// Design of experiments (`grid`, `sobol`, …).
    pub doe: DoeKind,
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
    /// The uncertain worlds and the ranking rule (studies with `[uncertainty]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robust: Option<super::robust::RobustInfo>,
    /// The case's wall-clock budget (`--case-timeout`) [s], also the budget of the report's
    /// best/worst reruns (in a merge too); absent = none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub case_timeout_s: Option<f64>,
    /// The assumption ledger: every inferred model parameter with its value, source and
    /// range (studies with `[uncertainty]`; docs/assumptions.md).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ledger: Option<serde_json::Value>,
}

impl Manifest {
    /// The manifest's record of a raw schema (`[name, kind]` pairs); [`Manifest::schema`]
    /// reads it back.
    pub fn columns_of(schema: &[(String, ColumnKind)]) -> Vec<[String; 2]> {
        schema
            .iter()
            .map(|(n, k)| [n.clone(), k.to_string()])
            .collect()
    }

    /// The raw schema; a column kind this version does not know is bad input (a manifest of
    /// another version or edited by hand).
    pub fn schema(&self) -> Result<Vec<(String, ColumnKind)>, StudyError> {
        self.columns
            .iter()
            .map(|[n, k]| {
                kind_of(k).map(|k| (n.clone(), k)).ok_or_else(|| {
                    StudyError::Input(format!(
                        "{MANIFEST_FILE}: column `{n}`: unknown column kind `{k}`"
                    ))
                })
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

/// `git rev-parse HEAD` of the working directory, when available.
pub fn git_commit() -> Option<String> {
    let out = std::process::Command::new("git")
        .args(["rev-parse", "HEAD"])
        .stderr(std::process::Stdio::null())
        .output()
        .ok()?;
    let s = String::from_utf8(out.stdout).ok()?.trim().to_string();
    (out.status.success() && s.len() >= 7).then_some(s)
}

/// Whether the working directory's git checkout has uncommitted changes to tracked files;
/// `None` outside a checkout or without git.
pub fn git_dirty() -> Option<bool> {
    let out = std::process::Command::new("git")
        .args(["status", "--porcelain", "--untracked-files=no"])
        .stderr(std::process::Stdio::null())
        .output()
        .ok()?;
    out.status.success().then_some(!out.stdout.is_empty())
}

/// `rustc --version` of the build (`build.rs`).
pub fn rustc_version() -> Option<String> {
    let v = env!("USM_RUSTC_VERSION");
    (!v.is_empty()).then(|| v.to_string())
}

/// The CPU model and logical CPU count of this machine, e.g. `AMD EPYC 7B13 (2 logical CPUs)`.
pub fn cpu_model() -> Option<String> {
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines().find_map(|l| {
                l.strip_prefix("model name")?
                    .split_once(':')
                    .map(|(_, v)| v.trim().to_string())
            })
        })
        .unwrap_or_else(|| std::env::consts::ARCH.to_string());
    let n = std::thread::available_parallelism().map_or(1, |n| n.get());
    Some(format!("{model} ({n} logical CPUs)"))
}

/// `path` relative to the directory `base` (both made absolute and resolved first), e.g.
/// `../../studies/a.toml`; `path` as given when either cannot be resolved.
pub fn relative_path(path: &Path, base: &Path) -> String {
    let (Ok(p), Ok(b)) = (std::fs::canonicalize(path), std::fs::canonicalize(base)) else {
        return path.display().to_string();
    };
    let (pc, bc): (Vec<_>, Vec<_>) = (p.components().collect(), b.components().collect());
    let common = pc.iter().zip(&bc).take_while(|(a, b)| a == b).count();
    if common == 0 {
        return p.display().to_string();
    }
    let mut rel = std::path::PathBuf::new();
    for _ in common..bc.len() {
        rel.push("..");
    }
    for c in &pc[common..] {
        rel.push(c);
    }
    rel.to_string_lossy().replace('\\', "/")
}

/// The study file a manifest of output directory `dir` names: its `study_file` resolved
/// against `dir` (an absolute one, of an older manifest, as it is).
pub fn study_path(dir: &Path, m: &Manifest) -> std::path::PathBuf {
    dir.join(&m.study_file)
}

/// Most world parameter values (worlds × parameters) `manifest.json` lists; beyond it they
/// are left to `worlds.csv` (issue 39 item 3: 130 000 Saltelli worlds × 24 parameters made a
/// 75 MB manifest). 10 000 numbers are ≈ 250 kB of JSON.
pub const MAX_LISTED_WORLD_VALUES: usize = 10_000;

/// Write `manifest.json` into `dir` (worlds' values beyond [`MAX_LISTED_WORLD_VALUES`] left
/// to `worlds.csv`; [`read_manifest`] reads them back).
pub fn write_manifest(dir: &Path, m: &Manifest) -> Result<(), StudyError> {
    let listed = m
        .robust
        .as_ref()
        .map_or(0, |r| r.world_values.iter().map(Vec::len).sum::<usize>());
    let mut short;
    let m = if listed > MAX_LISTED_WORLD_VALUES {
        short = m.clone();
        if let Some(r) = short.robust.as_mut() {
            r.world_values.clear();
            r.world_values_in = Some(super::robust::WORLDS_CSV.to_string());
        }
        &short
    } else {
        m
    };
    let text = serde_json::to_string_pretty(m).map_err(|e| StudyError::Other(e.to_string()))?;
    let p = dir.join(MANIFEST_FILE);
    crate::report::atomic_write(&p, (text + "\n").as_bytes()).map_err(StudyError::from)
}

/// Read `manifest.json` of an output directory.
pub fn read_manifest(dir: &Path) -> Result<Manifest, StudyError> {
    let p = dir.join(MANIFEST_FILE);
    let text = std::fs::read_to_string(&p).map_err(|e| {
        StudyError::Input(format!(
            "{}: {e} (is {} a finished sweep output? an unfinished one can be completed with --resume)",
            p.display(),
            dir.display()
        ))
    })?;
    let mut m: Manifest = serde_json::from_str(&text)
        .map_err(|e| StudyError::Input(format!("{}: {e}", p.display())))?;
    if let Some(r) = m.robust.as_mut() {
        if let Some(file) = r.world_values_in.take() {
            r.world_values = world_values_from(&dir.join(&file), r)?;
        }
    }
    Ok(m)
}

/// The worlds' parameter values of `info` read back from `worlds.csv` at `path` (one row per
/// case and world: every row of world k carries its values); a world no row names (met by no
/// case) gets NaN values.
fn world_values_from(
    path: &Path,
    info: &super::robust::RobustInfo,
) -> Result<Vec<Vec<f64>>, StudyError> {
    let bad = |e: String| {
        StudyError::Input(format!(
            "{}: {e} (manifest.json leaves the worlds' values to it)",
            path.display()
        ))
    };
    let t = crate::report::read_csv(path).map_err(|e| bad(e.to_string()))?;
    let worlds = t.i64("world").map_err(|e| bad(e.to_string()))?;
    let cols = info
        .params
        .iter()
        .map(|p| t.f64(&p.name).map_err(|e| bad(e.to_string())))
        .collect::<Result<Vec<_>, _>>()?;
    let n = worlds
        .iter()
        .map(|&k| k.max(0) as usize + 1)
        .max()
        .unwrap_or(0);
    let mut out = vec![vec![f64::NAN; cols.len()]; n];
    for (r, &k) in worlds.iter().enumerate() {
        let Ok(k) = usize::try_from(k) else {
            return Err(bad(format!("row {}: world {k} is negative", r + 2)));
        };
        for (j, c) in cols.iter().enumerate() {
            out[k][j] = c[r];
        }
    }
    Ok(out)
}
