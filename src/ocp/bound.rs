//! The optimal-control bound of a design on a transport leg (issue 41, docs/ocp.md §6): the
//! least thruster and joint energy the best local optimum found spends on a straight leg
//! of the mission, with multi-start and an in-memory warm start, and the N−1 bound (one
//! thruster removed) warm-started so that it is never below the intact design's.
//!
//! The leg: from rest at the origin (body straight, level) to the base origin `distance`
//! metres ahead along inertial +x, base level and heading +x, joints straight, every
//! velocity zero, in `duration` seconds, in the leg's current (inertial, m/s). Controls:
//! every thrust within the design's limits and every joint torque within ±`joint_torque`
//! (docs/ocp.md §2). Objective (docs/ocp.md §1): `Σ Δt Σ_j c φ(u_j)` (actuator-disk power
//! at zero inflow, smoothed) + `Σ Δt Σ_i ψ(τ_i q̇_i)` (joint mechanical power, smoothed)
//! + `effort Σ Δt ‖u‖²`.
// Stage and component loops read clearest with indices (k: knot, i: component).
#![allow(clippy::needless_range_loop)]

use super::chain::ChainModel;
use super::cruise::{cruise_start, ramped_cruise_start, RAMP};
use super::model::OcpModel;
use super::problem::ProblemSpec;
use super::qp::QpSettings;
use super::run::build_model;
use super::sqp::{solve, Hessian, OcpProblem, OcpSolution, SqpSettings, Status};
use super::start::{perturbed_controls, Trajectory};
use crate::model::Vehicle;
use crate::study::schema::OCP_WORK_TRUSTED;
use nalgebra::DMatrix;

/// A straight transport leg as an optimal-control problem (module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct LegSpec {
    /// Distance the base origin moves along inertial +x [m].
    pub distance: f64,
    /// Horizon T [s].
    pub duration: f64,
    /// Knots N (Δt = T/N).
    pub knots: usize,
    /// Symplectic Euler steps per interval (h = Δt/substeps, docs/ocp.md §2): at Δt = 1 s
    /// with one step the leg's optimum swims on energy the discretisation supplies (§4);
    /// 10 substeps (h = 0.1 s) balance the work of water and actuators to 0.1 %.
    pub substeps: usize,
    /// The fluid's current, inertial [m/s].
    pub current: [f64; 3],
    /// Joint torque bound |τ_i| ≤ this [N·m].
    pub joint_torque: f64,
    /// Weight of `Σ Δt ‖u‖²` (> 0: keeps the torques' Hessian positive).
    pub effort: f64,
    /// Starts of the multi-start (≥ 1).
    pub starts: usize,
    /// Seed of the perturbed starts.
    pub seed: u64,
    /// Perturbation of the starts, × each control's bound.
    pub perturbation: f64,
    /// KKT tolerance.
    pub tolerance: f64,
    /// Most SQP iterations per start.
    pub max_iterations: usize,
}

impl Default for LegSpec {
    /// 10 m in 20 s (0.5 m/s, the transport controller's cruise), N = 20 with 10 substeps,
    /// still water.
    fn default() -> Self {
        Self {
            distance: 10.0,
            duration: 20.0,
            knots: 20,
            substeps: 10,
            current: [0.0; 3],
            joint_torque: 20.0,
            effort: 1e-3,
            starts: 3,
            seed: 0,
            perturbation: 0.05,
            tolerance: 1e-6,
            max_iterations: 150,
        }
    }
}

/// The problem of `leg` on `vehicle` (thruster actuation, full hydrodynamics).
pub fn leg_problem(vehicle: &Vehicle, leg: &LegSpec) -> ProblemSpec {
    let n = vehicle.n_joints();
    ProblemSpec {
        origin: format!("transport leg {} m in {} s", leg.distance, leg.duration),
        vehicle: vehicle.clone(),
        hydrodynamics: true,
        thrusters: true,
        duration: leg.duration,
        knots: leg.knots,
        substeps: leg.substeps.max(1),
        joint_angles: vec![0.0; n],
        current: Some(leg.current),
        ee_displacement: None,
        ee_rpy: None,
        base_displacement: Some([leg.distance, 0.0, 0.0]),
        base_rpy: Some([0.0; 3]),
        terminal_joints: Some(vec![0.0; n]),
        zero_velocity: true,
        effort: leg.effort,
        energy: [1.0, 1.0],
        smoothing: [0.01, 0.01],
        bounds: [f64::INFINITY, f64::INFINITY, leg.joint_torque],
        joint_limit: (f64::INFINITY, 0.0),
        sigma_floor: None,
        tolerance: leg.tolerance,
        max_iterations: leg.max_iterations,
        hessian: Hessian::Exact,
        gauss_newton_above: 1e-2,
        warm_start: None,
        // The settings the shipped leg (`studies/ocp_transport.toml`) measured best (§4): the
        // cruise start, Levenberg damping 100 (P1), the feedback rollout (P2).
        cruise_start: true,
        proximal: 100.0,
        feedback: true,
        qp: (1e-8, 60),
        starts: leg.starts.max(1),
        seed: leg.seed,
        perturbation: leg.perturbation,
    }
}

/// Least and greatest ramp fraction of the multi-start's cruise starts (C1): from a quick
/// start (a tenth of the horizon accelerating) to a triangular speed profile.
pub const RAMP_RANGE: (f64, f64) = (0.1, 0.5);

/// The ramp fraction of start `s` of a cruise-started leg: [`RAMP`] for start 0, else uniform
/// in [`RAMP_RANGE`] from ChaCha8 seeded with (`seed`, `s`).
pub fn start_ramp(seed: u64, s: usize) -> f64 {
    use rand::{Rng, SeedableRng};
    if s == 0 {
        return RAMP;
    }
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(s as u64);
    rng.random_range(RAMP_RANGE.0..=RAMP_RANGE.1)
}

/// The bound of one design on one problem: the best local optimum over the starts.
#[derive(Clone, Debug)]
pub struct Bound {
    /// Objective J of the best start (converged first, then feasible with the lowest J, then
    /// the lowest primal residual).
    pub objective: f64,
    /// `Σ Δt Σ_j c |u_j|^{3/2}` of the best start [J]: thruster energy at zero inflow.
    pub thruster_energy_static: f64,
    /// `Σ Δt Σ_i |τ_i q̇_i|` of the best start [J]: joint mechanical energy.
    pub joint_energy: f64,
    /// (max − min) / min of the converged starts' objectives (NaN with fewer than two).
    pub spread: f64,
    /// The best start's status.
    pub status: Status,
    /// The best start's KKT residuals (primal, stationarity, complementarity).
    pub kkt: [f64; 3],
    /// Wall time of every start together [s].
    pub time_s: f64,
    /// Converged starts.
    pub converged: usize,
    /// SQP iterations of every start together.
    pub iterations: usize,
    /// The best start's work-balance error on its grid (docs/ocp.md §6):
    /// `|W_other − W_other,refined| / max(|W_act|, |W_act,refined|)` against the same controls
    /// integrated [`WORK_REFINE`] times finer (`ocp::fidelity` (F3)–(F4)); NaN when the refined
    /// integration fails. Above a few per cent the optimum swims on energy the grid supplies.
    pub work_error: f64,
    /// The best start's solution.
    pub solution: OcpSolution,
}

/// Refinement of the work-balance check of [`Bound::work_error`].
pub const WORK_REFINE: usize = 10;

/// [`Bound::work_error`] of `(xs, us)` on `model`.
pub fn work_error(model: &ChainModel, xs: &[Vec<f64>], us: &[Vec<f64>]) -> f64 {
    match super::fidelity::grid_fidelity(model, xs, us, WORK_REFINE) {
        Ok(f) => {
            let scale = f
                .actuator_work
                .abs()
                .max(f.actuator_work_refined.abs())
                .max(f64::MIN_POSITIVE);
            (f.other_work - f.other_work_refined).abs() / scale
        }
        Err(_) => f64::NAN,
    }
}

/// The control bounds of a thruster-actuated problem: thrust limits, then ±joint torque.
fn bounds(spec: &ProblemSpec) -> (Vec<f64>, Vec<f64>) {
    let mut lo: Vec<f64> = spec.vehicle.thrusters.iter().map(|t| t.u_min).collect();
    let mut hi: Vec<f64> = spec.vehicle.thrusters.iter().map(|t| t.u_max).collect();
    let n = spec.vehicle.n_joints();
    lo.extend(std::iter::repeat_n(-spec.bounds[2], n));
    hi.extend(std::iter::repeat_n(spec.bounds[2], n));
    (lo, hi)
}

/// Solve `spec` (thruster actuation) from `spec.starts` starts: start 0 from `warm` (states
/// and controls), else from the cruise start with `spec.cruise_start`, else from zero
/// controls rolled out, start s ≥ 1 from start 0's controls
/// perturbed (ChaCha8 seeded with (`spec.seed`, s)), rolled out. Deterministic.
pub fn solve_bound(spec: &ProblemSpec, warm: Option<&Trajectory>) -> Bound {
    let (mut model, x0) = build_model(spec);
    let (nx, nu) = (model.nx(), model.nu());
    let dt = model.dt();
    let (u_lo, u_hi) = bounds(spec);
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
    // Start 0: the warm start, else the cruise start (`spec.cruise_start`, docs/ocp.md §4
    // (C1)–(C3); zero controls if it fails), else zero controls rolled out.
    let d = spec.base_displacement.unwrap_or_default();
    let cruise = match warm {
        None if spec.cruise_start => {
            cruise_start(&mut model, &prob.x0, spec.knots, d, &prob.u_lo, &prob.u_hi).ok()
        }
        _ => None,
    };
    let warm_given = warm;
    let warm = warm.or(cruise.as_ref());
    let base = warm.map_or_else(|| vec![vec![0.0; nu]; spec.knots], |w| w.1.clone());
    let mut sols: Vec<OcpSolution> = Vec::with_capacity(spec.starts);
    for s in 0..spec.starts.max(1) {
        let (lo, hi) = (&prob.u_lo, &prob.u_hi);
        // Start s ≥ 1 of a cruise-started leg: the cruise start with its own ramp fraction
        // (`start_ramp`), dynamically consistent as start 0 (a perturbed cruise rolled out
        // diverged at iteration 0–1, and kept on start 0's states it did not converge in 150
        // iterations: docs/ocp.md §6).
        let ramped = (s > 0 && spec.cruise_start)
            .then(|| {
                let r = start_ramp(spec.seed, s);
                ramped_cruise_start(&mut model, &prob.x0, spec.knots, d, r, lo, hi).ok()
            })
            .flatten();
        let sol = match ramped {
            Some((xs, us)) => solve(&mut model, &prob, Some(us), Some(xs), &set),
            None => {
                let us = perturbed_controls(&base, lo, hi, spec.perturbation, spec.seed, s);
                // Without a cruise start, start s ≥ 1 keeps start 0's states (multiple
                // shooting: the perturbed controls' defects are the SQP's to close) with
                // plain trial points.
                let xs = warm.map(|w| w.0.clone());
                let set_s = if s == 0 || xs.is_none() {
                    set
                } else {
                    SqpSettings {
                        feedback: false,
                        ..set
                    }
                };
                solve(&mut model, &prob, Some(us), xs, &set_s)
            }
        };
        sols.push(sol);
    }
    // A leg the cruise settings cannot fly (short legs, where the cruise start is far from
    // the optimum): one more start from zero controls with the plain SQP (no damping, plain
    // rollout, QP tolerance 1e-10). Counted among the starts; the best feasible one is kept.
    let flies = |s: &OcpSolution| flies(s.status, &s.kkt, spec.tolerance);
    if spec.cruise_start && warm_given.is_none() && !sols.iter().any(flies) {
        let plain = SqpSettings {
            proximal: 0.0,
            feedback: false,
            qp: QpSettings {
                tolerance: 1e-10,
                max_iterations: spec.qp.1,
            },
            ..set
        };
        let zero = vec![vec![0.0; nu]; spec.knots];
        sols.push(solve(&mut model, &prob, Some(zero), None, &plain));
    }
    summarise(&model, sols, spec.tolerance)
}

/// Whether a solve that ended with `status` and KKT residuals `kkt` holds a trajectory the model
/// can fly that meets the leg's end: converged, or primal feasible (defects and terminal rows
/// within `tolerance`) — a stalled or capped solve may still hold one.
pub fn flies(status: Status, kkt: &[f64; 3], tolerance: f64) -> bool {
    status == Status::Converged || kkt[0] <= tolerance
}

impl Bound {
    /// Whether the best start holds a trajectory the model can fly ([`flies`]).
    pub fn flies(&self, tolerance: f64) -> bool {
        flies(self.status, &self.kkt, tolerance)
    }

    /// Whether the bound counts: it flies, and its energy is the actuators' rather than the
    /// grid's (work error at most [`OCP_WORK_TRUSTED`]).
    pub fn counts(&self, tolerance: f64) -> bool {
        self.flies(tolerance) && self.work_error <= OCP_WORK_TRUSTED
    }
}

/// The best of `sols` (converged first, then primal feasible — defects and terminal rows within
/// `tolerance` — with the lowest objective, else the lowest primal residual; ties to the
/// earlier start).
fn summarise(model: &ChainModel, mut sols: Vec<OcpSolution>, tolerance: f64) -> Bound {
    let conv: Vec<f64> = sols
        .iter()
        .filter(|s| s.status == Status::Converged)
        .map(|s| s.objective)
        .collect();
    let spread = match conv.len() {
        0 | 1 => f64::NAN,
        _ => {
            let lo = conv.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = conv.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            (hi - lo) / lo.abs().max(f64::MIN_POSITIVE)
        }
    };
    let time_s = sols.iter().map(|s| s.timing.total).sum();
    let iterations = sols.iter().map(|s| s.iterations).sum();
    let key = |s: &OcpSolution| {
        let j = if s.objective.is_finite() {
            s.objective
        } else {
            f64::INFINITY
        };
        let infeasible = s.kkt[0].is_nan() || s.kkt[0] > tolerance;
        // Among infeasible starts the nearest to feasible (the zero-control fallback barely
        // moves, J ≈ 0 at primal ≈ 5: the lowest J would name it).
        let p = if s.kkt[0].is_nan() {
            f64::INFINITY
        } else {
            s.kkt[0]
        };
        (
            s.status != Status::Converged,
            infeasible,
            if infeasible { p } else { j },
        )
    };
    let mut best = 0;
    for (i, s) in sols.iter().enumerate() {
        if key(s) < key(&sols[best]) {
            best = i;
        }
    }
    let solution = sols.swap_remove(best);
    let n = model.n_joints();
    let (e_t, e_j) = model.costs().map_or((f64::NAN, f64::NAN), |c| {
        let b = c.breakdown(n, &solution.xs, &solution.us);
        (b.thruster_energy_static, b.joint_energy)
    });
    let work_error = work_error(model, &solution.xs, &solution.us);
    Bound {
        work_error,
        objective: solution.objective,
        thruster_energy_static: e_t,
        joint_energy: e_j,
        spread,
        status: solution.status,
        kkt: solution.kkt,
        time_s,
        converged: conv.len(),
        iterations,
        solution,
    }
}

/// `vehicle` with thruster `j` removed (the N−1 design of a dead thruster).
pub fn without_thruster(vehicle: &Vehicle, j: usize) -> Vehicle {
    let mut v = vehicle.clone();
    v.thrusters.remove(j);
    v.name = format!("{} without thruster {}", vehicle.name, j + 1);
    v
}

/// An N−1 solution as a warm start of the intact design: thruster `j`'s thrust inserted at
/// zero (feasible for the intact design: same states, same generalised forces).
pub fn reinsert_thruster(sol: &OcpSolution, j: usize) -> Trajectory {
    let us = sol
        .us
        .iter()
        .map(|u| {
            let mut w = u.clone();
            w.insert(j, 0.0);
            w
        })
        .collect();
    (sol.xs.clone(), us)
}

/// The intact bound and the N−1 bound of thruster `j` on the problem `spec` (thruster
/// actuation): the N−1 problem first, then the intact design from its own starts **and**
/// warm-started from the N−1 optimum, the better kept. The SQP's line search accepts a
/// step from a feasible point only if it lowers J (Armijo under the switching condition),
/// so from the N−1 optimum (feasible for the intact design with thruster `j` at zero, same
/// objective J₋) the intact solve cannot end above J₋: the intact bound is never above the
/// N−1 bound. Returns (intact, N−1).
pub fn intact_and_n_minus_one(spec: &ProblemSpec, j: usize) -> (Bound, Bound) {
    let mut reduced = spec.clone();
    reduced.vehicle = without_thruster(&spec.vehicle, j);
    let minus = solve_bound(&reduced, None);
    let cold = solve_bound(spec, None);
    let mut single = spec.clone();
    single.starts = 1;
    let warm = solve_bound(&single, Some(&reinsert_thruster(&minus.solution, j)));
    // A start counts when it converged or ended primal feasible (a stalled warm start
    // still holds the feasible N−1 point it started from); the lower objective wins.
    let t = spec.tolerance;
    let intact = match (cold.flies(t), warm.flies(t)) {
        (true, true) if cold.objective <= warm.objective => cold,
        (true, false) => cold,
        _ => warm,
    };
    (intact, minus)
}
