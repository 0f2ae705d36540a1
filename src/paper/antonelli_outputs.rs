//! The `paper antonelli` pipeline: Antonelli & Chiaverini's case studies (docs/model.md §8) —
//! the kinematic cases 1, 1b and 2 ([`crate::paper::antonelli`]) on `uvms-planar` and the
//! dynamic case 3 ([`crate::paper::antonelli::dynamic`]: the NPS AUV II under current,
//! 3a holding its pose, 3b following case 1's re-orientation). Writes one CSV of time
//! histories per case (`<case>.csv`; case 3 under the as-written reading), the paper-like
//! figures (`fig*.svg`, see [`super::antonelli_figures`]) and a `summary.json` of what the
//! paper's text claims, with `table1` (the as-written reading) and `table1_readings` (every
//! named reading, [`CASE3_READINGS`]) beside the paper's Table I, and the steady-state
//! breakdown of the current forces.

use std::path::Path;

use serde::Serialize;

use crate::dynamics::manoeuvring::ManoeuvringKernel;
use crate::model::presets::uvms_planar;
use crate::paper::antonelli::dynamic::{
    run_dynamic_case, run_dynamic_case_on, BaseTrajectory, Case3Reading, DynamicCase,
    DynamicHistory, CASE3_READINGS,
};
use crate::paper::antonelli::{
    antonelli_case, run_kinematic_case, AntonelliCase, KinematicHistory, TaskTrace,
};
use crate::paper::nps_auv2::{nps_auv2, nps_auv2_hydro};
use crate::pipeline::error::{create_dir, PipelineError};
use crate::report::{atomic_write, write_csv, Table};
use crate::spatial::{cross_force, Se3, Vec3, Vec6};

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

/// The paper's Table I (Antonelli & Chiaverini 1998, section 5): `∫‖f‖dt` [N·s] and
/// `∫‖m‖dt` [N·m·s] over 100 s, a: without re-orientation, b: with.
pub const PAPER_TABLE1: Table1Values = Table1Values {
    force_integral_a: 2300.0,
    force_integral_b: 800.0,
    moment_integral_a: 9500.0,
    moment_integral_b: 5800.0,
};

/// The four entries of Table I.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Table1Values {
    /// `∫‖f‖dt` of case 3a [N·s].
    pub force_integral_a: f64,
    /// `∫‖f‖dt` of case 3b [N·s].
    pub force_integral_b: f64,
    /// `∫‖m‖dt` of case 3a [N·m·s].
    pub moment_integral_a: f64,
    /// `∫‖m‖dt` of case 3b [N·m·s].
    pub moment_integral_b: f64,
}

impl Table1Values {
    fn as_array(&self) -> [f64; 4] {
        [
            self.force_integral_a,
            self.force_integral_b,
            self.moment_integral_a,
            self.moment_integral_b,
        ]
    }
}

/// Table I of ours beside the paper's: the four integrals (`force_integral_a` … flattened into
/// this object), the paper's values, the relative difference `ours/paper − 1` of each, and
/// the a/b ratios.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Table1 {
    /// Ours.
    #[serde(flatten)]
    pub ours: Table1Values,
    /// The paper's.
    pub paper: Table1Values,
    /// `ours / paper − 1`, entry by entry (0.19: ours 19 % above the paper's).
    pub relative_difference: Table1Values,
    /// `[force a/b, moment a/b]`, ours.
    pub ratio_a_over_b: [f64; 2],
    /// `[force a/b, moment a/b]`, the paper's (2.875, 1.638).
    pub paper_ratio_a_over_b: [f64; 2],
}

impl Table1 {
    /// Ours (from the two runs) beside [`PAPER_TABLE1`].
    pub fn new(a: &DynamicHistory, b: &DynamicHistory) -> Self {
        let ours = Table1Values {
            force_integral_a: a.force_integral,
            force_integral_b: b.force_integral,
            moment_integral_a: a.moment_integral,
            moment_integral_b: b.moment_integral,
        };
        let p = PAPER_TABLE1;
        let q: Vec<f64> = ours
            .as_array()
            .iter()
            .zip(p.as_array())
            .map(|(o, p)| o / p - 1.0)
            .collect();
        Self {
            ours,
            paper: p,
            relative_difference: Table1Values {
                force_integral_a: q[0],
                force_integral_b: q[1],
                moment_integral_a: q[2],
                moment_integral_b: q[3],
            },
            ratio_a_over_b: [
                ours.force_integral_a / ours.force_integral_b,
                ours.moment_integral_a / ours.moment_integral_b,
            ],
            paper_ratio_a_over_b: [
                p.force_integral_a / p.force_integral_b,
                p.moment_integral_a / p.moment_integral_b,
            ],
        }
    }
}

/// A case-3 run in numbers (SI units).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DynamicSummary {
    /// `case3a` or `case3b`.
    pub name: String,
    /// `∫‖f‖dt` [N·s].
    pub force_integral: f64,
    /// `∫‖m‖dt` [N·m·s].
    pub moment_integral: f64,
    /// `∫‖f‖dt` over the first 10 s (the re-orientation of 3b) [N·s].
    pub force_integral_first_10s: f64,
    /// `∫‖m‖dt` over the first 10 s [N·m·s].
    pub moment_integral_first_10s: f64,
    /// Largest distance from the reference position [m].
    pub max_position_error: f64,
    /// Largest yaw error [rad].
    pub max_yaw_error: f64,
    /// Largest `|r|` over the logged samples [rad/s].
    pub max_yaw_rate: f64,
    /// Final pose `(x, y, ψ)` [m, m, rad].
    pub final_pose: [f64; 3],
    /// Final `‖f‖` [N] and `‖m‖` [N·m].
    pub final_norms: [f64; 2],
}

/// Trapezoid integral of the logged `y` over `t ≤ t_end` (for the first-10-s split; the
/// run's totals are exact sums at the control rate).
fn logged_integral(t: &[f64], y: &[f64], t_end: f64) -> f64 {
    t.windows(2)
        .zip(y.windows(2))
        .filter(|(w, _)| w[1] <= t_end + 1e-9)
        .map(|(w, v)| 0.5 * (w[1] - w[0]) * (v[0] + v[1]))
        .sum()
}

/// The summary of a case-3 run.
pub fn summarize_dynamic(h: &DynamicHistory) -> DynamicSummary {
    DynamicSummary {
        name: h.name.clone(),
        force_integral: h.force_integral,
        moment_integral: h.moment_integral,
        force_integral_first_10s: logged_integral(&h.t, &h.force_norm, 10.0),
        moment_integral_first_10s: logged_integral(&h.t, &h.moment_norm, 10.0),
        max_position_error: h.max_position_error(),
        max_yaw_error: h.max_yaw_error(),
        max_yaw_rate: h.twist[5].iter().fold(0.0, |m: f64, r| m.max(r.abs())),
        final_pose: [
            last(&h.position[0]),
            last(&h.position[1]),
            last(&h.attitude[2]),
        ],
        final_norms: [last(&h.force_norm), last(&h.moment_norm)],
    }
}

/// The hydrodynamic wrench on the NPS AUV II held still in the current, by part (not SNAME:
/// `F_b` axes of the crate, x forward, y port, z up; moments about `CO`) [N, N·m].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SteadyCurrentForces {
    /// Vehicle heading [rad].
    pub heading: f64,
    /// Velocity-product derivatives (`Xvv v²`, `Yv u v`, `Zvv v²`, `Mvv v²`, `Nv u v`, …).
    pub products: [f64; 6],
    /// Surge resistance `Cd0 ½ρL² |u|u`.
    pub resistance: [f64; 6],
    /// Cross-flow drag.
    pub crossflow: [f64; 6],
    /// Added-mass Coriolis `−C_A(ν_r) ν_r` (the Munk moment `(M_A,11 − M_A,22) u v` on yaw, a
    /// second time beside Healey's `N_uv`): only in the readings with
    /// [`DynamicCase::added_mass_coriolis`].
    pub added_mass_coriolis: [f64; 6],
    /// `‖f‖` and `‖m‖` [N, N·m] as written: products and cross-flow.
    pub norms: [f64; 2],
    /// `‖f‖` and `‖m‖` [N, N·m] of all four parts (the previous reading).
    pub norms_previous: [f64; 2],
    /// `100 s × norms`: what a perfect station keeper spends over the paper's 100 s, as
    /// written.
    pub over_100s: [f64; 2],
    /// `100 s × norms_previous`.
    pub over_100s_previous: [f64; 2],
}

/// The current's force on the still vehicle at heading `psi` (at rest, so `V_r = −R_Ibᵀ ν_c`),
/// by part; the norms as written (no surge resistance, no `C_A`) and with every part.
pub fn steady_current_forces(current: &crate::spatial::Vec3, psi: f64) -> SteadyCurrentForces {
    let v = nps_auv2();
    let hydro = nps_auv2_hydro(v.fluid.rho);
    let k = ManoeuvringKernel::new(&hydro);
    let (s, c) = psi.sin_cos();
    let rel = Vec6::new(
        -(c * current.x + s * current.y),
        s * current.x - c * current.y,
        0.0,
        0.0,
        0.0,
        0.0,
    );
    // `parts` takes the twist at the body origin and returns moments about it; the base
    // frame sits at CO, a pure translation ahead, so move the wrench to CO.
    let p = k.parts(&rel);
    let to_co = |w: Vec6| v.base.wrench_to_child(&w);
    let (pr, re, cf) = (to_co(p.products), to_co(p.resistance), to_co(p.crossflow));
    // Fossen's C_A(ν_r) ν_r at CO (the Kirchhoff term; the water applies its negative).
    let m_a = Se3::new(hydro.axes, Vec3::zeros()).inertia_to_parent(&hydro.added_mass);
    let ca = -cross_force(&rel, &(m_a * rel));
    let norms_of = |w: Vec6| [w.fixed_rows::<3>(0).norm(), w.fixed_rows::<3>(3).norm()];
    let norms = norms_of(pr + cf);
    let norms_previous = norms_of(pr + re + cf + ca);
    let arr = |w: Vec6| [w[0], w[1], w[2], w[3], w[4], w[5]];
    SteadyCurrentForces {
        heading: psi,
        products: arr(pr),
        resistance: arr(re),
        crossflow: arr(cf),
        added_mass_coriolis: arr(ca),
        norms,
        norms_previous,
        over_100s: norms.map(|n| 100.0 * n),
        over_100s_previous: norms_previous.map(|n| 100.0 * n),
    }
}

/// Table I under one named reading of case 3 ([`CASE3_READINGS`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ReadingTable1 {
    /// The reading: its name, what it is and its switches.
    #[serde(flatten)]
    pub reading: Case3Reading,
    /// Its Table I beside the paper's.
    pub table1: Table1,
    /// The two runs (3a, 3b) in numbers.
    pub runs: [DynamicSummary; 2],
}

/// Table I under every reading of [`CASE3_READINGS`], in that order; `case1` is case 1's
/// vehicle motion ([`BaseTrajectory::from_kinematic`]), from which each reading takes 3b's
/// reference ([`Case3Reading::reference_b`]); 3a holds the initial pose.
pub fn case3_readings(case1: &BaseTrajectory) -> Result<Vec<ReadingTable1>, PipelineError> {
    let hold = BaseTrajectory::hold([0.0; 3]);
    CASE3_READINGS
        .iter()
        .map(|reading| {
            let a = run_dynamic_case(&DynamicCase::from_reading("case3a", reading), &hold)?;
            let b = run_dynamic_case(
                &DynamicCase::from_reading("case3b", reading),
                &reading.reference_b(case1),
            )?;
            Ok(ReadingTable1 {
                reading: *reading,
                table1: Table1::new(&a, &b),
                runs: [summarize_dynamic(&a), summarize_dynamic(&b)],
            })
        })
        .collect()
}

/// Table I as written with one group of the NPS AUV II's coefficients changed: how much of
/// each entry that group carries (not a reading of the paper; the diagnosis of FINDINGS.md).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Sensitivity {
    /// Short name.
    pub name: &'static str,
    /// What is changed.
    pub what: &'static str,
    /// Table I beside the paper's.
    pub table1: Table1,
    /// The two runs (3a, 3b) in numbers.
    pub runs: [DynamicSummary; 2],
}

type Change = fn(&mut crate::model::manoeuvring::Manoeuvring);

/// The coefficient groups [`case3_sensitivities`] changes.
const SENSITIVITIES: [(&str, &str, Change); 3] = [
    (
        "no_velocity_products",
        "as written without the velocity-product derivatives (Healey's lift and coupling terms)",
        |m| m.products.iter_mut().for_each(|p| p.fill(0.0)),
    ),
    (
        "no_crossflow",
        "as written without the cross-flow drag integrals",
        |m| m.crossflow.width = 0.0,
    ),
    (
        "crossflow_x1_8",
        "as written with the cross-flow drag coefficients x1.8",
        |m| {
            m.crossflow.k_y *= 1.8;
            m.crossflow.k_z *= 1.8;
        },
    ),
];

/// Table I as written under each coefficient change of the module's sensitivity list
/// (velocity products off, cross-flow off, cross-flow ×1.8); `case1` as in
/// [`case3_readings`].
pub fn case3_sensitivities(case1: &BaseTrajectory) -> Result<Vec<Sensitivity>, PipelineError> {
    let hold = BaseTrajectory::hold([0.0; 3]);
    let reading = Case3Reading::AS_WRITTEN;
    SENSITIVITIES
        .iter()
        .map(|(name, what, change)| {
            let case = |n: &str| DynamicCase::from_reading(n, &reading);
            let mut v = case("").vehicle();
            if let crate::model::Hydro::Manoeuvring(m) = &mut v.bodies[0].hydro {
                change(m);
            }
            let a = run_dynamic_case_on(&v, &case("case3a"), &hold)?;
            let b = run_dynamic_case_on(&v, &case("case3b"), &reading.reference_b(case1))?;
            Ok(Sensitivity {
                name,
                what,
                table1: Table1::new(&a, &b),
                runs: [summarize_dynamic(&a), summarize_dynamic(&b)],
            })
        })
        .collect()
}

/// `table1_readings` of `summary.json`: an object keyed by reading name, in
/// [`CASE3_READINGS`] order.
struct ReadingMap<'a>(&'a [ReadingTable1]);

impl Serialize for ReadingMap<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut m = s.serialize_map(Some(self.0.len()))?;
        for r in self.0 {
            m.serialize_entry(r.reading.name, r)?;
        }
        m.end()
    }
}

/// `summary.json`: the case summaries, Table I and the choices the paper leaves open.
#[derive(Serialize)]
struct Summary<'a> {
    source: &'static str,
    inferred: &'static str,
    cases: &'a [CaseSummary],
    case3: &'a [DynamicSummary],
    table1_reading: &'static str,
    table1: &'a Table1,
    table1_readings: ReadingMap<'a>,
    table1_sensitivity: &'a [Sensitivity],
    steady_current_forces: [SteadyCurrentForces; 2],
}

/// What `run_antonelli` returns.
#[derive(Clone, Debug, PartialEq)]
pub struct AntonelliOutcome {
    /// Cases 1, 1b, 2.
    pub kinematic: Vec<CaseSummary>,
    /// Cases 3a, 3b (as written).
    pub dynamic: Vec<DynamicSummary>,
    /// Table I as written, ours beside the paper's.
    pub table1: Table1,
    /// Table I under every named reading (the as-written one first).
    pub readings: Vec<ReadingTable1>,
}

fn write_table(columns: Vec<(String, &[f64])>, path: &Path) -> Result<(), PipelineError> {
    let mut table = Table::new();
    for (name, col) in columns {
        table.push(name, col.to_vec())?;
    }
    Ok(write_csv(&table, path)?)
}

/// Run cases 1, 1b, 2, 3a and 3b and write `<case>.csv`, the figures and `summary.json` into
/// `out`; `on_case` is called after each kinematic case. Returns the summaries and Table I.
pub fn run_antonelli(
    out: &Path,
    on_case: &mut dyn FnMut(&CaseSummary),
) -> Result<AntonelliOutcome, PipelineError> {
    create_dir(out)?;
    let v = uvms_planar();
    let mut summaries = Vec::new();
    let mut histories = Vec::new();
    for which in AntonelliCase::ALL {
        let h = run_kinematic_case(&v, &antonelli_case(which))?;
        write_table(h.columns(), &out.join(format!("{}.csv", which.name())))?;
        let s = summarize(&h);
        on_case(&s);
        summaries.push(s);
        histories.push(h);
    }
    let case1 = case1_vehicle_motion()?;
    let as_written = Case3Reading::AS_WRITTEN;
    let hold = BaseTrajectory::hold([0.0; 3]);
    let a = run_dynamic_case(&DynamicCase::paper("case3a"), &hold)?;
    let b = run_dynamic_case(
        &DynamicCase::paper("case3b"),
        &as_written.reference_b(&case1),
    )?;
    let readings = case3_readings(&case1)?;
    let sensitivity = case3_sensitivities(&case1)?;
    for h in [&a, &b] {
        write_table(h.columns(), &out.join(format!("{}.csv", h.name)))?;
    }
    super::antonelli_figures::write_figures(out, &histories, &[&a, &b])?;
    let table1 = Table1::new(&a, &b);
    let dynamic = vec![summarize_dynamic(&a), summarize_dynamic(&b)];
    let current = DynamicCase::paper("").current;
    let summary = Summary {
        source: "Antonelli & Chiaverini (1998), section 5 and Table I; SPEC §8",
        inferred: "arm geometry of uvms-planar (SPEC §8); 10 s kinematic runs (the quintic's \
                   duration); RK4 at 1 ms, samples every 50 ms; Moore–Penrose pseudoinverses \
                   of the planar Jacobians (λ = 0). Case 3: the NPS AUV II alone (legacy MSS \
                   constants ρ = 1000, m = 5454.54), starting at rest; sliding-mode gains and \
                   boundary layer of paper::sliding; 100 Hz control, RK4 at 10 ms. Read from \
                   the text (table1, reading as_written): 3b follows case 1's heading with \
                   the position held; no surge resistance (a current along x is not \
                   modelled); the regulation law of ref. [1] without feed-forward; Healey's \
                   derivatives alone (no C_A on top). Other readings: table1_readings",
        cases: &summaries,
        case3: &dynamic,
        table1_reading: as_written.name,
        table1: &table1,
        table1_readings: ReadingMap(&readings),
        table1_sensitivity: &sensitivity,
        steady_current_forces: [
            steady_current_forces(&current, 0.0),
            steady_current_forces(&current, 0.78),
        ],
    };
    let json = serde_json::to_vec_pretty(&summary)?;
    atomic_write(&out.join("summary.json"), &json)?;
    Ok(AntonelliOutcome {
        kinematic: summaries,
        dynamic,
        table1,
        readings,
    })
}

/// One of the paper's cases as a `simulate` preset (`antonelli-case1`, `-case1b`, `-case2`,
/// `-case3a`, `-case3b`). Not a TOML scenario: the kinematic cases have no dynamics and case 3
/// drives generalised forces without allocation, which the transport/work closed loop does
/// not model; `simulate` dispatches these names here.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AntonelliPreset {
    /// A kinematic case (1, 1b, 2).
    Kinematic(AntonelliCase),
    /// Case 3a: hold the pose against the current (as written).
    Case3a,
    /// Case 3b: follow case 1's re-orientation (as written: heading only, position held).
    Case3b,
}

impl AntonelliPreset {
    /// The preset names, in the paper's order.
    pub const NAMES: [&'static str; 5] = [
        "antonelli-case1",
        "antonelli-case1b",
        "antonelli-case2",
        "antonelli-case3a",
        "antonelli-case3b",
    ];

    /// The preset called `name`, if any.
    pub fn parse(name: &str) -> Option<Self> {
        match name.strip_prefix("antonelli-")? {
            "case3a" => Some(AntonelliPreset::Case3a),
            "case3b" => Some(AntonelliPreset::Case3b),
            other => AntonelliCase::ALL
                .into_iter()
                .find(|c| c.name() == other)
                .map(AntonelliPreset::Kinematic),
        }
    }
}

/// Case 1's vehicle motion sampled at case 3's control rate (10 ms), from which each reading
/// takes 3b's reference ([`Case3Reading::reference_b`]).
pub fn case1_vehicle_motion() -> Result<BaseTrajectory, PipelineError> {
    let mut case1 = antonelli_case(AntonelliCase::Case1);
    case1.record_every = 10;
    Ok(BaseTrajectory::from_kinematic(&run_kinematic_case(
        &uvms_planar(),
        &case1,
    )?))
}

/// Run one preset and write `<case>.csv` and `summary.json` (its [`CaseSummary`] or
/// [`DynamicSummary`]) into `out`; returns the summary as JSON.
pub fn run_antonelli_preset(
    preset: AntonelliPreset,
    out: &Path,
) -> Result<serde_json::Value, PipelineError> {
    create_dir(out)?;
    let summary = match preset {
        AntonelliPreset::Kinematic(which) => {
            let h = run_kinematic_case(&uvms_planar(), &antonelli_case(which))?;
            write_table(h.columns(), &out.join(format!("{}.csv", which.name())))?;
            serde_json::to_value(summarize(&h))?
        }
        AntonelliPreset::Case3a | AntonelliPreset::Case3b => {
            let (name, reference) = if preset == AntonelliPreset::Case3a {
                ("case3a", BaseTrajectory::hold([0.0; 3]))
            } else {
                (
                    "case3b",
                    Case3Reading::AS_WRITTEN.reference_b(&case1_vehicle_motion()?),
                )
            };
            let h = run_dynamic_case(&DynamicCase::paper(name), &reference)?;
            write_table(h.columns(), &out.join(format!("{name}.csv")))?;
            serde_json::to_value(summarize_dynamic(&h))?
        }
    };
    atomic_write(
        &out.join("summary.json"),
        &serde_json::to_vec_pretty(&summary)?,
    )?;
    Ok(summary)
}
