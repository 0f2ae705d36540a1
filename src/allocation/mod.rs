//! Thrust allocation (docs/model.md §5, USM-36/37): map a commanded base wrench `τ_c` to thruster forces `u`.
//!
//! Conventions used throughout this module:
//! - `n_thrusters` is the number of thrusters (never called `m`: `m` is a moment below).
//! - `T` is the thruster configuration matrix, 6×n_thrusters, expressed in the base frame `F_b`:
//!   column `j` is the wrench `[f; m]` (force in N, moment in N·m about the base-frame origin)
//!   produced by one newton of thrust of thruster `j`. Rows 0–2 are force x, y, z, rows 3–5
//!   moment x, y, z.
//! - `τ` (`tau`) is the commanded wrench in the same frame and units.
//! - `u` are thruster forces in N, with per-thruster bounds `u_min ≤ u ≤ u_max` (N) and positive
//!   usage weights `w` (`W = diag(w)`).
//! - Every method reports the wrench slack `s = T u − τ` (base frame, N and N·m).
//!
//! Methods ([`Method`]):
//! - `pinv`: damped weighted pseudoinverse `u = W⁻¹Tᵀ(TW⁻¹Tᵀ + λ²I)⁻¹τ` (USM-37), bounds ignored;
//! - `qp`: `min uᵀWu + q‖s‖²` s.t. `Tu = τ + s`, `u_min ≤ u ≤ u_max`;
//! - `minimax`: `min t + q‖s‖² + ε‖u‖²` s.t. `Tu = τ + s`, `−t ≤ u_j ≤ t`, bounds;
//! - `power`: `min Σ w_j|u_j|^{3/2} + q‖s‖²` s.t. `Tu = τ + s`, bounds (exact, power cones);
//! - each constrained form optionally adds the rate/fluctuation terms `‖u − u_prev‖²_R` and
//!   `|u − u_prev| ≤ Δu` ([`RateSettings`]).
//!
//! The objectives carry no ½ factor. Constrained forms are solved with Clarabel; this module is the
//! only user of `clarabel` in the crate. A solver outcome is never an `Err`: it is reported in
//! [`AllocStatus`]. Bad input (dimensions, ordering of bounds, non-finite values, non-positive
//! weights) is an [`AllocError`].
//!
//! `qp` steps whose unconstrained optimum lies within the bounds skip Clarabel: that optimum (one
//! n_thrusters×n_thrusters Cholesky solve) is the QP solution, certified by the KKT conditions
//! with zero bound multipliers (`interior`); [`Allocation::path`] says which way a step went.
//!
//! Files: `settings` (method, formulation, [`AllocSettings`] with defaults and `validate()`),
//! `error` ([`AllocError`] and the input checks), `allocator` ([`Allocator`], [`Allocation`],
//! [`AllocStatus`], [`AllocPath`]), `interior` (the certified interior shortcut of `qp`),
//! `conic` (the Clarabel formulations), `attainable` (attainable wrench), `authority` (attainable
//! authority along the commanded axes about a reference point, and N−1);
//! `pinv` (the damped pseudoinverse kernel and `T u`); here: the one-shot conveniences.

mod allocator;
mod attainable;
mod authority;
mod authority_lp;
mod conic;
mod error;
mod interior;
mod pinv;
mod settings;
#[cfg(test)]
pub(crate) mod tests;

use nalgebra::{Matrix6xX, Vector6};

pub use allocator::{AllocPath, AllocStatus, Allocation, Allocator};
pub use attainable::{attainable_wrench, AttainableWrench};
pub use authority::{
    attainable_authority, attainable_authority_n1, transport_moments, AttainableAuthority,
    AuthoritySolver,
};
pub(crate) use error::check_t;
use error::{check_lambda, check_tau, check_vec};
pub use error::{AllocError, MAX_LAMBDA, MAX_T_ENTRY};
use pinv::pinv_into;
pub use pinv::wrench;
pub use settings::{
    AllocSettings, Formulation, Method, ParseMethodError, RateSettings, DEFAULT_EPS,
    DEFAULT_LAMBDA, DEFAULT_Q, DEFAULT_SLACK_TOL, DEFAULT_TOL,
};

/// Damped weighted pseudoinverse allocation (USM-37), a one-shot convenience:
/// `u = W⁻¹Tᵀ(TW⁻¹Tᵀ + λ²I)⁻¹τ` with `W = diag(w)`, `T` 6×n_thrusters (base frame, N and
/// N·m per N), `τ` (base frame; N, N·m). Returns `u` (N). Bounds are not involved.
pub fn damped_pinv(
    t: &Matrix6xX<f64>,
    tau: &Vector6<f64>,
    w: &[f64],
    lambda: f64,
) -> Result<Vec<f64>, AllocError> {
    check_t(t, None)?;
    check_tau(tau)?;
    let n_thrusters = t.ncols();
    check_vec("weights", w, n_thrusters)?;
    if let Some((index, &value)) = w.iter().enumerate().find(|(_, &x)| x <= 0.0) {
        return Err(AllocError::BadWeight {
            arg: "weights",
            index,
            value,
            requirement: "> 0",
        });
    }
    check_lambda(lambda)?;
    let w_inv: Vec<f64> = w.iter().map(|x| 1.0 / x).collect();
    let mut u = vec![0.0; n_thrusters];
    pinv_into(t, tau, &w_inv, lambda, &mut u);
    Ok(u)
}

/// One-shot allocation: build an [`Allocator`] for `method` and allocate `τ` once with `T`
/// (6×n_thrusters, base frame), bounds `u_min`, `u_max` (N) and weights `w` (docs/model.md §5, USM-36/37).
pub fn allocate(
    method: Method,
    t: &Matrix6xX<f64>,
    tau: &Vector6<f64>,
    u_min: &[f64],
    u_max: &[f64],
    w: &[f64],
    settings: AllocSettings,
) -> Result<Allocation, AllocError> {
    check_t(t, None)?;
    let mut a = Allocator::new(method, t.ncols(), u_min, u_max, w, settings)?;
    a.allocate(t, tau)
}
