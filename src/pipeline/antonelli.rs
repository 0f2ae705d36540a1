//! The `paper antonelli` pipeline: Antonelli & Chiaverini's kinematic case studies 1, 1b and 2
//! (SPEC §8, [`crate::scenario::antonelli`]) on `uvms-planar`, written as one CSV of time
//! histories per case (`<case>.csv`, the columns of
//! [`KinematicHistory::columns`]) and a `summary.json` of what the paper's text claims
//! (targets reached, end-effector held or tracked, vehicle motion, bounded rates).
//! Case 3 (the dynamic NPS AUV II runs and Table I) and the paper-like figures are not part
//! of it yet.

use std::path::Path;

use serde::Serialize;

use super::error::{create_dir, PipelineError};
use crate::model::presets::uvms_planar;
use crate::report::{atomic_write, write_csv, Table};
use crate::scenario::antonelli::{
    antonelli_case, run_kinematic_case, AntonelliCase, KinematicHistory, TaskTrace,
};

/// What a kinematic case run shows, in the terms of the paper's text (SI units, rad).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CaseSummary {
    /// `case1`, `case1b` or `case2`.
    pub name: String,
    /// Simulated time [s].
    pub duration: f64,
    /// Largest end-effector position error `‖(x_e, y_e) − (x_e,d, y_e,d)‖` over the run [m].
    pub max_ee_position_error: f64,
    /// Largest end-effector heading error `|ψ_e,d − ψ_e|` over the run [rad].
    pub max_ee_heading_error: f64,
    /// Name of the fourth primary row (`psi` or `q2`).
    pub fourth_task: String,
    /// Its final value [rad].
    pub fourth_task_final: f64,
    /// Its final desired value [rad].
    pub fourth_task_target: f64,
    /// Final vehicle pose `(x, y, ψ)` [m, m, rad].
    pub final_vehicle: [f64; 3],
    /// Largest vehicle distance from its initial (and desired) position [m].
    pub max_vehicle_displacement: f64,
    /// Final end-effector pose `(x_e, y_e, ψ_e)` [m, m, rad].
    pub final_ee: [f64; 3],
    /// Final joint angles [rad].
    pub final_q: Vec<f64>,
    /// Largest joint rate magnitude [rad/s].
    pub max_joint_rate: f64,
    /// Smallest algorithmic-singularity measure `σ_min(J_s N_p)` over the samples.
    pub min_sigma_s: f64,
    /// Time of that smallest measure [s].
    pub t_min_sigma_s: f64,
}

fn last(x: &[f64]) -> f64 {
    x.last().copied().unwrap_or(f64::NAN)
}

fn find<'a>(h: &'a KinematicHistory, name: &str) -> Option<&'a TaskTrace> {
    h.primary.iter().find(|t| t.name == name)
}

/// The summary of one run.
pub fn summarize(h: &KinematicHistory) -> CaseSummary {
    let ee_pos = match (find(h, "x_e"), find(h, "y_e")) {
        (Some(x), Some(y)) => (0..h.t.len())
            .map(|i| (x.desired[i] - x.value[i]).hypot(y.desired[i] - y.value[i]))
            .fold(0.0, f64::max),
        _ => f64::NAN,
    };
    let fourth = h.primary.get(3);
    let (i_min, sigma) =
        h.sigma_s.iter().enumerate().fold(
            (0, f64::INFINITY),
            |a, (i, &s)| if s < a.1 { (i, s) } else { a },
        );
    CaseSummary {
        name: h.name.clone(),
        duration: last(&h.t),
        max_ee_position_error: ee_pos,
        max_ee_heading_error: find(h, "psi_e").map_or(f64::NAN, TaskTrace::max_abs_error),
        fourth_task: fourth.map_or(String::new(), |t| t.name.clone()),
        fourth_task_final: fourth.map_or(f64::NAN, TaskTrace::final_value),
        fourth_task_target: fourth.map_or(f64::NAN, |t| last(&t.desired)),
        final_vehicle: [last(&h.base[0]), last(&h.base[1]), last(&h.base[2])],
        max_vehicle_displacement: (0..h.t.len())
            .map(|i| (h.base[0][i] - h.base[0][0]).hypot(h.base[1][i] - h.base[1][0]))
            .fold(0.0, f64::max),
        final_ee: [last(&h.ee[0]), last(&h.ee[1]), last(&h.ee[2])],
        final_q: h.q.iter().map(|s| last(s)).collect(),
        max_joint_rate: h.qd.iter().flatten().fold(0.0, |a: f64, b| a.max(b.abs())),
        min_sigma_s: sigma,
        t_min_sigma_s: h.t.get(i_min).copied().unwrap_or(f64::NAN),
    }
}

/// `summary.json`: the case summaries and the choices the paper leaves open.
#[derive(Serialize)]
struct Summary<'a> {
    source: &'static str,
    inferred: &'static str,
    cases: &'a [CaseSummary],
}

/// Run cases 1, 1b and 2 and write `<case>.csv` and `summary.json` into `out`; `on_case` is
/// called after each case. Returns the summaries.
pub fn run_antonelli(
    out: &Path,
    on_case: &mut dyn FnMut(&CaseSummary),
) -> Result<Vec<CaseSummary>, PipelineError> {
    create_dir(out)?;
    let v = uvms_planar();
    let mut summaries = Vec::new();
    for which in AntonelliCase::ALL {
        let h = run_kinematic_case(&v, &antonelli_case(which))?;
        let mut table = Table::new();
        for (name, col) in h.columns() {
            table.push(name, col.to_vec())?;
        }
        write_csv(&table, &out.join(format!("{}.csv", which.name())))?;
        let s = summarize(&h);
        on_case(&s);
        summaries.push(s);
    }
    let summary = Summary {
        source: "Antonelli & Chiaverini (1998), section 5; SPEC §8",
        inferred: "arm geometry of uvms-planar (SPEC §8); 10 s runs (the quintic's duration); \
                   RK4 at 1 ms, samples every 50 ms; Moore–Penrose pseudoinverses of the planar \
                   Jacobians (λ = 0)",
        cases: &summaries,
    };
    let json = serde_json::to_vec_pretty(&summary)?;
    atomic_write(&out.join("summary.json"), &json)?;
    Ok(summaries)
}
