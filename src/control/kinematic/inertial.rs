//! Inertial-frame task variables (Antonelli & Chiaverini, AC-4 and AC-10…13; docs/model.md §8): scalar
//! task coordinates `ξ` of a floating-base chain measured in the inertial frame `I`, stacked
//! into a task vector with its Jacobian `J` (`ξ̇ = J ζ`, `ζ = [V_b; q̇]` as everywhere in the
//! crate), and the closed-loop task rate of AC-8/9, `w = ξ̇_d + K (ξ_d − ξ)`.
//!
//! | variable | value | Jacobian row |
//! |---|---|---|
//! | end-effector position `x_e, y_e, z_e` [m] | `p_Ie[a]` | `e_aᵀ R_Ie J_e,v` |
//! | end-effector heading `ψ_e` [rad] | `atan2(R₁₀, R₀₀)` of `R_Ie` | `g(R_Ie) J_e,ω` |
//! | base position `x, y, z` [m] | `p_Ib[a]` | `e_aᵀ [R_Ib 0 0]` |
//! | base heading `ψ` [rad] | heading of `R_Ib` | `[0 g(R_Ib) 0]` |
//! | joint `q_k` [rad] | `q_k` | `e_{6+k}ᵀ` |
//!
//! `J_e = [J_e,v; J_e,ω]` is the end-effector Jacobian in `F_e` (USM-18), `g(R)` the
//! [`crate::spatial::heading_gradient`] (`ψ̇ = g·ω` for body-fixed `ω`; `g = e_z` when the frame
//! is level, as in the paper's planar system). Heading errors are wrapped into `(−π, π]`.

use super::ee_pose;
use crate::control::error::{check_nonneg, ControlError};
use crate::kinematics::{ee_jacobian, BasePose, KinWorkspace};
use crate::spatial::{heading, heading_gradient, wrap_angle};
use faer::{Mat, MatRef};

/// One scalar task coordinate measured in the inertial frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TaskVariable {
    /// End-effector position along inertial axis `0` (x), `1` (y) or `2` (z) [m].
    EePosition(usize),
    /// End-effector heading `ψ_e` (ZYX yaw of `F_e` in `I`) [rad].
    EeHeading,
    /// Base-origin position along inertial axis `0`, `1` or `2` [m].
    BasePosition(usize),
    /// Base heading `ψ` (ZYX yaw of `F_b` in `I`) [rad].
    BaseHeading,
    /// Joint angle `q_k` (0-based `k`) [rad].
    Joint(usize),
}

impl TaskVariable {
    /// Whether the coordinate is an angle whose error is wrapped into `(−π, π]`.
    pub fn is_heading(self) -> bool {
        matches!(self, TaskVariable::EeHeading | TaskVariable::BaseHeading)
    }

    /// A short column name: `x_e`, `y_e`, `z_e`, `psi_e`, `x`, `y`, `z`, `psi`, `q1`, ….
    pub fn name(self) -> String {
        const AXES: [&str; 3] = ["x", "y", "z"];
        match self {
            TaskVariable::EePosition(a) => format!("{}_e", AXES[a.min(2)]),
            TaskVariable::EeHeading => "psi_e".into(),
            TaskVariable::BasePosition(a) => AXES[a.min(2)].into(),
            TaskVariable::BaseHeading => "psi".into(),
            TaskVariable::Joint(k) => format!("q{}", k + 1),
        }
    }
}

/// A stack of [`TaskVariable`]s for a chain with `n` joints: its current value `ξ` and
/// Jacobian `J` (rows in the variables' order, `6 + n` columns), refreshed by
/// [`InertialTask::update`] in preallocated buffers.
#[derive(Clone, Debug)]
pub struct InertialTask {
    vars: Vec<TaskVariable>,
    value: Vec<f64>,
    jac: Mat<f64>,
    j_e: Mat<f64>,
}

impl InertialTask {
    /// A task of the given variables for a chain of `n` joints; errors on an axis above 2 or
    /// a joint index ≥ `n`, or an empty list.
    pub fn new(vars: &[TaskVariable], n: usize) -> Result<Self, ControlError> {
        if vars.is_empty() {
            return Err(ControlError::new("task", "has no variables"));
        }
        for (i, v) in vars.iter().enumerate() {
            let bad = match *v {
                TaskVariable::EePosition(a) | TaskVariable::BasePosition(a) => a > 2,
                TaskVariable::Joint(k) => k >= n,
                _ => false,
            };
            if bad {
                return Err(ControlError::new(
                    format!("task[{i}]"),
                    format!("{v:?} does not exist on a chain of {n} joints"),
                ));
            }
        }
        Ok(Self {
            vars: vars.to_vec(),
            value: vec![0.0; vars.len()],
            jac: Mat::zeros(vars.len(), 6 + n),
            j_e: Mat::zeros(6, 6 + n),
        })
    }

    /// The variables, in row order.
    pub fn variables(&self) -> &[TaskVariable] {
        &self.vars
    }

    /// Task dimension `m`.
    pub fn dim(&self) -> usize {
        self.vars.len()
    }

    /// The task value `ξ` of the last [`InertialTask::update`].
    pub fn value(&self) -> &[f64] {
        &self.value
    }

    /// The task Jacobian `J` (`m`×(6+n)) of the last [`InertialTask::update`].
    pub fn jacobian(&self) -> MatRef<'_, f64> {
        self.jac.as_ref()
    }

    /// Evaluate `ξ` and `J` at the base pose `base`, joint angles `q` [rad] and a workspace
    /// after [`crate::kinematics::forward_kinematics`] at `q`.
    pub fn update(&mut self, base: &BasePose, ws: &KinWorkspace, q: &[f64]) {
        let g_ib = base.to_se3();
        let g_ie = ee_pose(base, &ws.g_be);
        if self
            .vars
            .iter()
            .any(|v| matches!(v, TaskVariable::EePosition(_) | TaskVariable::EeHeading))
        {
            ee_jacobian(ws, &mut self.j_e);
        }
        let ncol = self.jac.ncols();
        for (row, var) in self.vars.iter().enumerate() {
            for c in 0..ncol {
                self.jac[(row, c)] = 0.0;
            }
            match *var {
                TaskVariable::EePosition(a) => {
                    self.value[row] = g_ie.p[a];
                    for c in 0..ncol {
                        self.jac[(row, c)] =
                            (0..3).map(|k| g_ie.r[(a, k)] * self.j_e[(k, c)]).sum();
                    }
                }
                TaskVariable::EeHeading => {
                    self.value[row] = heading(&g_ie.r);
                    let g = heading_gradient(&g_ie.r);
                    for c in 0..ncol {
                        self.jac[(row, c)] = (0..3).map(|k| g[k] * self.j_e[(3 + k, c)]).sum();
                    }
                }
                TaskVariable::BasePosition(a) => {
                    self.value[row] = g_ib.p[a];
                    for k in 0..3 {
                        self.jac[(row, k)] = g_ib.r[(a, k)];
                    }
                }
                TaskVariable::BaseHeading => {
                    self.value[row] = heading(&g_ib.r);
                    let g = heading_gradient(&g_ib.r);
                    for k in 0..3 {
                        self.jac[(row, 3 + k)] = g[k];
                    }
                }
                TaskVariable::Joint(k) => {
                    self.value[row] = q[k];
                    self.jac[(row, 6 + k)] = 1.0;
                }
            }
        }
    }

    /// The closed-loop task rate of AC-8/9, `w = ξ̇_d + K (ξ_d − ξ)` (row units per second),
    /// into `out`: `desired` `ξ_d`, `desired_rate` `ξ̇_d`, `gains` the diagonal of `K` (each
    /// ≥ 0, 1/s); heading errors wrapped into `(−π, π]`. Errors on mismatched lengths or a
    /// negative or non-finite gain.
    pub fn closed_loop_rate(
        &self,
        desired: &[f64],
        desired_rate: &[f64],
        gains: &[f64],
        out: &mut [f64],
    ) -> Result<(), ControlError> {
        let m = self.dim();
        if desired.len() != m || desired_rate.len() != m || gains.len() != m || out.len() != m {
            return Err(ControlError::new(
                "task",
                format!("references, gains and output must have {m} entries"),
            ));
        }
        for (i, var) in self.vars.iter().enumerate() {
            check_nonneg(&format!("gains[{i}]"), gains[i])?;
            let mut e = desired[i] - self.value[i];
            if var.is_heading() {
                e = wrap_angle(e);
            }
            out[i] = desired_rate[i] + gains[i] * e;
        }
        Ok(())
    }
}
