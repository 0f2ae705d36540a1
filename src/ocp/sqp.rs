//! Direct multiple shooting solved by an SQP with the exact Lagrangian Hessian or the
//! Gauss–Newton one (docs/ocp.md §3).
//!
//! Variables: the states `x_0 … x_N` (manifold representations, `x_0` fixed) and the
//! controls `u_0 … u_{N−1}`. Problem:
//!
//! ```text
//! min J = Σ_{k<N} (e_kᵀ Q e_k + u_kᵀ R u_k) + e_Nᵀ Q_N e_N,   e_k = x_k ⊖ x_ref
//! s.t. f(x_k, u_k) ⊖ x_{k+1} = 0,   c(x_N) = 0,   u_lo ≤ u_k ≤ u_hi
//! ```
//!
//! Each iteration linearises the defects and the terminal equality (the model's Jacobians,
//! tangent coordinates), takes the Hessian `2Q`, `2R`, `2Q_N` plus, for [`Hessian::Exact`],
//! the dynamics' and the terminal equality's curvature weighted by the previous QP's
//! multipliers (`∇²(λ_{k+1}ᵀ f)` per stage, with its cross block `S_k`, and `∇²(νᵀ c)`; the
//! curvature of `⊖` on the `x_{k+1}` side is left out), convexified when a Riccati
//! factorisation is not positive definite ([`regularised_qp`]), and solves the QP of
//! [`super::qp`] (Riccati-based interior point, bounds strictly feasible). The step is accepted by a backtracking filter line search (Wächter & Biegler
//! 2006) on the pair (θ, J), `θ = Σ‖d_k‖₁ + ‖c‖₁`: a trial point must not be dominated by
//! the filter and must decrease θ or J by the margin γ = 1e-5·θ; when θ is small
//! (≤ 1e-4·max(1, θ_start)) and the step is a descent direction of J with
//! `α(−∇J·Δ)^2.3 > θ^1.1`, Armijo on J is required instead (and the filter is not grown).
//! No feasibility restoration: no acceptable step down to α = 1e-10 ends the solve as
//! `Stalled`.
//!
//! KKT residuals at an iterate, with the QP's multipliers (λ, ν, z):
//! primal `max(‖d_k‖∞, ‖c‖∞)`; stationarity `max ‖∇_u L‖∞, ‖∇_x L‖∞` with
//! `∇_u L = 2R u_k + B_kᵀλ_{k+1} − z_lo + z_hi`, `∇_x L = 2Q e_k + A_kᵀλ_{k+1} − λ_k`,
//! `∇_{x_N} L = 2Q_N e_N + Cᵀν − λ_N`; complementarity `max (u − u_lo)∘z_lo, (u_hi − u)∘z_hi`.
//! Converged when all three are at most the tolerance (default 1e-6).
// Stage and component loops read clearest with indices (k: knot, i: component).
#![allow(clippy::needless_range_loop)]

use super::model::OcpModel;
use super::qp::{solve_box_qp, QpSettings, QpSolution};
use super::riccati::LqError;
use super::sqp_eval::{evaluate, feedback_rollout, kkt_residuals, strictly_inside, Eval};
use nalgebra::DVector;
use serde::Serialize;
use std::time::Instant;

/// Margin of the filter's acceptance tests (γ_θ = γ_φ).
const GAMMA: f64 = 1e-5;

pub use super::sqp_eval::OcpProblem;

/// The Hessian of the SQP's subproblems.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Hessian {
    /// `2Q`, `2R`, `2Q_N`: the objective's only (no curvature of the dynamics).
    GaussNewton,
    /// The Lagrangian's: the objective's plus `∇²(λ_{k+1}ᵀ f)` per stage and `∇²(νᵀ c)` at
    /// the end, with the previous QP's multipliers (full step, whatever the line search
    /// accepted; the first iteration has none and is Gauss–Newton)
    /// ([`OcpModel::weighted_hessian`]), convexified by [`regularised_qp`] when a Riccati
    /// factorisation is not positive definite.
    Exact,
}

/// Settings of the SQP.
#[derive(Clone, Copy, Debug)]
pub struct SqpSettings {
    /// The subproblems' Hessian.
    pub hessian: Hessian,
    /// With [`Hessian::Exact`]: the Gauss–Newton Hessian is used while the previous
    /// iterate's primal infeasibility exceeds this (∞: exact from the second iteration).
    pub gauss_newton_above: f64,
    /// KKT tolerance (primal, stationarity, complementarity; ∞-norms).
    pub tolerance: f64,
    /// Most SQP iterations.
    pub max_iterations: usize,
    /// Initial Levenberg weight ρ_p of the state increments (docs/ocp.md §3, eq. (P1));
    /// 0: off (the plain SQP step).
    pub proximal: f64,
    /// Trial points of the line search by the feedback rollout of eq. (P2) (dynamically
    /// feasible: only the terminal residual remains) instead of `x_k ⊕ αδx_k`, `u_k + αδu_k`.
    pub feedback: bool,
    /// Settings of the QP interior point.
    pub qp: QpSettings,
}

impl Default for SqpSettings {
    fn default() -> Self {
        Self {
            hessian: Hessian::Exact,
            gauss_newton_above: f64::INFINITY,
            tolerance: 1e-6,
            max_iterations: 200,
            proximal: 0.0,
            feedback: false,
            qp: QpSettings::default(),
        }
    }
}

/// How a solve ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// KKT residuals at most the tolerance.
    Converged,
    /// The iteration limit was reached first.
    MaxIterations,
    /// The linearised terminal constraint cannot be reached (QP infeasible).
    Infeasible,
    /// The dynamics failed or produced non-finite values, or the QP lost convexity.
    Diverged,
    /// The line search found no acceptable step (a point the method cannot improve).
    Stalled,
}

impl Status {
    /// The status as `summary.json` writes it (`converged`, `max_iterations`, …).
    pub fn word(self) -> &'static str {
        match self {
            Status::Converged => "converged",
            Status::MaxIterations => "max_iterations",
            Status::Infeasible => "infeasible",
            Status::Diverged => "diverged",
            Status::Stalled => "stalled",
        }
    }
}

/// One row of the iteration log.
#[derive(Clone, Debug, Serialize)]
pub struct IterLog {
    /// Iteration (0 = the start).
    pub iteration: usize,
    /// Objective J.
    pub objective: f64,
    /// Primal infeasibility (∞-norm of defects and terminal residual).
    pub primal: f64,
    /// Stationarity (∞-norm of the Lagrangian gradient, QP multipliers).
    pub stationarity: f64,
    /// Complementarity of the control bounds.
    pub complementarity: f64,
    /// Accepted step length (0 on the last row).
    pub step: f64,
    /// Interior-point iterations of this QP.
    pub qp_iterations: usize,
    /// Entries in the filter.
    pub filter_size: usize,
    /// Regularisation δ added to the Hessian's diagonal (0: none).
    pub regularisation: f64,
    /// Terminal penalty ρ (ρ CᵀC added to `Q_N`; 0: none).
    pub terminal_penalty: f64,
    /// Levenberg weight ρ_p on the state increments of this QP (eq. (P1); 0: none).
    pub proximal: f64,
}

/// Wall-clock time by phase [s].
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Timing {
    /// Derivatives (dynamics and terminal Jacobians).
    pub derivatives: f64,
    /// Of which the Lagrangian Hessians (exact Hessian only).
    pub hessian: f64,
    /// QP solves (Riccati factorisations).
    pub qp: f64,
    /// Line search (dynamics rollouts of the trial points).
    pub line_search: f64,
    /// Everything.
    pub total: f64,
}

/// The result of a solve (the last iterate, whatever the status).
#[derive(Clone, Debug)]
pub struct OcpSolution {
    /// States x_0 … x_N (representations).
    pub xs: Vec<Vec<f64>>,
    /// Controls u_0 … u_{N−1}.
    pub us: Vec<Vec<f64>>,
    /// How the solve ended.
    pub status: Status,
    /// What stopped it, in words.
    pub message: String,
    /// Objective J.
    pub objective: f64,
    /// Final KKT residuals (primal, stationarity, complementarity).
    pub kkt: [f64; 3],
    /// Terminal residual ∞-norm.
    pub terminal_violation: f64,
    /// SQP iterations taken.
    pub iterations: usize,
    /// The iteration log.
    pub log: Vec<IterLog>,
    /// Time by phase.
    pub timing: Timing,
}

/// Solve `prob` on `model` from the initial guess `us` (controls; pushed strictly inside
/// the bounds) and `xs` (states; `None`: rolled out from `x0` with `us`).
pub fn solve<M: OcpModel>(
    model: &mut M,
    prob: &OcpProblem,
    us: Option<Vec<Vec<f64>>>,
    xs: Option<Vec<Vec<f64>>>,
    set: &SqpSettings,
) -> OcpSolution {
    let t0 = Instant::now();
    let (n, nu) = (prob.knots, model.nu());
    let mut us = us.unwrap_or_else(|| vec![vec![0.0; nu]; n]);
    for u in us.iter_mut() {
        for i in 0..nu {
            u[i] = strictly_inside(u[i], prob.u_lo[i], prob.u_hi[i]);
        }
    }
    let mut st = SolveState {
        xs: xs.unwrap_or_default(),
        us,
        log: Vec::new(),
        timing: Timing::default(),
        iterations: 0,
        mult: None,
        reg: Reg::default(),
        proximal: set.proximal,
    };
    let end = iterate(model, prob, set, &mut st);
    st.timing.total = t0.elapsed().as_secs_f64();
    let e = end.eval.as_ref();
    OcpSolution {
        xs: st.xs,
        us: st.us,
        status: end.status,
        message: end.message,
        objective: e.map_or(f64::NAN, |e| e.objective),
        kkt: end.kkt,
        terminal_violation: e.map_or(f64::NAN, |e| e.term.c_vec.amax()),
        iterations: st.iterations,
        log: st.log,
        timing: st.timing,
    }
}

/// The iterate and the bookkeeping of a solve.
struct SolveState {
    xs: Vec<Vec<f64>>,
    us: Vec<Vec<f64>>,
    log: Vec<IterLog>,
    timing: Timing,
    iterations: usize,
    /// Multiplier estimates (costates λ_0 … λ_N, terminal ν) for the exact Hessian.
    mult: Option<(Vec<DVector<f64>>, DVector<f64>)>,
    /// Last convexification that made every factorisation positive definite.
    reg: Reg,
    /// Levenberg weight ρ_p for the next QP (eq. (P1)).
    proximal: f64,
}

/// How the iteration ended.
struct End {
    status: Status,
    message: String,
    eval: Option<Eval>,
    kkt: [f64; 3],
}

impl End {
    fn new(status: Status, message: String, eval: Option<Eval>, kkt: [f64; 3]) -> Self {
        Self {
            status,
            message,
            eval,
            kkt,
        }
    }
}

/// Multipliers of the lower and upper control bounds, per stage.
type BoundMultipliers = (Vec<DVector<f64>>, Vec<DVector<f64>>);

/// The filter of the line search and its scale.
#[derive(Default)]
struct Filter {
    entries: Vec<(f64, f64)>,
    theta_first: Option<f64>,
}

/// The states of `st` rolled out from `x_0` with its controls (single-shooting start).
fn roll_out_start<M: OcpModel>(
    model: &mut M,
    prob: &OcpProblem,
    st: &mut SolveState,
) -> Result<(), super::model::ModelError> {
    let n = prob.knots;
    let mut x = vec![prob.x0.clone(); n + 1];
    for k in 0..n {
        let (a, b) = x.split_at_mut(k + 1);
        let r = model.step(&a[k], &st.us[k], &mut b[0]);
        if r.is_err() {
            st.xs = x;
            return r;
        }
    }
    st.xs = x;
    Ok(())
}

/// The SQP iteration on `st` (states rolled out first when empty).
fn iterate<M: OcpModel>(
    model: &mut M,
    prob: &OcpProblem,
    set: &SqpSettings,
    st: &mut SolveState,
) -> End {
    let nu = model.nu();
    if st.xs.is_empty() {
        if let Err(e) = roll_out_start(model, prob, st) {
            return End::new(Status::Diverged, e.0, None, [f64::NAN; 3]);
        }
    }
    st.xs[0].copy_from_slice(&prob.x0);
    let mut filter = Filter::default();
    let mut z_warm: Option<BoundMultipliers> = None;
    loop {
        let it = st.iterations;
        let ts = Instant::now();
        let primal = st.log.last().map_or(f64::INFINITY, |r| r.primal);
        let mult = match set.hessian {
            Hessian::Exact if primal <= set.gauss_newton_above => {
                st.mult.as_ref().map(|(l, v)| (l.as_slice(), v))
            }
            _ => None,
        };
        let mut ev = match evaluate(model, prob, &st.xs, &st.us, Some(mult)) {
            Ok(e) => e,
            Err(e) => return End::new(Status::Diverged, e.0, None, [f64::NAN; 3]),
        };
        st.timing.derivatives += ts.elapsed().as_secs_f64();
        st.timing.hessian += ev.hessian_time;
        let bound = |b: &[f64]| -> Vec<DVector<f64>> {
            let us = &st.us;
            us.iter()
                .map(|u| DVector::from_iterator(nu, (0..nu).map(|i| b[i] - u[i])))
                .collect()
        };
        let (lo, hi) = (bound(&prob.u_lo), bound(&prob.u_hi));
        // Levenberg damping (P1): a failed line search retries the QP with ρ_p ×10.
        let pristine = (set.proximal > 0.0).then(|| (ev.stages.clone(), ev.term.q_mat.clone()));
        let mut rho_p = st.proximal;
        let (qp, mut row, kkt, step) = loop {
            if rho_p > 0.0 {
                shift_states(&mut ev, rho_p);
            }
            let tq = Instant::now();
            let warm = z_warm.as_ref().map(|(a, b)| (a.as_slice(), b.as_slice()));
            let (qp, reg) = regularised_qp(&mut ev, &lo, &hi, warm, set, st.reg);
            st.reg = reg;
            st.timing.qp += tq.elapsed().as_secs_f64();
            let qp = match qp {
                Ok(q) => q,
                Err(e) => {
                    let status = match e {
                        LqError::Unreachable { .. } => Status::Infeasible,
                        LqError::NotConvex(_) => Status::Diverged,
                    };
                    let kkt = [ev.infeas_max, f64::NAN, f64::NAN];
                    return End::new(status, e.to_string(), Some(ev), kkt);
                }
            };
            let kkt = kkt_residuals(prob, &ev, &qp, &st.us, model.nx());
            let row = IterLog {
                iteration: it,
                objective: ev.objective,
                primal: ev.infeas_max,
                stationarity: kkt[1],
                complementarity: kkt[2],
                step: 0.0,
                qp_iterations: qp.iterations,
                filter_size: filter.entries.len(),
                regularisation: reg.delta,
                terminal_penalty: reg.rho,
                proximal: rho_p,
            };
            if kkt.iter().all(|r| *r <= set.tolerance) {
                st.log.push(row);
                let msg = format!("KKT residuals at most {:e}", set.tolerance);
                return End::new(Status::Converged, msg, Some(ev), kkt);
            }
            if it >= set.max_iterations {
                st.log.push(row);
                let msg = format!("{} iterations", set.max_iterations);
                return End::new(Status::MaxIterations, msg, Some(ev), kkt);
            }
            let tl = Instant::now();
            let step = line_search(model, prob, st, &ev, &qp, &mut filter, set.feedback);
            st.timing.line_search += tl.elapsed().as_secs_f64();
            match &pristine {
                Some((stages, q_n)) if step.is_none() && rho_p < MAX_PROXIMAL => {
                    rho_p = (rho_p * 10.0).max(set.proximal);
                    for (s, p) in ev.stages.iter_mut().zip(stages) {
                        s.q_mat.copy_from(&p.q_mat);
                        s.r_mat.copy_from(&p.r_mat);
                    }
                    ev.term.q_mat.copy_from(q_n);
                }
                _ => break (qp, row, kkt, step),
            }
        };
        let Some((alpha, xt, ut)) = step else {
            st.log.push(row);
            if qp.least_squares {
                let msg = "terminal constraint not reachable by the linearised dynamics (least-squares step) and no acceptable step".to_string();
                return End::new(Status::Infeasible, msg, Some(ev), kkt);
            }
            let msg = "the filter line search found no acceptable step".to_string();
            return End::new(Status::Stalled, msg, Some(ev), kkt);
        };
        st.proximal = adapt_proximal(rho_p, alpha, set.proximal);
        row.step = alpha;
        st.log.push(row);
        st.xs = xt;
        st.us = ut;
        st.mult = Some((qp.lam, qp.nu));
        z_warm = Some((qp.z_lo, qp.z_hi));
        st.iterations += 1;
    }
}

/// Largest regularisation tried before the subproblem is declared not convex.
const MAX_REG: f64 = 1e12;

/// Largest terminal penalty ρ of [`regularised_qp`].
const MAX_RHO: f64 = 1e6;

/// The convexifications of a subproblem: the terminal penalty ρ and the diagonal shift δ.
#[derive(Clone, Copy, Debug, Default)]
struct Reg {
    rho: f64,
    delta: f64,
}

/// The QP of `ev`, convexified when a Riccati factorisation is not positive definite.
/// First `ρ CᵀC` is added to `Q_N` (ρ from `ρ_last/4`, times 10 up to 1e6): on the
/// terminal equality's solution set it adds a constant, so the QP's primal solution is
/// unchanged and ν is recovered as `ν' + ρ C δx_N`, but it makes the Riccati recursion
/// positive definite whenever the Hessian is on the null space of the constraints
/// (Debreu's lemma) — the stage-wise Riccati otherwise needs it on the larger space of
/// free terminal states. Then `δ I` is added to every `Q_k`, `R_k` and `Q_N` (IPOPT's
/// inertia correction: δ from `max(1e-8, δ_last/3)` or 1e-4, times 8). Returns the QP
/// result and the (ρ, δ) used (left added to `ev`).
#[allow(clippy::type_complexity)]
fn regularised_qp(
    ev: &mut Eval,
    lo: &[DVector<f64>],
    hi: &[DVector<f64>],
    warm: Option<(&[DVector<f64>], &[DVector<f64>])>,
    set: &SqpSettings,
    last: Reg,
) -> (Result<QpSolution, LqError>, Reg) {
    let ctc = ev.term.c_mat.transpose() * &ev.term.c_mat;
    let mut reg = Reg::default();
    if set.hessian == Hessian::Exact && last.rho >= 4.0 {
        reg.rho = last.rho / 4.0;
        ev.term.q_mat += &ctc * reg.rho;
    }
    loop {
        let mut qp = solve_box_qp(&ev.stages, &ev.term, lo, hi, warm, &set.qp);
        let convex = !matches!(qp, Err(LqError::NotConvex(_)));
        if convex || set.hessian == Hessian::GaussNewton {
            if let Ok(q) = qp.as_mut() {
                if reg.rho > 0.0 {
                    let n = q.dx.len() - 1;
                    q.nu += &ev.term.c_mat * &q.dx[n] * reg.rho;
                }
            }
            return (qp, reg);
        }
        if reg.rho < MAX_RHO {
            let next = (reg.rho * 10.0).max(1.0);
            ev.term.q_mat += &ctc * (next - reg.rho);
            reg.rho = next;
            continue;
        }
        let next = if reg.delta > 0.0 {
            reg.delta * 8.0
        } else if last.delta > 0.0 {
            (last.delta / 3.0).max(1e-8)
        } else {
            1e-4
        };
        if next > MAX_REG {
            return (qp, reg);
        }
        shift_diagonal(ev, next - reg.delta);
        reg.delta = next;
    }
}

/// Largest Levenberg weight ρ_p tried before the line search is declared stalled.
const MAX_PROXIMAL: f64 = 1e10;

/// Add `rho` to the diagonals of the state blocks `Q_k` (k ≥ 1; δx_0 = 0) and of `Q_N`:
/// the Levenberg term `ρ_p Σ_k ‖δx_k‖²/2` of eq. (P1).
fn shift_states(ev: &mut Eval, rho: f64) {
    for s in ev.stages.iter_mut().skip(1) {
        for i in 0..s.q_mat.nrows() {
            s.q_mat[(i, i)] += rho;
        }
    }
    for i in 0..ev.term.q_mat.nrows() {
        ev.term.q_mat[(i, i)] += rho;
    }
}

/// The Levenberg weight after a step of length `alpha` taken with `rho` (eq. (P1)): a full
/// step divides it by 10 (to 0 below 1e-8 × the initial `rho0`: the plain SQP step, hence
/// its local convergence, near the solution), a step shorter than 1/4 multiplies it by 4
/// (at least 1e-3 × `rho0`), any other keeps it.
fn adapt_proximal(rho: f64, alpha: f64, rho0: f64) -> f64 {
    if alpha >= 1.0 {
        let r = rho / 10.0;
        if r < 1e-8 * rho0 {
            0.0
        } else {
            r
        }
    } else if alpha < 0.25 {
        (rho * 4.0).max(1e-3 * rho0)
    } else {
        rho
    }
}

/// Add `d` to the diagonals of every stage's `Q_k`, `R_k` and of `Q_N`.
fn shift_diagonal(ev: &mut Eval, d: f64) {
    for s in ev.stages.iter_mut() {
        for i in 0..s.q_mat.nrows() {
            s.q_mat[(i, i)] += d;
        }
        for i in 0..s.r_mat.nrows() {
            s.r_mat[(i, i)] += d;
        }
    }
    for i in 0..ev.term.q_mat.nrows() {
        ev.term.q_mat[(i, i)] += d;
    }
}

/// Filter line search (Wächter & Biegler 2006, without restoration) along the QP step:
/// the accepted step length and trial point, or `None` below α = 1e-10.
#[allow(clippy::type_complexity)]
fn line_search<M: OcpModel>(
    model: &mut M,
    prob: &OcpProblem,
    st: &SolveState,
    ev: &Eval,
    qp: &QpSolution,
    filter: &mut Filter,
    feedback: bool,
) -> Option<(f64, Vec<Vec<f64>>, Vec<Vec<f64>>)> {
    let (n, nu) = (prob.knots, model.nu());
    let mut slope = 0.0;
    for k in 0..n {
        slope += ev.stages[k].r_vec.dot(&qp.du[k]) + ev.stages[k].q_vec.dot(&qp.dx[k]);
    }
    slope += ev.term.q_vec.dot(&qp.dx[n]);
    let (theta0, j0) = (ev.infeas1, ev.objective);
    let scale = *filter.theta_first.get_or_insert(theta0.max(1.0));
    let (theta_min, theta_max) = (1e-4 * scale, 1e4 * scale);
    // Fraction to the boundary of the model's barrier domain (IPOPT's τ = 0.99).
    let mut alpha = (1..=n).fold(1.0f64, |a, k| {
        a.min(model.max_step(&st.xs[k], qp.dx[k].as_slice()))
    });
    let (mut xt, mut ut) = (st.xs.clone(), st.us.clone());
    let mut dxk = vec![0.0; model.nx()];
    let mut scratch = (
        vec![0.0; model.nx()],
        vec![0.0; model.nq()],
        vec![0.0; model.nx()],
    );
    while alpha >= 1e-10 {
        let trial = if feedback && !qp.gains.is_empty() {
            let (xs, us) = (&st.xs, &st.us);
            feedback_rollout(
                model,
                prob,
                xs,
                us,
                qp,
                alpha,
                &mut xt,
                &mut ut,
                &mut scratch,
            )
        } else {
            for k in 0..=n {
                if k > 0 {
                    for (d, v) in dxk.iter_mut().zip(qp.dx[k].iter()) {
                        *d = alpha * v;
                    }
                    model.retract(&st.xs[k], &dxk, &mut xt[k]);
                }
                if k < n {
                    for i in 0..nu {
                        ut[k][i] = st.us[k][i] + alpha * qp.du[k][i];
                    }
                }
            }
            Ok(())
        };
        if trial.is_err() {
            alpha *= 0.5;
            continue;
        }
        if let Ok(e) = evaluate(model, prob, &xt, &ut, None) {
            let (theta, j) = (e.infeas1, e.objective);
            let in_filter =
                theta <= theta_max && filter.entries.iter().all(|&(tf, jf)| theta < tf || j < jf);
            let armijo = j <= j0 + 1e-4 * alpha * slope;
            let switching = slope < 0.0 && alpha * (-slope).powf(2.3) > theta0.powf(1.1);
            let ok = if switching && theta0 <= theta_min {
                in_filter && armijo
            } else {
                in_filter && (theta <= (1.0 - GAMMA) * theta0 || j <= j0 - GAMMA * theta0)
            };
            if ok {
                if !(switching && armijo) {
                    filter
                        .entries
                        .push(((1.0 - GAMMA) * theta0, j0 - GAMMA * theta0));
                }
                return Some((alpha, xt, ut));
            }
        }
        alpha *= 0.5;
    }
    None
}
