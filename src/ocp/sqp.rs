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

use super::cost::add_path_cost;
use super::model::{ModelError, OcpModel};
use super::qp::{residuals, solve_box_qp, QpSettings, QpSolution};
use super::riccati::{LqError, LqStage, LqTerminal};
use nalgebra::{DMatrix, DVector};
use serde::Serialize;
use std::time::Instant;

/// Margin of the filter's acceptance tests (γ_θ = γ_φ).
const GAMMA: f64 = 1e-5;

/// The problem data besides the model.
#[derive(Clone, Debug)]
pub struct OcpProblem {
    /// Number of intervals N (states x_0 … x_N).
    pub knots: usize,
    /// Initial state (representation, nq).
    pub x0: Vec<f64>,
    /// Reference state of the state cost (nq).
    pub x_ref: Vec<f64>,
    /// Stage state weight `Q` (nx×nx, symmetric positive semidefinite).
    pub q: DMatrix<f64>,
    /// Stage control weight `R` (nu×nu, symmetric positive definite).
    pub r: DMatrix<f64>,
    /// Terminal state weight `Q_N` (nx×nx).
    pub q_n: DMatrix<f64>,
    /// Lower control bounds (nu; `-inf` for none).
    pub u_lo: Vec<f64>,
    /// Upper control bounds (nu; `inf` for none).
    pub u_hi: Vec<f64>,
}

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

/// Everything evaluated at one iterate.
struct Eval {
    stages: Vec<LqStage>,
    term: LqTerminal,
    objective: f64,
    /// Σ‖d_k‖₁ + ‖c‖₁.
    infeas1: f64,
    /// max ‖d_k‖∞, ‖c‖∞.
    infeas_max: f64,
    /// Time spent on the Lagrangian Hessians [s].
    hessian_time: f64,
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

/// The SQP iteration on `st` (states rolled out first when empty).
fn iterate<M: OcpModel>(
    model: &mut M,
    prob: &OcpProblem,
    set: &SqpSettings,
    st: &mut SolveState,
) -> End {
    let (n, nu) = (prob.knots, model.nu());
    if st.xs.is_empty() {
        let mut x = vec![prob.x0.clone(); n + 1];
        for k in 0..n {
            let (a, b) = x.split_at_mut(k + 1);
            if let Err(e) = model.step(&a[k], &st.us[k], &mut b[0]) {
                st.xs = x;
                return End::new(Status::Diverged, e.0, None, [f64::NAN; 3]);
            }
        }
        st.xs = x;
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
        let mut row = IterLog {
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
        let step = line_search(model, prob, st, &ev, &qp, &mut filter);
        st.timing.line_search += tl.elapsed().as_secs_f64();
        let Some((alpha, xt, ut)) = step else {
            st.log.push(row);
            if qp.least_squares {
                let msg = "terminal constraint not reachable by the linearised dynamics (least-squares step) and no acceptable step".to_string();
                return End::new(Status::Infeasible, msg, Some(ev), kkt);
            }
            let msg = "the filter line search found no acceptable step".to_string();
            return End::new(Status::Stalled, msg, Some(ev), kkt);
        };
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

/// KKT residuals (primal, stationarity, complementarity) at the current iterate with the
/// QP's multipliers.
fn kkt_residuals(
    prob: &OcpProblem,
    ev: &Eval,
    qp: &QpSolution,
    us: &[Vec<f64>],
    nx: usize,
) -> [f64; 3] {
    let n = prob.knots;
    let nu = prob.u_lo.len();
    let zx = vec![DVector::zeros(nx); n + 1];
    let zu = vec![DVector::zeros(nu); n];
    let (stat, _) = residuals(
        &ev.stages, &ev.term, &zx, &zu, &qp.lam, &qp.nu, &qp.z_lo, &qp.z_hi,
    );
    let mut comp: f64 = 0.0;
    for k in 0..n {
        for i in 0..nu {
            if prob.u_lo[i].is_finite() {
                comp = comp.max((us[k][i] - prob.u_lo[i]) * qp.z_lo[k][i]);
            }
            if prob.u_hi[i].is_finite() {
                comp = comp.max((prob.u_hi[i] - us[k][i]) * qp.z_hi[k][i]);
            }
        }
    }
    [ev.infeas_max, stat, comp]
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
    while alpha >= 1e-10 {
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

/// `v` moved strictly inside `[lo, hi]` (by 1e-3 of the width, or 1e-3 from a one-sided bound).
fn strictly_inside(v: f64, lo: f64, hi: f64) -> f64 {
    let margin = if lo.is_finite() && hi.is_finite() {
        1e-3 * (hi - lo)
    } else {
        1e-3
    };
    v.max(lo + margin).min(hi - margin)
}

/// Multiplier estimates (λ_0 … λ_N, ν) weighting the dynamics' and terminal curvature.
type Multipliers<'a> = (&'a [DVector<f64>], &'a DVector<f64>);

/// Objective, defects and terminal residual at (xs, us); with `derivatives = Some(m)`, also
/// the Jacobians and the QP data: the Gauss–Newton Hessian, plus the Lagrangian's curvature
/// when `m` holds multipliers.
fn evaluate<M: OcpModel>(
    model: &mut M,
    prob: &OcpProblem,
    xs: &[Vec<f64>],
    us: &[Vec<f64>],
    derivatives: Option<Option<Multipliers>>,
) -> Result<Eval, ModelError> {
    let mut hessian_time = 0.0;
    let mut hbuf = DMatrix::zeros(0, 0);
    if let Some(Some(_)) = derivatives {
        hbuf = DMatrix::zeros(model.nx() + model.nu(), model.nx() + model.nu());
    }
    let (n, nx, nu, nq, nc) = (prob.knots, model.nx(), model.nu(), model.nq(), model.nc());
    let paths = model.has_path_costs();
    let mut pbuf = (vec![0.0; nx + nu], DMatrix::zeros(nx + nu, nx + nu));
    let mut stages = Vec::with_capacity(n);
    let mut f = vec![0.0; nq];
    let mut d = vec![0.0; nx];
    let mut e = vec![0.0; nx];
    let mut objective = 0.0;
    let (mut infeas1, mut infeas_max) = (0.0, 0.0f64);
    for k in 0..n {
        let mut s = LqStage::zeros(nx, nu);
        model.step(&xs[k], &us[k], &mut f)?;
        if f.iter().any(|v| !v.is_finite()) {
            return Err(ModelError(format!("non-finite state at knot {}", k + 1)));
        }
        model.difference(&xs[k + 1], &f, &mut d);
        s.d.copy_from_slice(&d);
        infeas1 += s.d.lp_norm(1);
        infeas_max = infeas_max.max(s.d.amax());
        model.difference(&prob.x_ref, &xs[k], &mut e);
        let ev = DVector::from_column_slice(&e);
        let uv = DVector::from_column_slice(&us[k]);
        objective += ev.dot(&(&prob.q * &ev)) + uv.dot(&(&prob.r * &uv));
        if paths {
            objective += model.stage_cost(&xs[k], &us[k]);
        }
        if let Some(mult) = derivatives {
            model.jacobians(&xs[k], &us[k], &mut s.a, &mut s.b)?;
            s.q_mat = &prob.q * 2.0;
            s.q_vec = &prob.q * &ev * 2.0;
            s.r_mat = &prob.r * 2.0;
            s.r_vec = &prob.r * &uv * 2.0;
            if let Some((lam, _)) = mult {
                let th = Instant::now();
                model.weighted_hessian(&xs[k], &us[k], lam[k + 1].as_slice(), &mut hbuf)?;
                s.q_mat += hbuf.view((0, 0), (nx, nx));
                s.r_mat += hbuf.view((nx, nx), (nu, nu));
                s.s_mat.copy_from(&hbuf.view((nx, 0), (nu, nx)));
                hessian_time += th.elapsed().as_secs_f64();
            }
            if paths {
                add_path_cost(model, &xs[k], &us[k], mult.is_some(), &mut s, &mut pbuf);
            }
        }
        stages.push(s);
    }
    model.difference(&prob.x_ref, &xs[n], &mut e);
    let ev = DVector::from_column_slice(&e);
    objective += ev.dot(&(&prob.q_n * &ev));
    let mut q_vec_n = &prob.q_n * &ev * 2.0;
    let mut q_n = &prob.q_n * 2.0;
    if paths {
        objective += model.terminal_cost(&xs[n]);
        if derivatives.is_some() {
            let mut g = vec![0.0; nx];
            let mut h = DMatrix::zeros(nx, nx);
            model.terminal_cost_derivatives(&xs[n], &mut g, &mut h);
            q_vec_n += DVector::from_vec(g);
            q_n += h;
        }
    }
    let mut c = vec![0.0; nc];
    model.terminal(&xs[n], &mut c);
    let c_vec = DVector::from_vec(c);
    infeas1 += c_vec.lp_norm(1);
    infeas_max = infeas_max.max(c_vec.amax());
    let mut c_mat = DMatrix::zeros(nc, nx);
    if let Some(mult) = derivatives {
        model.terminal_jacobian(&xs[n], &mut c_mat);
        if let Some((_, nu_mult)) = mult {
            let mut h = DMatrix::zeros(nx, nx);
            model.terminal_hessian(&xs[n], nu_mult.as_slice(), &mut h);
            q_n += h;
        }
    }
    if !objective.is_finite() || !infeas1.is_finite() {
        return Err(ModelError("non-finite objective or residual".into()));
    }
    Ok(Eval {
        stages,
        term: LqTerminal {
            q_mat: q_n,
            q_vec: q_vec_n,
            c_mat,
            c_vec,
        },
        objective,
        infeas1,
        infeas_max,
        hessian_time,
    })
}
