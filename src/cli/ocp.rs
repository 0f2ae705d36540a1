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
    /// Fly the optimum in closed loop: run SCENARIO (a scenario file or preset of the same
    /// design) following DIR/trajectory.csv, as `simulate SCENARIO --reference` does, into
    /// DIR/tracked/, and give the tracked run's energy and final errors beside the open-loop
    /// optimum in summary.json (`tracked`).
    #[arg(long, value_name = "SCENARIO")]
    pub track: Option<String>,
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
    if let Some(scenario) = &args.track {
        track_optimum(scenario, &spec.vehicle.name, &args.out)?;
    }
    println!("wrote {}", args.out.display());
    Ok(if s.status == Status::Converged {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    })
}

/// Run `scenario` following `out/trajectory.csv` into `out/tracked/` and add the tracked run
/// beside the optimum to `out/summary.json` (`tracked`): thruster energy (the project's
/// definition with the axial inflow, and at zero inflow) of the run and of the optimum, the
/// controller's price (their difference at zero inflow), the end effector's final errors
/// against the optimum's last pose, the base path error and the run's success.
fn track_optimum(scenario: &str, design: &str, out: &std::path::Path) -> anyhow::Result<()> {
    let t = super::simulate_reference::track(
        scenario,
        &out.join("trajectory.csv"),
        &out.join("tracked"),
    )?;
    if t.design != design {
        println!(
            "warning: --track {scenario}: the scenario's design is {}, the problem's {design}: \
             the tracked run flies another plant",
            t.design
        );
    }
    let summary_path = out.join("summary.json");
    let mut summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&summary_path)?)?;
    let optimum_inflow = summary["objective_terms"]["thruster_energy_with_inflow"].as_f64();
    let metric = |k: &str| t.run.metric(k);
    let c = &t.comparison;
    let price = c
        .reference_thruster_energy_static
        .map(|r| c.tracked_thruster_energy_static - r);
    let tracked = serde_json::json!({
        "scenario": t.scenario,
        "design": t.design,
        "out": "tracked",
        "thruster_energy_j": metric("thruster_energy"),
        "optimum_thruster_energy_j": optimum_inflow,
        "thruster_energy_static_j": c.tracked_thruster_energy_static,
        "optimum_thruster_energy_static_j": c.reference_thruster_energy_static,
        "price_static_j": price,
        "final_position_error_m": metric("final_position_error"),
        "final_orientation_error_deg": metric("final_orientation_error_deg"),
        "base_error_max_m": c.base_error_max,
        "base_error_final_m": c.base_error_final,
        "success": metric("success"),
        "failure": t.run.failure.as_ref().map(|(time, cause)| format!("t = {time:.3} s: {cause}")),
    });
    println!(
        "tracked in closed loop ({scenario}, {}): thruster energy {:.4e} J (optimum {}), final \
         end-effector error {:.4} m / {:.3} deg, base error max {:.4} m{}",
        out.join("tracked").display(),
        metric("thruster_energy").unwrap_or(f64::NAN),
        optimum_inflow.map_or("n/a".into(), |e| format!("{e:.4e} J")),
        metric("final_position_error").unwrap_or(f64::NAN),
        metric("final_orientation_error_deg").unwrap_or(f64::NAN),
        c.base_error_max,
        t.run
            .failure
            .as_ref()
            .map_or(String::new(), |(time, cause)| format!(
                "; stopped at t = {time:.3} s: {cause}"
            )),
    );
    if let Some(map) = summary.as_object_mut() {
        map.insert("tracked".into(), tracked);
    }
    let mut text = serde_json::to_string_pretty(&summary)?;
    text.push('\n');
    usm_study::report::atomic_write(&summary_path, text.as_bytes())?;
    Ok(())
}
