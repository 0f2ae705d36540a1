//! `usm-study paper [--out results/paper]`: regenerate the USM paper's simulations (see
//! [`usm_study::pipeline::paper`]).

use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;
use usm_study::pipeline::paper::run_paper;

/// Arguments of `paper`.
#[derive(Debug, Args)]
pub struct PaperArgs {
    /// Output directory.
    #[arg(long, default_value = "results/paper")]
    pub out: PathBuf,
    /// Also write each run's time series (CSV and Parquet; about 2 MB per run).
    #[arg(long)]
    pub timeseries: bool,
}

/// Run `paper`: exit code 1 when a run stopped early.
pub fn run(a: &PaperArgs) -> anyhow::Result<ExitCode> {
    let outcome = run_paper(&a.out, a.timeseries, &mut |r| {
        eprintln!(
            "[paper] {}: {} in {:.2} s",
            r.dir,
            if r.failed { "FAILED" } else { "ok" },
            r.seconds
        );
    })?;
    eprintln!("[paper] wrote {}", a.out.display());
    Ok(if outcome.failed.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
