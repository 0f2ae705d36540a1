//! The workspace of the dynamics algorithms (Pinocchio's `Data`): every mutable quantity of
//! [`super::algorithms`] lives here, sized once per vehicle, so that no algorithm allocates.
//!
//! Frames and names: `kin.g_up[i]` is body `i` in its parent's frame (body 0: in the base
//! frame `F_b`); `kin.g_b[i]` is body `i` in `F_b`; `r_ii[i]` is body `i`'s orientation in
//! the inertial frame `R_Ii`; `twist[i]`, `accel[i]`, `force[i]` are body `i`'s twist
//! `[v; ω]`, spatial acceleration and wrench `[f; m]`, all in body `i`'s own frame (moments
//! about its origin). Generalised vectors are ordered `[base (6, in F_b); joints (n)]`.

use super::hydro::{DampingKernel, HullSite, Restoring};
use super::structure::is_axial;
use crate::kinematics::KinWorkspace;
use crate::model::Vehicle;
use crate::spatial::{Mat3, Mat6, Vec3, Vec6};
use faer::Mat;
use nalgebra::{Matrix6, Vector6};

/// Preallocated workspace of the dynamics algorithms for one vehicle (Pinocchio's `Data`).
///
/// Built by [`DynWorkspace::new`] from a vehicle; constant per-body quantities (spatial
/// inertias and their sparsity, hydrodynamic kernels, the joints' shapes) are resolved then,
/// so rebuild the workspace if the vehicle changes, and treat the per-body inertias as
/// read-only. Results of the last call stay readable in the public fields.
#[derive(Clone, Debug)]
pub struct DynWorkspace {
    /// Kinematic quantities at the last configuration, filled by the one position pass
    /// [`forward_kinematics`](crate::kinematics::forward_kinematics): `g_up` (body `i` in its
    /// parent's frame), `g_b`, joint twists in `F_b`, `g_be`.
    pub kin: KinWorkspace,
    /// Body orientations in the inertial frame `R_Ii = R_Ib R_bi` (refreshed only by calls
    /// that take a base pose and use the current; the restoring forces need only the last
    /// rows, which every call with restoring forces refreshes in `up`).
    pub r_ii: Vec<Mat3>,
    /// The inertial vertical `e_z` in each body's frame, the last row of `R_Ii`.
    pub(super) up: Vec<Vec3>,
    /// Rigid-body spatial inertia `I_RB,i` about body `i`'s origin, in its frame.
    pub i_rb: Vec<Mat6>,
    /// Added-mass spatial inertia `M_A,i` about body `i`'s origin, in its frame.
    pub m_a: Vec<Mat6>,
    /// `I_RB,i + M_A,i`.
    pub i_tot: Vec<Mat6>,
    /// Whether `i_rb[i]`, `m_a[i]`, `i_tot[i]` are axial (`structure::is_axial`: the passes
    /// skip their exact zeros).
    pub(super) axial: Vec<AxialInertias>,
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
    /// Mass matrix `M(q)` (USM-22), (6+n)×(6+n), from [`mass_matrix`](super::mass_matrix) /
    /// [`dynamics_terms`](super::dynamics_terms).
    pub mass: Mat<f64>,
    /// Bias forces `h = C ζ + D ζ + N` (6+n), from [`bias`](super::bias) /
    /// [`dynamics_terms`](super::dynamics_terms).
    pub bias: Vec<f64>,
    /// Generalised acceleration `ζ̇ = [V̇_b; q̈]` from
    /// [`forward_dynamics`](super::forward_dynamics) /
    /// [`hybrid_dynamics`](super::hybrid_dynamics).
    pub zeta_dot: Vec<f64>,
    /// Joint torques recovered by [`hybrid_dynamics`](super::hybrid_dynamics) [N·m].
    pub joint_torque: Vec<f64>,
    /// Articulated-body inertias `I^A_i` (body frames) of the O(n) forward dynamics.
    pub(super) art_inertia: Vec<Mat6>,
    /// Velocity-product accelerations `c_i = V_i × s_i q̇_k` (body frames, ABA).
    pub(super) vp_accel: Vec<Vec6>,
    /// `U_i = I^A_i s_i` of body `i`'s joint (ABA).
    pub(super) aba_u: Vec<Vec6>,
    /// `1 / D_i = 1 / (s_iᵀ I^A_i s_i)` (ABA).
    pub(super) aba_dinv: Vec<f64>,
    /// `u_i = τ_k − s_iᵀ p^A_i` (ABA).
    pub(super) aba_force: Vec<f64>,
    /// `F_k = Ic_{k+1} S_k` in `F_b`, one per joint (the composite-inertia columns of the
    /// O(n) hybrid dynamics).
    pub(super) comp_twist: Vec<Vec6>,
    /// Thrust wrench of each body in `F_b` (the simulator's O(n + m) generalised thrust).
    pub(super) thrust_body: Vec<Vec6>,
    /// Cholesky factor scratch, column-major lower triangle (`crate::linalg::factor`).
    pub(super) chol: Vec<f64>,
    /// Right-hand-side scratch (6+n).
    pub(super) rhs: Vec<f64>,
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
        let i_tot: Vec<Mat6> = i_rb.iter().zip(&m_a).map(|(a, b)| a + b).collect();
        let axial = (0..nb)
            .map(|i| AxialInertias {
                rigid: is_axial(&i_rb[i]),
                added: is_axial(&m_a[i]),
                total: is_axial(&i_tot[i]),
            })
            .collect();
        Self {
            kin: KinWorkspace::new(v),
            r_ii: vec![Mat3::identity(); nb],
            up: vec![Vec3::z(); nb],
            i_rb,
            m_a,
            i_tot,
            axial,
            // A serial chain, tail to head: only the tail's rear face and the head's front
            // face are free (where lift may act, `CylinderDrag::lift`); the chain-level
            // quantities of the hull drag are read here once (`HullSite`).
            damping: v
                .bodies
                .iter()
                .zip(HullSite::of_chain(v))
                .map(|(b, site)| DampingKernel::of(b, rho, &site))
                .collect(),
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
            art_inertia: vec![Mat6::zeros(); nb],
            vp_accel: vec![Vec6::zeros(); nb],
            aba_u: vec![Vec6::zeros(); nb],
            aba_dinv: vec![0.0; nb],
            aba_force: vec![0.0; nb],
            comp_twist: vec![Vec6::zeros(); v.n_joints()],
            thrust_body: vec![Vec6::zeros(); nb],
            chol: vec![0.0; nv * nv],
            rhs: vec![0.0; nv],
        }
    }

    /// The same workspace with the dense products everywhere (no axial inertia or joint),
    /// for tests of the structured kernels.
    #[cfg(test)]
    pub(crate) fn dense(mut self) -> Self {
        self.axial.fill(AxialInertias::default());
        self.kin = self.kin.dense();
        self
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

/// Which of a body's spatial inertias are axial (`structure::is_axial`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct AxialInertias {
    /// `I_RB`.
    pub rigid: bool,
    /// `M_A`.
    pub added: bool,
    /// `I_RB + M_A`.
    pub total: bool,
}
