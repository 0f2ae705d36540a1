//! The equality-constrained linear-quadratic subproblem of every Newton step, solved by a
//! Riccati recursion with a parametric terminal multiplier (docs/ocp.md §3).
//!
//! ```text
//! min  Σ_{k<N} ½ δu_kᵀ R_k δu_k + r_kᵀ δu_k + ½ δx_kᵀ Q_k δx_k + q_kᵀ δx_k + δu_kᵀ S_k δx_k
//!      + ½ δx_Nᵀ Q_N δx_N + q_Nᵀ δx_N
//! s.t. δx_0 = 0,   δx_{k+1} = A_k δx_k + B_k δu_k + d_k,   C δx_N + c = 0
//! ```
//!
//! The value function is `V_k(δx) = ½ δxᵀ P_k δx + (p_k + Γ_k ν)ᵀ δx + const`, affine in the
//! terminal multiplier ν (nc): `P_N = Q_N`, `p_N = q_N`, `Γ_N = Cᵀ`, and backwards
//! `H = R + BᵀPB` (Cholesky), `G = S + BᵀPA`, `K = −H⁻¹G`, `k = −H⁻¹(r + Bᵀ(P d + p))`,
//! `K_ν = −H⁻¹BᵀΓ`, `P ← Q + AᵀPA + GᵀK`, `p ← q + Aᵀ(P d + p) + Gᵀk`, `Γ ← AᵀΓ + GᵀK_ν`.
//! The forward pass gives `δx_N = ξ_N + Ξ_N ν`, and the terminal equality the nc×nc system
//! `C Ξ_N ν = −(C ξ_N + c)` (LU with full pivoting; when rank-deficient, the minimum-norm
//! least-squares solution by SVD — when the system is inconsistent, the terminal constraint
//! is not reachable by the linearised dynamics and the step meets only its reachable part:
//! [`LqSolution::least_squares`]). The
//! costates are `λ_k = P_k δx_k + p_k + Γ_k ν` (multipliers of the dynamics rows, with the
//! Lagrangian `… + λ_{k+1}ᵀ(A δx + B δu + d − δx_{k+1})`). Cost O(N (nx + nc)³).
// Stage and component loops read clearest with indices (k: knot, i: component).
#![allow(clippy::needless_range_loop)]

use nalgebra::{DMatrix, DVector};

/// One stage `k < N` of the subproblem (sizes nx, nu).
#[derive(Clone, Debug)]
pub struct LqStage {
    /// `A_k` (nx×nx): ∂x_{k+1}/∂x_k in tangent coordinates.
    pub a: DMatrix<f64>,
    /// `B_k` (nx×nu): ∂x_{k+1}/∂u_k.
    pub b: DMatrix<f64>,
    /// Defect `d_k` (nx).
    pub d: DVector<f64>,
    /// State Hessian `Q_k` (nx×nx, symmetric positive semidefinite).
    pub q_mat: DMatrix<f64>,
    /// State gradient `q_k` (nx).
    pub q_vec: DVector<f64>,
    /// Control Hessian `R_k` (nu×nu, symmetric positive definite together with `BᵀPB`).
    pub r_mat: DMatrix<f64>,
    /// Cross Hessian `S_k = ∂²/∂u∂x` (nu×nx; zero for the Gauss–Newton Hessian).
    pub s_mat: DMatrix<f64>,
    /// Control gradient `r_k` (nu).
    pub r_vec: DVector<f64>,
}

impl LqStage {
    /// A stage of zeros (sizes nx, nu).
    pub fn zeros(nx: usize, nu: usize) -> Self {
        Self {
            a: DMatrix::zeros(nx, nx),
            b: DMatrix::zeros(nx, nu),
            d: DVector::zeros(nx),
            q_mat: DMatrix::zeros(nx, nx),
            q_vec: DVector::zeros(nx),
            r_mat: DMatrix::zeros(nu, nu),
            s_mat: DMatrix::zeros(nu, nx),
            r_vec: DVector::zeros(nu),
        }
    }
}

/// The terminal stage: cost `½ δxᵀ Q_N δx + q_Nᵀ δx` and the equality `C δx + c = 0` (nc rows,
/// nc may be 0).
#[derive(Clone, Debug)]
pub struct LqTerminal {
    /// `Q_N` (nx×nx).
    pub q_mat: DMatrix<f64>,
    /// `q_N` (nx).
    pub q_vec: DVector<f64>,
    /// `C` (nc×nx).
    pub c_mat: DMatrix<f64>,
    /// `c` (nc).
    pub c_vec: DVector<f64>,
}

/// The solution of the subproblem.
#[derive(Clone, Debug)]
pub struct LqSolution {
    /// `δx_0 … δx_N`.
    pub dx: Vec<DVector<f64>>,
    /// `δu_0 … δu_{N−1}`.
    pub du: Vec<DVector<f64>>,
    /// Costates `λ_0 … λ_N` (multipliers of `δx_0 = 0` and of the dynamics rows).
    pub lam: Vec<DVector<f64>>,
    /// Terminal multiplier ν (nc).
    pub nu: DVector<f64>,
    /// Whether `C Ξ_N ν = −(C ξ_N + c)` was inconsistent and ν is its least-squares
    /// (minimum-norm) solution: the step then meets the terminal rows the linearised dynamics
    /// can move and leaves the others (a singular configuration; the SQP reports
    /// `infeasible` if it ends unconverged after such a step).
    pub least_squares: bool,
}

/// Why the subproblem has no solution.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LqError {
    /// `R_k + B_kᵀ P_{k+1} B_k` is not positive definite at stage `k`.
    #[error("reduced Hessian of stage {0} is not positive definite")]
    NotConvex(usize),
    /// The linearised dynamics cannot reach the terminal constraint (`C Ξ_N ν = −(C ξ_N + c)`
    /// inconsistent).
    #[error("terminal constraint not reachable by the linearised dynamics (rank {rank} of {nc})")]
    Unreachable {
        /// Numerical rank of `C Ξ_N`.
        rank: usize,
        /// Number of terminal equalities.
        nc: usize,
    },
}

/// Preallocated storage of [`solve_lq_into`] for one size (N, nx, nu, nc): the gains, the
/// value functions, the affine forward pass and the per-stage temporaries, so that the
/// recursion allocates nothing (only the nc×nc terminal system's LU does, once per solve).
#[derive(Clone, Debug)]
pub struct LqWorkspace {
    kfb: Vec<DMatrix<f64>>,
    kff: Vec<DVector<f64>>,
    kn: Vec<DMatrix<f64>>,
    p_mat: Vec<DMatrix<f64>>,
    p_vec: Vec<DVector<f64>>,
    gamma: Vec<DMatrix<f64>>,
    xi: Vec<DVector<f64>>,
    big_xi: Vec<DMatrix<f64>>,
    pb: DMatrix<f64>,
    pa: DMatrix<f64>,
    h: DMatrix<f64>,
    g: DMatrix<f64>,
    pd_p: DVector<f64>,
    u0: DVector<f64>,
    u1: DMatrix<f64>,
    x: DVector<f64>,
}

impl LqWorkspace {
    /// The feedback gains `K_k` of the last solve (`δu_k = K_k δx_k + k_k + K^ν_k ν`):
    /// the trial rollout of the SQP's line search (docs/ocp.md §3, eq. (P2)).
    pub fn feedback_gains(&self) -> &[DMatrix<f64>] {
        &self.kfb
    }

    /// Storage for N stages of sizes nx, nu and nc terminal rows.
    pub fn new(n: usize, nx: usize, nu: usize, nc: usize) -> Self {
        Self {
            kfb: vec![DMatrix::zeros(nu, nx); n],
            kff: vec![DVector::zeros(nu); n],
            kn: vec![DMatrix::zeros(nu, nc); n],
            p_mat: vec![DMatrix::zeros(nx, nx); n + 1],
            p_vec: vec![DVector::zeros(nx); n + 1],
            gamma: vec![DMatrix::zeros(nx, nc); n + 1],
            xi: vec![DVector::zeros(nx); n + 1],
            big_xi: vec![DMatrix::zeros(nx, nc); n + 1],
            pb: DMatrix::zeros(nx, nu),
            pa: DMatrix::zeros(nx, nx),
            h: DMatrix::zeros(nu, nu),
            g: DMatrix::zeros(nu, nx),
            pd_p: DVector::zeros(nx),
            u0: DVector::zeros(nu),
            u1: DMatrix::zeros(nu, nc),
            x: DVector::zeros(nx),
        }
    }
}

impl LqSolution {
    /// A solution of zeros for N stages of sizes nx, nu and nc terminal rows.
    pub fn zeros(n: usize, nx: usize, nu: usize, nc: usize) -> Self {
        Self {
            dx: vec![DVector::zeros(nx); n + 1],
            du: vec![DVector::zeros(nu); n],
            lam: vec![DVector::zeros(nx); n + 1],
            nu: DVector::zeros(nc),
            least_squares: false,
        }
    }
}

/// In-place Cholesky factorisation `H = L Lᵀ` (L in the lower triangle of `h`); false if
/// `h` is not numerically positive definite.
fn cholesky_in_place(h: &mut DMatrix<f64>) -> bool {
    let m = h.nrows();
    for j in 0..m {
        let mut d = h[(j, j)];
        for k in 0..j {
            d -= h[(j, k)] * h[(j, k)];
        }
        if d.is_nan() || d <= 0.0 {
            return false;
        }
        let d = d.sqrt();
        h[(j, j)] = d;
        for i in j + 1..m {
            let mut v = h[(i, j)];
            for k in 0..j {
                v -= h[(i, k)] * h[(j, k)];
            }
            h[(i, j)] = v / d;
        }
    }
    true
}

/// `b ← −(L Lᵀ)⁻¹ b` for each column of `b` (L from [`cholesky_in_place`]).
fn cholesky_neg_solve(l: &DMatrix<f64>, b: &mut [f64]) {
    let m = l.nrows();
    for col in b.chunks_mut(m.max(1)) {
        for i in 0..m {
            let mut v = col[i];
            for k in 0..i {
                v -= l[(i, k)] * col[k];
            }
            col[i] = v / l[(i, i)];
        }
        for i in (0..m).rev() {
            let mut v = col[i];
            for k in i + 1..m {
                v -= l[(k, i)] * col[k];
            }
            col[i] = v / l[(i, i)];
        }
        for v in col.iter_mut() {
            *v = -*v;
        }
    }
}

/// `m ← (m + mᵀ)/2` in place.
fn symmetrise(m: &mut DMatrix<f64>) {
    for i in 0..m.nrows() {
        for j in i + 1..m.ncols() {
            let v = 0.5 * (m[(i, j)] + m[(j, i)]);
            m[(i, j)] = v;
            m[(j, i)] = v;
        }
    }
}

/// Solve the subproblem (see the module documentation), allocating its storage.
pub fn solve_lq(stages: &[LqStage], term: &LqTerminal) -> Result<LqSolution, LqError> {
    let n = stages.len();
    let nx = term.q_mat.nrows();
    let nu = stages.first().map_or(0, |s| s.b.ncols());
    let nc = term.c_vec.len();
    let mut ws = LqWorkspace::new(n, nx, nu, nc);
    let mut out = LqSolution::zeros(n, nx, nu, nc);
    solve_lq_into(stages, term, &mut ws, &mut out)?;
    Ok(out)
}

/// Solve the subproblem into `out` with the storage `ws` (both sized for `stages` and
/// `term`, [`LqWorkspace::new`], [`LqSolution::zeros`]); the backward and forward passes
/// allocate nothing.
pub fn solve_lq_into(
    stages: &[LqStage],
    term: &LqTerminal,
    ws: &mut LqWorkspace,
    out: &mut LqSolution,
) -> Result<(), LqError> {
    let n = stages.len();
    let nc = term.c_vec.len();
    // Backward pass.
    ws.p_mat[n].copy_from(&term.q_mat);
    ws.p_vec[n].copy_from(&term.q_vec);
    ws.gamma[n].tr_copy_from(&term.c_mat);
    for (k, s) in stages.iter().enumerate().rev() {
        let (pm_lo, pm_hi) = ws.p_mat.split_at_mut(k + 1);
        let (pv_lo, pv_hi) = ws.p_vec.split_at_mut(k + 1);
        let (gm_lo, gm_hi) = ws.gamma.split_at_mut(k + 1);
        let (p_next, pv_next, g_next) = (&pm_hi[0], &pv_hi[0], &gm_hi[0]);
        ws.pb.gemm(1.0, p_next, &s.b, 0.0);
        ws.h.copy_from(&s.r_mat);
        ws.h.gemm_tr(1.0, &s.b, &ws.pb, 1.0);
        symmetrise(&mut ws.h);
        ws.g.copy_from(&s.s_mat);
        ws.g.gemm_tr(1.0, &ws.pb, &s.a, 1.0); // S + BᵀPA
        ws.pd_p.copy_from(pv_next);
        ws.pd_p.gemv(1.0, p_next, &s.d, 1.0);
        let (kfb, kff, kn) = (&mut ws.kfb[k], &mut ws.kff[k], &mut ws.kn[k]);
        kff.copy_from(&s.r_vec);
        kff.gemv_tr(1.0, &s.b, &ws.pd_p, 1.0);
        kn.gemm_tr(1.0, &s.b, g_next, 0.0);
        kfb.copy_from(&ws.g);
        if !cholesky_in_place(&mut ws.h) {
            return Err(LqError::NotConvex(k));
        }
        cholesky_neg_solve(&ws.h, kfb.as_mut_slice());
        cholesky_neg_solve(&ws.h, kff.as_mut_slice());
        cholesky_neg_solve(&ws.h, kn.as_mut_slice());
        ws.pa.gemm(1.0, p_next, &s.a, 0.0);
        let p_k = &mut pm_lo[k];
        p_k.copy_from(&s.q_mat);
        p_k.gemm_tr(1.0, &s.a, &ws.pa, 1.0);
        p_k.gemm_tr(1.0, &ws.g, kfb, 1.0);
        symmetrise(p_k);
        let pv_k = &mut pv_lo[k];
        pv_k.copy_from(&s.q_vec);
        pv_k.gemv_tr(1.0, &s.a, &ws.pd_p, 1.0);
        pv_k.gemv_tr(1.0, &ws.g, kff, 1.0);
        let g_k = &mut gm_lo[k];
        g_k.gemm_tr(1.0, &s.a, g_next, 0.0);
        g_k.gemm_tr(1.0, &ws.g, kn, 1.0);
    }
    // Forward pass, affine in ν: δx_k = ξ_k + Ξ_k ν.
    ws.xi[0].fill(0.0);
    ws.big_xi[0].fill(0.0);
    for (k, s) in stages.iter().enumerate() {
        let (xi_lo, xi_hi) = ws.xi.split_at_mut(k + 1);
        let (bx_lo, bx_hi) = ws.big_xi.split_at_mut(k + 1);
        ws.u0.copy_from(&ws.kff[k]);
        ws.u0.gemv(1.0, &ws.kfb[k], &xi_lo[k], 1.0);
        ws.u1.copy_from(&ws.kn[k]);
        ws.u1.gemm(1.0, &ws.kfb[k], &bx_lo[k], 1.0);
        xi_hi[0].copy_from(&s.d);
        xi_hi[0].gemv(1.0, &s.a, &xi_lo[k], 1.0);
        xi_hi[0].gemv(1.0, &s.b, &ws.u0, 1.0);
        bx_hi[0].gemm(1.0, &s.a, &bx_lo[k], 0.0);
        bx_hi[0].gemm(1.0, &s.b, &ws.u1, 1.0);
    }
    out.least_squares = false;
    if nc == 0 {
        out.nu.fill(0.0);
    } else {
        let lhs = &term.c_mat * &ws.big_xi[n];
        let rhs = -(&term.c_mat * &ws.xi[n] + &term.c_vec);
        let (nu, ls) = terminal_multiplier(lhs, &rhs)?;
        out.nu.copy_from(&nu);
        out.least_squares = ls;
    }
    for k in 0..=n {
        ws.x.copy_from(&ws.xi[k]);
        ws.x.gemv(1.0, &ws.big_xi[k], &out.nu, 1.0);
        let lam = &mut out.lam[k];
        lam.copy_from(&ws.p_vec[k]);
        lam.gemv(1.0, &ws.p_mat[k], &ws.x, 1.0);
        lam.gemv(1.0, &ws.gamma[k], &out.nu, 1.0);
        if k < n {
            let du = &mut out.du[k];
            du.copy_from(&ws.kff[k]);
            du.gemv(1.0, &ws.kfb[k], &ws.x, 1.0);
            du.gemv(1.0, &ws.kn[k], &out.nu, 1.0);
        }
        out.dx[k].copy_from(&ws.x);
    }
    Ok(())
}

/// ν from `C Ξ_N ν = rhs`: LU with full pivoting when `C Ξ_N` has full rank; otherwise the
/// minimum-norm least-squares solution by SVD (singular values below 1e-12 of the largest
/// dropped), flagged (`true`) when the system is inconsistent — a terminal row the
/// linearised dynamics cannot move and that is not met (a singular configuration, e.g. the
/// straight body asked to shorten). [`LqError::Unreachable`] only when the SVD fails or
/// gives non-finite values.
fn terminal_multiplier(
    lhs: DMatrix<f64>,
    rhs: &DVector<f64>,
) -> Result<(DVector<f64>, bool), LqError> {
    let nc = rhs.len();
    let scale = lhs.amax().max(f64::MIN_POSITIVE);
    let lu = lhs.clone().full_piv_lu();
    let u = lu.u();
    let rank = (0..nc).filter(|&i| u[(i, i)].abs() > 1e-13 * scale).count();
    if rank == nc {
        if let Some(nu) = lu.solve(rhs) {
            return Ok((nu, false));
        }
    }
    let svd = lhs.clone().svd(true, true);
    let smax = svd.singular_values.max().max(f64::MIN_POSITIVE);
    let nu = svd
        .solve(rhs, 1e-12 * smax)
        .map_err(|_| LqError::Unreachable { rank, nc })?;
    let resid = (&lhs * &nu - rhs).amax();
    if !resid.is_finite() || nu.iter().any(|v| !v.is_finite()) {
        return Err(LqError::Unreachable { rank, nc });
    }
    Ok((nu, resid > 1e-6 * (1.0 + rhs.amax())))
}
