//! `usm-study paper [usm|antonelli] [--out DIR]`: regenerate a seed paper's simulations — the
//! USM paper (see [`usm_study::pipeline::paper`], the default) or Antonelli & Chiaverini's
//! case studies and Table I (see [`usm_study::pipeline::antonelli`]).

use clap::{Args, ValueEnum};
use std::path::PathBuf;
use std::process::ExitCode;
use usm_study::pipeline::antonelli::run_antonelli;
use usm_study::pipeline::paper::run_paper;

/// Which paper to regenerate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum PaperName {
    /// The USM paper (its scenario presets, allocator comparison).
    Usm,
    /// Antonelli & Chiaverini (1998): kinematic case studies 1, 1b and 2 on `uvms-planar`,
    /// case 3 (NPS AUV II under current, Table I) and the paper-like figures.
    Antonelli,
}

/// Arguments of `paper`.
#[derive(Debug, Args)]
pub struct PaperArgs {
    /// The paper.
    #[arg(value_enum, default_value = "usm")]
    pub paper: PaperName,
    /// Output directory (default `results/paper` for `usm`, `results/antonelli` for
    /// `antonelli`).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Also write each run's time series (CSV and Parquet; about 2 MB per run; `usm` only).
    #[arg(long)]
    pub timeseries: bool,
}

/// Run `paper`: exit code 1 when a run stopped early.
pub fn run(a: &PaperArgs) -> anyhow::Result<ExitCode> {
    if a.paper == PaperName::Antonelli {
        let out = a.out.clone().unwrap_or_else(|| "results/antonelli".into());
        let outcome = run_antonelli(&out, &mut |s| {
            eprintln!(
                "[paper antonelli] {}: {} → {:.4} (target {:.4}), max end-effector error {:.2e} m",
                s.name,
                s.fourth_task,
                s.fourth_task_final,
                s.fourth_task_target,
                s.max_ee_position_error
            );
        })?;
        let t = &outcome.table1;
        eprintln!(
            "[paper antonelli] Table I (ours / paper): ∫‖f‖ a {:.0} / {:.0}, b {:.0} / {:.0}; \
             ∫‖m‖ a {:.0} / {:.0}, b {:.0} / {:.0}",
            t.ours.force_integral_a,
            t.paper.force_integral_a,
            t.ours.force_integral_b,
            t.paper.force_integral_b,
            t.ours.moment_integral_a,
            t.paper.moment_integral_a,
            t.ours.moment_integral_b,
            t.paper.moment_integral_b
        );
        eprintln!("[paper antonelli] wrote {}", out.display());
        return Ok(ExitCode::SUCCESS);
    }
    let out = a.out.clone().unwrap_or_else(|| "results/paper".into());
    let outcome = run_paper(&out, a.timeseries, &mut |r| {
        eprintln!(
            "[paper] {}: {} in {:.2} s",
            r.dir,
            if r.failed { "FAILED" } else { "ok" },
            r.seconds
        );
    })?;
    eprintln!("[paper] wrote {}", out.display());
    Ok(if outcome.failed.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
