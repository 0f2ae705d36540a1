//! `usm-study inspect DESIGN [--state STATE.json] [--format text|json]`.

use super::{fmt_num, Format};
use crate::kinematics::{ee_jacobian, forward_kinematics, thruster_matrix_owned, KinWorkspace};
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
    /// Singular values of T(q), unscaled, descending.
    pub tcm_singular_values: Vec<f64>,
    /// Numerical rank of T(q) with the relative tolerance `rank_tol`.
    pub tcm_rank: usize,
    /// Unit base-wrench directions T(q) cannot produce (left singular vectors with
    /// singular value below the tolerance), each labelled by its dominant axis.
    pub tcm_lost_directions: Vec<LostDirection>,
}

/// A wrench direction lost by T(q).
#[derive(Debug, Serialize)]
pub struct LostDirection {
    /// Dominant base axis: surge, sway, heave, roll, pitch or yaw.
    pub axis: String,
    /// Unit 6-vector `[f; m]` in the base frame.
    pub direction: [f64; 6],
}

const AXES: [&str; 6] = ["surge", "sway", "heave", "roll", "pitch", "yaw"];

fn rows(m: &Mat<f64>) -> Vec<Vec<f64>> {
    (0..m.nrows())
        .map(|r| (0..m.ncols()).map(|c| m[(r, c)]).collect())
        .collect()
}

/// Evaluate the kinematic report of `v` at `s`.
pub fn kinematics_report(v: &Vehicle, s: &VehicleState, rank_tol: f64) -> KinematicsReport {
    let mut ws = KinWorkspace::new(v);
    forward_kinematics(v, &s.q, &mut ws);
    let g_ie = s.base.to_se3().compose(&ws.g_be);
    let mut j = Mat::<f64>::zeros(6, v.n_dof());
    ee_jacobian(&ws, &mut j);
    let t = thruster_matrix_owned(v, &ws);
    let m = t.ncols();
    let (sv, lost) = if m == 0 {
        (Vec::new(), Vec::new())
    } else {
        // Full SVD of the 6×6 Gram matrix T Tᵀ gives all six left singular directions,
        // including those of a T with fewer than six columns.
        let gram = &t * t.transpose();
        let eig = gram.symmetric_eigen();
        let mut idx: Vec<usize> = (0..6).collect();
        idx.sort_by(|a, b| eig.eigenvalues[*b].total_cmp(&eig.eigenvalues[*a]));
        let sv: Vec<f64> = idx
            .iter()
            .map(|&i| eig.eigenvalues[i].max(0.0).sqrt())
            .collect();
        let tol = rank_tol * sv[0];
        let lost = idx
            .iter()
            .zip(&sv)
            .filter(|(_, s)| **s <= tol)
            .map(|(&i, _)| {
                let d = eig.eigenvectors.column(i);
                let k = d.iamax();
                let sign = if d[k] < 0.0 { -1.0 } else { 1.0 };
                let mut dir = [0.0; 6];
                for (r, x) in dir.iter_mut().enumerate() {
                    *x = sign * d[r];
                }
                LostDirection {
                    axis: AXES[k].to_string(),
                    direction: dir,
                }
            })
            .collect();
        let keep = m.min(6);
        (sv[..keep].to_vec(), lost)
    };
    let tol = rank_tol * sv.first().copied().unwrap_or(0.0);
    KinematicsReport {
        design: v.name.clone(),
        total_mass: v.total_mass(),
        total_length: v.total_length(),
        ee_position: [g_ie.p.x, g_ie.p.y, g_ie.p.z],
        ee_rotation: [0, 1, 2].map(|r| [0, 1, 2].map(|c| g_ie.r[(r, c)])),
        ee_jacobian: rows(&j),
        tcm: (0..6)
            .map(|r| (0..m).map(|c| t[(r, c)]).collect())
            .collect(),
        tcm_rank: sv.iter().filter(|s| **s > tol).count(),
        tcm_singular_values: sv,
        tcm_lost_directions: lost,
    }
}

/// Run `inspect`.
pub fn run(a: &InspectArgs) -> anyhow::Result<ExitCode> {
    let v = load_design(&a.design)?;
    let s = match &a.state {
        Some(p) => load_state(p, &v)?,
        None => VehicleState::rest(&v),
    };
    let k = kinematics_report(&v, &s, a.rank_tol);
    match a.format {
        Format::Json => {
            let text = serde_json::to_string_pretty(&k).context("serialising the report")?;
            println!("{text}");
        }
        Format::Text => print!("{}", text_report(&v, &k)),
    }
    Ok(ExitCode::SUCCESS)
}

fn text_report(v: &Vehicle, k: &KinematicsReport) -> String {
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
        let d: Vec<String> = l.direction.iter().map(|x| format!("{x:.3}")).collect();
        let _ = writeln!(o, "lost direction: {} [{}]", l.axis, d.join(" "));
    }
    o
}
