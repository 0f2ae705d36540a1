//! Direct multiple shooting solved by a Gauss–Newton SQP (docs/ocp.md §3).
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
//! tangent coordinates), takes the Gauss–Newton Hessian `2Q`, `2R`, `2Q_N` (exact for the
//! objective's least-squares terms; the curvature of the dynamics and of `⊖` is left out)
//! and solves the QP of [`super::qp`] (Riccati-based interior point, bounds strictly
//! feasible). The step is accepted by a backtracking filter line search (Wächter & Biegler
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

/// Settings of the SQP.
#[derive(Clone, Copy, Debug)]
pub struct SqpSettings {
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
}

/// Wall-clock time by phase [s].
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Timing {
    /// Derivatives (dynamics and terminal Jacobians).
    pub derivatives: f64,
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
        let ev = match evaluate(model, prob, &st.xs, &st.us, true) {
            Ok(e) => e,
            Err(e) => return End::new(Status::Diverged, e.0, None, [f64::NAN; 3]),
        };
        st.timing.derivatives += ts.elapsed().as_secs_f64();
        let bound = |b: &[f64]| -> Vec<DVector<f64>> {
            let us = &st.us;
            us.iter()
                .map(|u| DVector::from_iterator(nu, (0..nu).map(|i| b[i] - u[i])))
                .collect()
        };
        let (lo, hi) = (bound(&prob.u_lo), bound(&prob.u_hi));
        let tq = Instant::now();
        let warm = z_warm.as_ref().map(|(a, b)| (a.as_slice(), b.as_slice()));
        let qp = solve_box_qp(&ev.stages, &ev.term, &lo, &hi, warm, &set.qp);
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
            let msg = "the filter line search found no acceptable step".to_string();
            return End::new(Status::Stalled, msg, Some(ev), kkt);
        };
        row.step = alpha;
        st.log.push(row);
        st.xs = xt;
        st.us = ut;
        z_warm = Some((qp.z_lo, qp.z_hi));
        st.iterations += 1;
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
    let mut alpha = 1.0;
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
        if let Ok(e) = evaluate(model, prob, &xt, &ut, false) {
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

/// Objective, defects and terminal residual at (xs, us); with `derivatives`, also the
/// Jacobians and the Gauss–Newton QP data.
fn evaluate<M: OcpModel>(
    model: &mut M,
    prob: &OcpProblem,
    xs: &[Vec<f64>],
    us: &[Vec<f64>],
    derivatives: bool,
) -> Result<Eval, ModelError> {
    let (n, nx, nu, nq, nc) = (prob.knots, model.nx(), model.nu(), model.nq(), model.nc());
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
        if derivatives {
            model.jacobians(&xs[k], &us[k], &mut s.a, &mut s.b)?;
            s.q_mat = &prob.q * 2.0;
            s.q_vec = &prob.q * &ev * 2.0;
            s.r_mat = &prob.r * 2.0;
            s.r_vec = &prob.r * &uv * 2.0;
        }
        stages.push(s);
    }
    model.difference(&prob.x_ref, &xs[n], &mut e);
    let ev = DVector::from_column_slice(&e);
    objective += ev.dot(&(&prob.q_n * &ev));
    let mut c = vec![0.0; nc];
    model.terminal(&xs[n], &mut c);
    let c_vec = DVector::from_vec(c);
    infeas1 += c_vec.lp_norm(1);
    infeas_max = infeas_max.max(c_vec.amax());
    let mut c_mat = DMatrix::zeros(nc, nx);
    if derivatives {
        model.terminal_jacobian(&xs[n], &mut c_mat);
    }
    if !objective.is_finite() || !infeas1.is_finite() {
        return Err(ModelError("non-finite objective or residual".into()));
    }
    Ok(Eval {
        stages,
        term: LqTerminal {
            q_mat: &prob.q_n * 2.0,
            q_vec: &prob.q_n * &ev * 2.0,
            c_mat,
            c_vec,
        },
        objective,
        infeas1,
        infeas_max,
    })
}
