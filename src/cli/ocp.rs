//! `usm-study ocp PROBLEM.toml --out DIR`: solve an optimal-control problem file (docs/ocp.md)
//! and write `trajectory.csv`, `iterations.csv` and `summary.json` into DIR.
//!
//! Exit code: 0 when the solver converged to its KKT tolerance, 1 otherwise (the last iterate
//! is still written, its status in `summary.json`). A malformed problem file is an `Err`
//! naming the file, the line and the key (exit 2).

use std::path::PathBuf;
use std::process::ExitCode;

use usm_study::ocp::{load_problem, solve_spec, write_outputs, Status};

/// Arguments of `usm-study ocp`.
#[derive(Debug, clap::Args)]
pub struct OcpArgs {
    /// Problem file (TOML; docs/ocp.md).
    pub problem: PathBuf,
    /// Output directory (created).
    #[arg(long)]
    pub out: PathBuf,
}

/// Run `ocp`.
pub fn run(args: &OcpArgs) -> anyhow::Result<ExitCode> {
    let spec = load_problem(&args.problem)?;
    let mut run = solve_spec(&spec)?;
    write_outputs(&args.out, &spec, &mut run)?;
    let s = &run.solution;
    println!(
        "ocp {}: {:?} after {} iterations ({}); J = {:.6}, KKT primal {:.2e} stationarity {:.2e} \
         complementarity {:.2e}, terminal violation {:.2e}, {:.3} s",
        spec.origin,
        s.status,
        s.iterations,
        s.message,
        s.objective,
        s.kkt[0],
        s.kkt[1],
        s.kkt[2],
        s.terminal_violation,
        s.timing.total
    );
    println!("wrote {}", args.out.display());
    Ok(if s.status == Status::Converged {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
