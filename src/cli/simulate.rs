//! `usm-study simulate SCENARIO [--out DIR] [--allocation METHOD] [--set key=value ...]`.

use super::fmt_num;
use crate::allocation::Method;
use crate::control::transport::yaw_joint_mask;
use crate::input::keypath::{parse_override, set};
use crate::model::Vehicle;
use crate::report::figures::{run_figure, trajectory_table};
use crate::report::{write_csv, write_parquet};
use crate::scenario::{load_table, parse_table, resolve_design, run_scenario, RunResult};
use anyhow::Context;
use clap::Args;
use serde_json::json;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `simulate`.
#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Scenario file (TOML) or preset: transport-method1, transport-method2, work-setpoint.
    pub scenario: String,
    /// Output directory (default: out/<scenario name>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Override the allocation method: pinv, qp, minimax or power.
    #[arg(long)]
    pub allocation: Option<Method>,
    /// Override any scenario key, e.g. `--set control.k_psi=0.3 --set scenario.duration=60`
    /// (values are TOML: numbers, strings, arrays).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Do not write the SVG figure.
    #[arg(long)]
    pub no_plots: bool,
}

/// Run `simulate`.
pub fn run(a: &SimulateArgs) -> anyhow::Result<ExitCode> {
    let (mut table, src) = load_table(&a.scenario)?;
    if let Some(m) = a.allocation {
        set_allocation_method(&mut table, m);
    }
    for s in &a.set {
        let (path, value) = parse_override(s)?;
        set(&mut table, &path.0, value, s).map_err(|e| anyhow::anyhow!("--set {s}: {e}"))?;
    }
    let file = parse_table(&table, &src)?;
    let vehicle = resolve_design(&file, &src)?;
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out").join(&file.scenario.name));
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    eprintln!(
        "[simulate] {} ({} mode, design {}, {} s, allocation {})",
        file.scenario.name,
        file.scenario.mode,
        vehicle.name,
        file.scenario.duration,
        file.allocation.method.name()
    );
    let r = run_scenario(&vehicle, &file)?;
    write_outputs(&r, &out, &vehicle, !a.no_plots)?;
    print_summary(&r);
    eprintln!("[simulate] wrote {}", out.display());
    match &r.failure {
        Some((t, cause)) => {
            eprintln!(
                "error: run stopped at t = {t:.3} s: {cause} (outputs hold the run up to then)"
            );
            Ok(ExitCode::from(1))
        }
        None => Ok(ExitCode::SUCCESS),
    }
}

/// Set `allocation.method` in a scenario table (the `--allocation` override).
pub fn set_allocation_method(table: &mut toml::Table, m: Method) {
    if let Some(t) = table
        .entry("allocation")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()))
        .as_table_mut()
    {
        t.insert("method".into(), toml::Value::String(m.name().into()));
    }
}

/// Write `timeseries.csv`, `timeseries.parquet`, `summary.json` and (optionally) the
/// paper-style figure `figure.svg` of a run of `vehicle` into `out`.
pub fn write_outputs(
    r: &RunResult,
    out: &std::path::Path,
    vehicle: &Vehicle,
    plots: bool,
) -> anyhow::Result<()> {
    let design = vehicle.name.as_str();
    let table = trajectory_table(&r.trajectory.names, &r.trajectory.columns)?;
    write_csv(&table, &out.join("timeseries.csv"))?;
    write_parquet(&table, &out.join("timeseries.parquet"))?;
    let metrics: serde_json::Map<String, serde_json::Value> = r
        .metrics
        .iter()
        .map(|(k, v)| {
            (
                k.clone(),
                if v.is_finite() {
                    json!(v)
                } else {
                    json!(v.to_string())
                },
            )
        })
        .collect();
    let summary = json!({
        "scenario": r.name,
        "mode": r.mode.to_string(),
        "design": design,
        "status": if r.failure.is_some() { "failed" } else { "ok" },
        "failure": r.failure.as_ref().map(|(t, c)| json!({"time": t, "cause": c})),
        "metrics": metrics,
        "allocation": {
            "steps": r.allocation_counts[0],
            "slack_active": r.allocation_counts[1],
            "solver_failures": r.allocation_counts[2],
        },
        "timing": r.timing,
    });
    let text = serde_json::to_string_pretty(&summary)?;
    let tmp = out.join(".summary.json.tmp");
    std::fs::write(&tmp, text).with_context(|| format!("writing {}", tmp.display()))?;
    std::fs::rename(&tmp, out.join("summary.json"))?;
    if plots && table.n_rows() > 0 {
        let yaw_joints: Vec<usize> = yaw_joint_mask(vehicle)
            .iter()
            .enumerate()
            .filter(|(_, y)| **y)
            .map(|(i, _)| i)
            .collect();
        let fig = run_figure(
            &table,
            &yaw_joints,
            &format!("{} ({} mode)", r.name, r.mode),
        )?;
        fig.write_svg(&out.join("figure.svg"))?;
    }
    Ok(())
}

fn print_summary(r: &RunResult) {
    println!("{} ({} mode)", r.name, r.mode);
    for (k, v) in &r.metrics {
        println!("  {k:<30} {}", fmt_num(*v));
    }
    let t = &r.timing;
    println!(
        "  wall time {:.3} s ({:.0}x real time): dynamics {:.3} s, allocation {:.3} s, control {:.3} s, logging {:.3} s",
        t.total_s, t.realtime_factor, t.dynamics_s, t.allocation_s, t.control_s, t.logging_s
    );
}
