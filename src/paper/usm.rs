//! The `paper` pipeline: regenerate the USM paper's simulations — the scenario presets
//! (Fig. 8 a–h and Fig. 9 of the paper, and the torque-limited transport variant) and the
//! allocator comparison — with their figures,
//! summaries and the comparison tables of `README.md`, and the transport readings comparison
//! ([`super::readings`]) in `readings/` and the secondary-objectives comparison
//! ([`super::secondary`]) in `secondary/`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::secondary::run_secondary_comparison;
use super::transport_claims::run_readings_and_claims;
use crate::allocation::Method;
use crate::outcome::run_scenario;
use crate::pipeline::error::{create_dir, create_subdir, PipelineError};
use crate::pipeline::simulate::{set_allocation_method, write_run_outputs, RunFiles};
use crate::report::{atomic_write, fmt_num, MarkdownTable};
use crate::scenario::{load_table, parse_table, preset_names, resolve_design};

/// Metrics shown in the transport comparison table.
const TRANSPORT_KEYS: [&str; 14] = [
    "seg0_convergence_time",
    "seg0_overshoot",
    "seg1_convergence_time",
    "seg1_overshoot",
    "cross_track_rms",
    "base_cross_track_rms",
    "thruster_energy",
    "thruster_energy_static",
    "energy_per_metre",
    "joint_energy",
    "joint_torque_peak",
    "effort_abs",
    "peak_thrust",
    "saturation_fraction",
];
/// Metrics shown in the work-mode table.
const WORK_KEYS: [&str; 11] = [
    "final_position_error",
    "final_orientation_error_deg",
    "settling_time_position",
    "settling_time_orientation",
    "base_drift",
    "ee_roll_max_deg",
    "ee_roll_max_settled_deg",
    "ee_damped_fraction",
    "thruster_energy",
    "peak_thrust",
    "success",
];
/// Metrics shown in the allocator tables.
const ALLOC_KEYS: [&str; 6] = [
    "peak_thrust",
    "effort_sq",
    "effort_abs",
    "thruster_energy",
    "saturation_fraction",
    "slack_fraction",
];

/// The opening of `README.md`.
const INTRO: &str = "# The USM paper's simulations, regenerated\n\n\
     Regenerate with `cargo run --release -- paper --out results/paper`.\n\
     Each directory holds `summary.json` (metrics, allocation counts, timing) and\n\
     `figure.svg` (laid out like the paper's Fig. 8 / Fig. 9). Transport runs last the\n\
     paper's 140 s, which leaves 45 s after the segment commanded at 95 s: a NaN\n\
     convergence time means \"not within the run\" (see FINDINGS.md for 170 s runs).\n\
     `readings/readings.md` compares both transport methods under every reading of the\n\
     paper's open choices (`paper readings` regenerates only that), and\n\
     `readings/claims.md` judges the paper's transport claims under the printed and the\n\
     adopted reading, with and without cross-flow lift;\n\
     `secondary/secondary.md` the paper's secondary objectives on and off (`paper secondary`).\n";

/// One finished run, as reported to the caller.
#[derive(Clone, Debug)]
pub struct PaperRun<'a> {
    /// Output subdirectory, e.g. `transport-method1` or `allocators/work-setpoint-qp`.
    pub dir: &'a str,
    /// Whether the run stopped early.
    pub failed: bool,
    /// Wall-clock time of the run [s].
    pub seconds: f64,
}

/// What the pipeline did.
#[derive(Clone, Debug)]
pub struct PaperOutcome {
    /// Subdirectories of the runs that stopped early.
    pub failed: Vec<String>,
}

/// The runs: output subdirectory, scenario preset, allocation override. The presets,
/// then every allocator on transport Method 2 and on work mode.
fn planned_runs() -> Vec<(String, String, Option<Method>)> {
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
    runs
}

/// Runs every simulation of the paper into subdirectories of `out` (time series only when
/// `timeseries` is set), writes `out/README.md` with the comparison tables, and reports each
/// finished run through `on_run`. A run that stops early is recorded, not an error.
pub fn run_paper(
    out: &Path,
    timeseries: bool,
    on_run: &mut dyn FnMut(&PaperRun<'_>),
) -> Result<PaperOutcome, PipelineError> {
    create_dir(out)?;
    let mut md = String::from(INTRO);
    let mut failed = Vec::new();
    let mut rows: Vec<(String, Vec<(String, f64)>)> = Vec::new();
    let files = RunFiles {
        timeseries,
        figure: true,
        shapes: false,
    };
    for (dir, preset, method) in &planned_runs() {
        let (mut table, src) = load_table(preset)?;
        if let Some(m) = method {
            set_allocation_method(&mut table, *m);
        }
        let mut file = parse_table(&table, &src)?;
        // A reproduction shows the whole run, whatever its [success] verdict.
        file.success.stop_on_failure = false;
        let v = resolve_design(&file, &src)?;
        let r = run_scenario(&v, &file)?;
        let run_dir: PathBuf = out.join(dir);
        create_subdir(&run_dir)?;
        write_run_outputs(&r, &run_dir, &v, files)?;
        if !timeseries {
            // A time series left by an earlier run with `timeseries` would not match this run.
            for f in ["timeseries.csv", "timeseries.parquet"] {
                let _ = std::fs::remove_file(run_dir.join(f));
            }
        }
        on_run(&PaperRun {
            dir,
            failed: r.failure.is_some(),
            seconds: r.timing.total_s,
        });
        if let Some((t, c)) = &r.failure {
            failed.push(dir.clone());
            let _ = writeln!(md, "\n**{dir} stopped at t = {t:.2} s: {c}**");
        }
        rows.push((dir.clone(), r.metrics));
    }
    write_tables(&mut md, &rows);
    atomic_write(&out.join("README.md"), md.as_bytes())?;
    run_readings_and_claims(&out.join("readings"), &mut |_| {})?;
    run_secondary_comparison(&out.join("secondary"), &mut |_| {})?;
    Ok(PaperOutcome { failed })
}

/// Appends the four comparison tables to `md`.
fn write_tables(md: &mut String, rows: &[(String, Vec<(String, f64)>)]) {
    table(
        md,
        rows,
        "Transport mode: Method 1 vs Method 2 (USM Table III gains, qp allocation), and \
         Method 1 with torque-limited joint servos",
        &TRANSPORT_KEYS,
        &[
            "transport-method1".into(),
            "transport-method2".into(),
            "transport-method1-torque-limited".into(),
        ],
    );
    table(
        md,
        rows,
        "Work mode (USM-42): a pose within reach, and the paper-like pose beyond it",
        &WORK_KEYS,
        &["work-setpoint".into(), "work-setpoint-far".into()],
    );
    let allocators = |base: &str| -> Vec<String> {
        ["pinv", "qp", "minimax", "power"]
            .iter()
            .map(|m| format!("allocators/{base}-{m}"))
            .collect()
    };
    table(
        md,
        rows,
        "Allocators on transport Method 2",
        &ALLOC_KEYS,
        &allocators("transport-method2"),
    );
    table(
        md,
        rows,
        "Allocators in work mode",
        &ALLOC_KEYS,
        &allocators("work-setpoint"),
    );
}

/// Appends a section `title` with a table of the metrics `keys` (rows) of the runs `names`
/// (columns); `-` where a run or metric is missing.
fn table(
    md: &mut String,
    rows: &[(String, Vec<(String, f64)>)],
    title: &str,
    keys: &[&str],
    names: &[String],
) {
    let _ = writeln!(md, "\n## {title}\n");
    let mut t =
        MarkdownTable::new(std::iter::once("metric").chain(names.iter().map(String::as_str)));
    for k in keys {
        let cells = names.iter().map(|n| {
            rows.iter()
                .find(|(d, _)| d == n)
                .and_then(|(_, m)| m.iter().find(|(mk, _)| mk == k))
                .map_or("-".to_string(), |(_, v)| fmt_num(*v))
        });
        t.row(std::iter::once(format!("`{k}`")).chain(cells));
    }
    md.push_str(&t.finish());
}
