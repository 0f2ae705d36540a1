//! The staged passes of the recursive algorithms (MuJoCo's position → velocity →
//! acceleration staging, docs/model.md §4): inertial orientations and the composite-rigid-body mass
//! matrix after the position pass, then the Newton–Euler forward pass (twists,
//! accelerations), the per-body wrenches and the backward pass into generalised forces.
//! The public algorithms of [`super::algorithms`] chain them; names and frames as in
//! [`super::workspace`].

pub(super) use super::structure::inertia_to_parent;
use super::structure::{
    add_joint_accel, add_joint_rate, inertia_to_parent_axial, joint_component, mul_inertia,
    mul_inertia_linear, twist_to_child, wrench_to_parent,
};
use super::workspace::DynWorkspace;
use super::DynOptions;
use crate::kinematics::BasePose;
use crate::model::Vehicle;
use crate::spatial::{ang, cross_force, Vec3, Vec6};

// ---------------------------------------------------------------------------------------
// Position stage (after `forward_kinematics` into `ws.kin`).

/// Body orientations in the inertial frame, `R_Ii = R_Ib R_bi`, into `ws.r_ii` when `full`
/// (the current needs them), and always their last rows, the inertial vertical in body
/// coordinates, into `ws.up` (all the restoring forces need: 9 products a body instead of 27,
/// the same bits as the last row of the full product).
pub(super) fn orientation_pass(ws: &mut DynWorkspace, pose: &BasePose, full: bool) {
    let r_ib = *pose.orientation.to_rotation_matrix().matrix();
    if full {
        for ((r, u), g) in ws.r_ii.iter_mut().zip(&mut ws.up).zip(&ws.kin.g_b) {
            *r = r_ib * g.r;
            *u = Vec3::new(r[(2, 0)], r[(2, 1)], r[(2, 2)]);
        }
    } else {
        let (a, b, c) = (r_ib[(2, 0)], r_ib[(2, 1)], r_ib[(2, 2)]);
        for (u, g) in ws.up.iter_mut().zip(&ws.kin.g_b) {
            let r = &g.r;
            *u = Vec3::new(
                a * r[(0, 0)] + b * r[(1, 0)] + c * r[(2, 0)],
                a * r[(0, 1)] + b * r[(1, 1)] + c * r[(2, 1)],
                a * r[(0, 2)] + b * r[(1, 2)] + c * r[(2, 2)],
            );
        }
    }
}

/// Composite-rigid-body algorithm on the floating base, after the position pass
/// ([`forward_kinematics`](crate::kinematics::forward_kinematics) into `ws.kin`).
///
/// With `I^b_i` body `i`'s inertia in `F_b` and `Ic_i = Σ_{j≥i} I^b_j` (a chain), the base
/// twist and the joint twists `S_k` (in `F_b`) give `M_11 = Ic_0`, `M_1,k = Ic_{k+1} S_k`,
/// `M_l,k = S_lᵀ Ic_{k+1} S_k` for `l ≤ k` — exactly `Σ J_g,iᵀ I_i J_g,i` (USM-22).
pub(super) fn crba(ws: &mut DynWorkspace, added_mass: bool) {
    let n = ws.kin.g_up.len() - 1;
    composites(ws, added_mass);
    let mass = &mut ws.mass;
    let ic0 = &ws.composite[0];
    // Rotated blocks R A Rᵀ are symmetric only to rounding: symmetrise M_11 exactly.
    for c in 0..6 {
        for r in 0..=c {
            let x = 0.5 * (ic0[(r, c)] + ic0[(c, r)]);
            mass[(r, c)] = x;
            mass[(c, r)] = x;
        }
    }
    for k in 0..n {
        let s_k = &ws.kin.joint_twist_b[k];
        let f = ws.composite[k + 1] * s_k;
        for r in 0..6 {
            mass[(r, 6 + k)] = f[r];
            mass[(6 + k, r)] = f[r];
        }
        for l in 0..=k {
            let x = ws.kin.joint_twist_b[l].dot(&f);
            mass[(6 + l, 6 + k)] = x;
            mass[(6 + k, 6 + l)] = x;
        }
    }
}

/// The composite inertias `Ic_i = Σ_{j≥i} I^b_j` of the chain in `F_b` into `ws.composite`
/// (the first half of [`crba`]; with or without added mass).
pub(super) fn composites(ws: &mut DynWorkspace, added_mass: bool) {
    let nb = ws.kin.g_up.len();
    for i in (0..nb).rev() {
        let (inertia, axial) = if added_mass {
            (&ws.i_tot[i], ws.axial[i].total)
        } else {
            (&ws.i_rb[i], ws.axial[i].rigid)
        };
        let g = &ws.kin.g_b[i];
        let ib = if axial {
            inertia_to_parent_axial(g, inertia)
        } else {
            inertia_to_parent(g, inertia)
        };
        ws.composite[i] = if i + 1 < nb {
            ib + ws.composite[i + 1]
        } else {
            ib
        };
    }
}

// ---------------------------------------------------------------------------------------
// Velocity and acceleration stages.

/// Forward pass of Newton–Euler: body twists and (if `zeta_dot` is given) accelerations,
/// else the velocity-product accelerations only.
///
/// `V_0 = Ad_{g_b0}⁻¹ V_b`, `V_i = Ad_{g_up,i}⁻¹ V_{i−1} + s_i q̇_k`,
/// `a_i = Ad_{g_up,i}⁻¹ a_{i−1} + V_i × s_i q̇_k + s_i q̈_k`, `s_i = [0; axis_k]`.
pub(super) fn forward_pass(
    v: &Vehicle,
    ws: &mut DynWorkspace,
    zeta: &[f64],
    zeta_dot: Option<&[f64]>,
) {
    assert_eq!(zeta.len(), v.n_dof(), "generalised velocity length");
    let vb = Vec6::from_column_slice(&zeta[..6]);
    ws.twist[0] = ws.kin.g_up[0].twist_to_child(&vb);
    ws.accel[0] = match zeta_dot {
        Some(a) => {
            assert_eq!(a.len(), v.n_dof(), "generalised acceleration length");
            ws.kin.g_up[0].twist_to_child(&Vec6::from_column_slice(&a[..6]))
        }
        None => Vec6::zeros(),
    };
    for (k, j) in v.joints.iter().enumerate() {
        let i = k + 1;
        let (g, shape) = (&ws.kin.g_up[i], ws.kin.shape[k]);
        let mut vi = twist_to_child(g, shape, &ws.twist[i - 1]);
        let vp = add_joint_rate(shape, &j.axis, &mut vi, zeta[6 + k]);
        let mut ai = twist_to_child(g, shape, &ws.accel[i - 1]) + vp;
        if let Some(a) = zeta_dot {
            add_joint_accel(shape, &j.axis, &mut ai, a[6 + k]);
        }
        ws.twist[i] = vi;
        ws.accel[i] = ai;
    }
}

/// Body-frame current `R_Iiᵀ ν_c` [m/s] when the current is in use, else zero.
#[inline]
pub(super) fn body_current(v: &Vehicle, ws: &DynWorkspace, opts: &DynOptions, i: usize) -> Vec3 {
    if opts.current {
        ws.r_ii[i].transpose() * v.fluid.current
    } else {
        Vec3::zeros()
    }
}

/// Body twist relative to the water, `V_r = V_i − [v_c; 0]` (docs/model.md §4; `v_c` the body-frame
/// current [m/s], the angular part unchanged).
#[inline]
pub(super) fn relative_twist(vi: &Vec6, vc: &Vec3) -> Vec6 {
    Vec6::new(
        vi[0] - vc.x,
        vi[1] - vc.y,
        vi[2] - vc.z,
        vi[3],
        vi[4],
        vi[5],
    )
}

#[inline]
pub(super) fn uses_current(v: &Vehicle, opts: &DynOptions) -> bool {
    opts.current && v.fluid.current != Vec3::zeros()
}

/// Per-body Newton–Euler wrench (docs/model.md §4), after [`forward_pass`]:
///
/// `f_i = I_RB a_i + V_i ×* (I_RB V_i) + M_A (a_i + [ω_i × v_c; 0]) + V_r ×* (M_A V_r)
///        − F_damp(V_r) − F_restoring(R_Ii)`,
///
/// with `v_c = R_Iiᵀ ν_c` and `V_r = V_i − [v_c; 0]`. The `ω × v_c` term is the body-frame
/// derivative of the body-frame current, `d/dt(R_Iiᵀ ν_c) = −ω × v_c`, so that
/// `M_A V̇_r = M_A (V̇ + [ω × v_c; 0])` (Fossen's `M_A ν̇_r`); with it the dynamics in a
/// uniform current are the current-free dynamics seen from a frame drifting with the current
/// (tested). `V_r ×* (M_A V_r)` is Fossen's `C_A(ν_r) ν_r` (the Kirchhoff term), left out
/// for bodies whose manoeuvring derivatives hold it ([`super::hydro::DampingKernel::kirchhoff`]).
///
/// With `with_accel` false the acceleration terms `I a_i` are left out (`a_i = 0`): the
/// velocity-dependent and external part that the articulated-body algorithms propagate.
pub(super) fn body_forces(v: &Vehicle, ws: &mut DynWorkspace, opts: &DynOptions, with_accel: bool) {
    let current = uses_current(v, opts);
    for i in 0..ws.twist.len() {
        let axial = ws.axial[i];
        let vi = ws.twist[i];
        let ai = if with_accel {
            ws.accel[i]
        } else {
            Vec6::zeros()
        };
        let vc = if current {
            body_current(v, ws, opts, i)
        } else {
            Vec3::zeros()
        };
        let vr = relative_twist(&vi, &vc);
        let mut f;
        let rigid_vi = || mul_inertia(&ws.i_rb[i], axial.rigid, &vi);
        if opts.added_mass {
            f = if with_accel {
                mul_inertia(&ws.i_tot[i], axial.total, &ai)
            } else {
                Vec6::zeros()
            };
            if !ws.damping[i].kirchhoff() {
                // Manoeuvring derivatives carry the added mass's velocity forces themselves.
                f += cross_force(&vi, &rigid_vi());
                if current {
                    let wv = ang(&vi).cross(&vc);
                    f += mul_inertia_linear(&ws.m_a[i], axial.added, &wv);
                }
            } else if current {
                let ma = &ws.m_a[i];
                f += cross_force(&vi, &rigid_vi());
                f += cross_force(&vr, &mul_inertia(ma, axial.added, &vr));
                let wv = ang(&vi).cross(&vc);
                f += mul_inertia_linear(ma, axial.added, &wv);
            } else {
                f += cross_force(&vi, &mul_inertia(&ws.i_tot[i], axial.total, &vi));
            }
        } else if with_accel {
            f = mul_inertia(&ws.i_rb[i], axial.rigid, &ai) + cross_force(&vi, &rigid_vi());
        } else {
            f = cross_force(&vi, &rigid_vi());
        }
        if opts.drag {
            f -= ws.damping[i].wrench(&vr);
        }
        if opts.restoring {
            f -= ws.restoring[i].wrench_up(&ws.up[i]);
        }
        ws.force[i] = f;
    }
}

/// Backward pass: accumulate the body wrenches `ws.force` down the chain into generalised
/// forces `out = Σ J_g,iᵀ f_i` — joint `k`: `s_iᵀ f_i` of the subtree; base: the subtree
/// wrench in `F_b`. Consumes `ws.force` (it holds subtree wrenches afterwards).
pub(super) fn backward_pass(v: &Vehicle, ws: &mut DynWorkspace, out: &mut [f64]) {
    assert_eq!(out.len(), v.n_dof(), "generalised force length");
    for i in (1..ws.force.len()).rev() {
        let f = ws.force[i];
        out[6 + i - 1] = joint_component(ws.kin.shape[i - 1], &v.joints[i - 1].axis, &f);
        let fp = wrench_to_parent(&ws.kin.g_up[i], ws.kin.shape[i - 1], &f);
        ws.force[i - 1] += fp;
    }
    let fb = ws.kin.g_up[0].wrench_to_parent(&ws.force[0]);
    out[..6].copy_from_slice(fb.as_slice());
}

pub(super) fn needs_orientation(opts: &DynOptions) -> bool {
    opts.restoring || opts.current
}
