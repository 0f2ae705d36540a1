//! `usm-study tcm DESIGN`: static configuration-space analysis of the thruster configuration
//! matrix (SPEC §6) — how often `T(q)` is singular over the joint space.
//!
//! Writes to `--out` (default `results/tcm/<design name>`):
//! - `samples.csv`: one row per sample (streamed; memory stays bounded for any N):
//!   `index`, `q1_rad … qn_rad`, `sigma_min` (scaled σ_min, N per N), `kappa`, `rank`,
//!   `lost_axis` (empty unless σ_min < threshold or rank < 6);
//! - `samples.parquet`: the same table, only when N ≤ 200 000 (larger tables stay CSV only);
//! - `summary.json`: the [`StaticSummary`] plus the slice joints and the files written;
//! - `sigma_min_hist.svg`: histogram of σ_min; `sigma_min_slice.svg`: σ_min over a 2-D slice
//!   of joint space (the two most influential yaw joints, or `--slice I,J`; others 0).

use crate::model::design::load_design;
use crate::report::{
    heatmap, histogram, read_csv_typed, write_parquet, ColourScale, ColumnKind, CsvAppender, Value,
};
use crate::sampling::Sampling;
use crate::study::static_tcm::{
    analyse, influential_joints, slice_grid, StaticSpec, StaticSummary,
};
use anyhow::{bail, Context};
use clap::Args;
use serde::Serialize;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Largest sample count for which `samples.parquet` is written.
pub const PARQUET_MAX_ROWS: usize = 200_000;

/// Arguments of `tcm`.
#[derive(Debug, Args)]
pub struct TcmArgs {
    /// Preset name (usm-paper, uvms-planar) or path to a design file (TOML).
    pub design: String,
    /// Number of joint configurations sampled within the joint limits.
    #[arg(long, default_value_t = crate::study::static_tcm::DEFAULT_SAMPLES)]
    pub samples: usize,
    /// Seed of the sampler.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Threshold on the scaled σ_min below which T counts as singular.
    #[arg(long, default_value_t = crate::study::static_tcm::DEFAULT_THRESHOLD)]
    pub threshold: f64,
    /// Sampling of joint space: sobol, lhs or random.
    #[arg(long, default_value = "sobol", value_parser = parse_sampling)]
    pub sampling: Sampling,
    /// Output directory (default results/tcm/<design name>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Characteristic length L [m] dividing the moment rows (default: half the vehicle length).
    #[arg(long)]
    pub char_length: Option<f64>,
    /// Worker threads (0: all cores). Results do not depend on it.
    #[arg(long, default_value_t = 0)]
    pub jobs: usize,
    /// Joints of the 2-D slice plot, `I,J` (0-based joint indices); default: the two most
    /// influential yaw joints.
    #[arg(long, value_parser = parse_pair)]
    pub slice: Option<(usize, usize)>,
    /// Grid resolution of the slice plot per joint.
    #[arg(long, default_value_t = 41)]
    pub resolution: usize,
    /// Number of worst (lowest σ_min) configurations reported.
    #[arg(long, default_value_t = crate::study::static_tcm::DEFAULT_WORST)]
    pub worst: usize,
}

fn parse_sampling(s: &str) -> Result<Sampling, String> {
    s.parse()
}

fn parse_pair(s: &str) -> Result<(usize, usize), String> {
    let (a, b) = s
        .split_once(',')
        .ok_or_else(|| format!("expected I,J (two joint indices), got '{s}'"))?;
    let p = |x: &str| {
        x.trim()
            .parse::<usize>()
            .map_err(|_| format!("'{x}' is not a joint index"))
    };
    Ok((p(a)?, p(b)?))
}

/// Progress display: an indicatif bar on a terminal, periodic lines otherwise.
pub(crate) struct Progress {
    bar: Option<indicatif::ProgressBar>,
    label: &'static str,
    unit: &'static str,
    total: usize,
    start: Instant,
    last: Mutex<Instant>,
    every: Duration,
    quiet: bool,
}

impl Progress {
    /// A progress display for `total` items; hidden entirely when `show` is false.
    pub(crate) fn new(label: &'static str, unit: &'static str, total: usize, show: bool) -> Self {
        let bar = (show && std::io::stderr().is_terminal()).then(|| {
            let b = indicatif::ProgressBar::new(total as u64);
            b.set_style(
                indicatif::ProgressStyle::with_template(
                    "{prefix} [{elapsed_precise}] {wide_bar} {pos}/{len} {msg} ({per_sec}, ETA {eta})",
                )
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            b.set_prefix(format!("[{label}]"));
            b.set_message(unit);
            b
        });
        let now = Instant::now();
        Self {
            bar,
            label,
            unit,
            total,
            start: now,
            last: Mutex::new(now),
            every: Duration::from_secs(5),
            quiet: !show,
        }
    }

    /// Report `done` items finished, `rate_done` of them counted for the rate.
    pub(crate) fn update(&self, done: usize, rate_done: usize) {
        if let Some(b) = &self.bar {
            b.set_position(done as u64);
            return;
        }
        if self.quiet {
            return;
        }
        let Ok(mut last) = self.last.lock() else {
            return;
        };
        let now = Instant::now();
        if now < *last + self.every && done < self.total {
            return;
        }
        *last = now;
        let secs = self.start.elapsed().as_secs_f64().max(1e-9);
        let rate = rate_done as f64 / secs;
        let eta = if rate > 0.0 {
            format!("{:.0} s", (self.total - done.min(self.total)) as f64 / rate)
        } else {
            "?".into()
        };
        eprintln!(
            "[{}] {done}/{} {}, {rate:.1} {}/s, ETA {eta}",
            self.label, self.total, self.unit, self.unit
        );
    }

    /// Remove the bar.
    pub(crate) fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

#[derive(Serialize)]
struct SummaryFile<'a> {
    #[serde(flatten)]
    summary: &'a StaticSummary,
    slice_joints: Option<[String; 2]>,
    files: Vec<String>,
}

fn sanitize(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Run `usm-study tcm`.
pub fn run(a: &TcmArgs) -> anyhow::Result<ExitCode> {
    let vehicle = load_design(&a.design)?;
    if vehicle.n_thrusters() == 0 {
        bail!(
            "design `{}` has no thrusters; there is no T(q) to analyse",
            vehicle.name
        );
    }
    let spec = StaticSpec {
        samples: a.samples,
        seed: a.seed,
        threshold: a.threshold,
        sampling: a.sampling,
        char_length: a.char_length,
        rank_rel_tol: crate::metrics::singularity::DEFAULT_RANK_REL_TOL,
        worst: a.worst,
    };
    spec.validate()?;
    let n = vehicle.n_joints();
    if let Some((i, j)) = a.slice {
        if i >= n || j >= n || i == j {
            bail!("--slice {i},{j}: needs two different joint indices in 0..{n}");
        }
    }
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| Path::new("results/tcm").join(sanitize(&vehicle.name)));
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let mut schema: Vec<(String, ColumnKind)> = vec![("index".into(), ColumnKind::I64)];
    schema.extend((1..=n).map(|k| (format!("q{k}_rad"), ColumnKind::F64)));
    schema.extend([
        ("sigma_min".to_string(), ColumnKind::F64),
        ("kappa".to_string(), ColumnKind::F64),
        ("rank".to_string(), ColumnKind::I64),
        ("lost_axis".to_string(), ColumnKind::Str),
    ]);
    let csv_path = out.join("samples.csv");
    let mut app = CsvAppender::create(&csv_path, &schema)?;
    let mut sigmas: Vec<f64> = Vec::with_capacity(a.samples);
    let progress = Progress::new("tcm", "samples", a.samples, a.samples >= 20_000);
    let mut row: Vec<Value> = Vec::with_capacity(schema.len());
    let summary = analyse(
        &vehicle,
        &spec,
        a.jobs,
        &mut |e| {
            sigmas.push(e.sigma_min);
            row.clear();
            row.push(Value::I64(e.index as i64));
            row.extend(e.q.iter().map(|q| Value::F64(*q)));
            row.extend([
                Value::F64(e.sigma_min),
                Value::F64(e.kappa),
                Value::I64(e.rank as i64),
                Value::Str(e.lost_axis.unwrap_or("")),
            ]);
            app.append(&row).map_err(|e| e.to_string())
        },
        &|done| progress.update(done, done),
    )?;
    progress.finish();
    app.sync()?;
    drop(app);
    let mut files = vec!["samples.csv".to_string()];
    if a.samples <= PARQUET_MAX_ROWS {
        let t = read_csv_typed(&csv_path, &schema)?;
        write_parquet(&t, &out.join("samples.parquet"))?;
        files.push("samples.parquet".into());
    }
    histogram(
        &sigmas,
        50,
        &format!(
            "{}: scaled σ_min of T(q), {} samples",
            vehicle.name, a.samples
        ),
        "σ_min [N/N]",
    )
    .write_svg(&out.join("sigma_min_hist.svg"))?;
    files.push("sigma_min_hist.svg".into());
    drop(sigmas);
    let pair = match a.slice {
        Some(p) => Some(p),
        None => influential_joints(&vehicle, &spec)?,
    };
    let mut slice_joints = None;
    if let Some((i, j)) = pair {
        let g = slice_grid(&vehicle, &spec, i, j, a.resolution, a.jobs)?;
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
        slice_joints = Some([ni.clone(), nj.clone()]);
    }
    files.push("summary.json".into());
    let json = serde_json::to_string_pretty(&SummaryFile {
        summary: &summary,
        slice_joints,
        files,
    })?;
    std::fs::write(out.join("summary.json"), json + "\n")?;
    print_summary(&summary, &out);
    Ok(ExitCode::SUCCESS)
}

fn print_summary(s: &StaticSummary, out: &Path) {
    let f = super::fmt_num;
    println!(
        "design {}: {} joints, {} thrusters; {} {} samples (seed {}), L = {} m",
        s.design,
        s.joints.len(),
        s.thrusters,
        s.samples,
        s.sampling,
        s.seed,
        f(s.char_length)
    );
    println!(
        "singular fraction (σ_min < {}): {}   rank-deficient: {}",
        f(s.threshold),
        f(s.singular_fraction),
        f(s.rank_deficient_fraction)
    );
    println!(
        "straight configuration: σ_min = {}, rank {}{}",
        f(s.straight.sigma_min),
        s.straight.rank,
        s.straight
            .lost_axis
            .map_or(String::new(), |a| format!(", loses {a}"))
    );
    let q = |d: &crate::study::static_tcm::Distribution| {
        d.quantiles
            .iter()
            .map(|(p, v)| format!("p{:02.0}={}", p * 100.0, f(*v)))
            .collect::<Vec<_>>()
            .join(" ")
    };
    println!(
        "σ_min: min={} mean={} {}",
        f(s.sigma_min.min),
        f(s.sigma_min.mean),
        q(&s.sigma_min)
    );
    println!(
        "κ:     {} (non-finite: {})",
        q(&s.kappa),
        s.kappa.non_finite
    );
    let lost: Vec<String> = s
        .lost_axes
        .iter()
        .filter(|a| a.count > 0)
        .map(|a| format!("{} {}", a.axis, a.count))
        .collect();
    println!(
        "lost directions: {}",
        if lost.is_empty() {
            "none".into()
        } else {
            lost.join(", ")
        }
    );
    for w in s.worst.iter().take(5) {
        let q: Vec<String> =
            w.q.iter()
                .map(|x| format!("{:.1}", x.to_degrees()))
                .collect();
        println!(
            "worst #{}: σ_min={} rank={} q=[{}] deg",
            w.index,
            f(w.sigma_min),
            w.rank,
            q.join(", ")
        );
    }
    println!("wrote {}", out.display());
}
