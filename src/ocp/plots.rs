//! The plots of an `ocp` run (issue 40 item 5, docs/ocp.md §4): `plots/states.svg` (base
//! position [m] and attitude [deg] in the inertial frame, joint angles [rad] and rates
//! [rad/s] at the knots), `plots/controls.svg` (each thrust [N] or base-wrench component and
//! each joint torque [N·m], held over its interval as the model holds it, against its
//! bounds, dashed) and `plots/convergence.svg` (the KKT residuals and the objective per SQP
//! iteration, `iterations.csv`'s numbers, on a log scale).

use std::path::Path;

use super::chain::ChainModel;
use super::problem::ProblemSpec;
use super::sqp::OcpSolution;
use crate::report::{Colour, Figure, Panel, Result, Scale, Series};
use crate::spatial::euler_zyx;

/// The knots' times `k Δt`, k = 0 … N.
fn times(dt: f64, n: usize) -> Vec<f64> {
    (0..n).map(|k| k as f64 * dt).collect()
}

/// A control held over each interval: the staircase `(t_k, u_k), (t_{k+1}, u_k)`.
fn held(dt: f64, u: impl Iterator<Item = f64>) -> (Vec<f64>, Vec<f64>) {
    let (mut x, mut y) = (Vec::new(), Vec::new());
    for (k, v) in u.enumerate() {
        x.extend([k as f64 * dt, (k + 1) as f64 * dt]);
        y.extend([v, v]);
    }
    (x, y)
}

/// A panel of one series per row of `rows` (`name(i)`, values over `t`).
fn lines(
    title: &str,
    y_label: &str,
    t: &[f64],
    rows: &[Vec<f64>],
    name: impl Fn(usize) -> String,
) -> Panel {
    let mut p = Panel::new(title, "time [s]", y_label);
    for (i, r) in rows.iter().enumerate() {
        p = p.with_series(Series::new(name(i), t.to_vec(), r.clone()).colour(Colour::Palette(i)));
    }
    p.legend = rows.len() <= 10;
    p
}

/// The states' figure of `sol` on the chain of `n` joints with step `dt`.
fn states(sol: &OcpSolution, n: usize, dt: f64) -> Figure {
    let t = times(dt, sol.xs.len());
    let mut pos = vec![Vec::new(); 3];
    let mut rpy = vec![Vec::new(); 3];
    let mut q = vec![Vec::new(); n];
    let mut qd = vec![Vec::new(); n];
    for x in &sol.xs {
        let pose = ChainModel::pose(x);
        let a = euler_zyx(pose.orientation.to_rotation_matrix().matrix());
        for i in 0..3 {
            pos[i].push(pose.position[i]);
            rpy[i].push(a[i].to_degrees());
        }
        for i in 0..n {
            q[i].push(x[7 + i]);
            qd[i].push(x[13 + n + i]);
        }
    }
    let axis = |i: usize| ["x", "y", "z"][i].to_string();
    let angle = |i: usize| ["roll", "pitch", "yaw"][i].to_string();
    let mut f = Figure::new("Optimal trajectory: states at the knots");
    f.panels = vec![
        lines("Base position (inertial)", "position [m]", &t, &pos, axis),
        lines("Base attitude (ZYX)", "angle [deg]", &t, &rpy, angle),
        lines("Joint angles", "angle [rad]", &t, &q, |i| {
            format!("q{}", i + 1)
        }),
        lines("Joint rates", "rate [rad/s]", &t, &qd, |i| {
            format!("q̇{}", i + 1)
        }),
    ];
    f.layout = (2, 2);
    f.size = (1000, 700);
    f
}

/// A controls panel: controls `range` of `sol` held over their intervals, with their bounds
/// `(lo, hi)` dashed (unbounded ones left out).
fn controls_panel(
    title: &str,
    y_label: &str,
    us: &[Vec<f64>],
    range: std::ops::Range<usize>,
    bounds: &[(f64, f64)],
    dt: f64,
    name: impl Fn(usize) -> String,
) -> Panel {
    let mut p = Panel::new(title, "time [s]", y_label);
    let tn = us.len() as f64 * dt;
    for (c, i) in range.enumerate() {
        let (x, y) = held(dt, us.iter().map(|u| u[i]));
        p = p.with_series(Series::new(name(c), x, y).colour(Colour::Palette(c)));
    }
    // One dashed pair per distinct bound.
    let mut seen: Vec<(f64, f64)> = Vec::new();
    for &(lo, hi) in bounds {
        if seen.contains(&(lo, hi)) {
            continue;
        }
        seen.push((lo, hi));
        for v in [lo, hi].into_iter().filter(|v| v.is_finite()) {
            let s = Series::new("", vec![0.0, tn], vec![v, v])
                .dashed()
                .colour(Colour::Grey);
            p = p.with_series(s);
        }
    }
    p.legend = p.series.iter().filter(|s| !s.name.is_empty()).count() <= 12;
    p
}

/// What the plots need of a run besides its problem: the solution, the body controls before
/// the joint torques (`nb`: thrusters, or 6 for a base wrench; `thrusters` says which) and Δt
/// [s].
pub struct PlotRun<'a> {
    /// The solution drawn.
    pub solution: &'a OcpSolution,
    /// Body controls before the joint torques.
    pub nb: usize,
    /// Whether they are thrusts.
    pub thrusters: bool,
    /// Δt [s].
    pub dt: f64,
}

/// The controls' figure: body controls (thrusts or the base wrench) and joint torques.
fn controls(spec: &ProblemSpec, run: &PlotRun) -> Figure {
    let sol = run.solution;
    let nb = run.nb;
    let n = spec.vehicle.n_joints();
    let nu = nb + n;
    let mut f = Figure::new("Optimal controls, held over each interval, against their bounds");
    let body = if run.thrusters {
        let b: Vec<(f64, f64)> = spec
            .vehicle
            .thrusters
            .iter()
            .map(|t| (t.u_min, t.u_max))
            .collect();
        controls_panel("Thrusts", "thrust [N]", &sol.us, 0..nb, &b, run.dt, |j| {
            format!("thruster {}", j + 1)
        })
    } else {
        let b: Vec<(f64, f64)> = (0..nb)
            .map(|i| {
                let m = spec.bounds[if i < 3 { 0 } else { 1 }];
                (-m, m)
            })
            .collect();
        let names = ["X", "Y", "Z", "K", "M", "N"];
        controls_panel(
            "Base wrench (body frame)",
            "force [N] / moment [N·m]",
            &sol.us,
            0..nb,
            &b,
            run.dt,
            |i| names.get(i).copied().unwrap_or("?").to_string(),
        )
    };
    let m = spec.bounds[2];
    let torques = controls_panel(
        "Joint torques",
        "torque [N·m]",
        &sol.us,
        nb..nu,
        &vec![(-m, m); n],
        run.dt,
        |i| format!("τ{}", i + 1),
    );
    f.panels = vec![body, torques];
    f.layout = (2, 1);
    f.size = (1000, 700);
    f
}

/// The convergence figure: primal, stationarity, complementarity and the tolerance per
/// iteration (log), and the objective.
fn convergence(spec: &ProblemSpec, sol: &OcpSolution) -> Figure {
    let it: Vec<f64> = sol.log.iter().map(|r| r.iteration as f64).collect();
    let col = |g: fn(&super::sqp::IterLog) -> f64| sol.log.iter().map(g).collect::<Vec<f64>>();
    let mut kkt = Panel::new("KKT residuals", "SQP iteration", "residual");
    kkt.y_scale = Scale::Log;
    kkt.x_scale = Scale::Integer;
    for (i, (name, y)) in [
        ("primal", col(|r| r.primal)),
        ("stationarity", col(|r| r.stationarity)),
        ("complementarity", col(|r| r.complementarity)),
    ]
    .into_iter()
    .enumerate()
    {
        kkt = kkt.with_series(Series::new(name, it.clone(), y).colour(Colour::Palette(i)));
    }
    if let (Some(a), Some(b)) = (it.first(), it.last()) {
        let tol = Series::new("tolerance", vec![*a, *b], vec![spec.tolerance; 2])
            .dashed()
            .colour(Colour::Grey);
        kkt = kkt.with_series(tol);
    }
    let mut obj = Panel::new("Objective", "SQP iteration", "J").with_series(Series::new(
        "J",
        it.clone(),
        col(|r| r.objective),
    ));
    obj.legend = false;
    obj.x_scale = Scale::Integer;
    let mut f = Figure::new(format!(
        "Convergence: {} iterations, {}",
        sol.iterations,
        sol.status.word()
    ));
    f.panels = vec![kkt, obj];
    f.layout = (1, 2);
    f.size = (1000, 420);
    f
}

/// Write `states.svg`, `controls.svg` and `convergence.svg` of `run` into `plots` (created).
pub fn write_plots(plots: &Path, spec: &ProblemSpec, run: &PlotRun) -> Result<()> {
    crate::report::create_subdir(plots).map_err(|e| crate::report::ReportError::Io {
        path: plots.to_path_buf(),
        action: "creating",
        source: e,
    })?;
    let n = spec.vehicle.n_joints();
    states(run.solution, n, run.dt).write_svg(&plots.join("states.svg"))?;
    controls(spec, run).write_svg(&plots.join("controls.svg"))?;
    convergence(spec, run.solution).write_svg(&plots.join("convergence.svg"))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn controls_are_held_over_their_intervals_against_each_distinct_bound() {
        let us = vec![vec![1.0, -2.0], vec![3.0, 0.5]];
        let p = controls_panel("t", "y", &us, 0..2, &[(-5.0, 5.0), (-5.0, 5.0)], 0.5, |i| {
            format!("u{i}")
        });
        // Two staircases, then one dashed pair for the one distinct bound.
        assert_eq!(p.series.len(), 4);
        assert_eq!(p.series[0].x, vec![0.0, 0.5, 0.5, 1.0]);
        assert_eq!(p.series[0].y, vec![1.0, 1.0, 3.0, 3.0]);
        assert_eq!(p.series[1].y, vec![-2.0, -2.0, 0.5, 0.5]);
        for (s, v) in p.series[2..].iter().zip([-5.0, 5.0]) {
            assert_eq!(s.style, crate::report::LineStyle::Dashed);
            assert_eq!((s.x.clone(), s.y.clone()), (vec![0.0, 1.0], vec![v, v]));
            assert!(s.name.is_empty(), "bounds stay out of the legend");
        }
        // An unbounded control draws no bound.
        let free = controls_panel(
            "t",
            "y",
            &us,
            0..1,
            &[(f64::NEG_INFINITY, f64::INFINITY)],
            0.5,
            |_| "u".into(),
        );
        assert_eq!(free.series.len(), 1);
    }
}
