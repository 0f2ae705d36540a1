//! The paper's gradient-based secondary objectives (USM section IV-A, objectives 2 and 3;
//! docs/model.md §5): "maintain good manipulability" and "maintain controllability, i.e. avoid singular
//! thruster configurations", as a joint velocity that climbs the gradient of each measure,
//! projected into the null space of every higher-priority task ([`super::Srmtp::push_velocity`]):
//!
//! `q̇_s = k_c ∇_q σ_β(q) + k_m ∇_q m(q)`,
//!
//! - `σ_c(q)` the **commanded-subspace σ_min** of the scaled TCM, `σ_min(S · T_L(q))`
//!   ([`crate::metrics::singularity::commanded_sigma`]; `S` the rows of the axes the mode
//!   commands, `T_L` the TCM with moment rows divided by the characteristic length L): the
//!   weakest commanded wrench per newton of thrust [N/N]; the gradient is that of its soft
//!   minimum `σ_β = −(1/β) ln Σ_i exp(−β σ_i)` over the commanded singular values
//!   ([`SecondarySettings::sharpness`]), which equals σ_min's gradient away from crossings
//!   and does not flip sign where the two smallest singular values cross;
//! - `m(q) = √det(J_q J_qᵀ)` Yoshikawa's manipulability of the end-effector Jacobian's joint
//!   columns (`J_q` = columns 6… of `J_e`, USM-18, in `F_e`; units m^a rad^b mixed as in `J_e`):
//!   zero in a singular joint configuration (a straight chain of yaw and pitch joints cannot
//!   roll its end-effector);
//! - `k_c` [rad²/s per N/N] and `k_m` the gains; both objectives share the lowest priority
//!   (their sum is projected once).
//!
//! The gradients are central finite differences over the joint angles (step `h`), each
//! evaluation one forward-kinematics pass into a private workspace — `T(q)` and `J_e` depend on
//! the joint angles only, so the base pose does not enter. Allocation-free per call.

use crate::control::error::{check_nonneg, check_pos, ControlError};
use crate::kinematics::{ee_jacobian, forward_kinematics, thruster_matrix, KinWorkspace};
use crate::metrics::singularity::{commanded_sigma, CommandedDofs};
use crate::model::Vehicle;
use faer::Mat;
use nalgebra::{Matrix6, Matrix6xX};
use serde::{Deserialize, Serialize};

/// `[secondary]` of a scenario file: gains of the secondary objectives (off by default: the
/// paper's simulations use none).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SecondarySettings {
    /// Gain `k_c` of the controllability objective (climb `σ_min(S·T_L)`) [rad²/s]. Default 0
    /// (off).
    pub controllability_gain: f64,
    /// Gain `k_m` of the manipulability objective (climb `√det(J_q J_qᵀ)`). Default 0 (off).
    pub manipulability_gain: f64,
    /// Sharpness β [1/(N/N)] of the soft minimum the controllability gradient climbs,
    /// `σ_β = −(1/β) ln Σ_i exp(−β σ_i)` over the commanded singular values (`σ_β → σ_min` as
    /// β grows; within `ln k / β` of it). Where two singular values cross, the hard minimum's
    /// gradient flips sign from one step to the next and the joint-rate references chatter;
    /// the soft minimum climbs both together. Default 50.
    pub sharpness: f64,
    /// Finite-difference step `h` of the gradients [rad]. Default 1e-4.
    pub step: f64,
    /// Transport only: bound on each joint's secondary offset from the USM-38 reference [rad]
    /// (the offset stays in the null space of the head's heading and pitch relative to the
    /// tail; see [`crate::control::transport`]). Default 0.3.
    pub max_offset: f64,
}

impl Default for SecondarySettings {
    fn default() -> Self {
        Self {
            controllability_gain: 0.0,
            manipulability_gain: 0.0,
            sharpness: 50.0,
            step: 1e-4,
            max_offset: 0.3,
        }
    }
}

impl SecondarySettings {
    /// Whether any objective has a positive gain.
    pub fn enabled(&self) -> bool {
        self.controllability_gain > 0.0 || self.manipulability_gain > 0.0
    }

    /// Check the values; errors name `secondary.<key>`.
    pub fn validate(&self) -> Result<(), ControlError> {
        check_nonneg("secondary.controllability_gain", self.controllability_gain)?;
        check_nonneg("secondary.manipulability_gain", self.manipulability_gain)?;
        check_pos("secondary.sharpness", self.sharpness)?;
        check_pos("secondary.step", self.step)?;
        check_nonneg("secondary.max_offset", self.max_offset)
    }
}

/// The secondary objectives of a design: the measures, their finite-difference gradient and
/// the buffers they need (see the module docs).
#[derive(Clone, Debug)]
pub struct SecondaryTasks {
    settings: SecondarySettings,
    vehicle: Vehicle,
    dofs: CommandedDofs,
    char_length: f64,
    ws: KinWorkspace,
    t: Matrix6xX<f64>,
    j_e: Mat<f64>,
    q: Vec<f64>,
    grad: Vec<f64>,
}

impl SecondaryTasks {
    /// For design `v`, the commanded axes `dofs` and the characteristic length `char_length`
    /// = L [m] of the scaled TCM.
    pub fn new(
        v: &Vehicle,
        settings: SecondarySettings,
        dofs: CommandedDofs,
        char_length: f64,
    ) -> Result<Self, ControlError> {
        settings.validate()?;
        check_pos("secondary.char_length", char_length)?;
        let n = v.n_joints();
        Ok(Self {
            settings,
            dofs,
            char_length,
            ws: KinWorkspace::new(v),
            t: Matrix6xX::zeros(v.n_thrusters()),
            j_e: Mat::zeros(6, 6 + n),
            q: vec![0.0; n],
            grad: vec![0.0; n],
            vehicle: v.clone(),
        })
    }

    /// The settings.
    pub fn settings(&self) -> &SecondarySettings {
        &self.settings
    }

    /// The commanded axes `S`.
    pub fn dofs(&self) -> CommandedDofs {
        self.dofs
    }

    /// `σ_min(S·T_L)` after forward kinematics into `self.ws`.
    fn sigma_here(&mut self) -> f64 {
        thruster_matrix(&self.vehicle, &self.ws, &mut self.t);
        commanded_sigma(&self.t, self.char_length, self.dofs).sigma_min
    }

    /// The soft minimum `σ_β` (see [`SecondarySettings::sharpness`]) after forward kinematics
    /// into `self.ws`, shifted by σ_min so that the exponentials cannot underflow.
    fn soft_sigma_here(&mut self) -> f64 {
        thruster_matrix(&self.vehicle, &self.ws, &mut self.t);
        let c = commanded_sigma(&self.t, self.char_length, self.dofs);
        let beta = self.settings.sharpness;
        let sum: f64 = c.singular_values[..c.k]
            .iter()
            .map(|s| (-beta * (s - c.sigma_min)).exp())
            .sum();
        c.sigma_min - sum.ln() / beta
    }

    /// `√det(J_q J_qᵀ)` after forward kinematics into `self.ws`.
    fn manipulability_here(&mut self) -> f64 {
        ee_jacobian(&self.ws, &mut self.j_e);
        let n = self.q.len();
        let gram = Matrix6::from_fn(|r, s| {
            (0..n)
                .map(|c| self.j_e[(r, 6 + c)] * self.j_e[(s, 6 + c)])
                .sum::<f64>()
        });
        gram.determinant().max(0.0).sqrt()
    }

    /// The measures with a positive gain at the configuration in `self.q`: `(σ_c, m)`, 0 for
    /// an objective that is off.
    fn measures(&mut self) -> (f64, f64) {
        forward_kinematics(&self.vehicle, &self.q, &mut self.ws);
        let sigma = if self.settings.controllability_gain > 0.0 {
            self.soft_sigma_here()
        } else {
            0.0
        };
        let manip = if self.settings.manipulability_gain > 0.0 {
            self.manipulability_here()
        } else {
            0.0
        };
        (sigma, manip)
    }

    /// The commanded-subspace σ_min `σ_min(S·T_L(q))` [N/N] at joint angles `q` [rad]
    /// (computed whatever the gains).
    pub fn controllability(&mut self, q: &[f64]) -> f64 {
        forward_kinematics(&self.vehicle, q, &mut self.ws);
        self.sigma_here()
    }

    /// The manipulability `√det(J_q J_qᵀ)` at joint angles `q` [rad] (whatever the gains).
    pub fn manipulability(&mut self, q: &[f64]) -> f64 {
        forward_kinematics(&self.vehicle, q, &mut self.ws);
        self.manipulability_here()
    }

    /// The secondary joint velocity `q̇_s = k_c ∇σ_c + k_m ∇m` [rad/s] at joint angles `q`
    /// [rad], by central differences of step `h` (length n; zeros where a measure is not
    /// finite).
    pub fn joint_velocity(&mut self, q: &[f64]) -> &[f64] {
        let (kc, km, h) = (
            self.settings.controllability_gain,
            self.settings.manipulability_gain,
            self.settings.step,
        );
        self.q.copy_from_slice(q);
        for (i, &qi) in q.iter().enumerate() {
            self.q[i] = qi + h;
            let (sp, mp) = self.measures();
            self.q[i] = qi - h;
            let (sm, mm) = self.measures();
            self.q[i] = qi;
            let g = kc * (sp - sm) / (2.0 * h) + km * (mp - mm) / (2.0 * h);
            self.grad[i] = if g.is_finite() { g } else { 0.0 };
        }
        &self.grad
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets::usm_paper;

    fn tasks(kc: f64, km: f64) -> SecondaryTasks {
        let v = usm_paper();
        let l = v.characteristic_length();
        let settings = SecondarySettings {
            controllability_gain: kc,
            manipulability_gain: km,
            ..Default::default()
        };
        let dofs = CommandedDofs::new([true, true, true, false, true, true]);
        SecondaryTasks::new(&v, settings, dofs, l).unwrap()
    }

    #[test]
    fn a_gradient_step_raises_each_measure() {
        let q = [0.3, 0.1, -0.2, 0.15, 0.25, -0.1, 0.1, 0.05];
        for (kc, km) in [(1.0, 0.0), (0.0, 1.0)] {
            let mut s = tasks(kc, km);
            let measure = |s: &mut SecondaryTasks, q: &[f64]| {
                if kc > 0.0 {
                    s.controllability(q)
                } else {
                    s.manipulability(q)
                }
            };
            let w0 = measure(&mut s, &q);
            let g = s.joint_velocity(&q).to_vec();
            let norm = g.iter().map(|x| x * x).sum::<f64>().sqrt();
            assert!(norm > 0.0, "{kc} {km}");
            let eps = 1e-3 / norm;
            let q1: Vec<f64> = q.iter().zip(&g).map(|(a, b)| a + eps * b).collect();
            let w1 = measure(&mut s, &q1);
            assert!(w1 > w0, "{kc} {km}: {w0} → {w1}");
            if km > 0.0 {
                // First order: w1 − w0 ≈ eps ‖g‖² / k_m (σ_min's ascent is that of its soft
                // minimum, close but not equal).
                let expect = eps * norm * norm;
                assert!(
                    (w1 - w0 - expect).abs() < 0.05 * expect,
                    "{}, {expect}",
                    w1 - w0
                );
            }
        }
    }

    #[test]
    fn straight_chain_has_zero_manipulability_and_off_means_zero_velocity() {
        let mut s = tasks(0.0, 0.0);
        assert_eq!(s.manipulability(&[0.0; 8]), 0.0);
        assert!(s.manipulability(&[0.3, 0.2, -0.1, 0.2, 0.1, -0.2, 0.1, 0.3]) > 0.0);
        assert!(s.joint_velocity(&[0.3; 8]).iter().all(|x| *x == 0.0));
        assert!(toml::from_str::<SecondarySettings>("gain = 1").is_err());
        let bad = SecondarySettings {
            step: 0.0,
            ..Default::default()
        };
        assert_eq!(bad.validate().unwrap_err().key, "secondary.step");
    }
}
