//! Work mode (docs/model.md §5, USM section V-B, USM-42): end-effector pose regulation with the base
//! held at a home position in the null space, by SRMTP:
//!
//! `ζ_r = J_e^#(q) (V_e,d + k_e ẽ) + (I − J_e^# J_e) J_b⁺ k_b p̃_b`
//!
//! - `J_e` the end-effector Jacobian (6×(6+n), `F_e`, USM-18), `J_e^#` its weighted
//!   pseudoinverse with usage weights `U`, as printed: `U J_eᵀ (J_e U J_eᵀ)⁻¹` (docs/model.md §5 reads
//!   the paper's `W` as a usage weight). Damping is only a singularity-robust option: with
//!   `σ = σ_min(J_e U^{1/2})` below the singular region ε ([`WorkGains::singular_region`]),
//!   `J_e^# = U J_eᵀ (J_e U J_eᵀ + λ² I)⁻¹` with the variable damping
//!   `λ² = λ_max² (1 − (σ/ε)²)` ([`singularity_robust_damping`], as in Chiaverini 1997, after
//!   Nakamura & Hanafusa 1986), and the projector `I − J_e^# J_e` uses the same λ. The paper's
//!   usage weights exclude base roll (`U` = 0), so a straight body, which cannot roll its end
//!   effector with its joints, is such a singularity (σ = 0);
//! - `ẽ = [p̃_e; ε̃_e]` the end-effector pose error in `F_e` ([`super::kinematic::ee_pose_error`]),
//!   `V_e,d` the desired end-effector twist in `F_e` (zero for setpoints);
//! - `J_b = [R_Ib 0]` and `p̃_b = p_b,home − p_Ib` (inertial, m); `J_b⁺` is the plain
//!   pseudoinverse (damping [`WorkGains::base_task_damping`], default 0 — exact, `J_b` has full
//!   row rank);
//! - optionally (off by default, as in the paper) a set-based joint-limit task on top of both,
//!   and the paper's secondary objectives (manipulability, controllability:
//!   [`super::kinematic::SecondaryTasks`]) below both, `ζ_r += N_{e,b} [0; q̇_s]` at the joint
//!   references ([`WorkController::set_secondary`]).
//!
//! Outputs: the reference base twist `V_r` (in `F_b`) for the dynamic controller (USM-33/34) and
//! joint rate references `q̇_r`; the joint angle references `q_r` are their time integral, kept
//! in the controller and clamped to the joint limits.

use super::error::{check_nonneg, ControlError};
use super::kinematic::{
    base_position_jacobian, ee_pose, ee_pose_error, JointLimitSettings, JointLimitTask,
    SecondaryTasks, Srmtp, TaskInverse,
};
use crate::kinematics::{ee_jacobian, BasePose, KinWorkspace};
use crate::model::Vehicle;
use crate::spatial::{Vec3, Vec6};
use faer::Mat;
use nalgebra::{Matrix6, UnitQuaternion};
use serde::{Deserialize, Serialize};

/// Work-mode gains (USM-42, USM section VI-C). Defaults are the paper's values.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WorkGains {
    /// End-effector error gain `k_e` (diagonal; 1/s): `[0.2, 0.2, 0.2, 0.4, 0.4, 0.4]`.
    pub k_e: [f64; 6],
    /// Base position gain `k_b` (diagonal; 1/s): `[0.15, 0.15, 0.15]`.
    pub k_b: [f64; 3],
    /// Usage weights `U` (diagonal, 6+n entries, each ≥ 0). `None`: the paper's
    /// `[0.3, 0.3, 0.3, 0.0, 0.3, 0.3]` for the base (the zero excludes base roll), then 0.7 for
    /// the first two joints and 1 for the rest (for n = 8 exactly the paper's W).
    pub weights: Option<Vec<f64>>,
    /// Largest damping `λ_max` of `J_e^#` and of the null-space projector, applied only
    /// inside the singular region (see [`WorkGains::singular_region`]); 0 = USM-42 as printed
    /// everywhere. Default 0.1 (the paper's λ, given for the allocator).
    pub damping: f64,
    /// Singular region ε of the singularity-robust damping: `σ_min(J_e U^{1/2})` below which
    /// `J_e^#` is damped, `λ² = λ_max² (1 − (σ/ε)²)`; 0 = never (USM-42 as printed, which
    /// fails at the straight start); a large ε (1e9) damps by `λ_max` everywhere (the constant
    /// damping used before). Default 0.3 (inferred: on the paper design at `work-setpoint`,
    /// regions of 0.05–0.1 leave the undamped inverse to drive end-effector roll excursions of
    /// 30–110° with saturated thrusters; from 0.3 on the run is smooth and undamped ~90 % of
    /// the time).
    pub singular_region: f64,
    /// Damping of the base task's pseudoinverse `J_b⁺` (0: exact).
    pub base_task_damping: f64,
    /// Whether the base-position task is used (the paper: yes).
    pub base_task: bool,
    /// Set-based joint-limit task (off by default, as in the paper).
    pub joint_limits: JointLimitSettings,
}

impl Default for WorkGains {
    fn default() -> Self {
        Self {
            k_e: [0.2, 0.2, 0.2, 0.4, 0.4, 0.4],
            k_b: [0.15, 0.15, 0.15],
            weights: None,
            damping: 0.1,
            singular_region: 0.3,
            base_task_damping: 0.0,
            base_task: true,
            joint_limits: JointLimitSettings::default(),
        }
    }
}

impl WorkGains {
    /// The paper's usage weights for a design with `n` joints (see [`WorkGains::weights`]).
    pub fn paper_weights(n: usize) -> Vec<f64> {
        let mut u = vec![0.3, 0.3, 0.3, 0.0, 0.3, 0.3];
        u.extend((0..n).map(|i| if i < 2 { 0.7 } else { 1.0 }));
        u
    }

    /// The usage weights for `n` joints: the configured ones, or the paper's.
    pub fn weights_for(&self, n: usize) -> Vec<f64> {
        self.weights
            .clone()
            .unwrap_or_else(|| Self::paper_weights(n))
    }

    /// Check the values against a design with `n` joints; errors name `work.<key>`.
    pub fn validate(&self, n: usize) -> Result<(), ControlError> {
        for (i, k) in self.k_e.iter().enumerate() {
            check_nonneg(&format!("work.k_e[{i}]"), *k)?;
        }
        for (i, k) in self.k_b.iter().enumerate() {
            check_nonneg(&format!("work.k_b[{i}]"), *k)?;
        }
        if let Some(w) = &self.weights {
            if w.len() != 6 + n {
                return Err(ControlError::new(
                    "work.weights",
                    format!(
                        "has {} entries, the design needs 6 + {n} = {}",
                        w.len(),
                        6 + n
                    ),
                ));
            }
            for (i, x) in w.iter().enumerate() {
                check_nonneg(&format!("work.weights[{i}]"), *x)?;
            }
        }
        check_nonneg("work.damping", self.damping)?;
        check_nonneg("work.singular_region", self.singular_region)?;
        check_nonneg("work.base_task_damping", self.base_task_damping)?;
        self.joint_limits
            .validate()
            .map_err(|e| ControlError::new(format!("work.{}", e.key), e.message))
    }
}

/// Work-mode setpoint (USM-42).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorkTarget {
    /// Desired end-effector position `p_d` in `I` [m].
    pub ee_position: Vec3,
    /// Desired end-effector orientation `q_d` (maps `F_e,d` vectors to `I`).
    pub ee_orientation: UnitQuaternion<f64>,
    /// Desired end-effector twist `V_e,d` in `F_e` [m/s, rad/s] (zero for a setpoint).
    pub ee_twist: Vec6,
    /// Home position of the base origin `p_b,home` in `I` [m].
    pub base_position: Vec3,
}

/// Result of one work-mode step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorkOutput {
    /// Reference base twist `V_r = [v_r; ω_r]` in `F_b` [m/s, rad/s] (first 6 entries of `ζ_r`).
    pub v_r: Vec6,
    /// End-effector pose error `ẽ = [p̃_e; ε̃_e]` in `F_e` [m, —].
    pub ee_error: Vec6,
    /// Base position error `p̃_b` in `I` [m].
    pub base_error: Vec3,
    /// Number of joints held by the joint-limit task in this step.
    pub active_limits: usize,
    /// The damping λ of `J_e^#` in this step (0 outside the singular region).
    pub damping: f64,
}

/// The singularity-robust damping of a weighted pseudoinverse whose smallest weighted
/// singular value is `sigma`: `λ = λ_max √(1 − (σ/ε)²)` inside the singular region
/// `σ < ε`, 0 outside it (and for `ε = 0`).
pub fn singularity_robust_damping(sigma: f64, lambda_max: f64, region: f64) -> f64 {
    if sigma < region {
        lambda_max * (1.0 - (sigma / region).powi(2)).max(0.0).sqrt()
    } else {
        0.0
    }
}

/// The smallest singular value of `J U^{1/2}` for a 6-row `j` and usage weights `u`:
/// `√λ_min(J U Jᵀ)` (the conditioning that governs `J^#`). Allocation-free.
fn weighted_sigma_min(j: &Mat<f64>, u: &[f64]) -> f64 {
    let a: Matrix6<f64> =
        Matrix6::from_fn(|r, s| (0..j.ncols()).map(|c| j[(r, c)] * u[c] * j[(s, c)]).sum());
    a.symmetric_eigenvalues().min().max(0.0).sqrt()
}

/// The work-mode kinematic controller: SRMTP buffers, Jacobians and the joint-reference
/// integrator. Allocation-free per step after [`WorkController::new`].
#[derive(Clone, Debug)]
pub struct WorkController {
    n: usize,
    gains: WorkGains,
    limits: Vec<(f64, f64)>,
    srmtp: Srmtp,
    j_e: Mat<f64>,
    j_b: Mat<f64>,
    jl: JointLimitTask,
    q_ref: Vec<f64>,
    qd_ref: Vec<f64>,
    secondary: Option<Box<SecondaryTasks>>,
    secondary_zeta: Vec<f64>,
}

impl WorkController {
    /// Build for a design; the joint references start at zero (call [`WorkController::reset`]
    /// with the initial joint angles).
    pub fn new(v: &Vehicle, gains: &WorkGains) -> Result<Self, ControlError> {
        let n = v.n_joints();
        gains.validate(n)?;
        let weights = gains.weights_for(n);
        let max_rows = n + 6 + 3;
        Ok(Self {
            n,
            gains: gains.clone(),
            limits: v.joint_limits(),
            srmtp: Srmtp::new(6 + n, max_rows, &weights, gains.damping)?,
            j_e: Mat::zeros(6, 6 + n),
            j_b: Mat::zeros(3, 6 + n),
            jl: JointLimitTask::new(n, gains.joint_limits.clone()),
            q_ref: vec![0.0; n],
            qd_ref: vec![0.0; n],
            secondary: None,
            secondary_zeta: vec![0.0; 6 + n],
        })
    }

    /// Add the secondary objectives at the lowest priority (USM section IV-A objectives 2, 3):
    /// each step their joint velocity at the joint references `q_r` is projected into the null
    /// space of the end-effector and base tasks.
    pub fn set_secondary(&mut self, tasks: SecondaryTasks) {
        self.secondary = Some(Box::new(tasks));
    }

    /// The gains.
    pub fn gains(&self) -> &WorkGains {
        &self.gains
    }

    /// Restart the joint-reference integrator at `q` [rad] (clamped to the limits; ignored
    /// entries if the length differs).
    pub fn reset(&mut self, q: &[f64]) {
        for (i, r) in self.q_ref.iter_mut().enumerate() {
            let (lo, hi) = self.limits[i];
            *r = q.get(i).copied().unwrap_or(0.0).clamp(lo, hi);
        }
        self.qd_ref.fill(0.0);
    }

    /// Joint angle references `q_r` [rad] (the integral of `q̇_r`, clamped to the limits).
    pub fn q_ref(&self) -> &[f64] {
        &self.q_ref
    }

    /// Joint rate references `q̇_r` [rad/s] of the last step.
    pub fn qd_ref(&self) -> &[f64] {
        &self.qd_ref
    }

    /// The full resolved reference `ζ_r = [V_r; q̇_r]` of the last step.
    pub fn zeta_r(&self) -> &[f64] {
        self.srmtp.zeta()
    }

    /// Counters of regularised / failed pseudoinverse factorisations (numerical warnings).
    pub fn warnings(&self) -> (u64, u64) {
        self.srmtp.pinv_stats()
    }

    /// Resolve USM-42 at the measured configuration without advancing the integrator.
    /// `base` is the measured base pose, `ws` a workspace after
    /// [`crate::kinematics::forward_kinematics`] at the measured joint angles. The joint-limit
    /// task (if enabled) checks the joint *references* `q_r`.
    pub fn resolve(
        &mut self,
        base: &BasePose,
        ws: &KinWorkspace,
        target: &WorkTarget,
    ) -> WorkOutput {
        let n = self.n;
        let g_ie = ee_pose(base, &ws.g_be);
        let e = ee_pose_error(&g_ie, &target.ee_position, &target.ee_orientation);
        let mut rate_e = [0.0; 6];
        for i in 0..6 {
            rate_e[i] = target.ee_twist[i] + self.gains.k_e[i] * e[i];
        }
        let p_b = target.base_position - base.position;
        let mut rate_b = [0.0; 3];
        for i in 0..3 {
            rate_b[i] = self.gains.k_b[i] * p_b[i];
        }
        ee_jacobian(ws, &mut self.j_e);
        let r_ib = *base.orientation.to_rotation_matrix().matrix();
        base_position_jacobian(&r_ib, &mut self.j_b);

        self.jl.clear();
        let sigma = weighted_sigma_min(&self.j_e, self.srmtp.weights());
        let lambda =
            singularity_robust_damping(sigma, self.gains.damping, self.gains.singular_region);
        self.srmtp.set_damping(lambda);
        let base_inv = TaskInverse::plain(self.gains.base_task_damping);
        // Dimensions are fixed at construction, so the pushes below cannot fail; a failure
        // would leave ζ_r partial, never panic.
        let solve = |s: &mut Self| {
            s.srmtp.reset();
            if s.jl.count() > 0 {
                let _ =
                    s.srmtp
                        .push_task(s.jl.jacobian(), s.jl.rate(), TaskInverse::weighted(lambda));
            }
            let _ = s
                .srmtp
                .push_task(s.j_e.as_ref(), &rate_e, TaskInverse::weighted(lambda));
            if s.gains.base_task {
                let _ = s.srmtp.push_task(s.j_b.as_ref(), &rate_b, base_inv);
            }
        };
        solve(self);
        if self.gains.joint_limits.enabled {
            // Set-based: activate joints driven into their band, re-solve; the active set only
            // grows, so this ends after at most n rounds.
            for _ in 0..n {
                let z = self.srmtp.zeta();
                if !self.jl.update(&self.q_ref, &z[6..], &self.limits) {
                    break;
                }
                solve(self);
            }
        }
        if let Some(sec) = &mut self.secondary {
            self.secondary_zeta[6..].copy_from_slice(sec.joint_velocity(&self.q_ref));
            let _ = self.srmtp.push_velocity(&self.secondary_zeta);
        }
        let z = self.srmtp.zeta();
        self.qd_ref.copy_from_slice(&z[6..]);
        WorkOutput {
            v_r: Vec6::from_column_slice(&z[..6]),
            ee_error: e,
            base_error: p_b,
            active_limits: self.jl.count(),
            damping: lambda,
        }
    }

    /// One control step (USM-42): [`WorkController::resolve`], then integrate
    /// `q_r ← clamp(q_r + q̇_r dt)` over the step `dt` [s] (no integration if `dt` is not
    /// positive and finite). Read `q_r` with [`WorkController::q_ref`].
    pub fn step(
        &mut self,
        base: &BasePose,
        ws: &KinWorkspace,
        target: &WorkTarget,
        dt: f64,
    ) -> WorkOutput {
        let out = self.resolve(base, ws, target);
        if dt.is_finite() && dt > 0.0 {
            for i in 0..self.n {
                let (lo, hi) = self.limits[i];
                let q = self.q_ref[i] + self.qd_ref[i] * dt;
                if q.is_finite() {
                    self.q_ref[i] = q.clamp(lo, hi);
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::forward_kinematics;
    use crate::model::presets::usm_paper;
    use crate::spatial::{lin, quat_integrate};

    /// Integrate ζ_r as if tracked perfectly: base pose by its body twist, joints by q̇_r.
    fn run(
        v: &Vehicle,
        gains: &WorkGains,
        q0: &[f64],
        target_offset: (Vec3, UnitQuaternion<f64>),
        steps: usize,
    ) -> (Vec<f64>, Vec<f64>, Vec3, f64) {
        let dt = 0.05;
        let mut ctl = WorkController::new(v, gains).unwrap();
        let mut ws = KinWorkspace::new(v);
        let mut base = BasePose::default();
        let mut q = q0.to_vec();
        forward_kinematics(v, &q, &mut ws);
        let g0 = ee_pose(&base, &ws.g_be);
        let q_e0 =
            UnitQuaternion::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(g0.r));
        let target = WorkTarget {
            ee_position: g0.p + target_offset.0,
            ee_orientation: target_offset.1 * q_e0,
            ee_twist: Vec6::zeros(),
            base_position: base.position,
        };
        ctl.reset(&q);
        let mut pos_err = Vec::new();
        let mut ang_err = Vec::new();
        for _ in 0..steps {
            forward_kinematics(v, &q, &mut ws);
            let out = ctl.step(&base, &ws, &target, dt);
            pos_err.push(lin(&out.ee_error).norm());
            let g = ee_pose(&base, &ws.g_be);
            let qe = UnitQuaternion::from_rotation_matrix(
                &nalgebra::Rotation3::from_matrix_unchecked(g.r),
            );
            ang_err.push(qe.angle_to(&target.ee_orientation));
            let r = base.orientation.to_rotation_matrix();
            base.position += r * lin(&out.v_r) * dt;
            base.orientation =
                quat_integrate(&base.orientation, &crate::spatial::ang(&out.v_r), dt);
            q.copy_from_slice(ctl.q_ref());
        }
        let moved = base.position.norm();
        (pos_err, ang_err, target.ee_position, moved)
    }

    #[test]
    fn work_mode_kinematic_loop_converges() {
        // USM paper preset, slightly bent start (straight is a kinematic singularity for EE
        // roll), setpoint ~0.5 m away and rotated 20° about a tilted axis, reachable with the
        // base at home; paper gains and U.
        let v = usm_paper();
        let q0 = [0.2, 0.1, -0.15, 0.05, 0.1, -0.1, -0.2, 0.05];
        let rot = UnitQuaternion::from_scaled_axis(
            Vec3::new(0.0, 0.4, 1.0).normalize() * 20f64.to_radians(),
        );
        let (pos, ang, _, moved) = run(
            &v,
            &WorkGains::default(),
            &q0,
            (Vec3::new(-0.2, 0.35, -0.25), rot),
            2400,
        );
        assert!(pos[0] > 0.45, "{}", pos[0]);
        // 120 s with k_e = 0.2–0.4 1/s: errors fall by many time constants.
        let (pf, af) = (*pos.last().unwrap(), *ang.last().unwrap());
        assert!(pf < 1e-3, "position error {pf}");
        assert!(af < 1e-2, "angle error {af}");
        // Monotone enough: never grows by more than damping-induced wiggle.
        assert!(pos.windows(2).all(|w| w[1] <= w[0] * 1.001 + 1e-9));
        // The base task keeps the base near home.
        assert!(moved < 0.5, "base moved {moved}");
    }

    #[test]
    fn unreachable_with_base_home_leaves_bounded_residual() {
        // 0.3 m beyond the chain's reach with the base at home: the base must move, so the base
        // task conflicts with the primary. Without it the primary converges; with it, the damped
        // projector (λ = 0.1) leaks a little of the base task into the primary and the pose
        // error settles at a small residual (an inherent property of damped SRMTP).
        let v = usm_paper();
        let q0 = [0.2, 0.1, -0.15, 0.05, 0.1, -0.1, -0.2, 0.05];
        let rot = UnitQuaternion::from_scaled_axis(Vec3::z() * 0.2);
        let off = (Vec3::new(0.3, 0.3, -0.25), rot);
        let no_base = WorkGains {
            base_task: false,
            ..Default::default()
        };
        let (pos, ang, _, moved) = run(&v, &no_base, &q0, off, 2400);
        assert!(*pos.last().unwrap() < 1e-4 && *ang.last().unwrap() < 1e-4);
        assert!(moved > 0.2);
        let (pos, _, _, moved) = run(&v, &WorkGains::default(), &q0, off, 2400);
        let pf = *pos.last().unwrap();
        assert!(pf > 1e-3 && pf < 0.02, "{pf}");
        assert!(moved > 0.2);
    }

    #[test]
    fn singularity_robust_damping_only_inside_the_region() {
        // λ = λ_max √(1 − (σ/ε)²): λ_max at σ = 0, 0 from σ = ε on, 0 everywhere for ε = 0.
        assert_eq!(singularity_robust_damping(0.0, 0.1, 0.3), 0.1);
        let mid = singularity_robust_damping(0.15, 0.1, 0.3);
        assert!((mid - 0.1 * 0.75f64.sqrt()).abs() < 1e-15, "{mid}");
        assert_eq!(singularity_robust_damping(0.3, 0.1, 0.3), 0.0);
        assert_eq!(singularity_robust_damping(2.0, 0.1, 0.3), 0.0);
        assert_eq!(singularity_robust_damping(0.0, 0.1, 0.0), 0.0);
    }

    #[test]
    fn ee_task_is_the_printed_weighted_pseudoinverse_outside_the_singular_region() {
        let v = usm_paper();
        let mut ws = KinWorkspace::new(&v);
        let base = BasePose::default();
        let g0 = |ws: &KinWorkspace| ee_pose(&base, &ws.g_be);
        let target_of = |g: &crate::spatial::Se3| WorkTarget {
            ee_position: g.p + Vec3::new(-0.1, 0.1, 0.05),
            ee_orientation: UnitQuaternion::from_rotation_matrix(
                &nalgebra::Rotation3::from_matrix_unchecked(g.r),
            ),
            ee_twist: Vec6::zeros(),
            base_position: base.position,
        };
        let only_ee = WorkGains {
            base_task: false,
            ..Default::default()
        };
        // Straight: the end effector cannot roll without base roll (U = 0 there), σ = 0, so
        // the full λ_max applies.
        forward_kinematics(&v, &[0.0; 8], &mut ws);
        let mut ctl = WorkController::new(&v, &only_ee).unwrap();
        let out = ctl.resolve(&base, &ws, &target_of(&g0(&ws)));
        assert_eq!(out.damping, only_ee.damping);
        // Well bent: σ_min(J_e U^½) is above the region, no damping, and J_e ζ_r = k_e ẽ
        // exactly (USM-42 as printed); the constant-damping reading misses it.
        let q = [0.6, 0.5, -0.6, 0.4, 0.6, -0.5, -0.6, 0.4];
        forward_kinematics(&v, &q, &mut ws);
        let target = target_of(&g0(&ws));
        let mut j = Mat::zeros(6, 14);
        ee_jacobian(&ws, &mut j);
        let residual = |gains: &WorkGains| {
            let mut ctl = WorkController::new(&v, gains).unwrap();
            let out = ctl.resolve(&base, &ws, &target);
            let z = ctl.zeta_r();
            let r = (0..6)
                .map(|a| {
                    let jz: f64 = (0..14).map(|c| j[(a, c)] * z[c]).sum();
                    (jz - gains.k_e[a] * out.ee_error[a]).powi(2)
                })
                .sum::<f64>()
                .sqrt();
            (out.damping, r)
        };
        let (lambda, r) = residual(&only_ee);
        assert!(weighted_sigma_min(&j, &only_ee.weights_for(8)) > only_ee.singular_region);
        assert_eq!(lambda, 0.0);
        assert!(r < 1e-9, "{r}");
        let constant = WorkGains {
            singular_region: 1e9,
            ..only_ee
        };
        let (lambda, r) = residual(&constant);
        assert!(lambda > 0.09 && r > 1e-5, "{lambda} {r}");
    }

    #[test]
    fn zero_weight_keeps_base_roll_rate_zero() {
        let v = usm_paper();
        let mut ctl = WorkController::new(&v, &WorkGains::default()).unwrap();
        let mut ws = KinWorkspace::new(&v);
        let q = [0.3, 0.2, -0.1, 0.1, 0.2, -0.3, 0.1, 0.2];
        forward_kinematics(&v, &q, &mut ws);
        let target = WorkTarget {
            ee_position: Vec3::new(3.0, 0.5, 0.2),
            ee_orientation: UnitQuaternion::from_euler_angles(0.3, 0.2, 0.1),
            ee_twist: Vec6::zeros(),
            base_position: Vec3::new(0.1, 0.0, 0.0),
        };
        let out = ctl.resolve(&BasePose::default(), &ws, &target);
        // Roll is excluded from J_e^# by U and J_b⁺ has no angular part, but N_e may still
        // carry roll only through the projection of the base task, which has none.
        assert!(out.v_r[3].abs() < 1e-12, "{}", out.v_r[3]);
        assert!(ctl.qd_ref().iter().any(|x| x.abs() > 1e-3));
    }

    #[test]
    fn joint_limit_task_keeps_references_inside() {
        let v = usm_paper();
        let margin = 0.1;
        let gains = WorkGains {
            joint_limits: JointLimitSettings {
                enabled: true,
                margin,
                gain: 1.0,
            },
            ..Default::default()
        };
        let mut ctl = WorkController::new(&v, &gains).unwrap();
        let mut ws = KinWorkspace::new(&v);
        let q0 = [1.3, 0.1, 1.3, 0.1, 1.3, 0.1, 1.3, 0.1];
        let mut q = q0.to_vec();
        ctl.reset(&q);
        // A setpoint curled far round to the left: it wants the yaw joints beyond +90°.
        let target = WorkTarget {
            ee_position: Vec3::new(-0.5, 0.5, 0.0),
            ee_orientation: UnitQuaternion::from_euler_angles(0.0, 0.0, 3.0),
            ee_twist: Vec6::zeros(),
            base_position: Vec3::zeros(),
        };
        let mut max_active = 0;
        for _ in 0..600 {
            forward_kinematics(&v, &q, &mut ws);
            let out = ctl.step(&BasePose::default(), &ws, &target, 0.05);
            max_active = max_active.max(out.active_limits);
            q.copy_from_slice(ctl.q_ref());
            for (i, qi) in q.iter().enumerate() {
                let (lo, hi) = (v.joints[i].min, v.joints[i].max);
                // Never beyond the band's edge (or the start, if that was inside the band);
                // the 1e-3 allows the push-back's first-order lag within one step.
                assert!(*qi <= (hi - margin).max(q0[i]) + 1e-3, "joint {i}: {qi}");
                assert!(*qi >= (lo + margin).min(q0[i]) - 1e-3, "joint {i}: {qi}");
            }
        }
        assert!(max_active > 0);
    }

    #[test]
    fn gains_from_toml() {
        let g: WorkGains =
            toml::from_str("k_b = [0.1, 0.1, 0.1]\n[joint_limits]\nenabled = true").unwrap();
        assert_eq!(g.k_e, [0.2, 0.2, 0.2, 0.4, 0.4, 0.4]);
        assert!(g.joint_limits.enabled);
        assert!(toml::from_str::<WorkGains>("k_x = 1").is_err());
        let bad = WorkGains {
            weights: Some(vec![1.0; 5]),
            ..Default::default()
        };
        assert_eq!(bad.validate(8).unwrap_err().key, "work.weights");
        assert_eq!(
            WorkGains::paper_weights(8),
            vec![0.3, 0.3, 0.3, 0.0, 0.3, 0.3, 0.7, 0.7, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0]
        );
    }
}
