//! The secondary-objectives comparison (`usm-study paper secondary`, issue 10 item 3): work
//! mode and both transport methods (through the 180° turn) without and with the paper's
//! secondary objectives (USM section IV-A: manipulability, controllability —
//! [`crate::control::kinematic::SecondaryTasks`]), written to `secondary.csv` and
//! `secondary.md`.
//!
//! Figures per run, from the logged joint angles (every `log_dt`):
//! - `sigma_c_min`: the smallest commanded-subspace σ_min `σ_min(S·T_L(q))` [N/N] over the run
//!   (transport also `sigma_c_min_turn`, over the 30 s after the turn command at 95 s);
//! - `exposure`: the fraction of samples with it below `metrics.threshold`;
//! - `manipulability_mean`: the mean of `√det(J_q J_qᵀ)` over the samples (its minimum is the
//!   straight start's 0);
//! - from the scenario metrics: thruster and joint energy, and tracking (work: final position
//!   and orientation errors, position settling time; transport: convergence time on the
//!   second segment, cross-track RMS after convergence, final cross-track error).

use std::fmt::Write as _;
use std::path::Path;

use crate::control::kinematic::{SecondarySettings, SecondaryTasks};
use crate::model::Vehicle;
use crate::outcome::{run_scenario, RunResult};
use crate::pipeline::error::{create_dir, PipelineError};
use crate::report::{atomic_write, MarkdownTable};
use crate::scenario::config::Mode;
use crate::scenario::{
    load_table, parse_table, resolve_design, Channel, ScenarioError, ScenarioFile,
};

/// Simulated time of the transport runs [s] (the turn is commanded at 95 s).
const TRANSPORT_DURATION: f64 = 170.0;
/// Start and length [s] of the turn window of `sigma_c_min_turn`.
const TURN_WINDOW: (f64, f64) = (95.0, 30.0);

/// The compared settings: name, `k_c`, `k_m`.
pub const SECONDARY_CASES: [(&str, f64, f64); 4] = [
    ("off", 0.0, 0.0),
    ("controllability", 0.5, 0.0),
    ("manipulability", 0.0, 0.1),
    ("both", 0.5, 0.1),
];

/// The scenario presets compared.
pub const SECONDARY_SCENARIOS: [&str; 3] =
    ["work-setpoint", "transport-method1", "transport-method2"];

/// Figures of one run, in table order.
pub const SECONDARY_KEYS: [&str; 11] = [
    "sigma_c_min",
    "sigma_c_min_turn",
    "exposure",
    "manipulability_mean",
    "thruster_energy",
    "joint_energy",
    "final_position_error",
    "settling_time_position",
    "seg1_convergence_time",
    "cross_track_rms",
    "final_cross_track",
];

/// One run of the comparison.
#[derive(Clone, Debug)]
pub struct SecondaryRun {
    /// Scenario preset.
    pub scenario: &'static str,
    /// Case name of [`SECONDARY_CASES`].
    pub case: &'static str,
    /// Whether the run stopped early.
    pub failed: bool,
    /// `(key, value)` in the order of [`SECONDARY_KEYS`]; NaN where undefined.
    pub metrics: Vec<(&'static str, f64)>,
}

impl SecondaryRun {
    /// A figure of [`SECONDARY_KEYS`] (NaN if unknown).
    pub fn get(&self, key: &str) -> f64 {
        self.metrics
            .iter()
            .find(|(k, _)| *k == key)
            .map_or(f64::NAN, |(_, v)| *v)
    }
}

/// Run `scenario` (a preset) with the secondary gains `k_c`, `k_m` and compute the figures of
/// the module docs.
pub fn run_secondary(
    scenario: &'static str,
    case: &'static str,
    k_c: f64,
    k_m: f64,
) -> Result<SecondaryRun, PipelineError> {
    let (mut table, src) = load_table(scenario)?;
    let mut sec = toml::Table::new();
    sec.insert("controllability_gain".into(), toml::Value::Float(k_c));
    sec.insert("manipulability_gain".into(), toml::Value::Float(k_m));
    table.insert("secondary".into(), toml::Value::Table(sec));
    if let Some(sc) = table.get_mut("scenario").and_then(|s| s.as_table_mut()) {
        if sc.get("mode").and_then(|m| m.as_str()) == Some("transport") {
            sc.insert("duration".into(), toml::Value::Float(TRANSPORT_DURATION));
        }
    }
    let mut file = parse_table(&table, &src)?;
    // A reproduction shows the whole run, whatever its [success] verdict.
    file.success.stop_on_failure = false;
    let v = resolve_design(&file, &src)?;
    let r = run_scenario(&v, &file)?;
    let (sigma, manip) = secondary_profile(&file, &v, &r)?;
    let t = r.trajectory.get(Channel::T).unwrap_or(&[]);
    let in_turn = |ti: f64| ti >= TURN_WINDOW.0 && ti < TURN_WINDOW.0 + TURN_WINDOW.1;
    let min = |xs: &mut dyn Iterator<Item = f64>| xs.fold(f64::INFINITY, f64::min);
    let s_min = min(&mut sigma.iter().copied());
    let s_turn = min(&mut sigma.iter().zip(t).filter(|p| in_turn(*p.1)).map(|p| *p.0));
    let below = sigma
        .iter()
        .filter(|s| **s < file.metrics.threshold)
        .count();
    let m_sum: f64 = manip.iter().sum();
    let transport = file.scenario.mode == Mode::Transport;
    let metrics = SECONDARY_KEYS
        .iter()
        .map(|&k| {
            let x = match k {
                "sigma_c_min" => s_min,
                "sigma_c_min_turn" if transport => s_turn,
                "sigma_c_min_turn" => f64::NAN,
                "exposure" => below as f64 / t.len().max(1) as f64,
                "manipulability_mean" => m_sum / t.len().max(1) as f64,
                _ => r.metric(k).unwrap_or(f64::NAN),
            };
            (k, x)
        })
        .collect();
    Ok(SecondaryRun {
        scenario,
        case,
        failed: r.failure.is_some(),
        metrics,
    })
}

/// The commanded-subspace σ_min `σ_min(S·T_L(q))` [N/N] and the manipulability
/// `√det(J_q J_qᵀ)` at every logged sample of a run `r` of `file` on `v` (from the logged joint
/// angles; `S` = [`crate::scenario::ScenarioFile::commanded_dofs`]).
pub fn secondary_profile(
    file: &ScenarioFile,
    v: &Vehicle,
    r: &RunResult,
) -> Result<(Vec<f64>, Vec<f64>), PipelineError> {
    let mut probe = SecondaryTasks::new(
        v,
        SecondarySettings::default(),
        file.commanded(),
        file.char_length(v),
    )
    .map_err(ScenarioError::from)?;
    let qs = r.trajectory.indexed(Channel::Q);
    let mut q = vec![0.0; qs.len()];
    let (mut sigma, mut manip) = (Vec::new(), Vec::new());
    for i in 0..r.trajectory.len() {
        for (k, c) in qs.iter().enumerate() {
            q[k] = c[i];
        }
        sigma.push(probe.controllability(&q));
        manip.push(probe.manipulability(&q));
    }
    Ok((sigma, manip))
}

/// Run every scenario of [`SECONDARY_SCENARIOS`] under every case of [`SECONDARY_CASES`], write
/// `out/secondary.csv` and `out/secondary.md`, report each run through `on_run`.
pub fn run_secondary_comparison(
    out: &Path,
    on_run: &mut dyn FnMut(&SecondaryRun),
) -> Result<Vec<SecondaryRun>, PipelineError> {
    create_dir(out)?;
    let mut runs = Vec::new();
    for scenario in SECONDARY_SCENARIOS {
        for (case, k_c, k_m) in SECONDARY_CASES {
            let r = run_secondary(scenario, case, k_c, k_m)?;
            on_run(&r);
            runs.push(r);
        }
    }
    let mut csv = String::from("scenario,case,controllability_gain,manipulability_gain,failed");
    for k in SECONDARY_KEYS {
        let _ = write!(csv, ",{k}");
    }
    csv.push('\n');
    for r in &runs {
        let (_, kc, km) = SECONDARY_CASES
            .iter()
            .find(|c| c.0 == r.case)
            .copied()
            .unwrap_or(("", f64::NAN, f64::NAN));
        let _ = write!(csv, "{},{},{kc},{km},{}", r.scenario, r.case, r.failed);
        for (_, v) in &r.metrics {
            let _ = write!(csv, ",{v}");
        }
        csv.push('\n');
    }
    atomic_write(&out.join("secondary.csv"), csv.as_bytes())?;
    atomic_write(&out.join("secondary.md"), secondary_md(&runs).as_bytes())?;
    Ok(runs)
}

/// `secondary.md`: one table, a row per scenario and case.
fn secondary_md(runs: &[SecondaryRun]) -> String {
    let mut md = String::from(
        "# The paper's secondary objectives: what they do to exposure, energy and tracking\n\n\
         Regenerate with `cargo run --release -- paper secondary --out results/paper/secondary`.\n\
         Cases (`[secondary]` of the scenario): controllability = `controllability_gain = 0.5`,\n\
         manipulability = `manipulability_gain = 0.1`, both = both. σ_c = commanded-subspace\n\
         σ_min of the scaled TCM [N/N] from the logged joint angles (10 Hz); turn = the 30 s\n\
         after the turn command; exposure = fraction of samples with σ_c below\n\
         `metrics.threshold`; m = manipulability √det(J_q J_qᵀ), mean over the run. Transport runs last 170 s.\n\n",
    );
    let mut t = MarkdownTable::new([
        "scenario",
        "case",
        "min σ_c",
        "min σ_c (turn)",
        "exposure",
        "mean m",
        "thruster energy [J]",
        "joint energy [J]",
        "final pos. error [m]",
        "settling [s]",
        "seg 1 conv. [s]",
        "cross-track RMS [m]",
        "final e_y [m]",
    ]);
    for r in runs {
        let cells = SECONDARY_KEYS.iter().map(|k| {
            let x = r.get(k);
            if x.is_nan() {
                "–".to_string()
            } else {
                format!("{x:.4}")
            }
        });
        t.row(
            [
                r.scenario.to_string(),
                if r.failed {
                    format!("{} (stopped early)", r.case)
                } else {
                    r.case.to_string()
                },
            ]
            .into_iter()
            .chain(cells),
        );
    }
    md.push_str(&t.finish());
    md
}
