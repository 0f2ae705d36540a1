//! OCP problem files (TOML) → a validated [`ProblemSpec`] (docs/ocp.md §6). Every error
//! names the file, the line and the key (`horizon.knots: must be at least 1`).
//!
//! ```toml
//! design = "designs/rigid_chain5.toml"  # preset, file (relative to this file) or [design] table
//! actuation = "base_wrench"  # or "thrusters": the design's thrusters (bounded by their limits)
//! [physics]
//! hydrodynamics = false      # true: added mass, drag, restoring forces, current
//! [horizon]
//! duration = 10.0            # T [s]
//! knots = 100                # N intervals, Δt = T/N
//! [initial]                  # optional: at rest at the origin
//! joint_angles = [0.0, 0.0, 0.0, 0.0]   # [rad]
//! [terminal]
//! ee_displacement = [0.0, 0.3, -0.2]    # end-effector target minus its start, inertial [m]
//! zero_velocity = true       # base twist and joint rates zero at T (required for now)
//! [objective]
//! effort = 1.0               # J = effort · Σ_k Δt ‖u_k‖²
//! [bounds]                   # optional, symmetric: |f_i| ≤ base_force, …
//! base_force = 50.0          # [N]
//! base_moment = 50.0         # [N·m]
//! joint_torque = 50.0        # [N·m]
//! [solver]
//! tolerance = 1e-6           # KKT tolerance
//! max_iterations = 200
//! hessian = "exact"          # or "gauss_newton" (objective only, no dynamics curvature)
//! gauss_newton_above = 1e-2  # optional: Gauss–Newton while the primal infeasibility is above
//! ```
// Stage and component loops read clearest with indices (k: knot, i: component).
#![allow(clippy::needless_range_loop)]

use super::sqp::Hessian;
use crate::input::document::{read_text, Document};
use crate::input::located::{InputError, Location};
use crate::model::design::{load_design, parse_design_value};
use crate::model::Vehicle;
use serde::Deserialize;
use std::path::Path;

/// Most knots accepted (the solver stores O(N nx²) numbers).
pub const MAX_KNOTS: usize = 100_000;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    design: toml::Value,
    #[serde(default)]
    actuation: Option<String>,
    #[serde(default)]
    physics: Physics,
    horizon: Horizon,
    #[serde(default)]
    initial: Initial,
    terminal: Terminal,
    #[serde(default)]
    objective: Objective,
    #[serde(default)]
    bounds: Bounds,
    #[serde(default)]
    solver: Solver,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct Physics {
    #[serde(default)]
    hydrodynamics: bool,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Horizon {
    duration: f64,
    knots: i64,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct Initial {
    joint_angles: Option<Vec<f64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Terminal {
    ee_displacement: [f64; 3],
    #[serde(default = "yes")]
    zero_velocity: bool,
}

fn yes() -> bool {
    true
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Objective {
    #[serde(default = "one")]
    effort: f64,
}

impl Default for Objective {
    fn default() -> Self {
        Self { effort: 1.0 }
    }
}

fn one() -> f64 {
    1.0
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct Bounds {
    base_force: Option<f64>,
    base_moment: Option<f64>,
    joint_torque: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Solver {
    #[serde(default = "tol")]
    tolerance: f64,
    #[serde(default = "iters")]
    max_iterations: i64,
    #[serde(default)]
    hessian: Option<String>,
    #[serde(default)]
    gauss_newton_above: Option<f64>,
}

impl Default for Solver {
    fn default() -> Self {
        Self {
            tolerance: tol(),
            max_iterations: iters(),
            hessian: None,
            gauss_newton_above: None,
        }
    }
}

fn tol() -> f64 {
    1e-6
}

fn iters() -> i64 {
    200
}

/// A validated problem.
#[derive(Clone, Debug)]
pub struct ProblemSpec {
    /// Where it came from (the file name).
    pub origin: String,
    /// The design.
    pub vehicle: Vehicle,
    /// Hydrodynamics on (added mass, drag, restoring, current) or off (rigid bodies).
    pub hydrodynamics: bool,
    /// Thruster actuation (thrusts within the design's limits, then joint torques); else the
    /// base wrench.
    pub thrusters: bool,
    /// Horizon T [s].
    pub duration: f64,
    /// Intervals N.
    pub knots: usize,
    /// Initial joint angles [rad] (n).
    pub joint_angles: Vec<f64>,
    /// End-effector target minus its initial position, inertial frame [m].
    pub ee_displacement: [f64; 3],
    /// Effort weight w of `J = w Σ Δt ‖u‖²`.
    pub effort: f64,
    /// Symmetric bounds: base force [N], base moment [N·m], joint torque [N·m] (∞: none).
    pub bounds: [f64; 3],
    /// KKT tolerance.
    pub tolerance: f64,
    /// Most SQP iterations.
    pub max_iterations: usize,
    /// The SQP's Hessian.
    pub hessian: Hessian,
    /// Gauss–Newton while the primal infeasibility exceeds this (∞: never).
    pub gauss_newton_above: f64,
}

/// Read and validate a problem file.
pub fn load_problem(path: &Path) -> Result<ProblemSpec, InputError> {
    let origin = path.display().to_string();
    let text = read_text(path).map_err(|e| InputError {
        at: Location::origin(&origin),
        error: format!("cannot read the problem file: {e}"),
    })?;
    parse_problem(&text, path)
}

/// Parse and validate problem text; `path` names the origin and anchors a relative design.
pub fn parse_problem(text: &str, path: &Path) -> Result<ProblemSpec, InputError> {
    let origin = path.display().to_string();
    let doc = Document::parse(text, &origin)?;
    if let Some((key, _)) = doc.first_non_finite() {
        return Err(doc.err(key, "must be a finite number"));
    }
    let f: File = doc.deserialize()?;
    let vehicle = match &f.design {
        toml::Value::String(d) => {
            let rel = path.parent().unwrap_or(Path::new("")).join(d);
            let arg = if rel.is_file() {
                rel.display().to_string()
            } else {
                d.clone()
            };
            load_design(&arg).map_err(|e| {
                let e: InputError = e.into();
                doc.err("design", e.to_string())
            })?
        }
        v @ toml::Value::Table(_) => parse_design_value(v, &format!("{origin} [design]"))?,
        _ => return Err(doc.err("design", "must be a preset name, a file name or a table")),
    };
    let n = vehicle.n_joints();
    let thrusters = actuation(&doc, f.actuation.as_deref(), &vehicle)?;
    let h = &f.horizon;
    if h.duration <= 0.0 {
        return Err(doc.err("horizon.duration", "must be positive [s]"));
    }
    if h.knots < 1 || h.knots > MAX_KNOTS as i64 {
        return Err(doc.err(
            "horizon.knots",
            format!("must be between 1 and {MAX_KNOTS}"),
        ));
    }
    let joint_angles = f.initial.joint_angles.unwrap_or_else(|| vec![0.0; n]);
    if joint_angles.len() != n {
        return Err(doc.err(
            "initial.joint_angles",
            format!(
                "has {} entries, the design has {n} joints",
                joint_angles.len()
            ),
        ));
    }
    if !f.terminal.zero_velocity {
        return Err(doc.err(
            "terminal.zero_velocity",
            "only `true` is supported (the terminal equality fixes every velocity)",
        ));
    }
    if f.objective.effort <= 0.0 {
        return Err(doc.err("objective.effort", "must be positive"));
    }
    let mut bounds = [f64::INFINITY; 3];
    for (i, (k, v)) in [
        ("bounds.base_force", f.bounds.base_force),
        ("bounds.base_moment", f.bounds.base_moment),
        ("bounds.joint_torque", f.bounds.joint_torque),
    ]
    .into_iter()
    .enumerate()
    {
        if let Some(v) = v {
            if v <= 0.0 {
                return Err(doc.err(k, "must be positive (a symmetric bound |u| ≤ value)"));
            }
            bounds[i] = v;
        }
    }
    if f.solver.tolerance <= 0.0 {
        return Err(doc.err("solver.tolerance", "must be positive"));
    }
    if f.solver.max_iterations < 1 {
        return Err(doc.err("solver.max_iterations", "must be at least 1"));
    }
    let hessian = match f.solver.hessian.as_deref() {
        None | Some("exact") => Hessian::Exact,
        Some("gauss_newton") => Hessian::GaussNewton,
        Some(other) => {
            return Err(doc.err(
                "solver.hessian",
                format!("`{other}` is not one of \"exact\", \"gauss_newton\""),
            ))
        }
    };
    let gauss_newton_above = f.solver.gauss_newton_above.unwrap_or(f64::INFINITY);
    if gauss_newton_above <= 0.0 {
        return Err(doc.err("solver.gauss_newton_above", "must be positive"));
    }
    Ok(ProblemSpec {
        origin,
        vehicle,
        hydrodynamics: f.physics.hydrodynamics,
        thrusters,
        duration: h.duration,
        knots: h.knots as usize,
        joint_angles,
        ee_displacement: f.terminal.ee_displacement,
        effort: f.objective.effort,
        bounds,
        tolerance: f.solver.tolerance,
        max_iterations: f.solver.max_iterations as usize,
        hessian,
        gauss_newton_above,
    })
}

/// Whether `actuation` asks for thrusters (validated against the design's thrusters).
fn actuation(doc: &Document, kind: Option<&str>, vehicle: &Vehicle) -> Result<bool, InputError> {
    let thrusters = match kind {
        None | Some("base_wrench") => false,
        Some("thrusters") if vehicle.n_thrusters() > 0 => true,
        Some("thrusters") => return Err(doc.err("actuation", "the design has no thrusters")),
        Some(other) => {
            return Err(doc.err(
                "actuation",
                format!("`{other}` is not one of \"base_wrench\", \"thrusters\""),
            ))
        }
    };
    if thrusters
        && vehicle
            .thrusters
            .iter()
            .any(|t| !(t.u_min < 0.0 && t.u_max > 0.0))
    {
        return Err(doc.err(
            "actuation",
            "thruster actuation needs every thruster's limits to straddle zero (the solver starts at zero thrust)",
        ));
    }
    Ok(thrusters)
}
