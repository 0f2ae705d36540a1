//! Recursive multibody algorithms on the floating-base chain (docs/model.md §4, USM-19 … USM-22):
//! composite-rigid-body mass matrix, recursive Newton–Euler bias forces and inverse
//! dynamics, forward and hybrid dynamics, energy and momentum.
//!
//! Pinocchio style: the [`Vehicle`] is immutable, every mutable quantity lives in a
//! [`DynWorkspace`] built once per vehicle, and every algorithm is a free function
//! `algo(&vehicle, &mut ws, …)` that allocates nothing.
//!
//! Each algorithm starts with the one position pass of the crate,
//! [`forward_kinematics`] into `ws.kin` (Pinocchio's `forwardKinematics` filling `liMi` and
//! `oMi`), then chains the staged passes of `dynamics::passes`; frames and names as in
//! [`super::workspace`].
//!
//! # Panics
//! The algorithms take slices sized for the vehicle (`q`: n, `zeta`, `tau`: 6+n) and panic on
//! a length mismatch — a programming error, like the kinematics functions. The
//! [`Simulator`](super::Simulator) and [`inspect_dynamics`](super::inspect_dynamics) check
//! lengths of user input and return errors instead.

use super::error::{check_finite, DynError};
use super::passes::{
    backward_pass, body_current, body_forces, crba, forward_pass, needs_orientation,
    orientation_pass, relative_twist,
};
use super::workspace::DynWorkspace;
use super::DynOptions;
use crate::kinematics::{forward_kinematics, BasePose};
use crate::linalg;
use crate::model::Vehicle;
use crate::spatial::Vec6;
use nalgebra::{Matrix6, Vector6};

/// Mass matrix `M(q) = Σ_i J_g,iᵀ (I_RB,i + M_A,i) J_g,i` (USM-22; without `M_A` when
/// `opts.added_mass` is off) by the composite-rigid-body algorithm, into `ws.mass`
/// ((6+n)×(6+n), base block in `F_b`). `q`: joint angles [rad]. Independent of the base pose.
pub fn mass_matrix(v: &Vehicle, ws: &mut DynWorkspace, q: &[f64], opts: &DynOptions) {
    forward_kinematics(v, q, &mut ws.kin);
    crba(ws, opts.added_mass);
}

/// Bias forces `h = C(q,ζ)ζ + D(q,ζ)ζ + N(R_Ib,q)` (USM-19/20: everything but actuation)
/// by recursive Newton–Euler with zero acceleration, into `ws.bias` (6+n: base wrench in
/// `F_b` [N, N·m], joint torques [N·m]). `pose`: base pose in the inertial frame; `q` [rad];
/// `zeta = [V_b; q̇]` (base twist in `F_b`, m/s and rad/s; joint rates rad/s).
pub fn bias(
    v: &Vehicle,
    ws: &mut DynWorkspace,
    pose: &BasePose,
    q: &[f64],
    zeta: &[f64],
    opts: &DynOptions,
) {
    forward_kinematics(v, q, &mut ws.kin);
    bias_after_position(v, ws, pose, zeta, opts);
}

fn bias_after_position(
    v: &Vehicle,
    ws: &mut DynWorkspace,
    pose: &BasePose,
    zeta: &[f64],
    opts: &DynOptions,
) {
    if needs_orientation(opts) {
        orientation_pass(ws, pose, opts.current);
    }
    forward_pass(v, ws, zeta, None);
    body_forces(v, ws, opts, true);
    let mut out = std::mem::take(&mut ws.bias);
    backward_pass(v, ws, &mut out);
    ws.bias = out;
}

/// Both `M(q)` (into `ws.mass`) and `h(q,ζ)` (into `ws.bias`) with one kinematics pass —
/// what forward dynamics and the base controller (USM-33: `M_11`, `h_1`) need. Arguments as
/// in [`mass_matrix`] and [`bias`].
pub fn dynamics_terms(
    v: &Vehicle,
    ws: &mut DynWorkspace,
    pose: &BasePose,
    q: &[f64],
    zeta: &[f64],
    opts: &DynOptions,
) {
    forward_kinematics(v, q, &mut ws.kin);
    crba(ws, opts.added_mass);
    bias_after_position(v, ws, pose, zeta, opts);
}

/// Inverse dynamics (USM-19 solved for τ) by recursive Newton–Euler with accelerations:
/// `tau = M(q) ζ̇ + h(q,ζ)` (6+n: base wrench in `F_b`, joint torques), written to `tau`.
/// `zeta_dot = [V̇_b; q̈]` with `V̇_b` the body-frame derivative of the base twist.
#[allow(clippy::too_many_arguments)]
pub fn inverse_dynamics(
    v: &Vehicle,
    ws: &mut DynWorkspace,
    pose: &BasePose,
    q: &[f64],
    zeta: &[f64],
    zeta_dot: &[f64],
    opts: &DynOptions,
    tau: &mut [f64],
) {
    forward_kinematics(v, q, &mut ws.kin);
    if needs_orientation(opts) {
        orientation_pass(ws, pose, opts.current);
    }
    forward_pass(v, ws, zeta, Some(zeta_dot));
    body_forces(v, ws, opts, true);
    backward_pass(v, ws, tau);
}

/// Forward dynamics from the `M` and `h` already in the workspace (after
/// [`dynamics_terms`]): solve `M ζ̇ = τ − h` (USM-19) by an in-place Cholesky, into
/// `ws.zeta_dot`. `tau`: generalised forces (6+n; base wrench in `F_b`, joint torques).
pub fn solve_forward(ws: &mut DynWorkspace, tau: &[f64]) -> Result<(), DynError> {
    let nv = ws.n_dof();
    if tau.len() != nv {
        return Err(DynError::new(
            "generalized_forces",
            format!("has length {}, expected {nv}", tau.len()),
        ));
    }
    check_finite("generalized_forces", tau)?;
    check_finite("bias", &ws.bias)?;
    for (r, t) in tau.iter().enumerate() {
        // Column r of the lower triangle, column-major.
        ws.chol[r * nv + r..(r + 1) * nv].copy_from_slice(&ws.mass.col_as_slice(r)[r..]);
        ws.rhs[r] = t - ws.bias[r];
    }
    // M must be numerically non-singular: pivots below n·ε·max|M_jj| are an error.
    let tol = linalg::relative_tolerance(&ws.chol, nv);
    linalg::factor(&mut ws.chol, nv, tol).map_err(|f| {
        DynError::new(
            "mass_matrix",
            format!(
                "is singular or not positive definite (Cholesky pivot {} = {:e})",
                f.pivot, f.value
            ),
        )
    })?;
    linalg::solve(&ws.chol, nv, &mut ws.rhs);
    ws.zeta_dot.copy_from_slice(&ws.rhs);
    check_finite("base_acceleration", &ws.zeta_dot[..6])?;
    check_finite("joint_accelerations", &ws.zeta_dot[6..])
}

/// Forward dynamics (USM-19, all joints torque-driven): `ζ̇ = M⁻¹(τ − h)` into
/// `ws.zeta_dot`; also leaves `M` and `h` in the workspace. Arguments as in [`bias`], plus
/// `tau` (6+n: base wrench in `F_b` [N, N·m], joint torques [N·m]).
///
/// Errors if `M` is numerically singular or a result is not finite.
#[allow(clippy::too_many_arguments)]
pub fn forward_dynamics(
    v: &Vehicle,
    ws: &mut DynWorkspace,
    pose: &BasePose,
    q: &[f64],
    zeta: &[f64],
    tau: &[f64],
    opts: &DynOptions,
) -> Result<(), DynError> {
    dynamics_terms(v, ws, pose, q, zeta, opts);
    solve_forward(ws, tau)
}

/// Hybrid dynamics from the `M` and `h` already in the workspace (after
/// [`dynamics_terms`]): the joints follow the prescribed `qdd` [rad/s²] and the base obeys
/// `M_11 V̇_b = τ_b − M_12 q̈ − h_1` (docs/model.md §4, 6×6 Cholesky); the joint torques are recovered
/// as `τ_q = M_21 V̇_b + M_22 q̈ + h_2 − Q_ext,q` into `ws.joint_torque`, and
/// `ws.zeta_dot = [V̇_b; q̈]`.
///
/// `q_ext` (6+n) are the generalised external forces other than the joint motors (e.g. the
/// thrust `J_g,iᵀ F_j`, whose base rows are `T(q) u`); the recovered torques are what the
/// joint motors must supply.
pub fn solve_hybrid(ws: &mut DynWorkspace, q_ext: &[f64], qdd: &[f64]) -> Result<(), DynError> {
    let nv = ws.n_dof();
    let n = nv - 6;
    if q_ext.len() != nv {
        return Err(DynError::new(
            "generalized_forces",
            format!("has length {}, expected {nv}", q_ext.len()),
        ));
    }
    if qdd.len() != n {
        return Err(DynError::new(
            "joint_accelerations",
            format!("has length {}, expected {n}", qdd.len()),
        ));
    }
    check_finite("generalized_forces", q_ext)?;
    check_finite("joint_accelerations", qdd)?;
    check_finite("bias", &ws.bias)?;
    let mass = &ws.mass;
    let m11 = Matrix6::from_fn(|r, c| mass[(r, c)]);
    let mut rhs = Vector6::zeros();
    for r in 0..6 {
        let mut s = q_ext[r] - ws.bias[r];
        for (k, a) in qdd.iter().enumerate() {
            s -= mass[(r, 6 + k)] * a;
        }
        rhs[r] = s;
    }
    let chol = m11.cholesky().ok_or_else(|| {
        DynError::new(
            "mass_matrix_base_block",
            "M_11 is singular or not positive definite",
        )
    })?;
    let vdot = chol.solve(&rhs);
    ws.zeta_dot[..6].copy_from_slice(vdot.as_slice());
    ws.zeta_dot[6..].copy_from_slice(qdd);
    for k in 0..n {
        let mut s = ws.bias[6 + k] - q_ext[6 + k];
        for c in 0..6 {
            s += mass[(6 + k, c)] * vdot[c];
        }
        for (l, a) in qdd.iter().enumerate() {
            s += mass[(6 + k, 6 + l)] * a;
        }
        ws.joint_torque[k] = s;
    }
    check_finite("base_acceleration", &ws.zeta_dot[..6])?;
    check_finite("joint_torques", &ws.joint_torque)
}

/// Hybrid dynamics (docs/model.md §4, ideal servos): prescribed joint accelerations `qdd`
/// [rad/s²], base acceleration from `M_11 V̇_b = τ_b − M_12 q̈ − h_1`, joint torques
/// recovered. Arguments as in [`bias`], plus `q_ext` (see [`solve_hybrid`]).
#[allow(clippy::too_many_arguments)]
pub fn hybrid_dynamics(
    v: &Vehicle,
    ws: &mut DynWorkspace,
    pose: &BasePose,
    q: &[f64],
    zeta: &[f64],
    q_ext: &[f64],
    qdd: &[f64],
    opts: &DynOptions,
) -> Result<(), DynError> {
    dynamics_terms(v, ws, pose, q, zeta, opts);
    solve_hybrid(ws, q_ext, qdd)
}

/// Kinetic energy `½ ζᵀ M(q) ζ` [J] (rigid, plus added mass when `opts.added_mass`).
/// Leaves `M` in `ws.mass`.
pub fn kinetic_energy(
    v: &Vehicle,
    ws: &mut DynWorkspace,
    q: &[f64],
    zeta: &[f64],
    opts: &DynOptions,
) -> f64 {
    mass_matrix(v, ws, q, opts);
    let nv = ws.n_dof();
    let mut e = 0.0;
    for (c, zc) in zeta.iter().enumerate().take(nv) {
        let mut s = 0.0;
        for (r, zr) in zeta.iter().enumerate().take(nv) {
            s += ws.mass[(r, c)] * zr;
        }
        e += zc * s;
    }
    0.5 * e
}

/// Total spatial momentum `[p; L]` in the inertial frame about the inertial origin
/// [N·s, N·m·s]: `Σ_i Ad_{g_Ii}⁻ᵀ (I_RB,i + M_A,i) V_i` (`M_A` only when
/// `opts.added_mass`), with the absolute body twists `V_i`. Conserved under zero external
/// forces when the fluid is at rest (docs/model.md §4).
pub fn spatial_momentum(
    v: &Vehicle,
    ws: &mut DynWorkspace,
    pose: &BasePose,
    q: &[f64],
    zeta: &[f64],
    opts: &DynOptions,
) -> Vec6 {
    forward_kinematics(v, q, &mut ws.kin);
    forward_pass(v, ws, zeta, None);
    let g_ib = pose.to_se3();
    let mut total = Vec6::zeros();
    for i in 0..ws.twist.len() {
        let inertia = if opts.added_mass {
            &ws.i_tot[i]
        } else {
            &ws.i_rb[i]
        };
        let p_i = inertia * ws.twist[i];
        total += g_ib.compose(&ws.kin.g_b[i]).wrench_to_parent(&p_i);
    }
    total
}

/// Generalised restoring forces `−N(R_Ib, q)` (6+n; the force the water and gravity apply,
/// base wrench in `F_b`, joint torques), written to `out`. Its power `ζᵀ out` is minus the
/// rate of change of the potential energy.
pub fn restoring_generalized(
    v: &Vehicle,
    ws: &mut DynWorkspace,
    pose: &BasePose,
    q: &[f64],
    out: &mut [f64],
) {
    forward_kinematics(v, q, &mut ws.kin);
    orientation_pass(ws, pose, false);
    for i in 0..ws.force.len() {
        ws.force[i] = ws.restoring[i].wrench_up(&ws.up[i]);
    }
    backward_pass(v, ws, out);
}

/// Generalised hydrodynamic damping forces `−D(q,ζ)ζ` (6+n, the force the water applies;
/// relative to the current when `opts.current`), written to `out`. `ζᵀ out ≤ 0` when the
/// current is off. Arguments as in [`bias`].
pub fn damping_generalized(
    v: &Vehicle,
    ws: &mut DynWorkspace,
    pose: &BasePose,
    q: &[f64],
    zeta: &[f64],
    opts: &DynOptions,
    out: &mut [f64],
) {
    forward_kinematics(v, q, &mut ws.kin);
    if opts.current {
        orientation_pass(ws, pose, true);
    }
    forward_pass(v, ws, zeta, None);
    for i in 0..ws.force.len() {
        let vc = body_current(v, ws, opts, i);
        let vi = ws.twist[i];
        let vr = relative_twist(&vi, &vc);
        ws.force[i] = ws.damping[i].wrench(&vr);
    }
    backward_pass(v, ws, out);
}
