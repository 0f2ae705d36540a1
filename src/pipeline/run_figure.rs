//! The paper-style figures of one closed-loop run, laid out like the USM paper's Fig. 8
//! (transport mode) and Fig. 9 (work mode), from a trajectory table. Columns are looked up
//! by [`Channel`] (`t`, `ee_y`, `u_0`, … as named by [`Channel::name`]), no physics. It lives
//! with the pipelines that draw it (issue 37 item 5: `report` knows nothing of the physics).

use crate::report::plot::{Colour, Figure, Panel, Series};
use crate::report::{Result, Table};
use crate::scenario::channels::{Channel, Pose, Twist};
use crate::scenario::config::Mode;

fn col(t: &Table, c: Channel) -> Result<Vec<f64>> {
    t.f64(&c.name()).map(|x| x.to_vec())
}

/// The columns of an indexed family (`Channel::U` → `u_0`, `u_1`, …) in order.
fn indexed(t: &Table, family: fn(usize) -> Channel) -> Vec<(usize, Vec<f64>)> {
    (0..)
        .map_while(|k| t.f64(&family(k).name()).ok().map(|c| (k, c.to_vec())))
        .collect()
}

/// Radians to degrees, element by element.
fn degrees(v: Vec<f64>) -> Vec<f64> {
    v.into_iter().map(f64::to_degrees).collect()
}

fn line(name: &str, x: &[f64], y: Vec<f64>, colour: usize) -> Series {
    Series::new(name, x.to_vec(), y).colour(Colour::Palette(colour))
}

fn thruster_panel(t: &Table, time: &[f64], label: &str) -> Panel {
    let mut p = Panel::new(label, "time [s]", "thrust [N]");
    for (j, u) in indexed(t, Channel::U) {
        p = p.with_series(line(&format!("T{}", j + 1), time, u, j));
    }
    p
}

/// Fig. 8 of the USM paper for one transport run: (a) Y position of the end-effector and the
/// base against the desired path, (b) end-effector surge and sway velocities, (c) yaw joint
/// angles (`yaw_joints`: their indices), (d) thruster forces.
pub fn transport_figure(t: &Table, yaw_joints: &[usize], title: &str) -> Result<Figure> {
    let time = col(t, Channel::T)?;
    let pos = Panel::new("(a) Y position", "time [s]", "y [m]")
        .with_series(line("desired", &time, col(t, Channel::PathY)?, 0).dashed())
        .with_series(line(
            "end-effector",
            &time,
            col(t, Channel::EePose(Pose::Y))?,
            3,
        ))
        .with_series(line("base", &time, col(t, Channel::BasePose(Pose::Y))?, 2));
    let vel = Panel::new("(b) End-effector velocity", "time [s]", "velocity [m/s]")
        .with_series(line("surge", &time, col(t, Channel::EeTwist(Twist::U))?, 0))
        .with_series(line("sway", &time, col(t, Channel::EeTwist(Twist::V))?, 3));
    let mut joints = Panel::new("(c) Yaw joint angles", "time [s]", "angle [deg]");
    for (i, &k) in yaw_joints.iter().enumerate() {
        joints = joints.with_series(line(
            &format!("yaw joint {}", i + 1),
            &time,
            degrees(col(t, Channel::Q(k))?),
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

/// Add three `(label, actual, reference)` channel pairs to panel `p`, the reference dashed in
/// the actual's colour, each series mapped through `scale`.
fn tracking_panel(
    t: &Table,
    time: &[f64],
    mut p: Panel,
    pairs: [(&str, Channel, Channel); 3],
    scale: fn(Vec<f64>) -> Vec<f64>,
) -> Result<Panel> {
    for (i, (label, actual, reference)) in pairs.into_iter().enumerate() {
        p = p
            .with_series(line(label, time, scale(col(t, actual)?), i))
            .with_series(line("", time, scale(col(t, reference)?), i).dashed());
    }
    Ok(p)
}

/// Fig. 9 of the USM paper for one work-mode run: (a) end-effector position and (b)
/// orientation against the setpoints, (c) base linear and (d) angular velocities against the
/// references, (e) joint angles, (f) thruster forces.
pub fn work_figure(t: &Table, title: &str) -> Result<Figure> {
    let time = col(t, Channel::T)?;
    let pose = |a: Pose| (a.suffix(), Channel::EePose(a), Channel::Setpoint(a));
    let twist = |a: Twist| (a.suffix(), Channel::BaseTwist(a), Channel::TwistRef(a));
    let same: fn(Vec<f64>) -> Vec<f64> = |v| v;
    let tracking = [
        (
            "(a) End-effector position",
            "position [m]",
            [Pose::X, Pose::Y, Pose::Z].map(pose),
            same,
        ),
        (
            "(b) End-effector orientation",
            "angle [deg]",
            [Pose::Roll, Pose::Pitch, Pose::Yaw].map(pose),
            degrees,
        ),
        (
            "(c) Base linear velocity",
            "velocity [m/s]",
            [Twist::U, Twist::V, Twist::W].map(twist),
            same,
        ),
        (
            "(d) Base angular velocity",
            "rate [rad/s]",
            [Twist::P, Twist::Q, Twist::R].map(twist),
            same,
        ),
    ];
    let mut f = Figure::new(title);
    for (label, y_label, pairs, scale) in tracking {
        let p = Panel::new(label, "time [s]", y_label);
        f = f.with_panel(tracking_panel(t, &time, p, pairs, scale)?);
    }
    let mut joints = Panel::new("(e) Joint angles", "time [s]", "angle [deg]");
    for (k, q) in indexed(t, Channel::Q) {
        joints = joints.with_series(line(&format!("q{}", k + 1), &time, degrees(q), k));
    }
    f = f
        .with_panel(joints)
        .with_panel(thruster_panel(t, &time, "(f) Thruster forces"));
    f.layout = (3, 2);
    f.size = (1200, 1200);
    Ok(f)
}

/// The figure of a run of `mode`: Fig. 8 for transport, Fig. 9 for work.
pub fn run_figure(t: &Table, mode: Mode, yaw_joints: &[usize], title: &str) -> Result<Figure> {
    match mode {
        Mode::Transport => transport_figure(t, yaw_joints, title),
        Mode::Work => work_figure(t, title),
    }
}
