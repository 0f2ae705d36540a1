//! Recursive multibody algorithms on the floating-base chain (SPEC §4, USM-19 … USM-22):
//! composite-rigid-body mass matrix, recursive Newton–Euler bias forces and inverse
//! dynamics, forward and hybrid dynamics, energy and momentum.
//!
//! Pinocchio style: the [`Vehicle`] is immutable, every mutable quantity lives in a
//! [`DynWorkspace`] built once per vehicle, and every algorithm is a free function
//! `algo(&vehicle, &mut ws, …)` that allocates nothing.
//!
//! Frames and names: `g_up[i]` is body `i` in its parent's frame (body 0: in the base frame
//! `F_b`); `kin.g_b[i]` is body `i` in `F_b`; `r_ii[i]` is body `i`'s orientation in the
//! inertial frame `R_Ii`; `twist[i]`, `accel[i]`, `force[i]` are body `i`'s twist `[v; ω]`,
//! spatial acceleration and wrench `[f; m]`, all in body `i`'s own frame (moments about its
//! origin). Generalised vectors are ordered `[base (6, in F_b); joints (n)]`.
//!
//! # Panics
//! The algorithms take slices sized for the vehicle (`q`: n, `zeta`, `tau`: 6+n) and panic on
//! a length mismatch — a programming error, like the kinematics functions. The
//! [`Simulator`](super::Simulator) and [`inspect_dynamics`](super::inspect_dynamics) check
//! lengths of user input and return errors instead.

use super::hydro::{DampingKernel, Restoring};
use super::{check_finite, DynError, DynOptions};
use crate::kinematics::{BasePose, KinWorkspace};
use crate::model::Vehicle;
use crate::spatial::{
    ang, cross_force, lin, rot_axis_angle, skew, stack, Mat3, Mat6, Se3, Vec3, Vec6,
};
use faer::Mat;
use nalgebra::{Matrix6, Vector6};

/// Preallocated workspace of the dynamics algorithms for one vehicle (Pinocchio's `Data`).
///
/// Built by [`DynWorkspace::new`] from a vehicle; constant per-body quantities (spatial
/// inertias, hydrodynamic kernels) are resolved then, so rebuild the workspace if the
/// vehicle changes. Results of the last call stay readable in the public fields.
#[derive(Clone, Debug)]
pub struct DynWorkspace {
    /// Kinematic quantities at the last configuration (`g_b`, joint twists in `F_b`,
    /// `g_be`), compatible with the [`kinematics`](crate::kinematics) functions.
    pub kin: KinWorkspace,
    /// Body `i` in its parent body's frame (body 0: in `F_b`), `g_(i-1)i(q)`.
    pub g_up: Vec<Se3>,
    /// Body orientations in the inertial frame `R_Ii = R_Ib R_bi` (refreshed only by calls
    /// that take a base pose and need it: restoring forces or current).
    pub r_ii: Vec<Mat3>,
    /// Rigid-body spatial inertia `I_RB,i` about body `i`'s origin, in its frame.
    pub i_rb: Vec<Mat6>,
    /// Added-mass spatial inertia `M_A,i` about body `i`'s origin, in its frame.
    pub m_a: Vec<Mat6>,
    /// `I_RB,i + M_A,i`.
    pub i_tot: Vec<Mat6>,
    /// Damping kernel of each body.
    pub damping: Vec<DampingKernel>,
    /// Hydrostatic parameters of each body.
    pub restoring: Vec<Restoring>,
    /// Composite inertia of bodies `i..` expressed in `F_b` (CRBA).
    pub composite: Vec<Mat6>,
    /// Body twists `V_i` in body frames [m/s, rad/s].
    pub twist: Vec<Vec6>,
    /// Body spatial accelerations `V̇_i` (body-frame derivative of the body twist).
    pub accel: Vec<Vec6>,
    /// Body wrenches of the last Newton–Euler pass [N, N·m].
    pub force: Vec<Vec6>,
    /// Mass matrix `M(q)` (USM-22), (6+n)×(6+n), from [`mass_matrix`] / [`dynamics_terms`].
    pub mass: Mat<f64>,
    /// Bias forces `h = C ζ + D ζ + N` (6+n), from [`bias`] / [`dynamics_terms`].
    pub bias: Vec<f64>,
    /// Generalised acceleration `ζ̇ = [V̇_b; q̈]` from [`forward_dynamics`] /
    /// [`hybrid_dynamics`].
    pub zeta_dot: Vec<f64>,
    /// Joint torques recovered by [`hybrid_dynamics`] [N·m].
    pub joint_torque: Vec<f64>,
    /// Generalised thrust map (6+n)×m (columns `J_g,iᵀ F_j`), for the simulator.
    pub thrust_map: Mat<f64>,
    /// Cholesky factor scratch, column-major lower triangle.
    chol: Vec<f64>,
    /// Inverse Cholesky diagonal scratch (6+n).
    inv_diag: Vec<f64>,
    /// Right-hand-side scratch (6+n).
    rhs: Vec<f64>,
}

impl DynWorkspace {
    /// A workspace sized for `v`, with its per-body inertias and hydrodynamic kernels
    /// resolved in `v.fluid`.
    pub fn new(v: &Vehicle) -> Self {
        let nb = v.bodies.len();
        let nv = v.n_dof();
        let rho = v.fluid.rho;
        let i_rb: Vec<Mat6> = v.bodies.iter().map(|b| b.rigid_spatial_inertia()).collect();
        let m_a: Vec<Mat6> = v.bodies.iter().map(|b| b.added_mass(rho)).collect();
        let i_tot = i_rb.iter().zip(&m_a).map(|(a, b)| a + b).collect();
        Self {
            kin: KinWorkspace::new(v),
            g_up: vec![Se3::identity(); nb],
            r_ii: vec![Mat3::identity(); nb],
            i_rb,
            m_a,
            i_tot,
            damping: v.bodies.iter().map(|b| DampingKernel::of(b, rho)).collect(),
            restoring: v
                .bodies
                .iter()
                .map(|b| Restoring::of(b, rho, v.fluid.g))
                .collect(),
            composite: vec![Mat6::zeros(); nb],
            twist: vec![Vec6::zeros(); nb],
            accel: vec![Vec6::zeros(); nb],
            force: vec![Vec6::zeros(); nb],
            mass: Mat::zeros(nv, nv),
            bias: vec![0.0; nv],
            zeta_dot: vec![0.0; nv],
            joint_torque: vec![0.0; v.n_joints()],
            thrust_map: Mat::zeros(nv, v.n_thrusters()),
            chol: vec![0.0; nv * nv],
            inv_diag: vec![0.0; nv],
            rhs: vec![0.0; nv],
        }
    }

    /// Number of generalised velocities `6 + n`.
    pub fn n_dof(&self) -> usize {
        self.bias.len()
    }

    /// The base block `M_11` (6×6, whole-body inertia about the base origin in `F_b`) of the
    /// last computed mass matrix (USM-33).
    pub fn mass_base_block(&self) -> Matrix6<f64> {
        Matrix6::from_fn(|r, c| self.mass[(r, c)])
    }

    /// The base rows `h_1 = n(R_Ib, q, ζ)` (6, in `F_b`) of the last computed bias (USM-33).
    pub fn bias_base(&self) -> Vector6<f64> {
        Vector6::from_column_slice(&self.bias[..6])
    }
}

// ---------------------------------------------------------------------------------------
// Position stage.

/// Forward kinematics into the workspace: `g_up`, `kin.g_b`, joint twists in `F_b` and
/// `kin.g_be` (the same quantities as [`crate::kinematics::forward_kinematics`]).
fn position_pass(v: &Vehicle, ws: &mut DynWorkspace, q: &[f64]) {
    assert_eq!(q.len(), v.joints.len(), "joint vector length");
    let g0 = v.base.inverse();
    ws.g_up[0] = g0;
    ws.kin.g_b[0] = g0;
    for (k, j) in v.joints.iter().enumerate() {
        let rot = Se3::new(rot_axis_angle(&j.axis, q[k]), Vec3::zeros());
        let g = j.placement.compose(&rot);
        ws.g_up[k + 1] = g;
        let gb = ws.kin.g_b[k].compose(&g);
        ws.kin.joint_twist_b[k] = gb.twist_to_parent(&stack(&Vec3::zeros(), &j.axis));
        ws.kin.g_b[k + 1] = gb;
    }
    let last = v.bodies.len() - 1;
    ws.kin.g_be = ws.kin.g_b[last].compose(&v.end_effector);
}

/// Body orientations in the inertial frame, `R_Ii = R_Ib R_bi`.
fn orientation_pass(ws: &mut DynWorkspace, pose: &BasePose) {
    let r_ib = *pose.orientation.to_rotation_matrix().matrix();
    for (r, g) in ws.r_ii.iter_mut().zip(&ws.kin.g_b) {
        *r = r_ib * g.r;
    }
}

/// `Ad_g⁻ᵀ I Ad_g⁻¹`: a spatial inertia about the child origin in the child frame, moved to
/// the parent frame, for `g = (R, p)` — by 3×3 blocks (about 60 % of the cost of two 6×6
/// products). With `I = [[A, B], [Bᵀ, C]]` and `A' = RARᵀ`, `B' = RBRᵀ`, `C' = RCRᵀ`:
/// `[[A', B' − A'p̂], [·ᵀ, C' + p̂B' − B'ᵀp̂ − p̂A'p̂]]`.
#[inline]
pub fn inertia_to_parent(g: &Se3, i: &Mat6) -> Mat6 {
    let r = &g.r;
    let rt = r.transpose();
    let a = r * i.fixed_view::<3, 3>(0, 0) * rt;
    let b = r * i.fixed_view::<3, 3>(0, 3) * rt;
    let c = r * i.fixed_view::<3, 3>(3, 3) * rt;
    let ph = skew(&g.p);
    let aph = a * ph;
    let ur = b - aph;
    let pb = ph * b;
    let lr = c + pb + pb.transpose() - ph * aph;
    let mut out = Mat6::zeros();
    out.fixed_view_mut::<3, 3>(0, 0).copy_from(&a);
    out.fixed_view_mut::<3, 3>(0, 3).copy_from(&ur);
    out.fixed_view_mut::<3, 3>(3, 0).copy_from(&ur.transpose());
    out.fixed_view_mut::<3, 3>(3, 3).copy_from(&lr);
    out
}

/// Composite-rigid-body algorithm on the floating base, after [`position_pass`].
///
/// With `I^b_i` body `i`'s inertia in `F_b` and `Ic_i = Σ_{j≥i} I^b_j` (a chain), the base
/// twist and the joint twists `S_k` (in `F_b`) give `M_11 = Ic_0`, `M_1,k = Ic_{k+1} S_k`,
/// `M_l,k = S_lᵀ Ic_{k+1} S_k` for `l ≤ k` — exactly `Σ J_g,iᵀ I_i J_g,i` (USM-22).
fn crba(ws: &mut DynWorkspace, added_mass: bool) {
    let nb = ws.g_up.len();
    let n = nb - 1;
    for i in (0..nb).rev() {
        let inertia = if added_mass {
            &ws.i_tot[i]
        } else {
            &ws.i_rb[i]
        };
        let ib = inertia_to_parent(&ws.kin.g_b[i], inertia);
        ws.composite[i] = if i + 1 < nb {
            ib + ws.composite[i + 1]
        } else {
            ib
        };
    }
    let m = &mut ws.mass;
    let ic0 = &ws.composite[0];
    // Rotated blocks R A Rᵀ are symmetric only to rounding: symmetrise M_11 exactly.
    for c in 0..6 {
        for r in 0..=c {
            let x = 0.5 * (ic0[(r, c)] + ic0[(c, r)]);
            m[(r, c)] = x;
            m[(c, r)] = x;
        }
    }
    for k in 0..n {
        let s_k = &ws.kin.joint_twist_b[k];
        let f = ws.composite[k + 1] * s_k;
        for r in 0..6 {
            m[(r, 6 + k)] = f[r];
            m[(6 + k, r)] = f[r];
        }
        for l in 0..=k {
            let x = ws.kin.joint_twist_b[l].dot(&f);
            m[(6 + l, 6 + k)] = x;
            m[(6 + k, 6 + l)] = x;
        }
    }
}

// ---------------------------------------------------------------------------------------
// Velocity and acceleration stages.

/// Forward pass of Newton–Euler: body twists and (if `zeta_dot` is given) accelerations,
/// else the velocity-product accelerations only.
///
/// `V_0 = Ad_{g_b0}⁻¹ V_b`, `V_i = Ad_{g_up,i}⁻¹ V_{i−1} + s_i q̇_k`,
/// `a_i = Ad_{g_up,i}⁻¹ a_{i−1} + V_i × s_i q̇_k + s_i q̈_k`, `s_i = [0; axis_k]`.
fn forward_pass(v: &Vehicle, ws: &mut DynWorkspace, zeta: &[f64], zeta_dot: Option<&[f64]>) {
    assert_eq!(zeta.len(), v.n_dof(), "generalised velocity length");
    let vb = Vec6::from_column_slice(&zeta[..6]);
    ws.twist[0] = ws.g_up[0].twist_to_child(&vb);
    ws.accel[0] = match zeta_dot {
        Some(a) => {
            assert_eq!(a.len(), v.n_dof(), "generalised acceleration length");
            ws.g_up[0].twist_to_child(&Vec6::from_column_slice(&a[..6]))
        }
        None => Vec6::zeros(),
    };
    for (k, j) in v.joints.iter().enumerate() {
        let i = k + 1;
        let w_j = j.axis * zeta[6 + k];
        let mut vi = ws.g_up[i].twist_to_child(&ws.twist[i - 1]);
        vi[3] += w_j.x;
        vi[4] += w_j.y;
        vi[5] += w_j.z;
        let (vl, va) = (lin(&vi), ang(&vi));
        let mut ai =
            ws.g_up[i].twist_to_child(&ws.accel[i - 1]) + stack(&vl.cross(&w_j), &va.cross(&w_j));
        if let Some(a) = zeta_dot {
            let dw = j.axis * a[6 + k];
            ai[3] += dw.x;
            ai[4] += dw.y;
            ai[5] += dw.z;
        }
        ws.twist[i] = vi;
        ws.accel[i] = ai;
    }
}

/// Body-frame current `R_Iiᵀ ν_c` [m/s] when the current is in use, else zero.
#[inline]
fn body_current(v: &Vehicle, ws: &DynWorkspace, opts: &DynOptions, i: usize) -> Vec3 {
    if opts.current {
        ws.r_ii[i].transpose() * v.fluid.current
    } else {
        Vec3::zeros()
    }
}

#[inline]
fn uses_current(v: &Vehicle, opts: &DynOptions) -> bool {
    opts.current && v.fluid.current != Vec3::zeros()
}

/// Per-body Newton–Euler wrench (SPEC §4), after [`forward_pass`]:
///
/// `f_i = I_RB a_i + V_i ×* (I_RB V_i) + M_A (a_i + [ω_i × v_c; 0]) + V_r ×* (M_A V_r)
///        − F_damp(V_r) − F_restoring(R_Ii)`,
///
/// with `v_c = R_Iiᵀ ν_c` and `V_r = V_i − [v_c; 0]`. The `ω × v_c` term is the body-frame
/// derivative of the body-frame current, `d/dt(R_Iiᵀ ν_c) = −ω × v_c`, so that
/// `M_A V̇_r = M_A (V̇ + [ω × v_c; 0])` (Fossen's `M_A ν̇_r`); with it the dynamics in a
/// uniform current are the current-free dynamics seen from a frame drifting with the current
/// (tested). `V_r ×* (M_A V_r)` is Fossen's `C_A(ν_r) ν_r` (the Kirchhoff term).
fn body_forces(v: &Vehicle, ws: &mut DynWorkspace, opts: &DynOptions) {
    let current = uses_current(v, opts);
    for i in 0..ws.twist.len() {
        let vi = ws.twist[i];
        let ai = ws.accel[i];
        let vc = if current {
            body_current(v, ws, opts, i)
        } else {
            Vec3::zeros()
        };
        let vr = Vec6::new(
            vi[0] - vc.x,
            vi[1] - vc.y,
            vi[2] - vc.z,
            vi[3],
            vi[4],
            vi[5],
        );
        let mut f;
        if opts.added_mass {
            f = ws.i_tot[i] * ai;
            if current {
                let ma = &ws.m_a[i];
                f += cross_force(&vi, &(ws.i_rb[i] * vi));
                f += cross_force(&vr, &(ma * vr));
                let wv = ang(&vi).cross(&vc);
                f += ma.fixed_view::<6, 3>(0, 0) * wv;
            } else {
                f += cross_force(&vi, &(ws.i_tot[i] * vi));
            }
        } else {
            f = ws.i_rb[i] * ai + cross_force(&vi, &(ws.i_rb[i] * vi));
        }
        if opts.drag {
            f -= ws.damping[i].wrench(&vr);
        }
        if opts.restoring {
            f -= ws.restoring[i].wrench(&ws.r_ii[i]);
        }
        ws.force[i] = f;
    }
}

/// Backward pass: accumulate the body wrenches `ws.force` down the chain into generalised
/// forces `out = Σ J_g,iᵀ f_i` — joint `k`: `s_iᵀ f_i` of the subtree; base: the subtree
/// wrench in `F_b`. Consumes `ws.force` (it holds subtree wrenches afterwards).
fn backward_pass(v: &Vehicle, ws: &mut DynWorkspace, out: &mut [f64]) {
    assert_eq!(out.len(), v.n_dof(), "generalised force length");
    for i in (1..ws.force.len()).rev() {
        let f = ws.force[i];
        out[6 + i - 1] = v.joints[i - 1].axis.dot(&ang(&f));
        let fp = ws.g_up[i].wrench_to_parent(&f);
        ws.force[i - 1] += fp;
    }
    let fb = ws.g_up[0].wrench_to_parent(&ws.force[0]);
    out[..6].copy_from_slice(fb.as_slice());
}

fn needs_orientation(opts: &DynOptions) -> bool {
    opts.restoring || opts.current
}

// ---------------------------------------------------------------------------------------
// Public algorithms.

/// Mass matrix `M(q) = Σ_i J_g,iᵀ (I_RB,i + M_A,i) J_g,i` (USM-22; without `M_A` when
/// `opts.added_mass` is off) by the composite-rigid-body algorithm, into `ws.mass`
/// ((6+n)×(6+n), base block in `F_b`). `q`: joint angles [rad]. Independent of the base pose.
pub fn mass_matrix(v: &Vehicle, ws: &mut DynWorkspace, q: &[f64], opts: &DynOptions) {
    position_pass(v, ws, q);
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
    position_pass(v, ws, q);
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
        orientation_pass(ws, pose);
    }
    forward_pass(v, ws, zeta, None);
    body_forces(v, ws, opts);
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
    position_pass(v, ws, q);
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
    position_pass(v, ws, q);
    if needs_orientation(opts) {
        orientation_pass(ws, pose);
    }
    forward_pass(v, ws, zeta, Some(zeta_dot));
    body_forces(v, ws, opts);
    backward_pass(v, ws, tau);
}

/// In-place right-looking Cholesky `A = LLᵀ` of an n×n matrix stored column-major (only
/// the lower triangle `a[c·n + r]`, `r ≥ c`, is read and overwritten by L;
/// `inv_diag[j] = 1/L_jj`). The trailing update runs down contiguous columns with
/// independent elements, so it vectorises (about twice as fast as dot-product forms at
/// n = 14). `Err((j, d))` if pivot `j` is `d ≤ tol` or not finite, with
/// `tol = n·ε·max|A_jj|` (pivots below it are rounding noise: A is numerically singular).
fn cholesky_in_place(a: &mut [f64], n: usize, inv_diag: &mut [f64]) -> Result<(), (usize, f64)> {
    let mut max_diag: f64 = 0.0;
    for j in 0..n {
        max_diag = max_diag.max(a[j * n + j].abs());
    }
    let tol = n as f64 * f64::EPSILON * max_diag;
    for j in 0..n {
        let (left, right) = a.split_at_mut((j + 1) * n);
        let col_j = &mut left[j * n..];
        let d = col_j[j];
        // (NaN fails `d > tol` too.)
        if d.partial_cmp(&tol) != Some(std::cmp::Ordering::Greater) || !d.is_finite() {
            return Err((j, d));
        }
        let d = d.sqrt();
        let inv = 1.0 / d;
        col_j[j] = d;
        inv_diag[j] = inv;
        for x in &mut col_j[j + 1..] {
            *x *= inv;
        }
        let col_j = &left[j * n..];
        for k in j + 1..n {
            let l_kj = col_j[k];
            let off = (k - j - 1) * n;
            for (x, l) in right[off + k..off + n].iter_mut().zip(&col_j[k..]) {
                *x -= l * l_kj;
            }
        }
    }
    Ok(())
}

/// Solve `L Lᵀ x = b` in place (`x` overwrites `b`), L column-major from
/// [`cholesky_in_place`].
fn cholesky_solve(l: &[f64], inv_diag: &[f64], n: usize, b: &mut [f64]) {
    for j in 0..n {
        let y = b[j] * inv_diag[j];
        b[j] = y;
        for (x, l) in b[j + 1..].iter_mut().zip(&l[j * n + j + 1..(j + 1) * n]) {
            *x -= l * y;
        }
    }
    for i in (0..n).rev() {
        let s: f64 = l[i * n + i + 1..(i + 1) * n]
            .iter()
            .zip(&b[i + 1..])
            .map(|(l, x)| l * x)
            .sum();
        b[i] = (b[i] - s) * inv_diag[i];
    }
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
    cholesky_in_place(&mut ws.chol, nv, &mut ws.inv_diag).map_err(|(j, d)| {
        DynError::new(
            "mass_matrix",
            format!("is singular or not positive definite (Cholesky pivot {j} = {d:e})"),
        )
    })?;
    cholesky_solve(&ws.chol, &ws.inv_diag, nv, &mut ws.rhs);
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
/// `M_11 V̇_b = τ_b − M_12 q̈ − h_1` (SPEC §4, 6×6 Cholesky); the joint torques are recovered
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
    let m = &ws.mass;
    let m11 = Matrix6::from_fn(|r, c| m[(r, c)]);
    let mut rhs = Vector6::zeros();
    for r in 0..6 {
        let mut s = q_ext[r] - ws.bias[r];
        for (k, a) in qdd.iter().enumerate() {
            s -= m[(r, 6 + k)] * a;
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
            s += m[(6 + k, c)] * vdot[c];
        }
        for (l, a) in qdd.iter().enumerate() {
            s += m[(6 + k, 6 + l)] * a;
        }
        ws.joint_torque[k] = s;
    }
    check_finite("base_acceleration", &ws.zeta_dot[..6])?;
    check_finite("joint_torques", &ws.joint_torque)
}

/// Hybrid dynamics (SPEC §4, ideal servos): prescribed joint accelerations `qdd`
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
/// forces when the fluid is at rest (SPEC §4).
pub fn spatial_momentum(
    v: &Vehicle,
    ws: &mut DynWorkspace,
    pose: &BasePose,
    q: &[f64],
    zeta: &[f64],
    opts: &DynOptions,
) -> Vec6 {
    position_pass(v, ws, q);
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
    position_pass(v, ws, q);
    orientation_pass(ws, pose);
    for i in 0..ws.force.len() {
        ws.force[i] = ws.restoring[i].wrench(&ws.r_ii[i]);
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
    position_pass(v, ws, q);
    if opts.current {
        orientation_pass(ws, pose);
    }
    forward_pass(v, ws, zeta, None);
    for i in 0..ws.force.len() {
        let vc = body_current(v, ws, opts, i);
        let vi = ws.twist[i];
        let vr = Vec6::new(
            vi[0] - vc.x,
            vi[1] - vc.y,
            vi[2] - vc.z,
            vi[3],
            vi[4],
            vi[5],
        );
        ws.force[i] = ws.damping[i].wrench(&vr);
    }
    backward_pass(v, ws, out);
}
