//! OCP problem files (TOML) → a validated [`ProblemSpec`] (docs/ocp.md §6). Every error
//! names the file, the line and the key (`horizon.knots: must be at least 1`).
//!
//! ```toml
//! design = "designs/rigid_chain5.toml"  # preset, file (relative to this file) or [design] table
//! actuation = "base_wrench"  # or "thrusters": the design's thrusters (bounded by their limits)
//! [physics]
//! hydrodynamics = false      # true: added mass, drag, restoring forces, current
//! current = [0.2, 0.0, 0.0]  # optional: the fluid's current, inertial [m/s] (replaces the design's)
//! [horizon]
//! duration = 10.0            # T [s]
//! knots = 100                # N intervals, Δt = T/N
//! substeps = 1               # symplectic Euler steps per interval, h = Δt/substeps (docs/ocp.md §2)
//! [initial]                  # optional: at rest at the origin
//! joint_angles = [0.0, 0.0, 0.0, 0.0]   # [rad]
//! [terminal]                 # every row group optional (at least one)
//! ee_displacement = [0.0, 0.3, -0.2]    # end-effector target minus its start, inertial [m]
//! ee_rpy_deg = [0.0, 10.0, 25.0]        # end-effector orientation, inertial (ZYX) [deg]
//! base_displacement = [2.0, 1.0, 0.0]   # base origin target minus its start [m]
//! base_rpy_deg = [0.0, 0.0, 90.0]       # base orientation [deg]
//! joint_angles = [0.0, 0.0, 0.0, 0.0]   # [rad]
//! zero_velocity = true       # base twist and joint rates zero at T (default true)
//! [objective]                # J = Σ_k effort Δt ‖u_k‖² + path costs (docs/ocp.md §1)
//! effort = 1.0               # > 0
//! thruster_energy = 0.0      # weight of Σ Δt Σ_j c φ(u_j) (smoothed |u|^{3/2}; thrusters only)
//! joint_energy = 0.0         # weight of Σ Δt Σ_i ψ(τ_i q̇_i) (smoothed |τ q̇|)
//! thrust_smoothing = 0.01    # ε_u [N]
//! power_smoothing = 0.01     # ε_p [W]
//! [bounds]                   # optional, symmetric: |f_i| ≤ base_force, …
//! base_force = 50.0          # [N]
//! base_moment = 50.0         # [N·m]
//! joint_torque = 50.0        # [N·m]
//! joint_angle = 1.0          # |q_i| ≤ value [rad], by a logarithmic barrier (strictly inside)
//! barrier = 1e-3             # the barrier's weight μ
//! sigma_min = 0.05           # commanded-axis σ_min of the scaled T(q) > value at every knot (barrier; docs/ocp.md §1)
//! sigma_axes = ["surge", "sway", "heave", "roll", "pitch", "yaw"]  # the commanded axes (default all six)
//! char_length = 1.5          # L of the scaling [m] (default half the vehicle's length)
//! [solver]
//! tolerance = 1e-6           # KKT tolerance
//! max_iterations = 200
//! hessian = "exact"          # or "gauss_newton" (objective only, no dynamics curvature)
//! gauss_newton_above = 1e-2  # optional: Gauss–Newton while the primal infeasibility is above
//! warm_start = "trajectory.csv"  # optional: an `ocp` trajectory (same design, actuation, knots)
//! proximal = 1.0            # initial Levenberg weight on the state increments (0: off; docs/ocp.md §3)
//! rollout = "linear"        # or "feedback": trial points rolled out with the QP's gains (docs/ocp.md §3)
//! qp_tolerance = 1e-10       # the QP interior point's stopping tolerance (absolute)
//! qp_iterations = 60         # its most Newton iterations
//! initial_guess = "rest"     # or "cruise": the base moving along base_displacement (docs/ocp.md §4)
//! starts = 1                 # multi-start: start 0 as given, the others perturbed
//! seed = 0                   # of the perturbations (ChaCha8 per start)
//! perturbation = 0.1         # uniform ± this × the bound (or × 1 where unbounded)
//! ```
// Stage and component loops read clearest with indices (k: knot, i: component).
#![allow(clippy::needless_range_loop)]

use super::sigma_floor::{check_sigma_floor, SigmaKeys};
pub use super::sigma_floor::{SigmaFloorSpec, AXES};
use super::sqp::Hessian;
use crate::input::document::{read_text, Document};
use crate::input::located::{InputError, Location};
use crate::model::design::{load_design, parse_design_value};
use crate::model::Vehicle;
use serde::Deserialize;
use std::path::Path;

/// Most substeps per interval accepted (each costs a full dynamics step per evaluation).
pub const MAX_SUBSTEPS: usize = 1000;

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
    #[serde(default)]
    current: Option<[f64; 3]>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Horizon {
    duration: f64,
    knots: i64,
    #[serde(default = "one_substep")]
    substeps: i64,
}

fn one_substep() -> i64 {
    1
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct Initial {
    joint_angles: Option<Vec<f64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Terminal {
    #[serde(default)]
    ee_displacement: Option<[f64; 3]>,
    #[serde(default)]
    ee_rpy_deg: Option<[f64; 3]>,
    #[serde(default)]
    base_displacement: Option<[f64; 3]>,
    #[serde(default)]
    base_rpy_deg: Option<[f64; 3]>,
    #[serde(default)]
    joint_angles: Option<Vec<f64>>,
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
    #[serde(default)]
    thruster_energy: f64,
    #[serde(default)]
    joint_energy: f64,
    #[serde(default = "smoothing")]
    thrust_smoothing: f64,
    #[serde(default = "smoothing")]
    power_smoothing: f64,
}

impl Default for Objective {
    fn default() -> Self {
        Self {
            effort: 1.0,
            thruster_energy: 0.0,
            joint_energy: 0.0,
            thrust_smoothing: smoothing(),
            power_smoothing: smoothing(),
        }
    }
}

fn smoothing() -> f64 {
    0.01
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
    joint_angle: Option<f64>,
    barrier: Option<f64>,
    sigma_min: Option<f64>,
    sigma_axes: Option<Vec<String>>,
    char_length: Option<f64>,
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
    #[serde(default)]
    warm_start: Option<String>,
    #[serde(default)]
    initial_guess: Option<String>,
    #[serde(default)]
    proximal: f64,
    #[serde(default)]
    rollout: Option<String>,
    #[serde(default = "qp_tol")]
    qp_tolerance: f64,
    #[serde(default = "qp_iters")]
    qp_iterations: i64,
    #[serde(default = "one_start")]
    starts: i64,
    #[serde(default)]
    seed: u64,
    #[serde(default = "perturbation")]
    perturbation: f64,
}

impl Default for Solver {
    fn default() -> Self {
        Self {
            tolerance: tol(),
            max_iterations: iters(),
            hessian: None,
            gauss_newton_above: None,
            warm_start: None,
            initial_guess: None,
            proximal: 0.0,
            rollout: None,
            qp_tolerance: qp_tol(),
            qp_iterations: qp_iters(),
            starts: 1,
            seed: 0,
            perturbation: perturbation(),
        }
    }
}

fn qp_tol() -> f64 {
    1e-10
}

fn qp_iters() -> i64 {
    60
}

fn one_start() -> i64 {
    1
}

fn perturbation() -> f64 {
    0.1
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
    /// Symplectic Euler steps per interval (h = T / (N · substeps), docs/ocp.md §2).
    pub substeps: usize,
    /// Initial joint angles [rad] (n).
    pub joint_angles: Vec<f64>,
    /// The fluid's current, inertial [m/s] (`None`: the design's).
    pub current: Option<[f64; 3]>,
    /// End-effector target minus its initial position, inertial frame [m].
    pub ee_displacement: Option<[f64; 3]>,
    /// End-effector orientation target, roll-pitch-yaw (ZYX) [rad].
    pub ee_rpy: Option<[f64; 3]>,
    /// Base origin target minus its initial position [m].
    pub base_displacement: Option<[f64; 3]>,
    /// Base orientation target, roll-pitch-yaw [rad].
    pub base_rpy: Option<[f64; 3]>,
    /// Terminal joint angles [rad].
    pub terminal_joints: Option<Vec<f64>>,
    /// Base twist and joint rates zero at T.
    pub zero_velocity: bool,
    /// Effort weight w of `J = w Σ Δt ‖u‖²`.
    pub effort: f64,
    /// Weights of the thruster energy and the joint energy (0: off).
    pub energy: [f64; 2],
    /// Smoothing ε_u [N] and ε_p [W] (docs/ocp.md §1).
    pub smoothing: [f64; 2],
    /// Symmetric bounds: base force [N], base moment [N·m], joint torque [N·m] (∞: none).
    pub bounds: [f64; 3],
    /// Symmetric joint-angle limit [rad] (∞: none) and the barrier weight μ.
    pub joint_limit: (f64, f64),
    /// The σ_min floor (`bounds.sigma_min`; its barrier weight is `joint_limit.1`).
    pub sigma_floor: Option<SigmaFloorSpec>,
    /// KKT tolerance.
    pub tolerance: f64,
    /// Most SQP iterations.
    pub max_iterations: usize,
    /// The SQP's Hessian.
    pub hessian: Hessian,
    /// Gauss–Newton while the primal infeasibility exceeds this (∞: never).
    pub gauss_newton_above: f64,
    /// Warm start: the trajectory file (resolved against the problem file's directory).
    pub warm_start: Option<std::path::PathBuf>,
    /// Start 0 without a warm start: the cruise start of `ocp::cruise` (docs/ocp.md §4,
    /// eq. (C1)–(C3)) instead of zero controls rolled out.
    pub cruise_start: bool,
    /// Initial Levenberg weight of the SQP (docs/ocp.md §3, eq. (P1); 0: off).
    pub proximal: f64,
    /// Line-search trial points by the feedback rollout (docs/ocp.md §3, eq. (P2)).
    pub feedback: bool,
    /// The QP interior point's tolerance and most iterations (docs/ocp.md §3).
    pub qp: (f64, usize),
    /// Number of starts (multi-start), the perturbations' seed and amplitude.
    pub starts: usize,
    /// Seed of the perturbed starts.
    pub seed: u64,
    /// Amplitude of the perturbed starts (fraction of each control bound).
    pub perturbation: f64,
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
    if h.substeps < 1 || h.substeps > MAX_SUBSTEPS as i64 {
        return Err(doc.err(
            "horizon.substeps",
            format!("must be between 1 and {MAX_SUBSTEPS}"),
        ));
    }
    let joint_angles = f
        .initial
        .joint_angles
        .clone()
        .unwrap_or_else(|| vec![0.0; n]);
    if joint_angles.len() != n {
        return Err(doc.err(
            "initial.joint_angles",
            format!(
                "has {} entries, the design has {n} joints",
                joint_angles.len()
            ),
        ));
    }
    check_terminal_objective(&doc, &f, n, thrusters)?;
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
    let (joint_limit, sigma_floor) = check_limits(&doc, &f, &vehicle, &joint_angles)?;
    let sv = &f.solver;
    let (hessian, gauss_newton_above, warm_start) = check_solver(&doc, sv, path)?;
    let (feedback, cruise_start) = check_strategy(
        &doc,
        sv,
        f.terminal.base_displacement.is_some(),
        warm_start.is_some(),
    )?;
    Ok(ProblemSpec {
        origin,
        vehicle,
        hydrodynamics: f.physics.hydrodynamics,
        thrusters,
        duration: h.duration,
        knots: h.knots as usize,
        substeps: h.substeps as usize,
        joint_angles,
        current: f.physics.current,
        ee_displacement: f.terminal.ee_displacement,
        ee_rpy: f.terminal.ee_rpy_deg.map(|a| a.map(f64::to_radians)),
        base_displacement: f.terminal.base_displacement,
        base_rpy: f.terminal.base_rpy_deg.map(|a| a.map(f64::to_radians)),
        terminal_joints: f.terminal.joint_angles.clone(),
        zero_velocity: f.terminal.zero_velocity,
        effort: f.objective.effort,
        energy: [f.objective.thruster_energy, f.objective.joint_energy],
        smoothing: [f.objective.thrust_smoothing, f.objective.power_smoothing],
        bounds,
        joint_limit,
        sigma_floor,
        tolerance: f.solver.tolerance,
        max_iterations: f.solver.max_iterations as usize,
        hessian,
        gauss_newton_above,
        warm_start,
        cruise_start,
        proximal: sv.proximal,
        feedback,
        qp: (sv.qp_tolerance, sv.qp_iterations as usize),
        starts: sv.starts as usize,
        seed: sv.seed,
        perturbation: sv.perturbation,
    })
}

/// The joint limit (limit, barrier weight) and the σ_min floor of `f`, validated against the
/// start (and the fixed terminal joint angles).
fn check_limits(
    doc: &Document,
    f: &File,
    vehicle: &Vehicle,
    joint_angles: &[f64],
) -> Result<((f64, f64), Option<SigmaFloorSpec>), InputError> {
    let b = &f.bounds;
    let keys = SigmaKeys {
        sigma_min: b.sigma_min,
        sigma_axes: b.sigma_axes.as_deref(),
        char_length: b.char_length,
    };
    let floor = check_sigma_floor(
        doc,
        keys,
        vehicle,
        joint_angles,
        f.terminal.joint_angles.as_deref(),
    )?;
    Ok((check_joint_limit(doc, b, joint_angles)?, floor))
}

/// The joint-limit keys (`bounds.joint_angle`, `barrier`), validated against the initial
/// joint angles: (limit, barrier weight).
fn check_joint_limit(
    doc: &Document,
    b: &Bounds,
    joint_angles: &[f64],
) -> Result<(f64, f64), InputError> {
    let joint_limit = (
        b.joint_angle.unwrap_or(f64::INFINITY),
        b.barrier.unwrap_or(1e-3),
    );
    if joint_limit.0 <= 0.0 {
        return Err(doc.err("bounds.joint_angle", "must be positive [rad]"));
    }
    if joint_limit.1 <= 0.0 {
        return Err(doc.err("bounds.barrier", "must be positive"));
    }
    if joint_angles.iter().any(|q| q.abs() >= joint_limit.0) {
        return Err(doc.err(
            "bounds.joint_angle",
            "the initial joint angles must be strictly inside the limit",
        ));
    }
    Ok(joint_limit)
}

/// The solver's strategy keys: `rollout` ("feedback" → true) and `initial_guess` ("cruise"
/// → true; needs a base target and no warm start). Returns (feedback, cruise start).
fn check_strategy(
    doc: &Document,
    sv: &Solver,
    base_target: bool,
    warm: bool,
) -> Result<(bool, bool), InputError> {
    let feedback = match sv.rollout.as_deref() {
        None | Some("linear") => false,
        Some("feedback") => true,
        Some(other) => {
            return Err(doc.err(
                "solver.rollout",
                format!("`{other}` is not one of \"linear\", \"feedback\""),
            ))
        }
    };
    let cruise_start = match sv.initial_guess.as_deref() {
        None | Some("rest") => false,
        Some("cruise") if base_target && !warm => true,
        Some("cruise") => {
            return Err(doc.err(
                "solver.initial_guess",
                "\"cruise\" needs terminal.base_displacement and no solver.warm_start",
            ))
        }
        Some(other) => {
            return Err(doc.err(
                "solver.initial_guess",
                format!("`{other}` is not one of \"rest\", \"cruise\""),
            ))
        }
    };
    Ok((feedback, cruise_start))
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

/// The terminal rows and the objective's weights of `f` (n joints, thruster actuation or not).
fn check_terminal_objective(
    doc: &Document,
    f: &File,
    n: usize,
    thrusters: bool,
) -> Result<(), InputError> {
    let t = &f.terminal;
    if let Some(q) = &t.joint_angles {
        if q.len() != n {
            return Err(doc.err(
                "terminal.joint_angles",
                format!("has {} entries, the design has {n} joints", q.len()),
            ));
        }
    }
    let any = t.ee_displacement.is_some()
        || t.ee_rpy_deg.is_some()
        || t.base_displacement.is_some()
        || t.base_rpy_deg.is_some()
        || t.joint_angles.is_some()
        || t.zero_velocity;
    if !any {
        return Err(doc.err("terminal", "fixes nothing: give at least one target"));
    }
    let ob = &f.objective;
    if ob.effort <= 0.0 {
        return Err(doc.err("objective.effort", "must be positive"));
    }
    for (k, v) in [
        ("objective.thruster_energy", ob.thruster_energy),
        ("objective.joint_energy", ob.joint_energy),
    ] {
        if v < 0.0 {
            return Err(doc.err(k, "must be at least 0 (0: off)"));
        }
    }
    if ob.thruster_energy > 0.0 && !thrusters {
        return Err(doc.err(
            "objective.thruster_energy",
            "needs actuation = \"thrusters\"",
        ));
    }
    for (k, v) in [
        ("objective.thrust_smoothing", ob.thrust_smoothing),
        ("objective.power_smoothing", ob.power_smoothing),
    ] {
        if v <= 0.0 {
            return Err(doc.err(k, "must be positive"));
        }
    }
    Ok(())
}

/// The solver section's checks: the Hessian, the Gauss–Newton threshold and the warm-start
/// file (resolved against the problem file's directory).
#[allow(clippy::type_complexity)]
fn check_solver(
    doc: &Document,
    sv: &Solver,
    path: &Path,
) -> Result<(Hessian, f64, Option<std::path::PathBuf>), InputError> {
    if sv.starts < 1 || sv.starts > 1000 {
        return Err(doc.err("solver.starts", "must be between 1 and 1000"));
    }
    if sv.qp_tolerance <= 0.0 {
        return Err(doc.err("solver.qp_tolerance", "must be positive"));
    }
    if sv.qp_iterations < 1 {
        return Err(doc.err("solver.qp_iterations", "must be at least 1"));
    }
    if sv.proximal < 0.0 {
        return Err(doc.err("solver.proximal", "must be at least 0 (0: off)"));
    }
    if sv.perturbation < 0.0 {
        return Err(doc.err("solver.perturbation", "must be at least 0"));
    }
    let warm_start = sv
        .warm_start
        .as_ref()
        .map(|w| path.parent().unwrap_or(Path::new("")).join(w));
    if let Some(w) = &warm_start {
        if !w.is_file() {
            return Err(doc.err(
                "solver.warm_start",
                format!("{} is not a file", w.display()),
            ));
        }
    }
    if sv.tolerance <= 0.0 {
        return Err(doc.err("solver.tolerance", "must be positive"));
    }
    if sv.max_iterations < 1 {
        return Err(doc.err("solver.max_iterations", "must be at least 1"));
    }
    let hessian = match sv.hessian.as_deref() {
        None | Some("exact") => Hessian::Exact,
        Some("gauss_newton") => Hessian::GaussNewton,
        Some(other) => {
            return Err(doc.err(
                "solver.hessian",
                format!("`{other}` is not one of \"exact\", \"gauss_newton\""),
            ))
        }
    };
    let gauss_newton_above = sv.gauss_newton_above.unwrap_or(f64::INFINITY);
    if gauss_newton_above <= 0.0 {
        return Err(doc.err("solver.gauss_newton_above", "must be positive"));
    }
    Ok((hessian, gauss_newton_above, warm_start))
}
