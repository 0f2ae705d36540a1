//! The paper-style figures of one closed-loop run, laid out like the USM paper's Fig. 8
//! (transport mode) and Fig. 9 (work mode), from a trajectory table. Only column names are
//! known here (`t`, `ee_y`, `u_0`, …, as written by the scenario module), no physics.

use super::plot::{Colour, Figure, Panel, Series};
use super::table::Table;
use super::{ReportError, Result};

/// A table from named f64 channels of equal length (a run's trajectory).
pub fn trajectory_table(names: &[String], columns: &[Vec<f64>]) -> Result<Table> {
    let mut t = Table::new();
    for (n, c) in names.iter().zip(columns) {
        t.push(n.clone(), c.clone())?;
    }
    Ok(t)
}

fn col(t: &Table, name: &str) -> Result<Vec<f64>> {
    t.f64(name).map(|c| c.to_vec())
}

/// Columns named `prefix0`, `prefix1`, … in order.
fn indexed(t: &Table, prefix: &str) -> Vec<(usize, Vec<f64>)> {
    (0..)
        .map_while(|k| t.f64(&format!("{prefix}{k}")).ok().map(|c| (k, c.to_vec())))
        .collect()
}

fn line(name: &str, x: &[f64], y: Vec<f64>, colour: usize) -> Series {
    Series::new(name, x.to_vec(), y).colour(Colour::Palette(colour))
}

fn thruster_panel(t: &Table, time: &[f64], label: &str) -> Panel {
    let mut p = Panel::new(label, "time [s]", "thrust [N]");
    for (j, u) in indexed(t, "u_") {
        p = p.with_series(line(&format!("T{}", j + 1), time, u, j));
    }
    p
}

/// Fig. 8 of the USM paper for one transport run: (a) Y position of the end-effector and the
/// base against the desired path, (b) end-effector surge and sway velocities, (c) yaw joint
/// angles (`yaw_joints`: their indices), (d) thruster forces.
pub fn transport_figure(t: &Table, yaw_joints: &[usize], title: &str) -> Result<Figure> {
    let time = col(t, "t")?;
    let deg = |v: Vec<f64>| v.into_iter().map(f64::to_degrees).collect::<Vec<_>>();
    let pos = Panel::new("(a) Y position", "time [s]", "y [m]")
        .with_series(line("desired", &time, col(t, "path_y")?, 0).dashed())
        .with_series(line("end-effector", &time, col(t, "ee_y")?, 3))
        .with_series(line("base", &time, col(t, "base_y")?, 2));
    let vel = Panel::new("(b) End-effector velocity", "time [s]", "velocity [m/s]")
        .with_series(line("surge", &time, col(t, "ee_u")?, 0))
        .with_series(line("sway", &time, col(t, "ee_v")?, 3));
    let mut joints = Panel::new("(c) Yaw joint angles", "time [s]", "angle [deg]");
    for (i, &k) in yaw_joints.iter().enumerate() {
        joints = joints.with_series(line(
            &format!("yaw joint {}", i + 1),
            &time,
            deg(col(t, &format!("q_{k}"))?),
            i,
        ));
    }
    let mut f = Figure::new(title)
        .with_panel(pos)
        .with_panel(vel)
        .with_panel(joints)
        .with_panel(thruster_panel(t, &time, "(d) Thruster forces"));
    f.layout = (2, 2);
    f.size = (1200, 850);
    Ok(f)
}

/// Fig. 9 of the USM paper for one work-mode run: (a) end-effector position and (b)
/// orientation against the setpoints, (c) base linear and (d) angular velocities against the
/// references, (e) joint angles, (f) thruster forces.
pub fn work_figure(t: &Table, title: &str) -> Result<Figure> {
    let time = col(t, "t")?;
    let deg = |v: Vec<f64>| v.into_iter().map(f64::to_degrees).collect::<Vec<_>>();
    let mut pos = Panel::new("(a) End-effector position", "time [s]", "position [m]");
    let mut ori = Panel::new("(b) End-effector orientation", "time [s]", "angle [deg]");
    for (i, a) in ["x", "y", "z"].iter().enumerate() {
        pos = pos
            .with_series(line(a, &time, col(t, &format!("ee_{a}"))?, i))
            .with_series(line("", &time, col(t, &format!("sp_{a}"))?, i).dashed());
    }
    for (i, a) in ["roll", "pitch", "yaw"].iter().enumerate() {
        ori = ori
            .with_series(line(a, &time, deg(col(t, &format!("ee_{a}"))?), i))
            .with_series(line("", &time, deg(col(t, &format!("sp_{a}"))?), i).dashed());
    }
    let mut lin = Panel::new("(c) Base linear velocity", "time [s]", "velocity [m/s]");
    for (i, a) in ["u", "v", "w"].iter().enumerate() {
        lin = lin
            .with_series(line(a, &time, col(t, &format!("base_{a}"))?, i))
            .with_series(line("", &time, col(t, &format!("ref_{a}"))?, i).dashed());
    }
    let mut angv = Panel::new("(d) Base angular velocity", "time [s]", "rate [rad/s]");
    for (i, a) in ["p", "q", "r"].iter().enumerate() {
        angv = angv
            .with_series(line(a, &time, col(t, &format!("base_{a}"))?, i))
            .with_series(line("", &time, col(t, &format!("ref_{a}"))?, i).dashed());
    }
    let mut joints = Panel::new("(e) Joint angles", "time [s]", "angle [deg]");
    for (k, q) in indexed(t, "q_") {
        joints = joints.with_series(line(&format!("q{}", k + 1), &time, deg(q), k));
    }
    let mut f = Figure::new(title)
        .with_panel(pos)
        .with_panel(ori)
        .with_panel(lin)
        .with_panel(angv)
        .with_panel(joints)
        .with_panel(thruster_panel(t, &time, "(f) Thruster forces"));
    f.layout = (3, 2);
    f.size = (1200, 1200);
    Ok(f)
}

/// The figure that fits the run: Fig. 8 when the table has a cross-track channel, Fig. 9 when
/// it has setpoints.
pub fn run_figure(t: &Table, yaw_joints: &[usize], title: &str) -> Result<Figure> {
    if t.column("cross_track").is_some() {
        transport_figure(t, yaw_joints, title)
    } else if t.column("sp_x").is_some() {
        work_figure(t, title)
    } else {
        Err(ReportError::InvalidFigure {
            figure: title.to_string(),
            detail: "the table has neither transport nor work-mode channels".into(),
        })
    }
}
