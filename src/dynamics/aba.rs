//! O(n) recursive forward and hybrid dynamics of the floating-base chain (docs/model.md §4, issue 23):
//! the articulated-body algorithm (Featherstone, *Rigid Body Dynamics Algorithms*, §7.3 and
//! §9.2 for the floating base; Pinocchio's `aba.hxx`) with each body's added-mass spatial
//! inertia in its articulated inertia, and the hybrid dynamics of the ideal servos without
//! the joint block of the mass matrix.
//!
//! Both treat the hydrodynamics exactly as the CRBA route does: every term of the body
//! wrench of `passes::body_forces` that is linear in the body acceleration is
//! `(I_RB + M_A) a_i` (`I_RB a_i` when the added mass is off), so that inertia enters the
//! articulated (or composite) inertia; every other term — rigid and added-mass Coriolis
//! (Kirchhoff), drag, restoring forces, the current's `M_A [ω × v_c; 0]` — is the body's
//! bias wrench `p_i`, computed by the same kernel with `a_i = 0`.
//!
//! Frames and names as in [`super::workspace`]; `s_i = [0; axis_k]` is joint `k = i − 1`'s
//! unit twist in body `i`'s frame. Nothing here allocates.

use super::error::{check_finite, DynError};
use super::passes::{
    backward_pass, body_forces, composites, forward_pass, inertia_to_parent, needs_orientation,
    orientation_pass,
};
use super::structure::{
    add_joint_accel, add_joint_rate, cholesky6_solve, inertia_times_joint, inertia_to_parent_joint,
    joint_component, twist_to_child, wrench_to_parent,
};
use super::workspace::DynWorkspace;
use super::DynOptions;
use crate::kinematics::{forward_kinematics, BasePose};
use crate::model::Vehicle;
use crate::spatial::{Mat6, Vec6};
use nalgebra::Matrix6;

/// Forward dynamics by the articulated-body algorithm, O(n): `ζ̇ = M⁻¹(τ − h)` into
/// `ws.zeta_dot`, equal to [`forward_dynamics`](super::forward_dynamics) (CRBA + bias +
/// Cholesky) to rounding, without forming `M`. Arguments as in
/// [`forward_dynamics`](super::forward_dynamics): `tau` (6+n) is the generalised force (base
/// wrench in `F_b` [N, N·m], joint torques [N·m]).
///
/// Leaves the body twists in `ws.twist` and the body accelerations in `ws.accel`; `ws.mass`
/// and `ws.bias` are not touched. Errors if an articulated inertia is not positive definite
/// or a result is not finite.
#[allow(clippy::too_many_arguments)]
pub fn forward_dynamics_aba(
    v: &Vehicle,
    ws: &mut DynWorkspace,
    pose: &BasePose,
    q: &[f64],
    zeta: &[f64],
    tau: &[f64],
    opts: &DynOptions,
) -> Result<(), DynError> {
    let nv = ws.n_dof();
    if tau.len() != nv {
        return Err(DynError::new(
            "generalized_forces",
            format!("has length {}, expected {nv}", tau.len()),
        ));
    }
    forward_kinematics(v, q, &mut ws.kin);
    aba_after_position(v, ws, pose, zeta, tau, opts)
}

/// [`forward_dynamics_aba`] after the position pass (`ws.kin` filled for `q`); `tau` of
/// length 6+n (checked by the caller).
pub(super) fn aba_after_position(
    v: &Vehicle,
    ws: &mut DynWorkspace,
    pose: &BasePose,
    zeta: &[f64],
    tau: &[f64],
    opts: &DynOptions,
) -> Result<(), DynError> {
    check_finite("generalized_forces", tau)?;
    if needs_orientation(opts) {
        orientation_pass(ws, pose, opts.current);
    }
    velocity_pass(v, ws, zeta);
    body_forces(v, ws, opts, false);
    for (i, f) in ws.force.iter().enumerate() {
        check_finite("bias", f.as_slice())
            .map_err(|e| DynError::new(format!("bias_wrench[{i}]"), e.message))?;
    }
    aba_backward(v, ws, tau, opts.added_mass)?;
    aba_forward(v, ws, tau)?;
    check_finite("base_acceleration", &ws.zeta_dot[..6])?;
    check_finite("joint_accelerations", &ws.zeta_dot[6..])
}

/// Velocity pass of the ABA: body twists into `ws.twist` and the local velocity-product
/// accelerations `c_i = V_i × s_i q̇_k` into `ws.vp_accel`.
fn velocity_pass(v: &Vehicle, ws: &mut DynWorkspace, zeta: &[f64]) {
    assert_eq!(zeta.len(), v.n_dof(), "generalised velocity length");
    let vb = Vec6::from_column_slice(&zeta[..6]);
    ws.twist[0] = ws.kin.g_up[0].twist_to_child(&vb);
    ws.vp_accel[0] = Vec6::zeros();
    for (k, j) in v.joints.iter().enumerate() {
        let i = k + 1;
        let shape = ws.kin.shape[k];
        let mut vi = twist_to_child(&ws.kin.g_up[i], shape, &ws.twist[i - 1]);
        ws.vp_accel[i] = add_joint_rate(shape, &j.axis, &mut vi, zeta[6 + k]);
        ws.twist[i] = vi;
    }
}

/// Backward pass of the ABA: articulated inertias `I^A_i` and bias wrenches `p^A_i` from the
/// tip to body 0 (`ws.art_inertia`, `ws.force`), with `U_i`, `1/D_i`, `u_i` of each joint.
fn aba_backward(
    v: &Vehicle,
    ws: &mut DynWorkspace,
    tau: &[f64],
    added_mass: bool,
) -> Result<(), DynError> {
    let nb = ws.twist.len();
    let inertia = if added_mass { &ws.i_tot } else { &ws.i_rb };
    ws.art_inertia.copy_from_slice(inertia);
    for i in (1..nb).rev() {
        let k = i - 1;
        let (axis, shape) = (v.joints[k].axis, ws.kin.shape[k]);
        let ia = &ws.art_inertia[i];
        let u_vec = inertia_times_joint(shape, &axis, ia);
        let d = joint_component(shape, &axis, &u_vec);
        if !(d > 0.0 && d.is_finite()) {
            return Err(DynError::new(
                format!("articulated_inertia[{i}]"),
                format!("is not positive definite along joint {k} (s I^A s = {d:e})"),
            ));
        }
        let dinv = 1.0 / d;
        let p = ws.force[i];
        let u = tau[6 + k] - joint_component(shape, &axis, &p);
        // I^a = I^A − U Uᵀ / D;  p^a = p^A + I^a c + U u / D.
        let ia_a: Mat6 = ia - u_vec * (u_vec.transpose() * dinv);
        let pa = p + ia_a * ws.vp_accel[i] + u_vec * (u * dinv);
        ws.aba_u[i] = u_vec;
        ws.aba_dinv[i] = dinv;
        ws.aba_force[i] = u;
        let g = ws.kin.g_up[i];
        let to_parent = inertia_to_parent_joint(&g, shape, &ia_a);
        ws.art_inertia[i - 1] += to_parent;
        let fp = wrench_to_parent(&g, shape, &pa);
        ws.force[i - 1] += fp;
    }
    Ok(())
}

/// Root solve and forward pass of the ABA: `V̇_b = (I^A_b)⁻¹ (τ_b − p^A_b)` in `F_b`, then
/// `a_i = Ad⁻¹ a_{i−1} + c_i`, `q̈_k = (u_i − U_iᵀ a_i) / D_i`, `a_i += s_i q̈_k`, into
/// `ws.zeta_dot` and `ws.accel`.
fn aba_forward(v: &Vehicle, ws: &mut DynWorkspace, tau: &[f64]) -> Result<(), DynError> {
    let g0 = ws.kin.g_up[0];
    let ia_b = inertia_to_parent(&g0, &ws.art_inertia[0]);
    // Symmetrise the rounding of the rotated blocks, as the CRBA's M_11.
    let ia_b = Matrix6::from_fn(|r, c| 0.5 * (ia_b[(r, c)] + ia_b[(c, r)]));
    let pb = g0.wrench_to_parent(&ws.force[0]);
    let rhs = Vec6::from_fn(|r, _| tau[r] - pb[r]);
    let vdot = cholesky6_solve(&ia_b, &rhs).ok_or_else(|| {
        DynError::new(
            "articulated_inertia_base",
            "is singular or not positive definite",
        )
    })?;
    ws.zeta_dot[..6].copy_from_slice(vdot.as_slice());
    ws.accel[0] = g0.twist_to_child(&vdot);
    for (k, j) in v.joints.iter().enumerate() {
        let i = k + 1;
        let mut a =
            twist_to_child(&ws.kin.g_up[i], ws.kin.shape[k], &ws.accel[i - 1]) + ws.vp_accel[i];
        let qdd = (ws.aba_force[i] - ws.aba_u[i].dot(&a)) * ws.aba_dinv[i];
        add_joint_accel(ws.kin.shape[k], &j.axis, &mut a, qdd);
        ws.accel[i] = a;
        ws.zeta_dot[6 + k] = qdd;
    }
    Ok(())
}

/// The position- and velocity-dependent terms of the O(n) hybrid dynamics (after which
/// [`solve_hybrid_on`] takes any `q_ext`, `q̈`): the composite inertias in `F_b`, `M_11`
/// (symmetrised, into the base block of `ws.mass`; the other blocks of `ws.mass` are not
/// touched), the columns `F_k = Ic_{k+1} S_k` of `M_12`, and the whole bias `h` into
/// `ws.bias` by recursive Newton–Euler. Arguments as in [`bias`](super::bias).
pub fn hybrid_terms(
    v: &Vehicle,
    ws: &mut DynWorkspace,
    pose: &BasePose,
    q: &[f64],
    zeta: &[f64],
    opts: &DynOptions,
) {
    forward_kinematics(v, q, &mut ws.kin);
    composites(ws, opts.added_mass);
    let ic0 = &ws.composite[0];
    for c in 0..6 {
        for r in 0..=c {
            let x = 0.5 * (ic0[(r, c)] + ic0[(c, r)]);
            ws.mass[(r, c)] = x;
            ws.mass[(c, r)] = x;
        }
    }
    for (k, f) in ws.comp_twist.iter_mut().enumerate() {
        *f = ws.composite[k + 1] * ws.kin.joint_twist_b[k];
    }
    if needs_orientation(opts) {
        orientation_pass(ws, pose, opts.current);
    }
    forward_pass(v, ws, zeta, None);
    body_forces(v, ws, opts, true);
    let mut out = std::mem::take(&mut ws.bias);
    backward_pass(v, ws, &mut out);
    ws.bias = out;
}

/// Hybrid dynamics in O(n) from the terms of [`hybrid_terms`]: the same equations and
/// outputs as [`solve_hybrid`](super::solve_hybrid) (`ws.zeta_dot = [V̇_b; q̈]`, the recovered
/// joint torques in `ws.joint_torque`), with the products of `M` by `q̈` and `V̇_b` taken
/// through the composite inertias instead of the dense joint block:
/// `M_12 q̈ = w_0`, `(M_21 V̇_b + M_22 q̈)_l = S_l·(w_l + Ic_{l+1}(v_l + V̇_b))`, with
/// `w_l = Σ_{k≥l} Ic_{k+1} S_k q̈_k` and `v_l = Σ_{k<l} S_k q̈_k` (all in `F_b`).
pub fn solve_hybrid_on(ws: &mut DynWorkspace, q_ext: &[f64], qdd: &[f64]) -> Result<(), DynError> {
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
    // w_l from the tip (no cancellation), into the ABA's U buffer (unused here).
    let mut w0 = Vec6::zeros();
    for ((f, a), w) in ws.comp_twist.iter().zip(qdd).zip(&mut ws.aba_u[..n]).rev() {
        w0 += f * *a;
        *w = w0;
    }
    let m11 = Matrix6::from_fn(|r, c| ws.mass[(r, c)]);
    let rhs = Vec6::from_fn(|r, _| q_ext[r] - ws.bias[r] - w0[r]);
    let vdot = cholesky6_solve(&m11, &rhs).ok_or_else(|| {
        DynError::new(
            "mass_matrix_base_block",
            "M_11 is singular or not positive definite",
        )
    })?;
    ws.zeta_dot[..6].copy_from_slice(vdot.as_slice());
    ws.zeta_dot[6..].copy_from_slice(qdd);
    // v_l + V̇_b by a running sum from the base.
    let mut vsum = vdot;
    for l in 0..n {
        let s_l = &ws.kin.joint_twist_b[l];
        let m = ws.composite[l + 1] * vsum + ws.aba_u[l];
        ws.joint_torque[l] = ws.bias[6 + l] - q_ext[6 + l] + s_l.dot(&m);
        vsum += s_l * qdd[l];
    }
    check_finite("base_acceleration", &ws.zeta_dot[..6])?;
    check_finite("joint_torques", &ws.joint_torque)
}

/// Hybrid dynamics (docs/model.md §4, ideal servos) in O(n): [`hybrid_terms`] then
/// [`solve_hybrid_on`]; the same results as [`hybrid_dynamics`](super::hybrid_dynamics).
#[allow(clippy::too_many_arguments)]
pub fn hybrid_dynamics_on(
    v: &Vehicle,
    ws: &mut DynWorkspace,
    pose: &BasePose,
    q: &[f64],
    zeta: &[f64],
    q_ext: &[f64],
    qdd: &[f64],
    opts: &DynOptions,
) -> Result<(), DynError> {
    hybrid_terms(v, ws, pose, q, zeta, opts);
    solve_hybrid_on(ws, q_ext, qdd)
}
