//! The floating multibody chain as discrete dynamics (docs/ocp.md §2): symplectic Euler on
//! the base pose's Lie group, base-wrench actuation.
//!
//! State representation (nq = 13 + 2n): `[p (3), Q (4: w, i, j, k), q (n), V_b (6), q̇ (n)]`
//! — base position in the inertial frame [m], unit quaternion `R_Ib`, joint angles [rad],
//! base twist `V_b = [v; ω]` in `F_b` [m/s, rad/s], joint rates [rad/s]. Tangent
//! (nx = 12 + 2n): `[δp, δθ, δq, δV, δq̇]`, with the retraction `p ⊕ δp = p + R δp`,
//! `R ⊕ δθ = R Exp(δθ)` (both in `F_b`, ℝ³ × SO(3)) and plain addition for the rest.
//!
//! Controls, by actuation: base wrench (nu = 6 + n): the base wrench `[f; m]` in `F_b`
//! [N, N·m] about the base origin and the joint torques [N·m] — the generalised force `τ` of
//! USM-19 directly (idealised actuation for comparison with rigid-body tools); thrusters
//! (nu = m + n, [`ChainModel::with_thrusters`]): the thrust of each of the m thrusters [N]
//! and the joint torques, `τ = G(q) u_T + [0; τ_q]` with `G` the generalised thrust map
//! (USM-25/26 extended to the joints, [`generalized_thrust_map`]: base rows `T(q)`).
//!
//! Step (symplectic Euler, as Crocoddyl's `IntegratedActionModelEuler` with Pinocchio's
//! free-flyer `integrate`): `ζ̇ = M(q)⁻¹(τ − h(q, ζ))` (USM-19, [`forward_dynamics`], CRBA +
//! Cholesky; hydrodynamics per [`DynOptions`]), `ζ⁺ = ζ + Δt ζ̇`, `g⁺ = g Exp_SE(3)(Δt V_b⁺)`,
//! `q⁺ = q + Δt q̇⁺`.
//!
//! Terminal equality ([`TerminalSpec`], rows in this order, each optional): end-effector
//! origin at a target (3, inertial [m]), end-effector orientation (3: `Log(R_tᵀ R_Ie)` [rad]),
//! base position (3, inertial [m]), base orientation (3: `Log(R_tᵀ R_Ib)`), joint angles (n
//! [rad]), base twist and joint rates zero (6 + n). [`ChainModel::new`] sets the end-effector
//! position and the velocities (nc = 9 + n).
//!
//! Path costs beyond the quadratic effort ([`PathCosts`], docs/ocp.md §1): thruster energy,
//! joint energy and the joint-limit barrier, analytic in `(q, q̇, u)`.
//!
//! Derivatives: the trait's central and second differences (ε = 1e-6, 1e-4 in tangent
//! coordinates), evaluated by the structured differences of [`super::derivatives`] — the same
//! numbers with the dynamics terms each perturbation leaves unchanged reused — not yet
//! analytic nor automatic (docs/ocp.md §2, §5).
// Stage and component loops read clearest with indices (k: knot, i: component).
#![allow(clippy::needless_range_loop)]

use super::cost::PathCosts;
use super::model::{FdScratch, ModelError, OcpModel};
use super::sigma_floor::SigmaFloor;
use super::sub_scratch::SubScratch;
use crate::dynamics::{dynamics_terms, solve_forward, DynOptions, DynWorkspace};
use crate::kinematics::{forward_kinematics, generalized_thrust_map, BasePose};
use crate::model::Vehicle;
use crate::spatial::{ang, lin, skew, Mat3, Vec3, Vec6};
use nalgebra::{DMatrix, Quaternion, Rotation3, UnitQuaternion};

/// The terminal equality's rows (module documentation); `None`: that row group is free.
#[derive(Clone, Debug, Default)]
pub struct TerminalSpec {
    /// End-effector origin, inertial [m].
    pub ee_position: Option<Vec3>,
    /// End-effector orientation `R_Ie`.
    pub ee_rotation: Option<Mat3>,
    /// Base origin, inertial [m].
    pub base_position: Option<Vec3>,
    /// Base orientation `R_Ib`.
    pub base_rotation: Option<Mat3>,
    /// Joint angles [rad] (n).
    pub joint_angles: Option<Vec<f64>>,
    /// Base twist and joint rates zero.
    pub zero_velocity: bool,
}

impl TerminalSpec {
    /// Number of rows for `n` joints.
    pub fn rows(&self, n: usize) -> usize {
        let three = [
            self.ee_position.is_some(),
            self.ee_rotation.is_some(),
            self.base_position.is_some(),
            self.base_rotation.is_some(),
        ];
        3 * three.iter().filter(|b| **b).count()
            + self.joint_angles.as_ref().map_or(0, |_| n)
            + if self.zero_velocity { 6 + n } else { 0 }
    }
}

/// `Log(R_tᵀ R)` [rad] (the rotation from the target to `r`, in the target's frame).
fn rotation_error(target: &Mat3, r: &Mat3) -> Vec3 {
    Rotation3::from_matrix_unchecked(target.transpose() * r).scaled_axis()
}

/// The chain's discrete dynamics and terminal constraint.
#[derive(Clone, Debug)]
pub struct ChainModel {
    pub(super) vehicle: Vehicle,
    pub(super) ws: DynWorkspace,
    pub(super) opts: DynOptions,
    dt: f64,
    /// Symplectic Euler steps per interval (docs/ocp.md §2, "Substeps") and their length
    /// `h = Δt / substeps` [s].
    substeps: usize,
    h: f64,
    /// Scratch of the composite step and its chained Jacobians (`substeps > 1`).
    sub: SubScratch,
    terminal: TerminalSpec,
    costs: Option<PathCosts>,
    /// The σ_min floor's barrier ([`SigmaFloor`], docs/ocp.md §1), if any.
    sigma: Option<SigmaFloor>,
    tau: Vec<f64>,
    zeta: Vec<f64>,
    /// Thruster actuation: the generalised thrust map G(q), (6+n)×m (None: base wrench).
    pub(super) gmap: Option<faer::Mat<f64>>,
    /// Scratch of the structured differences ([`super::derivatives`]).
    pub(super) fd: FdScratch,
}

impl ChainModel {
    /// The chain of `vehicle` with physics `opts`, step `dt` [s] and end-effector target
    /// `target` (inertial frame [m]).
    pub fn new(vehicle: Vehicle, opts: DynOptions, dt: f64, target: Vec3) -> Self {
        let ws = DynWorkspace::new(&vehicle);
        let nv = vehicle.n_dof();
        Self {
            vehicle,
            ws,
            opts,
            dt,
            substeps: 1,
            h: dt,
            sub: SubScratch::default(),
            terminal: TerminalSpec {
                ee_position: Some(target),
                zero_velocity: true,
                ..TerminalSpec::default()
            },
            costs: None,
            sigma: None,
            tau: vec![0.0; nv],
            zeta: vec![0.0; nv],
            gmap: None,
            fd: FdScratch::default(),
        }
    }

    /// The same chain with each interval Δt integrated by `substeps` (≥ 1) symplectic Euler
    /// steps of `h = Δt / substeps` under the interval's constant control (docs/ocp.md §2,
    /// "Substeps"): `f = f_h ∘ ⋯ ∘ f_h`. One substep is the plain step, bit for bit.
    pub fn with_substeps(mut self, substeps: usize) -> Self {
        self.substeps = substeps.max(1);
        self.h = self.dt / self.substeps as f64;
        self
    }

    /// Symplectic Euler steps per interval.
    pub fn substeps(&self) -> usize {
        self.substeps
    }

    /// The same model on intervals of `dt` [s], keeping the number of substeps per interval
    /// (the refined integration of [`super::fidelity`]).
    pub(super) fn with_interval(mut self, dt: f64) -> Self {
        self.dt = dt;
        self.h = dt / self.substeps as f64;
        self
    }

    /// The generalised force `τ` [N, N·m] (6 + n: base wrench in `F_b`, joint torques) of the
    /// last plain step or substep (`τ = G(q) u_T + [0; τ_q]`, or `τ = u`).
    pub(super) fn last_actuation(&self) -> &[f64] {
        &self.tau
    }

    /// Kinetic energy `½ ζᵀ M(q) ζ` [J] of the state `x` (rigid bodies and, with the
    /// hydrodynamics, the added mass; docs/ocp.md §4, eq. (F3)).
    pub fn kinetic_energy(&mut self, x: &[f64]) -> f64 {
        self.load_terms(x);
        let n = self.n_joints();
        let z = &x[7 + n..13 + 2 * n];
        let m = &self.ws.mass;
        let mut e = 0.0;
        // M's lower triangle is the one kept (column-major, as `solve_forward` reads it).
        for c in 0..z.len() {
            e += 0.5 * m[(c, c)] * z[c] * z[c];
            for r in c + 1..z.len() {
                e += m[(r, c)] * z[r] * z[c];
            }
        }
        e
    }

    /// The same chain actuated by its thrusters and joint torques (controls
    /// `[u_1 … u_m, τ_1 … τ_n]`, see the module documentation).
    pub fn with_thrusters(mut self) -> Self {
        let nv = self.vehicle.n_dof();
        self.gmap = Some(faer::Mat::zeros(nv, self.vehicle.n_thrusters()));
        self
    }

    /// The same chain with the terminal equality `terminal` instead.
    pub fn with_terminal(mut self, terminal: TerminalSpec) -> Self {
        self.terminal = terminal;
        self
    }

    /// The same chain with the path costs `costs` added to the objective.
    pub fn with_costs(mut self, costs: PathCosts) -> Self {
        self.costs = Some(costs);
        self
    }

    /// The path costs, if any.
    pub fn costs(&self) -> Option<&PathCosts> {
        self.costs.as_ref()
    }

    /// The same chain with the σ_min floor `floor` (its barrier (Σ2) at every knot; docs/ocp.md
    /// §1).
    pub fn with_sigma_floor(mut self, floor: SigmaFloor) -> Self {
        self.sigma = Some(floor);
        self
    }

    /// The σ_min floor, if any.
    pub fn sigma_floor(&self) -> Option<&SigmaFloor> {
        self.sigma.as_ref()
    }

    /// The least commanded-axis σ_min of the floor's scaled `T(q)` over the knots `xs`
    /// (`None` without a floor).
    pub fn least_sigma(&mut self, xs: &[Vec<f64>]) -> Option<f64> {
        let v = &self.vehicle;
        self.sigma.as_mut().map(|f| f.least_along(v, xs))
    }

    /// The σ floor's barrier (Σ2) at the state `x` (0 without a floor).
    fn sigma_barrier(&mut self, x: &[f64]) -> f64 {
        let n = self.n_joints();
        let (v, dt) = (&self.vehicle, self.dt);
        self.sigma
            .as_mut()
            .map_or(0.0, |f| f.value(v, dt, &x[7..7 + n]))
    }

    /// Add the σ floor's gradient and Gauss–Newton Hessian (Σ4) at the state `x`.
    fn sigma_derivatives(&mut self, x: &[f64], g: &mut [f64], h: &mut DMatrix<f64>) {
        let n = self.n_joints();
        let (v, dt) = (&self.vehicle, self.dt);
        if let Some(f) = self.sigma.as_mut() {
            f.add_derivatives(v, dt, &x[7..7 + n], g, h);
        }
    }

    /// The terminal equality.
    pub fn terminal_spec(&self) -> &TerminalSpec {
        &self.terminal
    }

    /// Step Δt [s].
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Whether the controls are thrusts (else a base wrench) before the joint torques.
    pub fn thruster_actuated(&self) -> bool {
        self.gmap.is_some()
    }

    /// Number of controls before the joint torques (m thrusters, or 6 wrench components).
    pub fn n_body_controls(&self) -> usize {
        self.gmap.as_ref().map_or(6, |g| g.ncols())
    }

    /// The vehicle.
    pub fn vehicle(&self) -> &Vehicle {
        &self.vehicle
    }

    /// Number of joints n.
    pub fn n_joints(&self) -> usize {
        self.vehicle.n_joints()
    }

    /// The representation of a state: pose, joint angles, base twist, joint rates.
    pub fn pack(pose: &BasePose, q: &[f64], twist: &[f64], qd: &[f64]) -> Vec<f64> {
        let quat = pose.orientation.quaternion();
        let mut x = Vec::with_capacity(13 + 2 * q.len());
        x.extend_from_slice(pose.position.as_slice());
        x.extend_from_slice(&[quat.w, quat.i, quat.j, quat.k]);
        x.extend_from_slice(q);
        x.extend_from_slice(twist);
        x.extend_from_slice(qd);
        x
    }

    /// The base pose of a state representation.
    pub fn pose(x: &[f64]) -> BasePose {
        BasePose {
            position: Vec3::new(x[0], x[1], x[2]),
            orientation: UnitQuaternion::new_normalize(Quaternion::new(x[3], x[4], x[5], x[6])),
        }
    }

    /// End-effector origin in the inertial frame [m] at state `x`.
    pub fn ee_position(&mut self, x: &[f64]) -> Vec3 {
        let n = self.n_joints();
        forward_kinematics(&self.vehicle, &x[7..7 + n], &mut self.ws.kin);
        let pose = Self::pose(x);
        pose.position + pose.orientation * self.ws.kin.g_be.p
    }

    /// End-effector pose in the inertial frame at state `x` (rotation, position).
    pub fn ee_pose(&mut self, x: &[f64]) -> (Mat3, Vec3) {
        let n = self.n_joints();
        forward_kinematics(&self.vehicle, &x[7..7 + n], &mut self.ws.kin);
        let pose = Self::pose(x);
        let r = *pose.orientation.to_rotation_matrix().matrix();
        (
            r * self.ws.kin.g_be.r,
            pose.position + r * self.ws.kin.g_be.p,
        )
    }
}

impl ChainModel {
    /// Axial inflow `V_a` [m/s] of every thruster at state `x` for thrusts `thrust` [N], as
    /// the closed loop's recorder computes it (docs/model.md §6): the thruster point's
    /// velocity relative to the water projected on `sign(u_j) d_j`.
    pub fn thruster_inflows(&mut self, x: &[f64], thrust: &[f64]) -> Vec<f64> {
        let n = self.n_joints();
        forward_kinematics(&self.vehicle, &x[7..7 + n], &mut self.ws.kin);
        let pose = Self::pose(x);
        let water_b = pose
            .orientation
            .inverse_transform_vector(&self.vehicle.fluid.current);
        let base = Vec6::from_column_slice(&x[7 + n..13 + n]);
        let qd = &x[13 + n..13 + 2 * n];
        let kin = &self.ws.kin;
        let th = self.vehicle.thrusters.iter().zip(thrust);
        th.map(|(t, u)| {
            let g = &kin.g_b[t.body];
            let mut tw = base;
            for (xi, r) in kin.joint_twist_b.iter().zip(qd).take(t.body) {
                tw += xi * *r;
            }
            let v_rel = lin(&tw) + ang(&tw).cross(&g.act_point(&t.position)) - water_b;
            u.signum() * g.act_vector(&t.direction).dot(&v_rel)
        })
        .collect()
    }
}

/// `Exp` of SO(3) and the left Jacobian `J(φ)` of SE(3)'s exponential:
/// `Exp_SE(3)([v; φ]) = (Exp(φ), J(φ) v)`, `J = I + (1−cos θ)/θ² [φ]× + (θ−sin θ)/θ³ [φ]×²`
/// (series below θ = 1e-4).
fn se3_exp_parts(v: &Vec3, phi: &Vec3) -> (UnitQuaternion<f64>, Vec3) {
    let th = phi.norm();
    let k = skew(phi);
    let (a, b) = if th < 1e-4 {
        let t2 = th * th;
        (0.5 - t2 / 24.0, 1.0 / 6.0 - t2 / 120.0)
    } else {
        (
            (1.0 - th.cos()) / (th * th),
            (th - th.sin()) / (th * th * th),
        )
    };
    let j = Mat3::identity() + k * a + k * k * b;
    (UnitQuaternion::from_scaled_axis(*phi), j * v)
}

impl ChainModel {
    /// Load the dynamics terms at state `x` into the workspace: `M(q)`, `h(q, ζ)` (USM-19,
    /// [`dynamics_terms`]) and, with thruster actuation, `G(q)` ([`generalized_thrust_map`]).
    pub(super) fn load_terms(&mut self, x: &[f64]) {
        let n = self.n_joints();
        let pose = Self::pose(x);
        self.zeta.copy_from_slice(&x[7 + n..13 + 2 * n]);
        dynamics_terms(
            &self.vehicle,
            &mut self.ws,
            &pose,
            &x[7..7 + n],
            &self.zeta,
            &self.opts,
        );
        if let Some(g) = self.gmap.as_mut() {
            // The kinematics of q are in ws.kin.
            generalized_thrust_map(&self.vehicle, &self.ws.kin, g);
        }
    }

    /// `out = f(x, u)` from the terms in the workspace (loaded for a state with the same
    /// terms as `x`, [`ChainModel::load_terms`]): `τ = G u_T + [0; τ_q]` (or `τ = u`),
    /// `ζ̇ = M⁻¹(τ − h)`, then the symplectic Euler update of the module documentation.
    pub(super) fn finish_step(
        &mut self,
        x: &[f64],
        u: &[f64],
        out: &mut [f64],
    ) -> Result<(), ModelError> {
        let n = self.n_joints();
        let pose = Self::pose(x);
        let q = &x[7..7 + n];
        self.zeta.copy_from_slice(&x[7 + n..13 + 2 * n]);
        match self.gmap.as_ref() {
            None => self.tau.copy_from_slice(u),
            Some(g) => {
                let m = g.ncols();
                for r in 0..6 + n {
                    let mut v = if r >= 6 { u[m + r - 6] } else { 0.0 };
                    for j in 0..m {
                        v += g[(r, j)] * u[j];
                    }
                    self.tau[r] = v;
                }
            }
        }
        solve_forward(&mut self.ws, &self.tau).map_err(|e| ModelError(e.to_string()))?;
        let dt = self.h;
        for (z, a) in self.zeta.iter_mut().zip(&self.ws.zeta_dot) {
            *z += dt * a;
        }
        let v = Vec3::new(self.zeta[0], self.zeta[1], self.zeta[2]) * dt;
        let w = Vec3::new(self.zeta[3], self.zeta[4], self.zeta[5]) * dt;
        let (dr, dp) = se3_exp_parts(&v, &w);
        let p = pose.position + pose.orientation * dp;
        let r = pose.orientation * dr;
        let quat = r.quaternion();
        out[..3].copy_from_slice(p.as_slice());
        out[3..7].copy_from_slice(&[quat.w, quat.i, quat.j, quat.k]);
        for k in 0..n {
            out[7 + k] = q[k] + dt * self.zeta[6 + k];
        }
        out[7 + n..13 + 2 * n].copy_from_slice(&self.zeta);
        Ok(())
    }
}

impl OcpModel for ChainModel {
    fn nq(&self) -> usize {
        13 + 2 * self.n_joints()
    }
    fn nx(&self) -> usize {
        12 + 2 * self.n_joints()
    }
    fn nu(&self) -> usize {
        self.n_body_controls() + self.n_joints()
    }
    fn nc(&self) -> usize {
        self.terminal.rows(self.n_joints())
    }

    fn step(&mut self, x: &[f64], u: &[f64], out: &mut [f64]) -> Result<(), ModelError> {
        if self.substeps == 1 {
            self.load_terms(x);
            return self.finish_step(x, u, out);
        }
        let mut s = std::mem::take(&mut self.sub);
        let r = self.substep_chain(x, u, out, &mut s);
        self.sub = s;
        r
    }

    fn jacobians(
        &mut self,
        x: &[f64],
        u: &[f64],
        a: &mut DMatrix<f64>,
        b: &mut DMatrix<f64>,
    ) -> Result<(), ModelError> {
        if self.substeps == 1 {
            return self.structured_jacobians(x, u, a, b);
        }
        let mut s = std::mem::take(&mut self.sub);
        let r = self.chained_jacobians(x, u, a, b, &mut s);
        self.sub = s;
        r
    }

    fn weighted_hessian(
        &mut self,
        x: &[f64],
        u: &[f64],
        w: &[f64],
        h: &mut DMatrix<f64>,
    ) -> Result<(), ModelError> {
        if self.substeps == 1 {
            return self.structured_hessian(x, u, w, h);
        }
        let mut s = std::mem::take(&mut self.sub);
        let r = self.chained_hessian(x, u, w, h, &mut s);
        self.sub = s;
        r
    }

    fn retract(&self, x: &[f64], dx: &[f64], out: &mut [f64]) {
        let n = self.n_joints();
        let pose = Self::pose(x);
        let p = pose.position + pose.orientation * Vec3::new(dx[0], dx[1], dx[2]);
        let r = pose.orientation * UnitQuaternion::from_scaled_axis(Vec3::new(dx[3], dx[4], dx[5]));
        let quat = r.quaternion();
        out[..3].copy_from_slice(p.as_slice());
        out[3..7].copy_from_slice(&[quat.w, quat.i, quat.j, quat.k]);
        for i in 0..6 + 2 * n {
            out[7 + i] = x[7 + i] + dx[6 + i];
        }
    }

    fn difference(&self, x0: &[f64], x1: &[f64], out: &mut [f64]) {
        let n = self.n_joints();
        let (a, b) = (Self::pose(x0), Self::pose(x1));
        let dp = a.orientation.inverse() * (b.position - a.position);
        let dr = (a.orientation.inverse() * b.orientation).scaled_axis();
        out[..3].copy_from_slice(dp.as_slice());
        out[3..6].copy_from_slice(dr.as_slice());
        for i in 0..6 + 2 * n {
            out[6 + i] = x1[7 + i] - x0[7 + i];
        }
    }

    fn terminal(&mut self, x: &[f64], out: &mut [f64]) {
        let n = self.n_joints();
        let (r_e, p_e) = self.ee_pose(x);
        let pose = Self::pose(x);
        let r_b = *pose.orientation.to_rotation_matrix().matrix();
        let t = &self.terminal;
        let mut i = 0;
        let mut put = |v: &[f64]| {
            out[i..i + v.len()].copy_from_slice(v);
            i += v.len();
        };
        if let Some(p) = t.ee_position {
            put((p_e - p).as_slice());
        }
        if let Some(r) = t.ee_rotation {
            put(rotation_error(&r, &r_e).as_slice());
        }
        if let Some(p) = t.base_position {
            put((pose.position - p).as_slice());
        }
        if let Some(r) = t.base_rotation {
            put(rotation_error(&r, &r_b).as_slice());
        }
        if let Some(q) = &t.joint_angles {
            for k in 0..n {
                put(&[x[7 + k] - q[k]]);
            }
        }
        if t.zero_velocity {
            put(&x[7 + n..13 + 2 * n]);
        }
    }

    fn has_path_costs(&self) -> bool {
        self.costs.is_some() || self.sigma.is_some()
    }

    fn stage_cost(&mut self, x: &[f64], u: &[f64]) -> f64 {
        let n = self.n_joints();
        self.costs.as_ref().map_or(0.0, |c| c.stage(n, x, u)) + self.sigma_barrier(x)
    }

    fn stage_cost_derivatives(
        &mut self,
        x: &[f64],
        u: &[f64],
        exact: bool,
        g: &mut [f64],
        h: &mut DMatrix<f64>,
    ) {
        let n = self.n_joints();
        if let Some(c) = self.costs.as_ref() {
            c.stage_derivatives(n, x, u, exact, g, h);
        }
        self.sigma_derivatives(x, g, h);
    }

    fn max_step(&mut self, x: &[f64], dx: &[f64]) -> f64 {
        let n = self.n_joints();
        let a = self.costs.as_ref().map_or(1.0, |c| c.max_step(n, x, dx));
        let v = &self.vehicle;
        let b = self
            .sigma
            .as_mut()
            .map_or(1.0, |f| f.max_step(v, &x[7..7 + n], &dx[6..6 + n]));
        a.min(b)
    }

    fn terminal_cost(&mut self, x: &[f64]) -> f64 {
        let n = self.n_joints();
        self.costs.as_ref().map_or(0.0, |c| c.barrier(n, x)) + self.sigma_barrier(x)
    }

    fn terminal_cost_derivatives(&mut self, x: &[f64], g: &mut [f64], h: &mut DMatrix<f64>) {
        let n = self.n_joints();
        if let Some(c) = self.costs.as_ref() {
            c.barrier_derivatives(n, x, g, h);
        }
        self.sigma_derivatives(x, g, h);
    }
}
