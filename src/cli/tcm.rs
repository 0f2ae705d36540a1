//! `usm-study tcm DESIGN`: static configuration-space analysis of the thruster configuration
//! matrix (docs/model.md §6) — how often `T(q)` is singular over the joint space. The files written are
//! described in [`usm_study::pipeline::tcm`].

use super::progress::Progress;
use anyhow::bail;
use clap::Args;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use usm_study::metrics::singularity::DEFAULT_RANK_REL_TOL;
use usm_study::model::design::load_design;
use usm_study::pipeline::tcm::{run_tcm, TcmConfig};
use usm_study::report::fmt_num;
use usm_study::sampling::{Sampling, UnknownSampling};
use usm_study::scenario::Mode;
use usm_study::statics::{Distribution, StaticSpec, StaticSummary, DEFAULT_THRESHOLD};

/// Most `--samples` accepted: 16 bytes are kept per sample (0.8 GB at the cap); more would
/// end in an allocation abort instead of a message.
const MAX_SAMPLES: usize = 50_000_000;

/// Arguments of `tcm`.
#[derive(Debug, Args)]
pub struct TcmArgs {
    /// Preset name (usm-paper, uvms-planar) or path to a design file (TOML).
    pub design: String,
    /// Number of joint configurations sampled within the joint limits.
    #[arg(long, default_value_t = usm_study::statics::DEFAULT_SAMPLES)]
    pub samples: usize,
    /// Seed of the sampler.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Threshold on the scaled σ_min below which T counts as singular (shared by the full and
    /// the commanded figures, and by the trajectory metrics' default).
    #[arg(long, default_value_t = DEFAULT_THRESHOLD)]
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
    /// Mode whose commanded wrench axes are scored beside the full six: transport or work
    /// (its default controller's selection: both leave roll free).
    #[arg(long, default_value = "transport", value_parser = parse_mode)]
    pub mode: Mode,
    /// Number of worst (lowest σ_min) configurations reported.
    #[arg(long, default_value_t = usm_study::statics::DEFAULT_WORST)]
    pub worst: usize,
}

/// A command-line value of `tcm` that does not parse.
#[derive(Debug, thiserror::Error)]
enum ArgError {
    /// `--mode` names no mode.
    #[error("unknown mode '{0}'; valid: transport, work")]
    Mode(String),
    /// `--slice` is not two comma-separated values.
    #[error("expected I,J (two joint indices), got '{0}'")]
    Pair(String),
    /// One value of `--slice` is not an index.
    #[error("'{0}' is not a joint index")]
    Index(String),
}

fn parse_sampling(s: &str) -> Result<Sampling, UnknownSampling> {
    s.parse()
}

fn parse_mode(s: &str) -> Result<Mode, ArgError> {
    toml::Value::String(s.into())
        .try_into()
        .map_err(|_| ArgError::Mode(s.into()))
}

fn parse_pair(s: &str) -> Result<(usize, usize), ArgError> {
    let (a, b) = s.split_once(',').ok_or_else(|| ArgError::Pair(s.into()))?;
    let p = |x: &str| {
        x.trim()
            .parse::<usize>()
            .map_err(|_| ArgError::Index(x.into()))
    };
    Ok((p(a)?, p(b)?))
}

/// Run `usm-study tcm`.
pub fn run(a: &TcmArgs) -> anyhow::Result<ExitCode> {
    let vehicle = load_design(&a.design)?;
    let n = vehicle.n_joints();
    if let Some((i, j)) = a.slice {
        if i >= n || j >= n || i == j {
            bail!("--slice {i},{j}: needs two different joint indices in 0..{n}");
        }
    }
    if a.samples > MAX_SAMPLES {
        bail!(
            "--samples: {} samples would keep {:.1} GB of per-sample values (σ_min and κ, for \
             exact quantiles); at most {MAX_SAMPLES}",
            a.samples,
            a.samples as f64 * 16.0 / 1e9
        );
    }
    let config = TcmConfig {
        spec: StaticSpec {
            samples: a.samples,
            seed: a.seed,
            threshold: a.threshold,
            sampling: a.sampling,
            char_length: a.char_length,
            rank_rel_tol: DEFAULT_RANK_REL_TOL,
            worst: a.worst,
            ..StaticSpec::default()
        }
        .for_mode(a.mode),
        out: a.out.clone().unwrap_or_else(|| {
            Path::new("results/tcm").join(usm_study::report::file_stem_safe(&vehicle.name))
        }),
        jobs: a.jobs,
        slice: a.slice,
        resolution: a.resolution,
    };
    let progress = Progress::new("tcm", "samples", a.samples, a.samples >= 20_000);
    let summary = run_tcm(&vehicle, &config, &|done| progress.update(done, done));
    progress.finish();
    print_summary(&summary?, &config.out);
    Ok(ExitCode::SUCCESS)
}

/// `p01=… p05=…` for the quantiles of `d`.
fn quantiles(d: &Distribution) -> String {
    d.quantiles
        .iter()
        .map(|(p, v)| format!("p{:02.0}={}", p * 100.0, fmt_num(*v)))
        .collect::<Vec<_>>()
        .join(" ")
}

fn print_summary(s: &StaticSummary, out: &Path) {
    let f = fmt_num;
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
        "{} mode commands {}: singular fraction {}   rank-deficient: {}",
        s.mode,
        s.commanded_axes,
        f(s.singular_fraction_commanded),
        f(s.rank_deficient_fraction_commanded)
    );
    let st = &s.straight.metrics;
    println!(
        "straight configuration: σ_min = {}, rank {}{}; commanded σ_min = {}",
        f(st.sigma_min),
        st.rank,
        st.lost_axis
            .map_or(String::new(), |a| format!(", loses {a}")),
        f(st.sigma_min_commanded)
    );
    println!(
        "σ_min: min={} mean={} {}",
        f(s.sigma_min.min),
        f(s.sigma_min.mean),
        quantiles(&s.sigma_min)
    );
    println!(
        "κ:     {} (non-finite: {})",
        quantiles(&s.kappa),
        s.kappa.non_finite
    );
    println!(
        "commanded σ_min: min={} mean={} {}",
        f(s.sigma_min_commanded.min),
        f(s.sigma_min_commanded.mean),
        quantiles(&s.sigma_min_commanded)
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
            f(w.metrics.sigma_min),
            w.metrics.rank,
            q.join(", ")
        );
    }
    println!("wrote {}", out.display());
}
