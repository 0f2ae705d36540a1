//! A problem file solved and written (docs/ocp.md §6): [`solve_spec`] builds the chain
//! model and the effort objective from a [`ProblemSpec`] and runs the SQP; [`write_outputs`]
//! writes `trajectory.csv` (the time-series column names of `simulate` where they apply),
//! `iterations.csv` (the iteration log) and `summary.json`.
// Stage and component loops read clearest with indices (k: knot, i: component).
#![allow(clippy::needless_range_loop)]

use super::chain::ChainModel;
use super::model::OcpModel;
use super::problem::ProblemSpec;
use super::sqp::{solve, OcpProblem, OcpSolution, SqpSettings};
use crate::dynamics::DynOptions;
use crate::kinematics::BasePose;
use crate::report::{atomic_write, format_f64, ReportError};
use crate::scenario::channels::{Channel, Pose, Twist};
use crate::spatial::{euler_zyx, Vec3};
use nalgebra::DMatrix;
use std::path::Path;

/// A solved problem: the model (for post-processing), the step and the solution.
#[derive(Debug)]
pub struct OcpRun {
    /// The chain model the problem was solved on.
    pub model: ChainModel,
    /// Δt = T/N [s].
    pub dt: f64,
    /// End-effector target, inertial [m].
    pub target: Vec3,
    /// The solution.
    pub solution: OcpSolution,
}

/// Solve a validated problem from the rest trajectory (zero controls rolled out).
pub fn solve_spec(spec: &ProblemSpec) -> OcpRun {
    let n = spec.vehicle.n_joints();
    let dt = spec.duration / spec.knots as f64;
    let opts = if spec.hydrodynamics {
        DynOptions::full()
    } else {
        DynOptions::rigid()
    };
    let x0 = ChainModel::pack(
        &BasePose::default(),
        &spec.joint_angles,
        &[0.0; 6],
        &vec![0.0; n],
    );
    let mut model = ChainModel::new(spec.vehicle.clone(), opts, dt, Vec3::zeros());
    let target = model.ee_position(&x0) + Vec3::from(spec.ee_displacement);
    let mut model = ChainModel::new(spec.vehicle.clone(), opts, dt, target);
    if spec.thrusters {
        model = model.with_thrusters();
    }
    let (nx, nu, nb) = (model.nx(), model.nu(), model.n_body_controls());
    let (mut u_lo, mut u_hi) = (Vec::with_capacity(nu), Vec::with_capacity(nu));
    for i in 0..nu {
        let (lo, hi) = match i {
            _ if i >= nb => (-spec.bounds[2], spec.bounds[2]),
            _ if spec.thrusters => (
                spec.vehicle.thrusters[i].u_min,
                spec.vehicle.thrusters[i].u_max,
            ),
            0..=2 => (-spec.bounds[0], spec.bounds[0]),
            _ => (-spec.bounds[1], spec.bounds[1]),
        };
        u_lo.push(lo);
        u_hi.push(hi);
    }
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
        ..SqpSettings::default()
    };
    let solution = solve(&mut model, &prob, None, None, &set);
    OcpRun {
        model,
        dt,
        target,
        solution,
    }
}

/// The column names of `trajectory.csv`: with `n_thrusters` = Some(m) the thrusts
/// (`simulate`'s actual-thrust names), else the base wrench.
pub fn trajectory_columns(n_joints: usize, n_thrusters: Option<usize>) -> Vec<String> {
    let mut c = vec![Channel::T.name()];
    c.extend(Pose::ALL.map(|p| Channel::BasePose(p).name()));
    c.extend(Twist::ALL.map(|t| Channel::BaseTwist(t).name()));
    c.extend(Pose::ALL.map(|p| Channel::EePose(p).name()));
    c.extend((0..n_joints).map(|k| Channel::Q(k).name()));
    c.extend((0..n_joints).map(|k| Channel::Qd(k).name()));
    c.extend((0..n_joints).map(|k| Channel::Tau(k).name()));
    if let Some(m) = n_thrusters {
        c.extend((0..m).map(|j| Channel::U(j).name()));
        return c;
    }
    c.extend(
        [
            "wrench_fx",
            "wrench_fy",
            "wrench_fz",
            "wrench_mx",
            "wrench_my",
            "wrench_mz",
        ]
        .map(String::from),
    );
    c
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
        "iteration,objective,primal,stationarity,complementarity,step,qp_iterations,filter_size,regularisation,terminal_penalty\n",
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
        "dt": run.dt,
        "hydrodynamics": spec.hydrodynamics,
        "actuation": if spec.thrusters { "thrusters" } else { "base_wrench" },
        "method": "multiple shooting, SQP, Riccati interior-point QP, filter line search",
        "hessian": spec.hessian,
        "derivatives": "central differences (eps 1e-6, tangent coordinates)",
        "optimum": "a local optimum from the rest trajectory (single start)",
    });
    let text = serde_json::to_string_pretty(&summary).unwrap_or_default();
    atomic_write(&dir.join("summary.json"), text.as_bytes())?;
    Ok(())
}
