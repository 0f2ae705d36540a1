//! `usm-study inspect DESIGN [--state STATE.json] [--format text|json] [--rigid]`.

use super::{fmt_num, Format};
use crate::dynamics::{inspect_dynamics, DynOptions, DynamicsReport, SimState};
use crate::kinematics::{ee_jacobian, forward_kinematics, thruster_matrix_owned, KinWorkspace};
use crate::metrics::singularity::{tcm_metrics, tcm_svd_metrics, LostDirection, TcmMetrics};
use crate::model::design::load_design;
use crate::model::Vehicle;
use crate::state::{load_state, VehicleState};
use anyhow::Context;
use clap::Args;
use faer::Mat;
use serde::Serialize;
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `inspect`.
#[derive(Debug, Args)]
pub struct InspectArgs {
    /// Preset name (usm-paper, uvms-planar) or path to a design file (TOML).
    pub design: String,
    /// State file (JSON): base_position, base_rotation, joint_angles, and optionally
    /// base_twist, joint_rates, generalized_forces. Default: straight, at rest, at the origin.
    #[arg(long)]
    pub state: Option<PathBuf>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    pub format: Format,
    /// Relative tolerance for the rank of T(q) (fraction of the largest singular value).
    #[arg(long, default_value_t = 1e-6)]
    pub rank_tol: f64,
    /// Bodies in vacuum: no added mass, drag, restoring forces or current (for comparison
    /// with ordinary rigid-body libraries).
    #[arg(long)]
    pub rigid: bool,
}

/// The kinematic part of the inspect report (stable JSON keys, SI units).
#[derive(Debug, Serialize)]
pub struct KinematicsReport {
    /// Design name.
    pub design: String,
    /// Total mass [kg].
    pub total_mass: f64,
    /// Total length [m].
    pub total_length: f64,
    /// End-effector position in the inertial frame [m].
    pub ee_position: [f64; 3],
    /// End-effector orientation (maps end-effector vectors to inertial), rows.
    pub ee_rotation: [[f64; 3]; 3],
    /// End-effector geometric Jacobian (USM-18) in the end-effector frame, 6×(6+n) rows.
    pub ee_jacobian: Vec<Vec<f64>>,
    /// Thruster configuration matrix T(q) (USM-26) in the base frame, 6×m rows.
    pub tcm: Vec<Vec<f64>>,
    /// Singular values of T(q), unscaled, six, descending (zeros when m < 6).
    pub tcm_singular_values: Vec<f64>,
    /// Numerical rank of T(q) with the relative tolerance `rank_tol`.
    pub tcm_rank: usize,
    /// Wrench directions T(q) cannot produce, each labelled by its dominant base axis.
    pub tcm_lost_directions: Vec<LostDirection>,
    /// Metrics of the moment-scaled T(q) (SPEC §6): σ_min, κ, rank, attainable wrench.
    pub tcm_scaled: TcmMetrics,
}

fn rows(m: &Mat<f64>) -> Vec<Vec<f64>> {
    (0..m.nrows())
        .map(|r| (0..m.ncols()).map(|c| m[(r, c)]).collect())
        .collect()
}

/// Evaluate the kinematic report of `v` at `s`; `rank_tol` is relative to σ_max.
pub fn kinematics_report(
    v: &Vehicle,
    s: &VehicleState,
    rank_tol: f64,
) -> anyhow::Result<KinematicsReport> {
    let mut ws = KinWorkspace::new(v);
    forward_kinematics(v, &s.q, &mut ws);
    let g_ie = s.base.to_se3().compose(&ws.g_be);
    let mut j = Mat::<f64>::zeros(6, v.n_dof());
    ee_jacobian(&ws, &mut j);
    let t = thruster_matrix_owned(v, &ws);
    let m = t.ncols();
    let u_min: Vec<f64> = v.thrusters.iter().map(|t| t.u_min).collect();
    let u_max: Vec<f64> = v.thrusters.iter().map(|t| t.u_max).collect();
    // A characteristic length of 1 m leaves T unscaled.
    let raw = tcm_svd_metrics(&t, 1.0, rank_tol).context("analysing T(q)")?;
    let scaled = tcm_metrics(&t, &u_min, &u_max, v.characteristic_length(), rank_tol)
        .context("analysing the scaled T(q)")?;
    Ok(KinematicsReport {
        design: v.name.clone(),
        total_mass: v.total_mass(),
        total_length: v.total_length(),
        ee_position: [g_ie.p.x, g_ie.p.y, g_ie.p.z],
        ee_rotation: [0, 1, 2].map(|r| [0, 1, 2].map(|c| g_ie.r[(r, c)])),
        ee_jacobian: rows(&j),
        tcm: (0..6)
            .map(|r| (0..m).map(|c| t[(r, c)]).collect())
            .collect(),
        tcm_singular_values: raw.singular_values.to_vec(),
        tcm_rank: raw.rank,
        tcm_lost_directions: raw.lost_directions,
        tcm_scaled: scaled,
    })
}

/// Run `inspect`.
pub fn run(a: &InspectArgs) -> anyhow::Result<ExitCode> {
    if !(a.rank_tol.is_finite() && a.rank_tol >= 0.0) {
        anyhow::bail!(
            "--rank-tol must be a finite number >= 0, got {}",
            a.rank_tol
        );
    }
    let v = load_design(&a.design)?;
    let s = match &a.state {
        Some(p) => load_state(p, &v)?,
        None => VehicleState::rest(&v),
    };
    let k = kinematics_report(&v, &s, a.rank_tol)?;
    let sim_state = SimState {
        pose: s.base,
        joint_angles: s.q.clone(),
        base_twist: s.twist,
        joint_rates: s.qd.clone(),
        thrust: vec![0.0; v.n_thrusters()],
    };
    let options = if a.rigid {
        DynOptions::rigid()
    } else {
        DynOptions::full()
    };
    let d = inspect_dynamics(&v, &sim_state, &s.generalized_forces, &options)
        .context("evaluating the dynamics at the state")?;
    match a.format {
        Format::Json => {
            let mut obj = serde_json::to_value(&k).context("serialising the report")?;
            let dv = serde_json::to_value(&d).context("serialising the report")?;
            if let (Some(o), serde_json::Value::Object(dm)) = (obj.as_object_mut(), dv) {
                o.extend(dm);
                o.insert("rigid".into(), serde_json::Value::Bool(a.rigid));
            }
            println!("{}", serde_json::to_string_pretty(&obj)?);
        }
        Format::Text => print!("{}", text_report(&v, &k, &d, a.rigid)),
    }
    Ok(ExitCode::SUCCESS)
}

fn text_report(v: &Vehicle, k: &KinematicsReport, d: &DynamicsReport, rigid: bool) -> String {
    use std::fmt::Write;
    let mut o = String::new();
    let _ = writeln!(o, "design {}", v.name);
    let _ = writeln!(
        o,
        "  {} bodies, {} joints, {} thrusters; total mass {:.3} kg, total length {:.3} m",
        v.bodies.len(),
        v.n_joints(),
        v.n_thrusters(),
        k.total_mass,
        k.total_length
    );
    let _ = writeln!(o, "\nbodies");
    let _ = writeln!(
        o,
        "  {:>3} {:<10} {:>9} {:>9} {:>9} {:>11} {:>7}",
        "#", "name", "mass kg", "length m", "radius m", "volume m3", "hydro"
    );
    for (i, b) in v.bodies.iter().enumerate() {
        let hydro = match b.hydro {
            crate::model::Hydro::Cylinder { .. } => "cyl",
            crate::model::Hydro::Coefficients { .. } => "coeff",
        };
        let _ = writeln!(
            o,
            "  {:>3} {:<10} {:>9.3} {:>9.3} {:>9.3} {:>11.5} {:>7}",
            i, b.name, b.mass, b.length, b.radius, b.volume, hydro
        );
    }
    let _ = writeln!(o, "\njoints (joint k joins body k to body k+1)");
    for (i, j) in v.joints.iter().enumerate() {
        let _ = writeln!(
            o,
            "  {:>3} {:<8} axis [{:.3} {:.3} {:.3}] at [{:.3} {:.3} {:.3}] limits [{:.1}°, {:.1}°]",
            i,
            j.name,
            j.axis.x,
            j.axis.y,
            j.axis.z,
            j.placement.p.x,
            j.placement.p.y,
            j.placement.p.z,
            j.min.to_degrees(),
            j.max.to_degrees()
        );
    }
    let _ = writeln!(o, "\nthrusters");
    for (i, t) in v.thrusters.iter().enumerate() {
        let _ = writeln!(
            o,
            "  {:>3} {:<6} on {:<6} at [{:.3} {:.3} {:.3}] dir [{:.3} {:.3} {:.3}] limits [{}, {}] N",
            i,
            t.name,
            v.bodies[t.body].name,
            t.position.x,
            t.position.y,
            t.position.z,
            t.direction.x,
            t.direction.y,
            t.direction.z,
            t.u_min,
            t.u_max
        );
    }
    let p = k.ee_position;
    let _ = writeln!(
        o,
        "\nend-effector position [m]: [{} {} {}]",
        fmt_num(p[0]),
        fmt_num(p[1]),
        fmt_num(p[2])
    );
    let _ = writeln!(o, "end-effector rotation:");
    for r in k.ee_rotation {
        let _ = writeln!(o, "  [{:>8.4} {:>8.4} {:>8.4}]", r[0], r[1], r[2]);
    }
    let _ = writeln!(
        o,
        "\nthruster configuration matrix T(q) (base frame; rows fx fy fz mx my mz)"
    );
    for (r, row) in k.tcm.iter().enumerate() {
        let cells: Vec<String> = row.iter().map(|x| format!("{x:>8.4}")).collect();
        let _ = writeln!(
            o,
            "  {} {}",
            ["fx", "fy", "fz", "mx", "my", "mz"][r],
            cells.join(" ")
        );
    }
    let sv: Vec<String> = k.tcm_singular_values.iter().map(|x| fmt_num(*x)).collect();
    let _ = writeln!(o, "singular values: {}", sv.join(", "));
    let _ = writeln!(o, "rank: {} of 6", k.tcm_rank);
    for l in &k.tcm_lost_directions {
        let dir: Vec<String> = l.direction.iter().map(|x| format!("{x:.3}")).collect();
        let _ = writeln!(o, "lost direction: {} [{}]", l.dominant_axis, dir.join(" "));
    }
    let sc = &k.tcm_scaled;
    let _ = writeln!(
        o,
        "scaled T (moments / {:.3} m): sigma_min {}, condition number {}",
        sc.char_length,
        fmt_num(sc.sigma_min),
        fmt_num(sc.condition_number)
    );
    if let Some(att) = &sc.attainable {
        let _ = writeln!(
            o,
            "attainable base wrench under the thrust limits [N, N·m]:"
        );
        for (i, axis) in ["surge", "sway", "heave", "roll", "pitch", "yaw"]
            .iter()
            .enumerate()
        {
            let _ = writeln!(
                o,
                "  {axis:<6} +{} / -{}",
                fmt_num(att.positive[i]),
                fmt_num(att.negative[i])
            );
        }
    }
    let _ = writeln!(
        o,
        "\ndynamics ({})",
        if rigid {
            "rigid bodies in vacuum"
        } else {
            "added mass, drag, restoring forces, current"
        }
    );
    let ev = &d.mass_matrix_eigenvalues;
    let _ = writeln!(
        o,
        "  mass matrix {n}x{n}: eigenvalues {} .. {}, condition number {}",
        fmt_num(ev.first().copied().unwrap_or(f64::NAN)),
        fmt_num(ev.last().copied().unwrap_or(f64::NAN)),
        fmt_num(d.mass_matrix_condition),
        n = d.mass_matrix.len()
    );
    let _ = writeln!(o, "  kinetic energy: {} J", fmt_num(d.kinetic_energy));
    let bias: Vec<String> = d.bias.iter().map(|x| fmt_num(*x)).collect();
    let _ = writeln!(o, "  bias h: [{}]", bias.join(", "));
    let acc: Vec<String> = d.acceleration.iter().map(|x| fmt_num(*x)).collect();
    let _ = writeln!(o, "  acceleration: [{}]", acc.join(", "));
    o
}
