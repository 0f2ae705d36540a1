//! Kinematic control (docs/model.md §5, USM section IV-A, USM-27…32): damped weighted pseudoinverse,
//! singularity-robust multiple task priority (SRMTP), and the task errors and Jacobians of the
//! end-effector pose, base position and joint-limit tasks.
//!
//! - Damped weighted pseudoinverse (USM-31 with the usage-weight reading of docs/model.md §5):
//!   `J^# = U Jᵀ (J U Jᵀ + λ² I)⁻¹`, `U = diag(u)` a **usage** weight (`u_i = 0` forbids
//!   coordinate `i`, larger `u_i` prefers it; the paper's `W` multiplies as `U`, not as `W⁻¹`).
//! - SRMTP (USM-32): `ζ_r = J_1^#(σ̇_1d + Λ_1σ̃_1) + N_1 J_2^#(σ̇_2d + Λ_2σ̃_2) + …`, where the
//!   projector below level `k` is `N_{1…k−1} = I − J_A^# J_A` with `J_A` the stacked Jacobians of
//!   all higher-priority tasks; [`Srmtp`] builds it incrementally. The stacked pseudoinverse of
//!   the projector uses the solver's own usage weights and damping (those given to
//!   [`Srmtp::new`]): the usage weight is a property of the vehicle's coordinates, not of a task.
//!   Each task's own pseudoinverse can be weighted or plain ([`TaskInverse`]).
//! - This is the singularity-robust task priority of Chiaverini (1997) that Antonelli &
//!   Chiaverini use (AC-7): each lower task enters as `N_{1…k−1} J_k^# w_k`, not through the
//!   pseudoinverse of the projected Jacobian `(J_k N_{1…k−1})^#` of the classical form, so an
//!   *algorithmic* singularity (`J_k N_{1…k−1}` losing rank, measured by
//!   [`Srmtp::projected_singular_value`]) degrades the lower task without large rates. With
//!   damping λ = 0, [`TaskInverse::weighted`]`(0)` and 0/1 usage weights it is AC-7 exactly
//!   with the Moore–Penrose pseudoinverse of the Jacobians restricted to the coordinates whose
//!   weight is 1 (the paper's planar system: `U` selects u, v, r and the joints).
//! - Tasks: end-effector pose ([`ee_pose_error`], Jacobian [`crate::kinematics::ee_jacobian`]),
//!   base position ([`base_position_jacobian`]), joint limits (set-based, [`JointLimitTask`]),
//!   and inertial-frame task variables ([`InertialTask`] of [`TaskVariable`]s: end-effector and
//!   base position and heading, joint angles; AC-10…13) with the closed-loop rate of AC-8/9.
//!   The paper's other secondary objectives — manipulability and controllability (the
//!   commanded-subspace σ_min of `T(q)`) — are gradient steps ([`SecondaryTasks`], finite
//!   differences over the joint angles) that [`Srmtp::push_velocity`] projects into the null
//!   space of every task above them.
//!
//! Dimensions: `N = 6 + n` generalised velocities `ζ = [V_b; q̇]` (base twist in `F_b`, m/s and
//! rad/s, then joint rates rad/s). Matrices are faer `Mat<f64>`; the small SPD systems are solved
//! by the crate's one in-place Cholesky factorisation (`dynamics::cholesky`, any
//! positive pivot accepted) in preallocated buffers — nothing allocates per call.
//! A non-positive pivot (λ = 0 and a singular `J U Jᵀ`) is retried once with a tiny diagonal
//! regularisation and counted ([`PinvWorkspace::regularised`]); if that also fails (non-finite
//! input) the contribution is zero and counted ([`PinvWorkspace::failed`]).

use super::error::{check_nonneg, ControlError};
use super::orientation_error;
use crate::kinematics::BasePose;
use crate::linalg;
use crate::spatial::{stack, Mat3, Se3, Vec3, Vec6};
use faer::{Mat, MatRef};
use nalgebra::{Rotation3, UnitQuaternion};
use serde::{Deserialize, Serialize};

mod inertial;
pub use inertial::{InertialTask, TaskVariable};
mod secondary;
pub use secondary::{SecondarySettings, SecondaryTasks};

/// Usage weight `u_c` of column `c` (1 when no weights are given).
#[inline]
fn weight(u: Option<&[f64]>, c: usize) -> f64 {
    u.map_or(1.0, |u| u[c])
}

/// Preallocated buffers for damped weighted pseudoinverses of Jacobians with up to `max_rows`
/// rows and exactly `n` columns (USM-31).
#[derive(Clone, Debug)]
pub struct PinvWorkspace {
    max_rows: usize,
    n: usize,
    a: Vec<f64>,
    y: Vec<f64>,
    regularised: u64,
    failed: u64,
}

impl PinvWorkspace {
    /// Buffers for `J` of at most `max_rows` rows and `n` columns.
    pub fn new(max_rows: usize, n: usize) -> Self {
        Self {
            max_rows,
            n,
            a: vec![0.0; max_rows * max_rows],
            y: vec![0.0; max_rows],
            regularised: 0,
            failed: 0,
        }
    }

    /// How many factorisations needed the fallback diagonal regularisation.
    pub fn regularised(&self) -> u64 {
        self.regularised
    }

    /// How many factorisations failed (non-finite input); their results were zero.
    pub fn failed(&self) -> u64 {
        self.failed
    }

    fn check(
        &self,
        j: MatRef<'_, f64>,
        u: Option<&[f64]>,
        lambda: f64,
    ) -> Result<(), ControlError> {
        if j.nrows() > self.max_rows || j.ncols() != self.n {
            return Err(ControlError::new(
                "jacobian",
                format!(
                    "is {}×{}, the workspace holds up to {}×{}",
                    j.nrows(),
                    j.ncols(),
                    self.max_rows,
                    self.n
                ),
            ));
        }
        if let Some(u) = u {
            if u.len() != self.n {
                return Err(ControlError::new(
                    "weights",
                    format!("has {} entries, needs {}", u.len(), self.n),
                ));
            }
        }
        check_nonneg("damping", lambda)
    }

    /// Build and factor `A = J U Jᵀ + λ² I` (`task_dim`×`task_dim`, `task_dim` = rows of `J`). Returns false if it could not be factored.
    fn factor(&mut self, j: MatRef<'_, f64>, u: Option<&[f64]>, lambda: f64) -> bool {
        let task_dim = j.nrows();
        let build = |a: &mut [f64], extra: f64| {
            for r in 0..task_dim {
                for s in 0..=r {
                    let mut acc = 0.0;
                    for c in 0..j.ncols() {
                        acc += j[(r, c)] * weight(u, c) * j[(s, c)];
                    }
                    a[r * task_dim + s] = acc;
                    a[s * task_dim + r] = acc;
                }
                a[r * task_dim + r] += lambda * lambda + extra;
            }
        };
        build(&mut self.a, 0.0);
        if linalg::factor(&mut self.a, task_dim, 0.0).is_ok() {
            return true;
        }
        build(&mut self.a, 0.0);
        let scale = (0..task_dim)
            .map(|r| self.a[r * task_dim + r].abs())
            .fold(0.0, f64::max);
        build(&mut self.a, 1e-12 * scale.max(1.0));
        if linalg::factor(&mut self.a, task_dim, 0.0).is_ok() {
            self.regularised += 1;
            true
        } else {
            self.failed += 1;
            false
        }
    }

    /// `out = J^# rhs = U Jᵀ (J U Jᵀ + λ² I)⁻¹ rhs` (USM-28/31). `j` is `task_dim`×n
    /// (`task_dim` ≤ `max_rows`), `u` the usage weights (n, `None` = identity), `lambda` the
    /// damping λ ≥ 0, `rhs` of length `task_dim`, `out` of length n. Errors only on mismatched dimensions or invalid λ.
    pub fn apply(
        &mut self,
        j: MatRef<'_, f64>,
        u: Option<&[f64]>,
        lambda: f64,
        rhs: &[f64],
        out: &mut [f64],
    ) -> Result<(), ControlError> {
        self.check(j, u, lambda)?;
        let task_dim = j.nrows();
        if rhs.len() != task_dim || out.len() != self.n {
            return Err(ControlError::new(
                "rhs",
                format!(
                    "lengths {} / {} do not match J ({}×{})",
                    rhs.len(),
                    out.len(),
                    task_dim,
                    self.n
                ),
            ));
        }
        if !self.factor(j, u, lambda) {
            out.fill(0.0);
            return Ok(());
        }
        self.y[..task_dim].copy_from_slice(rhs);
        linalg::solve(&self.a, task_dim, &mut self.y[..task_dim]);
        for (c, o) in out.iter_mut().enumerate() {
            let mut acc = 0.0;
            for r in 0..task_dim {
                acc += j[(r, c)] * self.y[r];
            }
            *o = weight(u, c) * acc;
        }
        Ok(())
    }

    /// The explicit `J^#` (n×`task_dim`) into `out` (resized only if its shape differs).
    pub fn pinv(
        &mut self,
        j: MatRef<'_, f64>,
        u: Option<&[f64]>,
        lambda: f64,
        out: &mut Mat<f64>,
    ) -> Result<(), ControlError> {
        self.check(j, u, lambda)?;
        let task_dim = j.nrows();
        if out.nrows() != self.n || out.ncols() != task_dim {
            *out = Mat::zeros(self.n, task_dim);
        }
        if !self.factor(j, u, lambda) {
            out.fill(0.0);
            return Ok(());
        }
        // Row c of J^# is u_c (A⁻¹ J[:, c])ᵀ.
        for c in 0..self.n {
            for r in 0..task_dim {
                self.y[r] = j[(r, c)];
            }
            linalg::solve(&self.a, task_dim, &mut self.y[..task_dim]);
            for r in 0..task_dim {
                out[(c, r)] = weight(u, c) * self.y[r];
            }
        }
        Ok(())
    }

    /// The null-space projector `N = I − J^# J` (n×n) into `out`.
    pub fn null_projector(
        &mut self,
        j: MatRef<'_, f64>,
        u: Option<&[f64]>,
        lambda: f64,
        out: &mut Mat<f64>,
    ) -> Result<(), ControlError> {
        self.check(j, u, lambda)?;
        let (task_dim, n) = (j.nrows(), self.n);
        if out.nrows() != n || out.ncols() != n {
            *out = Mat::zeros(n, n);
        }
        for a in 0..n {
            for b in 0..n {
                out[(a, b)] = if a == b { 1.0 } else { 0.0 };
            }
        }
        if task_dim == 0 || !self.factor(j, u, lambda) {
            return Ok(());
        }
        // (J^# J)[a, b] = u_a Σ_r J[r, a] (A⁻¹ J)[r, b]; solve A x = J[:, b] column by column.
        for b in 0..n {
            for r in 0..task_dim {
                self.y[r] = j[(r, b)];
            }
            linalg::solve(&self.a, task_dim, &mut self.y[..task_dim]);
            for a in 0..n {
                let wa = weight(u, a);
                if wa == 0.0 {
                    continue;
                }
                let mut acc = 0.0;
                for r in 0..task_dim {
                    acc += j[(r, a)] * self.y[r];
                }
                out[(a, b)] -= wa * acc;
            }
        }
        Ok(())
    }
}

/// Convenience: the explicit damped weighted pseudoinverse `J^# = U Jᵀ(J U Jᵀ + λ²I)⁻¹`
/// (n×`task_dim`) of a `task_dim`×n `j` (allocates a workspace; for analysis and tests, not for time steps).
pub fn damped_weighted_pinv(
    j: MatRef<'_, f64>,
    u: Option<&[f64]>,
    lambda: f64,
) -> Result<Mat<f64>, ControlError> {
    let mut ws = PinvWorkspace::new(j.nrows(), j.ncols());
    let mut out = Mat::zeros(j.ncols(), j.nrows());
    ws.pinv(j, u, lambda, &mut out)?;
    Ok(out)
}

/// How a task's own pseudoinverse is formed in [`Srmtp::push_task`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TaskInverse {
    /// Use the solver's usage weights `U` (true) or the identity (false).
    pub weighted: bool,
    /// Damping λ ≥ 0 of this task's pseudoinverse (0: exact pseudoinverse, which requires a
    /// full-row-rank Jacobian).
    pub damping: f64,
}

impl TaskInverse {
    /// Weighted by `U`, damped by `damping`.
    pub fn weighted(damping: f64) -> Self {
        Self {
            weighted: true,
            damping,
        }
    }

    /// Unweighted (`U = I`), damped by `damping` (0 = the Moore–Penrose pseudoinverse `J⁺`).
    pub fn plain(damping: f64) -> Self {
        Self {
            weighted: false,
            damping,
        }
    }
}

/// The SRMTP solver (USM-32): tasks are pushed in priority order; each contributes
/// `N_{1…k−1} J_k^# (σ̇_kd + Λ_k σ̃_k)` and its Jacobian rows are stacked into the projector of
/// the tasks below it. Preallocated for `N` columns and up to `max_rows` stacked rows.
///
/// Per step: [`Srmtp::reset`], then [`Srmtp::push_task`] for each task from the highest
/// priority, optionally [`Srmtp::push_velocity`], then read [`Srmtp::zeta`].
#[derive(Clone, Debug)]
pub struct Srmtp {
    n: usize,
    max_rows: usize,
    weights: Vec<f64>,
    lambda: f64,
    stack: Mat<f64>,
    rows: usize,
    null: Mat<f64>,
    null_dirty: bool,
    zeta: Vec<f64>,
    x: Vec<f64>,
    pinv: PinvWorkspace,
}

impl Srmtp {
    /// A solver for `n` generalised velocities, up to `max_rows` stacked task rows, usage
    /// weights `weights` (length `n`, each ≥ 0) and damping `lambda` ≥ 0 for the stacked
    /// null-space projectors.
    pub fn new(
        n: usize,
        max_rows: usize,
        weights: &[f64],
        lambda: f64,
    ) -> Result<Self, ControlError> {
        if weights.len() != n {
            return Err(ControlError::new(
                "weights",
                format!("has {} entries, needs {n}", weights.len()),
            ));
        }
        for (i, w) in weights.iter().enumerate() {
            check_nonneg(&format!("weights[{i}]"), *w)?;
        }
        check_nonneg("damping", lambda)?;
        Ok(Self {
            n,
            max_rows,
            weights: weights.to_vec(),
            lambda,
            stack: Mat::zeros(max_rows, n),
            rows: 0,
            null: Mat::identity(n, n),
            null_dirty: false,
            zeta: vec![0.0; n],
            x: vec![0.0; n],
            pinv: PinvWorkspace::new(max_rows, n),
        })
    }

    /// Start a new resolution: `ζ = 0`, `N = I`, no stacked rows.
    pub fn reset(&mut self) {
        self.zeta.fill(0.0);
        self.rows = 0;
        self.null_dirty = true;
    }

    /// Number of generalised velocities `N`.
    pub fn n(&self) -> usize {
        self.n
    }

    /// The usage weights `U`.
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// Damping λ of the stacked projectors.
    pub fn damping(&self) -> f64 {
        self.lambda
    }

    /// Set the damping λ ≥ 0 (negative or NaN: 0) of the stacked projectors from the next
    /// projection on — for a damping that varies with the configuration (singularity-robust).
    pub fn set_damping(&mut self, lambda: f64) {
        self.lambda = lambda.max(0.0);
        self.null_dirty = true;
    }

    /// The pseudoinverse workspace's counters (regularised / failed factorisations).
    pub fn pinv_stats(&self) -> (u64, u64) {
        (self.pinv.regularised(), self.pinv.failed())
    }

    fn refresh_null(&mut self) {
        if !self.null_dirty {
            return;
        }
        let j = self.stack.as_ref().subrows(0, self.rows);
        // Dimensions are consistent by construction, so this cannot fail.
        let _ = self
            .pinv
            .null_projector(j, Some(&self.weights), self.lambda, &mut self.null);
        self.null_dirty = false;
    }

    /// The current projector `N_{1…k}` onto the null space of all pushed tasks (N×N).
    pub fn null_projector(&mut self) -> MatRef<'_, f64> {
        self.refresh_null();
        self.null.as_ref()
    }

    /// Push the next task in priority order: `j` its `task_dim`×N Jacobian, `rate` the
    /// `task_dim`-vector `σ̇_d + Λ σ̃` (task units per second). Adds `N_{1…k−1} J^# rate` to
    /// `ζ` and stacks `j` below the higher-priority tasks. Errors on mismatched dimensions or
    /// when the stacked rows would exceed `max_rows`; nothing changes then.
    pub fn push_task(
        &mut self,
        j: MatRef<'_, f64>,
        rate: &[f64],
        inv: TaskInverse,
    ) -> Result<(), ControlError> {
        let task_dim = j.nrows();
        if j.ncols() != self.n || rate.len() != task_dim {
            return Err(ControlError::new(
                "task",
                format!(
                    "Jacobian {}×{} and rate of length {} do not fit N = {}",
                    task_dim,
                    j.ncols(),
                    rate.len(),
                    self.n
                ),
            ));
        }
        if self.rows + task_dim > self.max_rows {
            return Err(ControlError::new(
                "task",
                format!(
                    "stacking {task_dim} more rows exceeds the {} rows the solver was built for",
                    self.max_rows
                ),
            ));
        }
        let u = if inv.weighted {
            Some(self.weights.as_slice())
        } else {
            None
        };
        self.pinv.apply(j, u, inv.damping, rate, &mut self.x)?;
        self.add_projected();
        for r in 0..task_dim {
            for c in 0..self.n {
                self.stack[(self.rows + r, c)] = j[(r, c)];
            }
        }
        self.rows += task_dim;
        self.null_dirty = true;
        Ok(())
    }

    /// `ζ += N_{1…k} x` with `x` in `self.x`.
    fn add_projected(&mut self) {
        if self.rows == 0 {
            for (z, x) in self.zeta.iter_mut().zip(&self.x) {
                *z += x;
            }
            return;
        }
        self.refresh_null();
        for a in 0..self.n {
            let mut acc = 0.0;
            for b in 0..self.n {
                acc += self.null[(a, b)] * self.x[b];
            }
            self.zeta[a] += acc;
        }
    }

    /// Add a lowest-priority generalised velocity `v` (length N) projected into the null space
    /// of every pushed task, `ζ += N_{1…k} v` — the hook for gradient-based secondary
    /// objectives (e.g. `v = k U ∇w(q)` for a manipulability or TCM-conditioning measure `w`).
    pub fn push_velocity(&mut self, v: &[f64]) -> Result<(), ControlError> {
        if v.len() != self.n {
            return Err(ControlError::new(
                "velocity",
                format!("has {} entries, needs {}", v.len(), self.n),
            ));
        }
        self.x.copy_from_slice(v);
        self.add_projected();
        Ok(())
    }

    /// The resolved reference `ζ_r = [V_r; q̇_r]` (length N).
    pub fn zeta(&self) -> &[f64] {
        &self.zeta
    }

    /// The algorithmic-singularity measure of a candidate next task `j` (`m`×N): the smallest
    /// weighted singular value of `J N_{1…k}`, `√λ_min(J N U Nᵀ Jᵀ)`, with `N_{1…k}` the
    /// projector of the tasks pushed so far and `U` the usage weights. Zero when `j` loses rank
    /// inside the null space of the higher-priority tasks (an algorithmic singularity of
    /// Chiaverini 1997). Allocates: a diagnostic, not for the inner loop of a time step.
    pub fn projected_singular_value(&mut self, j: MatRef<'_, f64>) -> f64 {
        self.refresh_null();
        let (m, n) = (j.nrows(), self.n);
        let jn = nalgebra::DMatrix::from_fn(m, n, |r, c| {
            let s: f64 = (0..n).map(|k| j[(r, k)] * self.null[(k, c)]).sum();
            s * self.weights[c].sqrt()
        });
        let gram = &jn * jn.transpose();
        gram.symmetric_eigenvalues()
            .iter()
            .fold(f64::INFINITY, |a, &b| a.min(b))
            .max(0.0)
            .sqrt()
    }
}

/// End-effector pose error `ẽ = [p̃_e; ε̃_e]` in the end-effector frame (docs/model.md §5, USM-42):
/// `p̃_e = R_Ieᵀ (p_d − p_Ie)` [m] and `ε̃_e` the quaternion vector-part error of
/// [`super::orientation_error`] (current → desired, in `F_e`). `g_ie` is the end-effector pose
/// in `I`; `p_d` [m, `I`] and `q_d` (maps `F_e,d` vectors to `I`) the setpoint. With
/// `V_e = k ẽ` (k > 0) both parts decrease.
pub fn ee_pose_error(g_ie: &Se3, p_d: &Vec3, q_d: &UnitQuaternion<f64>) -> Vec6 {
    let q_e = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(g_ie.r));
    let p = g_ie.r.transpose() * (p_d - g_ie.p);
    stack(&p, &orientation_error(q_d, &q_e))
}

/// End-effector pose in `I`, `g_Ie = g_Ib g_be`, from the base pose and a workspace after
/// [`crate::kinematics::forward_kinematics`].
pub fn ee_pose(base: &BasePose, g_be: &Se3) -> Se3 {
    base.to_se3().compose(g_be)
}

/// Base-position task Jacobian (docs/model.md §5, USM-42): `J_b = [R_Ib 0_{3×(n+3)}]`, 3×(6+n), so that
/// `ṗ_Ib = J_b ζ` (inertial, m/s). `out` must be 3×(6+n); every entry is written.
pub fn base_position_jacobian(r_ib: &Mat3, out: &mut Mat<f64>) {
    for r in 0..3 {
        for c in 0..out.ncols() {
            out[(r, c)] = if c < 3 { r_ib[(r, c)] } else { 0.0 };
        }
    }
}

/// Settings of the set-based joint-limit task (USM section IV-A objective 1).
///
/// A joint is *active* when it lies within `margin` of a limit and the lower-priority solution
/// would move it further towards that limit; active joints then get an equality task at the
/// highest priority, `q̇_i = gain (q_b − q_i)` with `q_b = max − margin` (or `min + margin`): hold
/// at the activation boundary, pushed back gently if past it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct JointLimitSettings {
    /// Whether the task is used (default false: the paper's work-mode simulation has none).
    pub enabled: bool,
    /// Activation band inside each limit [rad] (default 5° = 0.0873 rad).
    pub margin: f64,
    /// Gain pulling an active joint back to the band's edge [1/s] (default 1).
    pub gain: f64,
}

impl Default for JointLimitSettings {
    fn default() -> Self {
        Self {
            enabled: false,
            margin: 5f64.to_radians(),
            gain: 1.0,
        }
    }
}

impl JointLimitSettings {
    /// Check the values; errors name `joint_limits.<key>`.
    pub fn validate(&self) -> Result<(), ControlError> {
        check_nonneg("joint_limits.margin", self.margin)?;
        check_nonneg("joint_limits.gain", self.gain)
    }
}

/// Buffers of the set-based joint-limit task: the active joints' selection rows
/// `e_{6+i}ᵀ` (k×(6+n)) and their rates.
#[derive(Clone, Debug)]
pub struct JointLimitTask {
    settings: JointLimitSettings,
    jac: Mat<f64>,
    rate: Vec<f64>,
    active: Vec<i8>,
    count: usize,
}

impl JointLimitTask {
    /// Buffers for `n` joints.
    pub fn new(n: usize, settings: JointLimitSettings) -> Self {
        Self {
            settings,
            jac: Mat::zeros(n, 6 + n),
            rate: vec![0.0; n],
            active: vec![0; n],
            count: 0,
        }
    }

    /// The settings.
    pub fn settings(&self) -> &JointLimitSettings {
        &self.settings
    }

    /// Clear the active set.
    pub fn clear(&mut self) {
        self.active.fill(0);
        self.count = 0;
    }

    /// Add to the active set every joint within the margin of a limit whose candidate rate
    /// `qd[i]` points towards it; rebuild the rows. `q` [rad], `qd` [rad/s], `limits` (min, max)
    /// [rad]. Returns whether the active set grew.
    pub fn update(&mut self, q: &[f64], qd: &[f64], limits: &[(f64, f64)]) -> bool {
        let mut grew = false;
        let margin = self.settings.margin;
        for i in 0..self.active.len() {
            if self.active[i] != 0 {
                continue;
            }
            let (lo, hi) = limits[i];
            if q[i] >= hi - margin && qd[i] > 0.0 {
                self.active[i] = 1;
                grew = true;
            } else if q[i] <= lo + margin && qd[i] < 0.0 {
                self.active[i] = -1;
                grew = true;
            }
        }
        if grew {
            let n = self.active.len();
            self.count = 0;
            for i in 0..n {
                if self.active[i] == 0 {
                    continue;
                }
                let row = self.count;
                for c in 0..(6 + n) {
                    self.jac[(row, c)] = 0.0;
                }
                self.jac[(row, 6 + i)] = 1.0;
                let (lo, hi) = limits[i];
                let rate = if self.active[i] > 0 {
                    (hi - margin - q[i]).min(0.0)
                } else {
                    (lo + margin - q[i]).max(0.0)
                };
                self.rate[row] = self.settings.gain * rate;
                self.count += 1;
            }
        }
        grew
    }

    /// Number of active joints.
    pub fn count(&self) -> usize {
        self.count
    }

    /// Rows of the active joints (count × (6+n)).
    pub fn jacobian(&self) -> MatRef<'_, f64> {
        self.jac.as_ref().subrows(0, self.count)
    }

    /// Rates of the active joints [rad/s].
    pub fn rate(&self) -> &[f64] {
        &self.rate[..self.count]
    }
}

#[cfg(test)]
#[path = "kinematic_tests.rs"]
mod tests;
