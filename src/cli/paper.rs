//! `usm-study paper [--out results/paper]`: regenerate the USM paper's simulations — the
//! three scenario presets (Fig. 8 a–h and Fig. 9 of the paper) and the allocator comparison —
//! with their figures, summaries and a comparison table.

use super::fmt_num;
use super::simulate::{set_allocation_method, write_outputs};
use crate::allocation::Method;
use crate::scenario::{load_table, parse_table, preset_names, resolve_design, run_scenario};
use anyhow::Context;
use clap::Args;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

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

/// Metrics shown in the comparison tables.
const TRANSPORT_KEYS: [&str; 10] = [
    "seg0_convergence_time",
    "seg0_overshoot",
    "seg1_convergence_time",
    "seg1_overshoot",
    "cross_track_rms",
    "base_cross_track_rms",
    "thruster_energy",
    "effort_abs",
    "peak_thrust",
    "saturation_fraction",
];
const WORK_KEYS: [&str; 8] = [
    "final_position_error",
    "final_orientation_error_deg",
    "settling_time_position",
    "settling_time_orientation",
    "base_drift",
    "ee_roll_max_deg",
    "thruster_energy",
    "peak_thrust",
];
const ALLOC_KEYS: [&str; 6] = [
    "peak_thrust",
    "effort_sq",
    "effort_abs",
    "thruster_energy",
    "saturation_fraction",
    "slack_fraction",
];

/// Run `paper`.
pub fn run(a: &PaperArgs) -> anyhow::Result<ExitCode> {
    std::fs::create_dir_all(&a.out).with_context(|| format!("creating {}", a.out.display()))?;
    let mut md = String::from(
        "# The USM paper's simulations, regenerated\n\n\
         Regenerate with `cargo run --release -- paper --out results/paper`.\n\
         Each directory holds `summary.json` (metrics, allocation counts, timing) and\n\
         `figure.svg` (laid out like the paper's Fig. 8 / Fig. 9). Transport runs last the\n\
         paper's 140 s, which leaves 45 s after the segment commanded at 95 s: a NaN\n\
         convergence time means \"not within the run\" (see FINDINGS.md for 170 s runs).\n",
    );
    let mut failed = false;
    let mut rows: Vec<(String, Vec<(String, f64)>)> = Vec::new();
    // The three presets, then every allocator on transport Method 2 and on work mode.
    let mut runs: Vec<(String, String, Option<Method>)> = preset_names()
        .into_iter()
        .map(|p| (p.to_string(), p.to_string(), None))
        .collect();
    for base in ["transport-method2", "work-setpoint"] {
        for m in [Method::Pinv, Method::Qp, Method::Minimax, Method::Power] {
            runs.push((
                format!("allocators/{base}-{}", m.name()),
                base.to_string(),
                Some(m),
            ));
        }
    }
    for (dir, preset, method) in &runs {
        let (mut table, src) = load_table(preset)?;
        if let Some(m) = method {
            set_allocation_method(&mut table, *m);
        }
        let file = parse_table(&table, &src)?;
        let v = resolve_design(&file, &src)?;
        let r = run_scenario(&v, &file)?;
        let out = a.out.join(dir);
        std::fs::create_dir_all(&out)?;
        write_outputs(&r, &out, &v, true)?;
        if !a.timeseries {
            for f in ["timeseries.csv", "timeseries.parquet"] {
                let _ = std::fs::remove_file(out.join(f));
            }
        }
        eprintln!(
            "[paper] {dir}: {} in {:.2} s",
            if r.failure.is_some() { "FAILED" } else { "ok" },
            r.timing.total_s
        );
        if let Some((t, c)) = &r.failure {
            failed = true;
            let _ = writeln!(md, "\n**{dir} stopped at t = {t:.2} s: {c}**");
        }
        rows.push((dir.clone(), r.metrics));
    }
    let table = |md: &mut String, title: &str, keys: &[&str], names: &[&str]| {
        let _ = writeln!(md, "\n## {title}\n");
        let _ = writeln!(md, "| metric | {} |", names.join(" | "));
        let _ = writeln!(md, "|---|{}", "---|".repeat(names.len()));
        for k in keys {
            let cells: Vec<String> = names
                .iter()
                .map(|n| {
                    rows.iter()
                        .find(|(d, _)| d == n)
                        .and_then(|(_, m)| m.iter().find(|(mk, _)| mk == k))
                        .map_or("-".to_string(), |(_, v)| fmt_num(*v))
                })
                .collect();
            let _ = writeln!(md, "| `{k}` | {} |", cells.join(" | "));
        }
    };
    table(
        &mut md,
        "Transport mode: Method 1 vs Method 2 (USM Table III gains, qp allocation)",
        &TRANSPORT_KEYS,
        &["transport-method1", "transport-method2"],
    );
    table(
        &mut md,
        "Work mode (USM-42)",
        &WORK_KEYS,
        &["work-setpoint"],
    );
    let names: Vec<String> = ["pinv", "qp", "minimax", "power"]
        .iter()
        .map(|m| format!("allocators/transport-method2-{m}"))
        .collect();
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    table(
        &mut md,
        "Allocators on transport Method 2",
        &ALLOC_KEYS,
        &refs,
    );
    let names: Vec<String> = ["pinv", "qp", "minimax", "power"]
        .iter()
        .map(|m| format!("allocators/work-setpoint-{m}"))
        .collect();
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    table(&mut md, "Allocators in work mode", &ALLOC_KEYS, &refs);
    let path = a.out.join("README.md");
    std::fs::write(&path, md).with_context(|| format!("writing {}", path.display()))?;
    eprintln!("[paper] wrote {}", a.out.display());
    Ok(if failed {
        ExitCode::from(1)
    } else {
        ExitCode::SUCCESS
    })
}
