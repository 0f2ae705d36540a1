//! A problem file solved and written (docs/ocp.md §6): [`solve_spec`] builds the chain
//! model and the effort objective from a [`ProblemSpec`] and runs the SQP; [`write_outputs`]
//! writes `trajectory.csv` (the time-series column names of `simulate` where they apply),
//! `iterations.csv` (the iteration log) and `summary.json`.
// Stage and component loops read clearest with indices (k: knot, i: component).
#![allow(clippy::needless_range_loop)]

use super::chain::{ChainModel, TerminalSpec};
use super::cost::PathCosts;
use super::cruise::cruise_start;
use super::fidelity::{grid_fidelity, GridFidelity};
use super::model::OcpModel;
use super::problem::ProblemSpec;
use super::qp::QpSettings;
use super::sigma_floor::SigmaFloor;
use super::sqp::{solve, OcpProblem, OcpSolution, SqpSettings, Status};
pub use super::start::trajectory_columns;
use super::start::{perturbed_controls, read_warm_start};
use crate::dynamics::DynOptions;
use crate::input::located::InputError;
use crate::kinematics::BasePose;
use crate::metrics::singularity::CommandedDofs;
use crate::metrics::trajectory::PowerModel;
use crate::report::{atomic_write, format_f64, ReportError};
use crate::spatial::{euler_zyx, Vec3};
use nalgebra::{DMatrix, UnitQuaternion};
use serde::Serialize;
use std::path::Path;

/// One start of a multi-start solve.
#[derive(Clone, Debug, Serialize)]
pub struct StartRecord {
    /// Start index (0: cold or warm start as given; ≥ 1 perturbed).
    pub start: usize,
    /// How it ended.
    pub status: Status,
    /// Objective J at its last iterate.
    pub objective: f64,
    /// SQP iterations.
    pub iterations: usize,
    /// KKT residuals (primal, stationarity, complementarity).
    pub kkt: [f64; 3],
    /// Wall time [s].
    pub time_s: f64,
}

/// A solved problem: the model (for post-processing), the step and the best solution.
#[derive(Debug)]
pub struct OcpRun {
    /// The chain model the problem was solved on.
    pub model: ChainModel,
    /// Δt = T/N [s].
    pub dt: f64,
    /// End-effector target, inertial [m] (its start when the end effector is free).
    pub target: Vec3,
    /// The best start's solution (lowest objective among the converged, else among all).
    pub solution: OcpSolution,
    /// Which start that is.
    pub best_start: usize,
    /// Every start.
    pub starts: Vec<StartRecord>,
    /// The solution integrated again [`FIDELITY_REFINE`] times finer (docs/ocp.md §4,
    /// "Grid fidelity"); the reason when that integration failed.
    pub fidelity: Result<GridFidelity, String>,
}

/// How many times finer the grid-fidelity check integrates each interval.
pub const FIDELITY_REFINE: usize = 10;

/// The chain model of a problem (terminal rows and path costs) and its initial state.
pub fn build_model(spec: &ProblemSpec) -> (ChainModel, Vec<f64>) {
    let n = spec.vehicle.n_joints();
    let dt = spec.duration / spec.knots as f64;
    let opts = if spec.hydrodynamics {
        DynOptions::full()
    } else {
        DynOptions::rigid()
    };
    let mut vehicle = spec.vehicle.clone();
    if let Some(c) = spec.current {
        vehicle.fluid.current = Vec3::from(c);
    }
    let start = BasePose::default();
    let x0 = ChainModel::pack(&start, &spec.joint_angles, &[0.0; 6], &vec![0.0; n]);
    let mut model = ChainModel::new(vehicle, opts, dt, Vec3::zeros()).with_substeps(spec.substeps);
    if spec.thrusters {
        model = model.with_thrusters();
    }
    let ee0 = model.ee_position(&x0);
    let rot = |a: [f64; 3]| {
        *UnitQuaternion::from_euler_angles(a[0], a[1], a[2])
            .to_rotation_matrix()
            .matrix()
    };
    let terminal = TerminalSpec {
        ee_position: spec.ee_displacement.map(|d| ee0 + Vec3::from(d)),
        ee_rotation: spec.ee_rpy.map(rot),
        base_position: spec
            .base_displacement
            .map(|d| start.position + Vec3::from(d)),
        base_rotation: spec.base_rpy.map(rot),
        joint_angles: spec.terminal_joints.clone(),
        zero_velocity: spec.zero_velocity,
    };
    let nb = model.n_body_controls();
    let mut costs = PathCosts::new(dt, nb, spec.thrusters);
    costs.thruster_energy = spec.energy[0];
    costs.joint_energy = spec.energy[1];
    costs.thrust_smoothing = spec.smoothing[0];
    costs.power_smoothing = spec.smoothing[1];
    if spec.joint_limit.0.is_finite() {
        costs.joint_limits = Some(vec![(-spec.joint_limit.0, spec.joint_limit.0); n]);
        costs.barrier = spec.joint_limit.1;
    }
    let paths = spec.energy.iter().any(|w| *w > 0.0) || costs.joint_limits.is_some();
    model = model.with_terminal(terminal);
    if paths {
        model = model.with_costs(costs);
    }
    if let Some(f) = &spec.sigma_floor {
        let floor = SigmaFloor::new(
            &spec.vehicle,
            f.lo,
            spec.joint_limit.1,
            CommandedDofs::new(f.axes),
            f.char_length,
        );
        model = model.with_sigma_floor(floor);
    }
    (model, x0)
}

/// The control bounds `(u_lo, u_hi)` of a problem.
fn control_bounds(spec: &ProblemSpec, model: &ChainModel) -> (Vec<f64>, Vec<f64>) {
    let (nu, nb) = (model.nu(), model.n_body_controls());
    (0..nu)
        .map(|i| match i {
            _ if i >= nb => (-spec.bounds[2], spec.bounds[2]),
            _ if spec.thrusters => (
                spec.vehicle.thrusters[i].u_min,
                spec.vehicle.thrusters[i].u_max,
            ),
            0..=2 => (-spec.bounds[0], spec.bounds[0]),
            _ => (-spec.bounds[1], spec.bounds[1]),
        })
        .unzip()
}

/// Solve a validated problem from each of its starts (docs/ocp.md §4): start 0 from the
/// warm start (or zero controls rolled out), the others perturbed; the best local optimum
/// found is returned as such. Errors: an unreadable or mismatched warm-start file.
pub fn solve_spec(spec: &ProblemSpec) -> Result<OcpRun, InputError> {
    let (mut model, x0) = build_model(spec);
    let (nx, nu) = (model.nx(), model.nu());
    let dt = model.dt();
    let (u_lo, u_hi) = control_bounds(spec, &model);
    let prob = OcpProblem {
        knots: spec.knots,
        x_ref: x0.clone(),
        x0,
        q: DMatrix::zeros(nx, nx),
        r: DMatrix::identity(nu, nu) * (spec.effort * dt),
        q_n: DMatrix::zeros(nx, nx),
        u_hi,
        u_lo,
    };
    let set = SqpSettings {
        tolerance: spec.tolerance,
        max_iterations: spec.max_iterations,
        hessian: spec.hessian,
        gauss_newton_above: spec.gauss_newton_above,
        proximal: spec.proximal,
        feedback: spec.feedback,
        qp: QpSettings {
            tolerance: spec.qp.0,
            max_iterations: spec.qp.1,
        },
    };
    let (warm_xs, warm_us) = match &spec.warm_start {
        Some(p) => {
            let (xs, us) = read_warm_start(p, &model, spec.knots)?;
            (Some(xs), us)
        }
        None if spec.cruise_start => {
            let d = spec.base_displacement.unwrap_or_default();
            let (lo, hi) = (&prob.u_lo, &prob.u_hi);
            let cruise = cruise_start(&mut model, &prob.x0, spec.knots, d, lo, hi);
            let (xs, us) = cruise.map_err(|e| InputError {
                at: crate::input::located::Location::origin(&spec.origin),
                error: format!("solver.initial_guess: the cruise start failed: {}", e.0),
            })?;
            (Some(xs), us)
        }
        None => (None, vec![vec![0.0; nu]; spec.knots]),
    };
    let mut best: Option<(usize, OcpSolution)> = None;
    let mut starts = Vec::with_capacity(spec.starts);
    for s in 0..spec.starts {
        let (lo, hi) = (&prob.u_lo, &prob.u_hi);
        let us = perturbed_controls(&warm_us, lo, hi, spec.perturbation, spec.seed, s);
        let xs = if s == 0 { warm_xs.clone() } else { None };
        let sol = solve(&mut model, &prob, Some(us), xs, &set);
        starts.push(StartRecord {
            start: s,
            status: sol.status,
            objective: sol.objective,
            iterations: sol.iterations,
            kkt: sol.kkt,
            time_s: sol.timing.total,
        });
        if better(&sol, best.as_ref().map(|b| &b.1)) {
            best = Some((s, sol));
        }
    }
    let (best_start, solution) = best.expect("at least one start (validated)");
    let target = match model.terminal_spec().ee_position {
        Some(p) => p,
        None => model.ee_position(&prob.x0),
    };
    let fidelity =
        grid_fidelity(&model, &solution.xs, &solution.us, FIDELITY_REFINE).map_err(|e| e.0);
    Ok(OcpRun {
        model,
        dt,
        target,
        solution,
        best_start,
        starts,
        fidelity,
    })
}

/// Whether `a` beats `b`: converged before not; among converged the lower objective, among
/// the others the lower primal infeasibility (non-finite last), then the lower objective.
fn better(a: &OcpSolution, b: Option<&OcpSolution>) -> bool {
    let Some(b) = b else {
        return true;
    };
    let key = |s: &OcpSolution| {
        let conv = s.status == Status::Converged;
        let primal = if conv || !s.kkt[0].is_finite() {
            if conv {
                0.0
            } else {
                f64::INFINITY
            }
        } else {
            s.kkt[0]
        };
        let j = if s.objective.is_finite() {
            s.objective
        } else {
            f64::INFINITY
        };
        (!conv, primal, j)
    };
    let (ka, kb) = (key(a), key(b));
    (ka.0, ka.1, ka.2) < (kb.0, kb.1, kb.2)
}

/// Write `trajectory.csv`, `iterations.csv` and `summary.json` into `dir` (created).
pub fn write_outputs(dir: &Path, spec: &ProblemSpec, run: &mut OcpRun) -> Result<(), ReportError> {
    crate::report::prepare_dir(dir).map_err(|e| ReportError::Io {
        path: dir.to_path_buf(),
        action: "creating",
        source: e,
    })?;
    let n = spec.vehicle.n_joints();
    let sol = &run.solution;
    let nb = run.model.n_body_controls();
    let thrusters = run.model.thruster_actuated().then_some(nb);
    let mut csv = trajectory_columns(n, thrusters).join(",");
    csv.push('\n');
    for (k, x) in sol.xs.iter().enumerate() {
        let pose = ChainModel::pose(x);
        let rpy = euler_zyx(pose.orientation.to_rotation_matrix().matrix());
        let (r_e, p_e) = run.model.ee_pose(x);
        let rpy_e = euler_zyx(&r_e);
        let mut row: Vec<f64> = vec![k as f64 * run.dt];
        row.extend_from_slice(pose.position.as_slice());
        row.extend_from_slice(rpy.as_slice());
        row.extend_from_slice(&x[7 + n..13 + n]);
        row.extend_from_slice(p_e.as_slice());
        row.extend_from_slice(rpy_e.as_slice());
        row.extend_from_slice(&x[7..7 + n]);
        row.extend_from_slice(&x[13 + n..13 + 2 * n]);
        let mut cells: Vec<String> = row.into_iter().map(format_f64).collect();
        match sol.us.get(k) {
            Some(u) => {
                cells.extend(u[nb..].iter().map(|v| format_f64(*v)));
                cells.extend(u[..nb].iter().map(|v| format_f64(*v)));
            }
            // No control at the last knot.
            None => cells.extend(std::iter::repeat_n(String::new(), n + nb)),
        }
        csv.push_str(&cells.join(","));
        csv.push('\n');
    }
    atomic_write(&dir.join("trajectory.csv"), csv.as_bytes())?;
    let mut it = String::from(
        "iteration,objective,primal,stationarity,complementarity,step,qp_iterations,filter_size,regularisation,terminal_penalty,proximal\n",
    );
    for r in &sol.log {
        let cells = [
            r.iteration.to_string(),
            format_f64(r.objective),
            format_f64(r.primal),
            format_f64(r.stationarity),
            format_f64(r.complementarity),
            format_f64(r.step),
            r.qp_iterations.to_string(),
            r.filter_size.to_string(),
            format_f64(r.regularisation),
            format_f64(r.terminal_penalty),
            format_f64(r.proximal),
        ];
        it.push_str(&cells.join(","));
        it.push('\n');
    }
    atomic_write(&dir.join("iterations.csv"), it.as_bytes())?;
    let last = sol
        .xs
        .last()
        .map(|x| run.model.ee_position(x))
        .unwrap_or_default();
    let summary = serde_json::json!({
        "problem": spec.origin,
        "design": spec.vehicle.name,
        "status": sol.status,
        "message": sol.message,
        "objective": sol.objective,
        "kkt": {
            "primal": sol.kkt[0],
            "stationarity": sol.kkt[1],
            "complementarity": sol.kkt[2],
            "tolerance": spec.tolerance,
        },
        "terminal_violation": sol.terminal_violation,
        "ee_final_error": (last - run.target).norm(),
        "iterations": sol.iterations,
        "time_s": sol.timing,
        "knots": spec.knots,
        "substeps": spec.substeps,
        "dt": run.dt,
        "grid_fidelity": fidelity_json(&run.fidelity),
        "hydrodynamics": spec.hydrodynamics,
        "actuation": if spec.thrusters { "thrusters" } else { "base_wrench" },
        "method": "multiple shooting, SQP, Riccati interior-point QP, filter line search",
        "hessian": spec.hessian,
        "derivatives": "central differences (eps 1e-6, tangent coordinates)",
        "objective_terms": objective_terms(run),
        "optimum": optimum_text(spec, run),
        "best_start": run.best_start,
        "spread": spread(&run.starts),
        "starts": run.starts,
    });
    let text = serde_json::to_string_pretty(&summary).unwrap_or_default();
    atomic_write(&dir.join("summary.json"), text.as_bytes())?;
    let plot = super::plots::PlotRun {
        solution: &run.solution,
        nb,
        thrusters: thrusters.is_some(),
        dt: run.dt,
    };
    super::plots::write_plots(&dir.join("plots"), spec, &plot)?;
    Ok(())
}

/// `summary.json`'s `grid_fidelity` ((F1)–(F4) of docs/ocp.md §4), or the failure.
fn fidelity_json(f: &Result<GridFidelity, String>) -> serde_json::Value {
    match f {
        Ok(f) => serde_json::json!({
            "refined_substeps": f.refined_substeps,
            "max_configuration_defect": f.max_configuration_defect,
            "max_velocity_defect": f.max_velocity_defect,
            "worst_interval": f.worst_interval,
            "relative_defect": f.relative_defect,
            "actuator_work_j": f.actuator_work,
            "actuator_work_refined_j": f.actuator_work_refined,
            "other_work_j": f.other_work,
            "other_work_refined_j": f.other_work_refined,
        }),
        Err(e) => serde_json::json!({ "failed": e }),
    }
}

/// The objective's terms at the returned solution: effort `w Σ Δt ‖u‖²` and the path
/// costs' breakdown (smoothed, exact).
fn objective_terms(run: &mut OcpRun) -> serde_json::Value {
    let least_sigma = run.model.least_sigma(&run.solution.xs);
    let floor = run.model.sigma_floor().map(|f| {
        serde_json::json!({
            "floor": f.lo,
            "axes": (0..6).filter(|&i| f.dofs.contains(i)).map(|i| super::problem::AXES[i]).collect::<Vec<_>>(),
            "char_length_m": f.char_length,
            "barrier": f.mu,
            "least_along_optimum": least_sigma,
        })
    });
    let sol = &run.solution;
    let n = run.model.n_joints();
    let sq: f64 = sol.us.iter().flatten().map(|v| v * v).sum();
    let costs = run.model.costs().map(|c| {
        let b = c.breakdown(n, &sol.xs, &sol.us);
        serde_json::json!({
            "weights": {"thruster_energy": c.thruster_energy, "joint_energy": c.joint_energy,
                        "barrier": c.joint_limits.as_ref().map(|_| c.barrier)},
            "smoothing": {"thrust_n": c.thrust_smoothing, "power_w": c.power_smoothing},
            "values": b,
        })
    });
    serde_json::json!({
        "effort_sum_dt_u2": sq * run.dt,
        "path_costs": costs,
        "thruster_energy_with_inflow": inflow_energy(run),
        "sigma_floor": floor,
    })
}

/// `Σ_k Δt Σ_j P_j(u_kj, V_a,kj)/η` [J] at the knots (the project's `thruster_energy`,
/// [`PowerModel::shaft_power`] with the inflow of [`ChainModel::thruster_inflows`]);
/// `None` under base-wrench actuation.
fn inflow_energy(run: &OcpRun) -> Option<f64> {
    let mut model = run.model.clone();
    if !model.thruster_actuated() {
        return None;
    }
    let (pm, m) = (PowerModel::default(), model.n_body_controls());
    let mut e = 0.0;
    for (x, u) in run.solution.xs.iter().zip(&run.solution.us) {
        let va = model.thruster_inflows(x, &u[..m]);
        e += run.dt
            * u[..m]
                .iter()
                .zip(&va)
                .map(|(u, v)| pm.shaft_power(*u, *v))
                .sum::<f64>();
    }
    Some(e)
}

/// What the returned optimum is, in words.
fn optimum_text(spec: &ProblemSpec, run: &OcpRun) -> String {
    let from = if spec.warm_start.is_some() {
        "the warm start"
    } else {
        "the rest trajectory"
    };
    if run.starts.len() == 1 {
        return format!("a local optimum from {from} (single start)");
    }
    format!(
        "the best local optimum found over {} starts (start 0 from {from}, the others perturbed by ±{} of the bounds, seed {}): start {}",
        run.starts.len(),
        spec.perturbation,
        spec.seed,
        run.best_start
    )
}

/// Objectives of the converged starts: count, min, median, max.
fn spread(starts: &[StartRecord]) -> serde_json::Value {
    let mut j: Vec<f64> = starts
        .iter()
        .filter(|s| s.status == Status::Converged)
        .map(|s| s.objective)
        .collect();
    j.sort_by(f64::total_cmp);
    let med = match j.len() {
        0 => f64::NAN,
        m if m % 2 == 1 => j[m / 2],
        m => 0.5 * (j[m / 2 - 1] + j[m / 2]),
    };
    serde_json::json!({
        "starts": starts.len(),
        "converged": j.len(),
        "objective_min": j.first(),
        "objective_median": if j.is_empty() { None } else { Some(med) },
        "objective_max": j.last(),
    })
}
