//! `usm-study inspect DESIGN [--state STATE.json] [--format text|json] [--rigid]`: the report
//! of [`usm_study::pipeline::inspect`], printed as text or JSON.

use super::format::Format;
use anyhow::Context;
use clap::Args;
use std::fmt::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use usm_study::model::design::load_design;
use usm_study::model::{Hydro, Vehicle};
use usm_study::pipeline::inspect::{inspect, InspectReport, KinematicsReport};
use usm_study::report::fmt_num;
use usm_study::state::{load_state, VehicleState};

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
    let report = inspect(&v, &s, a.rank_tol, a.rigid)?;
    match a.format {
        Format::Json => {
            let obj = report.to_json().context("serialising the report")?;
            println!("{}", serde_json::to_string_pretty(&obj)?);
        }
        Format::Text => {
            let mut o = String::new();
            write_design(&mut o, &v, &report.kinematics);
            write_kinematics(&mut o, &report.kinematics);
            write_authority(&mut o, &report.kinematics);
            write_dynamics(&mut o, &report);
            write_hydrostatics(&mut o, &report);
            print!("{o}");
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// `[a, b, c]` of numbers in the short format.
fn num_list(xs: &[f64]) -> String {
    xs.iter()
        .map(|x| fmt_num(*x))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The design: bodies, joints and thrusters.
fn write_design(o: &mut String, v: &Vehicle, k: &KinematicsReport) {
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
            Hydro::Cylinder { .. } => "cyl",
            Hydro::Coefficients { .. } => "coeff",
            Hydro::Manoeuvring(_) => "manoeuv",
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
}

/// End-effector pose, `T(q)`, its singular values, lost directions and attainable wrench.
fn write_kinematics(o: &mut String, k: &KinematicsReport) {
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
    let _ = writeln!(o, "singular values: {}", num_list(&k.tcm_singular_values));
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
}

/// Attainable authority about the centre of mass along transport's commanded axes, and N−1.
fn write_authority(o: &mut String, k: &KinematicsReport) {
    let a = &k.authority;
    let r = a.reference_point;
    let _ = writeln!(
        o,
        "\nattainable authority within the thrust limits, {} axes ({}), other commanded axes \
         at zero, about the centre of mass [{} {} {}] m (base frame) [N, N·m]:",
        a.mode,
        a.commanded_axes,
        fmt_num(r[0]),
        fmt_num(r[1]),
        fmt_num(r[2])
    );
    for (i, axis) in ["surge", "sway", "heave", "roll", "pitch", "yaw"]
        .iter()
        .enumerate()
        .filter(|(i, _)| !a.attainable.positive[*i].is_nan() || !a.attainable.negative[*i].is_nan())
    {
        let _ = writeln!(
            o,
            "  {axis:<6} +{} / -{}",
            fmt_num(a.attainable.positive[i]),
            fmt_num(a.attainable.negative[i])
        );
    }
    let _ = writeln!(
        o,
        "  weakest: force {} N, moment {} N·m",
        fmt_num(a.min_force),
        fmt_num(a.min_moment)
    );
    let n1 = &a.n1;
    if let Some(w) = n1.thrusters.get(n1.worst_thruster) {
        let _ = writeln!(
            o,
            "N−1 (one thruster at zero thrust): worst thruster {} ({}) loses {} % of its {} \
             authority; weakest force {} N, moment {} N·m over all removals (mean {} N, {} N·m)",
            w.index,
            w.name,
            fmt_num(100.0 * w.loss),
            w.loss_axis,
            fmt_num(n1.worst_force),
            fmt_num(n1.worst_moment),
            fmt_num(n1.mean_force),
            fmt_num(n1.mean_moment)
        );
    }
}

/// Mass matrix spectrum, kinetic energy, bias and acceleration.
fn write_dynamics(o: &mut String, report: &InspectReport) {
    let d = &report.dynamics;
    let _ = writeln!(
        o,
        "\ndynamics ({})",
        if report.rigid {
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
    let _ = writeln!(o, "  bias h: [{}]", num_list(&d.bias));
    let _ = writeln!(o, "  acceleration: [{}]", num_list(&d.acceleration));
}

/// Wet weight, centres, metacentric height, restoring moments and trim (docs/model.md §4).
fn write_hydrostatics(o: &mut String, report: &InspectReport) {
    let h = &report.hydrostatics;
    let (g, b) = (h.centre_of_gravity, h.centre_of_buoyancy);
    let trim = |x: Option<f64>| x.map_or("none (C = G: neutral)".into(), |d| format!("{d:.3}°"));
    let _ = writeln!(
        o,
        "\nhydrostatics (chain rigid at this state, base level; moments about the CG)"
    );
    let _ = writeln!(
        o,
        "  weight {} N, buoyancy {} N, wet weight {} N (positive sinks)",
        fmt_num(h.weight),
        fmt_num(h.buoyancy),
        fmt_num(h.wet_weight)
    );
    let _ = writeln!(
        o,
        "  CG [{}] m, CB [{}] m (base frame); metacentric height GM {} m",
        num_list(&g),
        num_list(&b),
        fmt_num(h.metacentric_height)
    );
    let _ = writeln!(
        o,
        "  restoring moment per radian: roll {} N·m/rad, pitch {} N·m/rad; at level [{}] N·m",
        fmt_num(h.roll_restoring_moment),
        fmt_num(h.pitch_restoring_moment),
        num_list(&h.level_moment)
    );
    let _ = writeln!(
        o,
        "  trim: roll {}, pitch {}",
        trim(h.trim_roll_deg),
        trim(h.trim_pitch_deg)
    );
}
