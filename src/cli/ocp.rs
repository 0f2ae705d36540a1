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

/// Relative grid defect above which `ocp` warns (docs/ocp.md §4, eq. (F2)).
const FIDELITY_WARN: f64 = 0.05;

/// Run `ocp`.
pub fn run(args: &OcpArgs) -> anyhow::Result<ExitCode> {
    let spec = load_problem(&args.problem)?;
    let mut run = solve_spec(&spec)?;
    write_outputs(&args.out, &spec, &mut run)?;
    usm_study::pipeline::ocp_shapes::write_ocp_shapes(
        &spec.vehicle,
        &mut run,
        &args.out.join("plots"),
    )?;
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
    match &run.fidelity {
        Ok(f) => {
            println!(
                "grid fidelity ({} → {} steps per interval): relative defect {:.2e} (interval {}), \
                 work of water and integrator {:.3e} J on the grid, {:.3e} J refined; actuators \
                 {:.3e} J",
                f.substeps,
                f.refined_substeps,
                f.relative_defect,
                f.worst_interval,
                f.other_work,
                f.other_work_refined,
                f.actuator_work
            );
            if f.relative_defect > FIDELITY_WARN {
                println!(
                    "warning: the grid is too coarse for this solution (relative defect above \
                     {:.0} %): raise horizon.knots or horizon.substeps (docs/ocp.md §4)",
                    FIDELITY_WARN * 100.0
                );
            }
        }
        Err(e) => println!("grid fidelity: the refined integration failed: {e}"),
    }
    println!("wrote {}", args.out.display());
    Ok(if s.status == Status::Converged {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}
