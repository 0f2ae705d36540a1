//! The SQP subproblem with box bounds on the controls: a primal-dual interior point
//! (Mehrotra predictor–corrector) whose every Newton system is the equality-constrained LQ
//! problem of [`super::riccati`] with the barrier's diagonal added to `R_k` — HPIPM's
//! approach (Frison & Diehl 2020), with the bounds kept strictly feasible (docs/ocp.md §3).
//!
//! Bounds `lo_k ≤ δu_k ≤ hi_k` (entries may be ±∞: no bound). With slacks
//! `s_lo = δu − lo`, `s_hi = hi − δu` and multipliers `z_lo, z_hi ≥ 0`, the Newton step on
//! `s∘z = τ` gives `Δz_lo = (τ_lo − s_lo z_lo − z_lo Δu)/s_lo`,
//! `Δz_hi = (τ_hi − s_hi z_hi + z_hi Δu)/s_hi`, and `(Δx, Δu, λ⁺, ν⁺)` from the LQ problem with
//! Hessian `R + diag(z_lo/s_lo + z_hi/s_hi)` and gradient `R δu + r − τ_lo/s_lo + τ_hi/s_hi`
//! (`Q δx + q` on the states), dynamics defects zero (the iterate keeps them satisfied) and
//! the terminal residual `C δx_N + c`. The iterate starts at `δu = 0`, which must be strictly
//! inside the bounds, and every step is shortened to stay strictly inside (fraction to the
//! boundary 0.995): no returned control ever violates a bound.
// Stage and component loops read clearest with indices (k: knot, i: component).
#![allow(clippy::needless_range_loop)]

use super::riccati::{
    solve_lq, solve_lq_into, LqError, LqSolution, LqStage, LqTerminal, LqWorkspace,
};
use nalgebra::{DMatrix, DVector};

/// Settings of the interior point.
#[derive(Clone, Copy, Debug)]
pub struct QpSettings {
    /// Stop when the complementarity `max s∘z`, the stationarity and the terminal residual
    /// are all below this.
    pub tolerance: f64,
    /// Most Newton iterations.
    pub max_iterations: usize,
}

impl Default for QpSettings {
    fn default() -> Self {
        Self {
            tolerance: 1e-10,
            max_iterations: 60,
        }
    }
}

/// The solution of the bounded subproblem.
#[derive(Clone, Debug)]
pub struct QpSolution {
    /// `δx_0 … δx_N`.
    pub dx: Vec<DVector<f64>>,
    /// `δu_0 … δu_{N−1}`, strictly inside the bounds.
    pub du: Vec<DVector<f64>>,
    /// Costates `λ_0 … λ_N`.
    pub lam: Vec<DVector<f64>>,
    /// Terminal multiplier ν.
    pub nu: DVector<f64>,
    /// Multipliers of the lower bounds (0 where unbounded).
    pub z_lo: Vec<DVector<f64>>,
    /// Multipliers of the upper bounds.
    pub z_hi: Vec<DVector<f64>>,
    /// The feedback gains `K_k` (nu×nx) of the last Riccati factorisation, barrier
    /// diagonal included (docs/ocp.md §3, eq. (P2)); empty without bounds.
    pub gains: Vec<DMatrix<f64>>,
    /// Newton iterations (Riccati factorisations) used.
    pub iterations: usize,
    /// Whether the tolerance was met (else the last iterate).
    pub converged: bool,
    /// Whether the terminal system was inconsistent (least-squares ν, see
    /// [`super::riccati::LqSolution::least_squares`]); the terminal residual is then not
    /// part of the stopping test.
    pub least_squares: bool,
}

/// Solve the bounded subproblem: `stages`/`term` as in [`solve_lq`], `lo`/`hi` one vector per
/// stage (nu each, `lo < 0 < hi` entrywise), `z0` optional warm-start multipliers.
#[allow(clippy::type_complexity)]
pub fn solve_box_qp(
    stages: &[LqStage],
    term: &LqTerminal,
    lo: &[DVector<f64>],
    hi: &[DVector<f64>],
    z0: Option<(&[DVector<f64>], &[DVector<f64>])>,
    set: &QpSettings,
) -> Result<QpSolution, LqError> {
    let n = stages.len();
    let nu = stages.first().map_or(0, |s| s.b.ncols());
    let nb: usize = lo
        .iter()
        .chain(hi.iter())
        .map(|v| v.iter().filter(|x| x.is_finite()).count())
        .sum();
    if nb == 0 {
        let s = solve_lq(stages, term)?;
        let zeros = vec![DVector::zeros(nu); n];
        return Ok(QpSolution {
            dx: s.dx,
            du: s.du,
            lam: s.lam,
            nu: s.nu,
            z_lo: zeros.clone(),
            z_hi: zeros,
            gains: Vec::new(),
            iterations: 1,
            converged: true,
            least_squares: s.least_squares,
        });
    }
    let nx = term.q_mat.nrows();
    // Iterate: δu = 0 and δx rolled out (dynamics rows satisfied).
    let mut du = vec![DVector::zeros(nu); n];
    let mut dx = vec![DVector::zeros(nx); n + 1];
    for (k, s) in stages.iter().enumerate() {
        dx[k + 1] = &s.a * &dx[k] + &s.d;
    }
    let mut lam = vec![DVector::zeros(nx); n + 1];
    let mut nuv = DVector::zeros(term.c_vec.len());
    let (mut z_lo, mut z_hi) = initial_multipliers(lo, hi, z0);
    let mut work: Vec<LqStage> = stages.to_vec();
    for w in work.iter_mut() {
        w.d.fill(0.0);
    }
    let mut wterm = term.clone();
    let nc = term.c_vec.len();
    let mut lq = LqWorkspace::new(n, nx, nu, nc);
    let mut aff = Direction::zeros(n, nx, nu, nc);
    let mut st = Direction::zeros(n, nx, nu, nc);
    let mut iterations = 0;
    let mut converged = false;
    let mut least_squares = false;
    for _ in 0..set.max_iterations {
        let (mu, comp_max) = complementarity(lo, hi, &du, &z_lo, &z_hi, None);
        let res = residuals(stages, term, &dx, &du, &lam, &nuv, &z_lo, &z_hi);
        if iterations > 0
            && comp_max <= set.tolerance
            && res.0 <= set.tolerance
            && (res.1 <= set.tolerance || least_squares)
        {
            converged = true;
            break;
        }
        iterations += 1;
        barrier_hessian(&mut work, stages, lo, hi, &du, &dx, &z_lo, &z_hi);
        wterm.q_vec.copy_from(&term.q_vec);
        wterm.q_vec.gemv(1.0, &term.q_mat, &dx[n], 1.0);
        wterm.c_vec.copy_from(&term.c_vec);
        wterm.c_vec.gemv(1.0, &term.c_mat, &dx[n], 1.0);
        // Predictor (τ = 0), then corrector (τ = σμ − Δs_aff∘Δz_aff).
        let zero = |_: usize, _: usize, _: bool| 0.0;
        let pt = Point {
            lo,
            hi,
            du: &du,
            dx: &dx,
            z_lo: &z_lo,
            z_hi: &z_hi,
        };
        newton(&mut work, stages, &wterm, &pt, &zero, &mut lq, &mut aff)?;
        let a_aff = step_length(lo, hi, &du, &z_lo, &z_hi, &aff, 1.0);
        let (mu_aff, _) = complementarity(lo, hi, &du, &z_lo, &z_hi, Some((a_aff, &aff)));
        let sigma = (mu_aff / mu).powi(3).clamp(0.0, 1.0);
        let target = |k: usize, i: usize, upper: bool| {
            if upper {
                sigma * mu + aff.sol.du[k][i] * aff.dz_hi[k][i]
            } else {
                sigma * mu - aff.sol.du[k][i] * aff.dz_lo[k][i]
            }
        };
        newton(&mut work, stages, &wterm, &pt, &target, &mut lq, &mut st)?;
        least_squares = st.sol.least_squares;
        let alpha = step_length(lo, hi, &du, &z_lo, &z_hi, &st, 0.995);
        for k in 0..=n {
            dx[k].axpy(alpha, &st.sol.dx[k], 1.0);
            lam[k].axpy(alpha, &st.sol.lam[k], 1.0 - alpha);
        }
        for k in 0..n {
            du[k].axpy(alpha, &st.sol.du[k], 1.0);
            z_lo[k].axpy(alpha, &st.dz_lo[k], 1.0);
            z_hi[k].axpy(alpha, &st.dz_hi[k], 1.0);
        }
        nuv.axpy(alpha, &st.sol.nu, 1.0 - alpha);
    }
    Ok(QpSolution {
        dx,
        du,
        lam,
        nu: nuv,
        z_lo,
        z_hi,
        gains: lq.feedback_gains().to_vec(),
        iterations,
        converged,
        least_squares,
    })
}

/// Starting bound multipliers: the warm start where positive, else `1/s`, in [1e-8, 1e8]
/// (0 where unbounded).
#[allow(clippy::type_complexity)]
fn initial_multipliers(
    lo: &[DVector<f64>],
    hi: &[DVector<f64>],
    z0: Option<(&[DVector<f64>], &[DVector<f64>])>,
) -> (Vec<DVector<f64>>, Vec<DVector<f64>>) {
    let init_z = |s: f64, warm: Option<f64>| -> f64 {
        if !s.is_finite() {
            return 0.0;
        }
        warm.filter(|z| *z > 0.0)
            .unwrap_or(1.0 / s)
            .clamp(1e-8, 1e8)
    };
    let nu = lo.first().map_or(0, |v| v.len());
    let mut z_lo = vec![DVector::zeros(nu); lo.len()];
    let mut z_hi = vec![DVector::zeros(nu); lo.len()];
    for k in 0..lo.len() {
        for i in 0..nu {
            let wl = z0.map(|(l, _)| l[k][i]);
            let wh = z0.map(|(_, h)| h[k][i]);
            z_lo[k][i] = init_z(-lo[k][i], wl);
            z_hi[k][i] = init_z(hi[k][i], wh);
        }
    }
    (z_lo, z_hi)
}

/// (mean, max) of the complementarity products `s∘z` over the finite bounds, at the
/// iterate or, with `Some((α, d))`, at the iterate moved by α along `d`.
fn complementarity(
    lo: &[DVector<f64>],
    hi: &[DVector<f64>],
    du: &[DVector<f64>],
    z_lo: &[DVector<f64>],
    z_hi: &[DVector<f64>],
    step: Option<(f64, &Direction)>,
) -> (f64, f64) {
    let (mut sum, mut max, mut count) = (0.0, 0.0f64, 0usize);
    for k in 0..du.len() {
        for i in 0..du[k].len() {
            let (a, ddu, dzl, dzh) = match step {
                Some((a, d)) => (a, d.sol.du[k][i], d.dz_lo[k][i], d.dz_hi[k][i]),
                None => (0.0, 0.0, 0.0, 0.0),
            };
            let u = du[k][i] + a * ddu;
            if lo[k][i].is_finite() {
                let sz = (u - lo[k][i]) * (z_lo[k][i] + a * dzl);
                sum += sz;
                max = max.max(sz);
                count += 1;
            }
            if hi[k][i].is_finite() {
                let sz = (hi[k][i] - u) * (z_hi[k][i] + a * dzh);
                sum += sz;
                max = max.max(sz);
                count += 1;
            }
        }
    }
    (sum / count.max(1) as f64, max)
}

/// The step problem's Hessian `R + diag(z_lo/s_lo + z_hi/s_hi)` and state gradient
/// `Q δx + q` at the iterate.
#[allow(clippy::too_many_arguments)]
fn barrier_hessian(
    work: &mut [LqStage],
    stages: &[LqStage],
    lo: &[DVector<f64>],
    hi: &[DVector<f64>],
    du: &[DVector<f64>],
    dx: &[DVector<f64>],
    z_lo: &[DVector<f64>],
    z_hi: &[DVector<f64>],
) {
    for (k, (w, s)) in work.iter_mut().zip(stages).enumerate() {
        w.r_mat.copy_from(&s.r_mat);
        for i in 0..du[k].len() {
            let mut sig = 0.0;
            if lo[k][i].is_finite() {
                sig += z_lo[k][i] / (du[k][i] - lo[k][i]);
            }
            if hi[k][i].is_finite() {
                sig += z_hi[k][i] / (hi[k][i] - du[k][i]);
            }
            w.r_mat[(i, i)] += sig;
        }
        w.q_vec.copy_from(&s.q_vec);
        w.q_vec.gemv(1.0, &s.q_mat, &dx[k], 1.0);
        w.q_vec.gemv_tr(1.0, &s.s_mat, &du[k], 1.0);
    }
}

/// A Newton direction of the interior point (preallocated, filled by [`newton`]).
struct Direction {
    sol: LqSolution,
    dz_lo: Vec<DVector<f64>>,
    dz_hi: Vec<DVector<f64>>,
}

impl Direction {
    fn zeros(n: usize, nx: usize, nu: usize, nc: usize) -> Self {
        Self {
            sol: LqSolution::zeros(n, nx, nu, nc),
            dz_lo: vec![DVector::zeros(nu); n],
            dz_hi: vec![DVector::zeros(nu); n],
        }
    }
}

/// The interior point's iterate: bounds, controls and states of the step, multipliers.
struct Point<'a> {
    lo: &'a [DVector<f64>],
    hi: &'a [DVector<f64>],
    du: &'a [DVector<f64>],
    dx: &'a [DVector<f64>],
    z_lo: &'a [DVector<f64>],
    z_hi: &'a [DVector<f64>],
}

/// One Newton direction for complementarity targets `tau(k, i, upper)` into `out`
/// (allocation-free: the Riccati storage `lq` is reused).
fn newton(
    work: &mut [LqStage],
    stages: &[LqStage],
    wterm: &LqTerminal,
    pt: &Point,
    tau: &dyn Fn(usize, usize, bool) -> f64,
    lq: &mut LqWorkspace,
    out: &mut Direction,
) -> Result<(), LqError> {
    let (lo, hi, du) = (pt.lo, pt.hi, pt.du);
    let nu = du.first().map_or(0, |v| v.len());
    for (k, (w, s)) in work.iter_mut().zip(stages).enumerate() {
        w.r_vec.copy_from(&s.r_vec);
        w.r_vec.gemv(1.0, &s.r_mat, &du[k], 1.0);
        w.r_vec.gemv(1.0, &s.s_mat, &pt.dx[k], 1.0);
        for i in 0..nu {
            if lo[k][i].is_finite() {
                w.r_vec[i] -= tau(k, i, false) / (du[k][i] - lo[k][i]);
            }
            if hi[k][i].is_finite() {
                w.r_vec[i] += tau(k, i, true) / (hi[k][i] - du[k][i]);
            }
        }
    }
    solve_lq_into(work, wterm, lq, &mut out.sol)?;
    for k in 0..du.len() {
        for i in 0..nu {
            let d = out.sol.du[k][i];
            out.dz_lo[k][i] = 0.0;
            out.dz_hi[k][i] = 0.0;
            if lo[k][i].is_finite() {
                let s = du[k][i] - lo[k][i];
                out.dz_lo[k][i] = (tau(k, i, false) - s * pt.z_lo[k][i] - pt.z_lo[k][i] * d) / s;
            }
            if hi[k][i].is_finite() {
                let s = hi[k][i] - du[k][i];
                out.dz_hi[k][i] = (tau(k, i, true) - s * pt.z_hi[k][i] + pt.z_hi[k][i] * d) / s;
            }
        }
    }
    Ok(())
}

/// The largest step in (0, 1] keeping slacks and multipliers at least `(1 − frac)` of their
/// current values (`frac` = 1: to the boundary).
fn step_length(
    lo: &[DVector<f64>],
    hi: &[DVector<f64>],
    du: &[DVector<f64>],
    z_lo: &[DVector<f64>],
    z_hi: &[DVector<f64>],
    d: &Direction,
    frac: f64,
) -> f64 {
    let mut a: f64 = 1.0;
    let mut limit = |v: f64, dv: f64| {
        if dv < 0.0 {
            a = a.min(-frac * v / dv);
        }
    };
    for k in 0..du.len() {
        for i in 0..du[k].len() {
            if lo[k][i].is_finite() {
                limit(du[k][i] - lo[k][i], d.sol.du[k][i]);
                limit(z_lo[k][i], d.dz_lo[k][i]);
            }
            if hi[k][i].is_finite() {
                limit(hi[k][i] - du[k][i], -d.sol.du[k][i]);
                limit(z_hi[k][i], d.dz_hi[k][i]);
            }
        }
    }
    a
}

/// (stationarity ∞-norm, terminal residual ∞-norm) of the bounded subproblem at an iterate.
#[allow(clippy::too_many_arguments)]
pub(crate) fn residuals(
    stages: &[LqStage],
    term: &LqTerminal,
    dx: &[DVector<f64>],
    du: &[DVector<f64>],
    lam: &[DVector<f64>],
    nu: &DVector<f64>,
    z_lo: &[DVector<f64>],
    z_hi: &[DVector<f64>],
) -> (f64, f64) {
    let n = stages.len();
    let nx = term.q_mat.nrows();
    let n_u = stages.first().map_or(0, |s| s.b.ncols());
    let (mut gu, mut gx) = (DVector::zeros(n_u), DVector::zeros(nx));
    let mut stat: f64 = 0.0;
    for (k, s) in stages.iter().enumerate() {
        gu.copy_from(&s.r_vec);
        gu.gemv(1.0, &s.r_mat, &du[k], 1.0);
        gu.gemv(1.0, &s.s_mat, &dx[k], 1.0);
        gu.gemv_tr(1.0, &s.b, &lam[k + 1], 1.0);
        gu -= &z_lo[k];
        gu += &z_hi[k];
        stat = stat.max(gu.amax());
        if k > 0 {
            gx.copy_from(&s.q_vec);
            gx.gemv(1.0, &s.q_mat, &dx[k], 1.0);
            gx.gemv_tr(1.0, &s.s_mat, &du[k], 1.0);
            gx.gemv_tr(1.0, &s.a, &lam[k + 1], 1.0);
            gx -= &lam[k];
            stat = stat.max(gx.amax());
        }
    }
    gx.copy_from(&term.q_vec);
    gx.gemv(1.0, &term.q_mat, &dx[n], 1.0);
    gx.gemv_tr(1.0, &term.c_mat, nu, 1.0);
    gx -= &lam[n];
    stat = stat.max(gx.amax());
    let mut cres = term.c_vec.clone();
    cres.gemv(1.0, &term.c_mat, &dx[n], 1.0);
    let cres = cres.amax();
    (stat, cres)
}
