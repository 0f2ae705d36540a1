//! Attainable wrench along the base axes under thrust limits (docs/model.md §6, TCM singularity metric).
//!
//! For each base axis `k` and sign `±`, the linear programme
//! `max α` s.t. `T u = ±α e_k`, `u_min ≤ u ≤ u_max` gives the largest pure force (k = 0..2, N) or
//! moment (k = 3..5, N·m) the thrusters can produce along `±e_k` without any other wrench
//! component. Solved with Clarabel, one solver for all twelve programmes (only the `α` column of
//! `A` changes, updated in place).

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use nalgebra::Matrix6xX;
use serde::Serialize;

use super::conic::clarabel_settings;
use super::error::{check_bounds, check_t, AllocError};

/// Largest pure wrench along each base axis (docs/model.md §6). Index order surge, sway, heave (N), roll,
/// pitch, yaw (N·m), base frame. `NaN` (serialised as `null`) where the programme failed or is
/// infeasible (possible only when `u = 0` violates the bounds).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AttainableWrench {
    /// `max α ≥ 0` with `T u = +α e_k`.
    pub positive: [f64; 6],
    /// `max α ≥ 0` with `T u = −α e_k` (a magnitude).
    pub negative: [f64; 6],
}

/// Attainable wrench along `±e_k`, k = 0..5, for `T` (6×n_thrusters, base frame, N and N·m per N of
/// thrust) and bounds `u_min ≤ u ≤ u_max` (N) (docs/model.md §6). Errors only on bad input.
pub fn attainable_wrench(
    t: &Matrix6xX<f64>,
    u_min: &[f64],
    u_max: &[f64],
) -> Result<AttainableWrench, AllocError> {
    check_t(t, None)?;
    let n_thrusters = t.ncols();
    check_bounds(u_min, u_max, n_thrusters)?;

    // x = [u (n_thrusters); α], rows: 6 equalities [T, −d] x = 0, then 2·n_thrusters box rows.
    let n = n_thrusters + 1;
    let rows = 6 + 2 * n_thrusters;
    let mut colptr = Vec::with_capacity(n + 1);
    let mut rowval = Vec::new();
    let mut nz = Vec::new();
    for j in 0..n_thrusters {
        colptr.push(rowval.len());
        for i in 0..6 {
            rowval.push(i);
            nz.push(t[(i, j)]);
        }
        rowval.push(6 + j);
        nz.push(1.0);
        rowval.push(6 + n_thrusters + j);
        nz.push(-1.0);
    }
    colptr.push(rowval.len());
    let alpha_start = nz.len();
    for i in 0..6 {
        rowval.push(i);
        nz.push(if i == 0 { -1.0 } else { 0.0 });
    }
    colptr.push(rowval.len());
    let a = CscMatrix::new(rows, n, colptr, rowval, nz.clone());
    let p = CscMatrix::zeros((n, n));
    let mut q = vec![0.0; n];
    q[n_thrusters] = -1.0;
    let mut b = vec![0.0; rows];
    b[6..6 + n_thrusters].copy_from_slice(u_max);
    for (bj, &lo) in b[6 + n_thrusters..].iter_mut().zip(u_min) {
        *bj = -lo;
    }
    let cones = [
        SupportedConeT::ZeroConeT(6),
        SupportedConeT::NonnegativeConeT(2 * n_thrusters),
    ];
    let mut out = AttainableWrench {
        positive: [f64::NAN; 6],
        negative: [f64::NAN; 6],
    };
    let Ok(mut solver) = DefaultSolver::new(&p, &q, &a, &b, &cones, clarabel_settings()) else {
        return Ok(out);
    };
    for k in 0..6 {
        for sign in [1.0, -1.0] {
            for i in 0..6 {
                nz[alpha_start + i] = if i == k { -sign } else { 0.0 };
            }
            if !(k == 0 && sign > 0.0) && solver.update_A(&nz).is_err() {
                return Ok(out);
            }
            solver.solve();
            let sol = &solver.solution;
            let alpha = if matches!(
                sol.status,
                SolverStatus::Solved | SolverStatus::AlmostSolved
            ) {
                sol.x[n_thrusters].max(0.0)
            } else {
                f64::NAN
            };
            if sign > 0.0 {
                out.positive[k] = alpha;
            } else {
                out.negative[k] = alpha;
            }
        }
    }
    Ok(out)
}
