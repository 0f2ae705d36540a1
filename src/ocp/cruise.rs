//! A start that already moves (docs/ocp.md §4, "the cruise start", eq. (C1)–(C3)): the
//! initial iterate of a transport leg, built so that the SQP's first QP is linearised where
//! the quadratic drag has a derivative (at rest it has none).
//!
//! States: the base translates along the straight segment from its initial position to the
//! terminal `base_displacement`, heading and joint angles held at their initial values,
//! joint rates zero. Its body-frame velocity at knot k is
//!
//! ```text
//! V_k = w_k / (Δt Σ_{i=1..N} w_i) · R_0ᵀ D                                  (C1)
//! w_k = sin²(π k / (2 m)) for k < m,  1 for m ≤ k ≤ N − m,  sin²(π (N − k) / (2 m)) above
//! ```
//!
//! (`m = ⌈r N⌉`, r = [`RAMP`]: accelerate over the first quarter, cruise, decelerate over the
//! last; `w_0 = w_N = 0`, at rest at both ends), and the positions follow the model's own
//! symplectic Euler update with zero angular rate, `p_{k+1} = p_k + Δt R_0 V_{k+1}` (C2), so
//! the position defects vanish and `Σ` reaches `p_0 + D` exactly at `k = N`.
//!
//! Controls: at every knot the thrusts and joint torques that best produce the next state,
//! `u_k = argmin ‖f(x_k, u) ⊖ x_{k+1}‖² + λ‖u‖²` (C3), by three Gauss–Newton steps from zero
//! with the model's `B_k = ∂f/∂u` (the dynamics are affine in u; λ = 1e-8 picks the
//! least-norm allocation where `G(q)` is rank-deficient, e.g. roll at the straight body),
//! clipped to the bounds. What the allocation cannot produce (roll, a bound) stays as a
//! defect for the SQP.

// Stage and component loops read clearest with indices (k: knot, i: component).
#![allow(clippy::needless_range_loop)]

use super::chain::ChainModel;
use super::model::{ModelError, OcpModel};
use super::start::Trajectory;
use crate::spatial::Vec3;
use nalgebra::{DMatrix, DVector};

/// Fraction of the horizon spent accelerating (and again decelerating) in (C1).
pub const RAMP: f64 = 0.25;

/// Tikhonov weight λ of the allocation (C3).
const ALLOCATION_DAMPING: f64 = 1e-8;

/// The speed weights `w_0 … w_N` of (C1): zero at both ends, a sin² ramp over `⌈ramp·N⌉`
/// knots at each end (`ramp` in (0, 0.5]; [`RAMP`] for the cruise start), one between.
pub fn ramp_profile(knots: usize, ramp: f64) -> Vec<f64> {
    let m = ((ramp * knots as f64).ceil() as usize).clamp(1, knots.div_ceil(2).max(1));
    (0..=knots)
        .map(|k| {
            let edge = k.min(knots - k);
            if edge >= m {
                1.0
            } else {
                (std::f64::consts::FRAC_PI_2 * edge as f64 / m as f64)
                    .sin()
                    .powi(2)
            }
        })
        .collect()
}

/// The cruise start of a leg (module documentation, (C1)–(C3)): from `x0` to the base
/// displaced by `displacement` (inertial [m]) in `knots` intervals of the model's Δt,
/// controls allocated within `[u_lo, u_hi]`. Errors: the dynamics failed.
pub fn cruise_start(
    model: &mut ChainModel,
    x0: &[f64],
    knots: usize,
    displacement: [f64; 3],
    u_lo: &[f64],
    u_hi: &[f64],
) -> Result<Trajectory, ModelError> {
    ramped_cruise_start(model, x0, knots, displacement, RAMP, u_lo, u_hi)
}

/// [`cruise_start`] with the ramp fraction `ramp` of (C1) (in (0, 0.5]; [`RAMP`] there): the
/// multi-start's other starts of a leg (docs/ocp.md §6), each a dynamically consistent
/// guess with its own speed profile.
pub fn ramped_cruise_start(
    model: &mut ChainModel,
    x0: &[f64],
    knots: usize,
    displacement: [f64; 3],
    ramp: f64,
    u_lo: &[f64],
    u_hi: &[f64],
) -> Result<Trajectory, ModelError> {
    let n = model.n_joints();
    let (nx, nu, nq) = (model.nx(), model.nu(), model.nq());
    let dt = model.dt();
    let pose0 = ChainModel::pose(x0);
    let d_body = pose0.orientation.inverse() * Vec3::from(displacement);
    let w = ramp_profile(knots, ramp);
    let scale = 1.0 / (dt * w[1..].iter().sum::<f64>());
    let (q0, qd0) = (&x0[7..7 + n], vec![0.0; n]);
    let mut xs = Vec::with_capacity(knots + 1);
    let mut pose = pose0;
    for k in 0..=knots {
        let v = d_body * (w[k] * scale);
        if k > 0 {
            pose.position += pose0.orientation * v * dt;
        }
        let twist = [v.x, v.y, v.z, 0.0, 0.0, 0.0];
        xs.push(ChainModel::pack(&pose, q0, &twist, &qd0));
    }
    xs[0].copy_from_slice(x0);
    let mut us = vec![vec![0.0; nu]; knots];
    let (mut a, mut b) = (DMatrix::zeros(nx, nx), DMatrix::zeros(nx, nu));
    let (mut f, mut d) = (vec![0.0; nq], vec![0.0; nx]);
    for k in 0..knots {
        for _ in 0..3 {
            model.step(&xs[k], &us[k], &mut f)?;
            model.difference(&xs[k + 1], &f, &mut d);
            model.jacobians(&xs[k], &us[k], &mut a, &mut b)?;
            let mut h = b.transpose() * &b;
            for i in 0..nu {
                h[(i, i)] += ALLOCATION_DAMPING;
            }
            let g = b.transpose() * DVector::from_column_slice(&d);
            let Some(ch) = h.cholesky() else {
                return Err(ModelError(format!("allocation not solvable at knot {k}")));
            };
            let du = ch.solve(&g);
            for i in 0..nu {
                us[k][i] = (us[k][i] - du[i]).clamp(u_lo[i], u_hi[i]);
            }
        }
    }
    Ok((xs, us))
}
