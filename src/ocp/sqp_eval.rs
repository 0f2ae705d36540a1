//! The SQP's evaluation of an iterate (docs/ocp.md §3): objective, multiple-shooting
//! defects, terminal residual and, with derivatives, the QP data (Jacobians, Gauss–Newton or
//! Lagrangian Hessian, path costs), and the KKT residuals with the QP's multipliers.
// Stage and component loops read clearest with indices (k: knot, i: component).
#![allow(clippy::needless_range_loop)]

use super::cost::add_path_cost;
use super::model::{ModelError, OcpModel};
use super::qp::{residuals, QpSolution};
use super::riccati::{LqStage, LqTerminal};
use nalgebra::{DMatrix, DVector};
use std::time::Instant;

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

/// Everything evaluated at one iterate.
pub(super) struct Eval {
    pub(super) stages: Vec<LqStage>,
    pub(super) term: LqTerminal,
    pub(super) objective: f64,
    /// Σ‖d_k‖₁ + ‖c‖₁.
    pub(super) infeas1: f64,
    /// max ‖d_k‖∞, ‖c‖∞.
    pub(super) infeas_max: f64,
    /// Time spent on the Lagrangian Hessians [s].
    pub(super) hessian_time: f64,
}

/// KKT residuals (primal, stationarity, complementarity) at the current iterate with the
/// QP's multipliers.
pub(super) fn kkt_residuals(
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

/// Multiplier estimates (λ_0 … λ_N, ν) weighting the dynamics' and terminal curvature.
pub(super) type Multipliers<'a> = (&'a [DVector<f64>], &'a DVector<f64>);

/// Objective, defects and terminal residual at (xs, us); with `derivatives = Some(m)`, also
/// the Jacobians and the QP data: the Gauss–Newton Hessian, plus the Lagrangian's curvature
/// when `m` holds multipliers.
pub(super) fn evaluate<M: OcpModel>(
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

/// Scratch of [`feedback_rollout`]: a tangent increment, a state, a state difference.
pub(super) type RolloutScratch = (Vec<f64>, Vec<f64>, Vec<f64>);

/// The trial point of step length `alpha` by the feedback rollout (docs/ocp.md §3, eq. (P2)):
/// `x̂_0 = x_0`, `û_k = u_k + α δu_k + K_k (x̂_k ⊖ (x_k ⊕ α δx_k))` (strictly inside the
/// bounds), `x̂_{k+1} = f(x̂_k, û_k)` — the QP's Riccati gains keep the rollout of an
/// unstable system near the linearised step; every defect of the trial point is zero.
#[allow(clippy::too_many_arguments)]
pub(super) fn feedback_rollout<M: OcpModel>(
    model: &mut M,
    prob: &OcpProblem,
    xs: &[Vec<f64>],
    us: &[Vec<f64>],
    qp: &QpSolution,
    alpha: f64,
    xt: &mut [Vec<f64>],
    ut: &mut [Vec<f64>],
    scratch: &mut RolloutScratch,
) -> Result<(), ModelError> {
    let (n, nu, nx) = (prob.knots, model.nu(), model.nx());
    let (dxk, xbar, e) = scratch;
    xt[0].copy_from_slice(&xs[0]);
    for k in 0..n {
        for (d, v) in dxk.iter_mut().zip(qp.dx[k].iter()) {
            *d = alpha * v;
        }
        model.retract(&xs[k], dxk, xbar);
        model.difference(xbar, &xt[k], e);
        let g = &qp.gains[k];
        for i in 0..nu {
            let mut v = us[k][i] + alpha * qp.du[k][i];
            for j in 0..nx {
                v += g[(i, j)] * e[j];
            }
            ut[k][i] = strictly_inside(v, prob.u_lo[i], prob.u_hi[i]);
        }
        let (a, b) = xt.split_at_mut(k + 1);
        model.step(&a[k], &ut[k], &mut b[0])?;
        if b[0].iter().any(|v| !v.is_finite()) {
            return Err(ModelError(format!("non-finite state at knot {}", k + 1)));
        }
    }
    Ok(())
}

/// `v` moved strictly inside `[lo, hi]` (by 1e-3 of the width, or 1e-3 from a one-sided bound).
pub(super) fn strictly_inside(v: f64, lo: f64, hi: f64) -> f64 {
    let margin = if lo.is_finite() && hi.is_finite() {
        1e-3 * (hi - lo)
    } else {
        1e-3
    };
    v.max(lo + margin).min(hi - margin)
}
