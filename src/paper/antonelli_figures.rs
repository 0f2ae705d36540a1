//! The figures of `paper antonelli`, laid out like Antonelli & Chiaverini's (1998):
//!
//! | file | paper | content |
//! |---|---|---|
//! | `fig2_case1.svg` | Fig. 2 | case 1: end-effector held, vehicle re-oriented |
//! | `fig3_case1b.svg`, `fig4_case1b_vehicle.svg` | Figs. 3–4 | case 1b: tracking, vehicle position and velocity |
//! | `fig5_case2.svg`, `fig6_case2_vehicle.svg` | Figs. 5–6 | case 2: tracking with dexterity, vehicle position and velocity |
//! | `fig7_force_norm.svg`, `fig8_moment_norm.svg` | Figs. 7–8 | case 3: `‖f‖`, `‖m‖` of the control forces, a and b |
//!
//! The kinematic figures have four panels: end-effector position (desired dashed), the
//! headings `ψ_e`, `ψ` (and `q₂` in case 2), the vehicle position, the joint angles.

use std::path::Path;

use crate::paper::antonelli::dynamic::DynamicHistory;
use crate::paper::antonelli::{KinematicHistory, TaskTrace};
use crate::pipeline::error::PipelineError;
use crate::report::plot::{Colour, Figure, Panel, Series};

const TIME: &str = "time [s]";

fn line(name: &str, t: &[f64], y: &[f64], colour: usize) -> Series {
    Series::new(name, t.to_vec(), y.to_vec()).colour(Colour::Palette(colour))
}

/// Actual (solid) and desired (dashed) of a task row, in `colour`.
fn task_pair(tr: &TaskTrace, t: &[f64], colour: usize) -> [Series; 2] {
    [
        line(&tr.name, t, &tr.value, colour),
        line(&format!("{} desired", tr.name), t, &tr.desired, colour).dashed(),
    ]
}

fn find<'a>(h: &'a KinematicHistory, name: &str) -> Option<&'a TaskTrace> {
    h.primary.iter().find(|tr| tr.name == name)
}

/// The four-panel figure of a kinematic case.
fn kinematic_figure(h: &KinematicHistory, title: &str) -> Figure {
    let t = &h.t;
    let mut ee = Panel::new("end-effector position", TIME, "[m]");
    let mut angles = Panel::new("primary angles", TIME, "[rad]");
    for (k, name) in ["x_e", "y_e"].iter().enumerate() {
        if let Some(tr) = find(h, name) {
            ee.series.extend(task_pair(tr, t, k));
        }
    }
    for tr in h
        .primary
        .iter()
        .filter(|tr| tr.heading || tr.name.starts_with('q'))
    {
        angles
            .series
            .extend(task_pair(tr, t, angles.series.len() / 2));
    }
    let mut vehicle = Panel::new("vehicle position", TIME, "[m]");
    vehicle.series.push(line("x", t, &h.base[0], 0));
    vehicle.series.push(line("y", t, &h.base[1], 1));
    let mut joints = Panel::new("joint angles", TIME, "[rad]");
    for (k, q) in h.q.iter().enumerate() {
        joints.series.push(line(&format!("q{}", k + 1), t, q, k));
    }
    let mut f = Figure::new(title)
        .with_panel(ee)
        .with_panel(angles)
        .with_panel(vehicle)
        .with_panel(joints);
    f.layout = (2, 2);
    f.size = (1000, 700);
    f
}

/// Vehicle position and velocity (the paper's Figs. 4 and 6).
fn vehicle_figure(h: &KinematicHistory, title: &str) -> Figure {
    let t = &h.t;
    let mut pos = Panel::new("vehicle position", TIME, "[m], [rad]");
    let mut vel = Panel::new("vehicle velocity", TIME, "[m/s], [rad/s]");
    for (k, (p, v)) in [("x", "x_dot"), ("y", "y_dot"), ("psi", "psi_dot")]
        .iter()
        .enumerate()
    {
        pos.series.push(line(p, t, &h.base[k], k));
        vel.series.push(line(v, t, &h.base_rate[k], k));
    }
    let mut f = Figure::new(title).with_panel(pos).with_panel(vel);
    f.layout = (2, 1);
    f.size = (800, 700);
    f
}

/// `‖f‖` or `‖m‖` of the case-3 runs (the paper's Figs. 7 and 8), a solid, b dashed.
fn norm_figure(runs: &[&DynamicHistory], moment: bool, title: &str) -> Figure {
    let (what, unit) = if moment {
        ("‖m‖", "[N·m]")
    } else {
        ("‖f‖", "[N]")
    };
    let mut p = Panel::new(
        format!("{what} of the control wrench (a: fixed attitude, b: re-oriented)"),
        TIME,
        format!("{what} {unit}"),
    );
    for (k, h) in runs.iter().enumerate() {
        let y = if moment {
            &h.moment_norm
        } else {
            &h.force_norm
        };
        let s = line(&h.name, &h.t, y, k);
        p.series.push(if k == 0 { s } else { s.dashed() });
    }
    let mut f = Figure::new(title).with_panel(p);
    f.layout = (1, 1);
    f.size = (800, 450);
    f
}

/// Write every figure of the module table into `out`: `kinematic` holds cases 1, 1b, 2 in
/// that order, `dynamic` cases 3a and 3b.
pub fn write_figures(
    out: &Path,
    kinematic: &[KinematicHistory],
    dynamic: &[&DynamicHistory],
) -> Result<(), PipelineError> {
    let mut figures = Vec::new();
    let titles = [
        (
            "fig2_case1",
            "Case 1: re-orientation with the end-effector held (paper Fig. 2)",
        ),
        (
            "fig3_case1b",
            "Case 1b: end-effector trajectory with re-orientation (Fig. 3)",
        ),
        (
            "fig5_case2",
            "Case 2: end-effector trajectory with dexterity q2 (Fig. 5)",
        ),
    ];
    for (h, (file, title)) in kinematic.iter().zip(titles) {
        figures.push((file, kinematic_figure(h, title)));
    }
    for (h, file, title) in [
        (
            kinematic.get(1),
            "fig4_case1b_vehicle",
            "Case 1b: vehicle position and velocity (Fig. 4)",
        ),
        (
            kinematic.get(2),
            "fig6_case2_vehicle",
            "Case 2: vehicle position and velocity (Fig. 6)",
        ),
    ] {
        if let Some(h) = h {
            figures.push((file, vehicle_figure(h, title)));
        }
    }
    figures.push((
        "fig7_force_norm",
        norm_figure(
            dynamic,
            false,
            "Case 3 as written: norm of the vehicle forces (Fig. 7)",
        ),
    ));
    figures.push((
        "fig8_moment_norm",
        norm_figure(
            dynamic,
            true,
            "Case 3 as written: norm of the vehicle moments (Fig. 8)",
        ),
    ));
    for (file, f) in figures {
        f.write_svg_pdf(&out.join(format!("{file}.svg")))?;
    }
    Ok(())
}
