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
//! `C Ξ_N ν = −(C ξ_N + c)` (LU with full pivoting; rank-deficient means the terminal
//! constraint is not reachable by the linearised dynamics: [`LqError::Unreachable`]). The
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
}

/// Why the subproblem has no solution.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LqError {
    /// `R_k + B_kᵀ P_{k+1} B_k` is not positive definite at stage `k`.
    #[error("reduced Hessian of stage {0} is not positive definite")]
    NotConvex(usize),
    /// The linearised dynamics cannot reach the terminal constraint (`C Ξ_N` singular).
    #[error("terminal constraint not reachable by the linearised dynamics (rank {rank} of {nc})")]
    Unreachable {
        /// Numerical rank of `C Ξ_N`.
        rank: usize,
        /// Number of terminal equalities.
        nc: usize,
    },
}

/// Solve the subproblem (see the module documentation). `stages` has N ≥ 1 entries of
/// consistent sizes.
pub fn solve_lq(stages: &[LqStage], term: &LqTerminal) -> Result<LqSolution, LqError> {
    let n = stages.len();
    let nx = term.q_mat.nrows();
    let nc = term.c_vec.len();
    // Backward pass.
    let mut p_mat = term.q_mat.clone();
    let mut p_vec = term.q_vec.clone();
    let mut gamma = term.c_mat.transpose();
    let mut gains: Vec<(DMatrix<f64>, DVector<f64>, DMatrix<f64>)> = Vec::with_capacity(n);
    let mut vals: Vec<(DMatrix<f64>, DVector<f64>, DMatrix<f64>)> = Vec::with_capacity(n + 1);
    vals.push((p_mat.clone(), p_vec.clone(), gamma.clone()));
    for (k, s) in stages.iter().enumerate().rev() {
        let pb = &p_mat * &s.b;
        let mut h = &s.r_mat + s.b.transpose() * &pb;
        h = (&h + h.transpose()) * 0.5;
        let hux = pb.transpose() * &s.a + &s.s_mat; // S + BᵀPA (nu×nx)
        let pd_p = &p_mat * &s.d + &p_vec;
        let hu = &s.r_vec + s.b.transpose() * &pd_p;
        let hun = s.b.transpose() * &gamma;
        let chol = h.cholesky().ok_or(LqError::NotConvex(k))?;
        let kfb = -chol.solve(&hux);
        let kff = -chol.solve(&hu);
        let kn = -chol.solve(&hun);
        let at = s.a.transpose();
        let hxu = hux.transpose();
        let mut p_new = &s.q_mat + &at * &p_mat * &s.a + &hxu * &kfb;
        p_new = (&p_new + p_new.transpose()) * 0.5;
        p_vec = &s.q_vec + &at * &pd_p + &hxu * &kff;
        gamma = &at * &gamma + &hxu * &kn;
        p_mat = p_new;
        gains.push((kfb, kff, kn));
        vals.push((p_mat.clone(), p_vec.clone(), gamma.clone()));
    }
    gains.reverse();
    vals.reverse();
    // Forward pass, affine in ν: δx_k = ξ_k + Ξ_k ν.
    let nu_dim = stages.first().map_or(0, |s| s.b.ncols());
    let mut xi = vec![DVector::zeros(nx); n + 1];
    let mut big_xi = vec![DMatrix::zeros(nx, nc); n + 1];
    for (k, s) in stages.iter().enumerate() {
        let (kfb, kff, kn) = &gains[k];
        let u0 = kfb * &xi[k] + kff;
        let u1 = kfb * &big_xi[k] + kn;
        xi[k + 1] = &s.a * &xi[k] + &s.b * u0 + &s.d;
        big_xi[k + 1] = &s.a * &big_xi[k] + &s.b * u1;
    }
    let nu = if nc == 0 {
        DVector::zeros(0)
    } else {
        let lhs = &term.c_mat * &big_xi[n];
        let rhs = -(&term.c_mat * &xi[n] + &term.c_vec);
        let lu = lhs.clone().full_piv_lu();
        let scale = lhs.amax().max(f64::MIN_POSITIVE);
        let u = lu.u();
        let rank = (0..nc).filter(|&i| u[(i, i)].abs() > 1e-13 * scale).count();
        if rank < nc {
            return Err(LqError::Unreachable { rank, nc });
        }
        lu.solve(&rhs).ok_or(LqError::Unreachable { rank, nc })?
    };
    let mut dx = Vec::with_capacity(n + 1);
    let mut du = Vec::with_capacity(n);
    let mut lam = Vec::with_capacity(n + 1);
    for k in 0..=n {
        let x = &xi[k] + &big_xi[k] * &nu;
        let (pm, pv, g) = &vals[k];
        lam.push(pm * &x + pv + g * &nu);
        if k < n {
            let (kfb, kff, kn) = &gains[k];
            du.push(kfb * &x + kff + kn * &nu);
        }
        dx.push(x);
    }
    debug_assert!(du.iter().all(|u| u.len() == nu_dim));
    Ok(LqSolution { dx, du, lam, nu })
}
