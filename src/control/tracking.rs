//! Tracking of a full-state [`Reference`] (docs/model.md §5 "References"): the kinematic law
//! that turns a reference base pose and twist into the base velocity reference `V_r` of the
//! dynamic control (USM-33/34), while the joint servos take the reference joint angles and
//! rates directly:
//!
//! `V_r = [R̃ v_b,r; R̃ ω_b,r] + [K_p R_Ibᵀ (p_b,r − p_b); K_o ε̃(q_b,r, q_b)]`,
//! `R̃ = R_Ibᵀ R_Ib,r`,
//!
//! with `(v_b,r, ω_b,r)` the reference twist in the reference frame `F_b,r`, brought into the
//! measured `F_b` by `R̃`; `ε̃` the orientation error of [`super::orientation_error`] (in `F_b`,
//! ≈ ½ θ a for a small rotation θ about a); `K_p`, `K_o` diagonal [1/s]. With
//! [`TrackingGains::feedforward`] the reference's base wrench (brought into `F_b` by `R̃`) is
//! added to the dynamic control's `τ_c`.

use super::error::{check_nonneg, ControlError};
use super::orientation_error;
use super::reference::Reference;
use crate::kinematics::BasePose;
use crate::spatial::{Vec3, Vec6};
use serde::{Deserialize, Serialize};

/// Gains of the reference-tracking law (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TrackingGains {
    /// Base position gain `K_p` (diagonal, `F_b` axes) [1/s]. Default `[0.5, 0.5, 0.5]`.
    pub k_position: [f64; 3],
    /// Base attitude gain `K_o` (diagonal, on ε̃) [1/s]. Default `[1, 1, 1]`.
    pub k_attitude: [f64; 3],
    /// Whether a reference base wrench (a file's `wrench_*` columns) is fed forward into
    /// `τ_c`. Default false (pure feedback on the reference motion).
    pub feedforward: bool,
}

impl Default for TrackingGains {
    fn default() -> Self {
        Self {
            k_position: [0.5; 3],
            k_attitude: [1.0; 3],
            feedforward: false,
        }
    }
}

impl TrackingGains {
    /// Check the gains; errors name `reference.<key>`.
    pub fn validate(&self) -> Result<(), ControlError> {
        for (i, k) in self.k_position.iter().enumerate() {
            check_nonneg(&format!("reference.k_position[{i}]"), *k)?;
        }
        for (i, k) in self.k_attitude.iter().enumerate() {
            check_nonneg(&format!("reference.k_attitude[{i}]"), *k)?;
        }
        Ok(())
    }

    /// The base velocity reference `V_r` in `F_b` of the module docs for the measured `base`
    /// and the reference `r`, and the reference wrench in `F_b` to feed forward (zero unless
    /// [`TrackingGains::feedforward`] and `r` has one).
    pub fn base_reference(&self, base: &BasePose, r: &Reference) -> (Vec6, Vec6) {
        let r_b = base.orientation.to_rotation_matrix();
        let rel = r_b.inverse() * r.base_orientation.to_rotation_matrix();
        let v = rel * Vec3::new(r.base_twist[0], r.base_twist[1], r.base_twist[2]);
        let w = rel * Vec3::new(r.base_twist[3], r.base_twist[4], r.base_twist[5]);
        let e_p = r_b.inverse() * (r.base_position - base.position);
        let e_o = orientation_error(&r.base_orientation, &base.orientation);
        let k = &self.k_position;
        let o = &self.k_attitude;
        let v_r = Vec6::new(
            v.x + k[0] * e_p.x,
            v.y + k[1] * e_p.y,
            v.z + k[2] * e_p.z,
            w.x + o[0] * e_o.x,
            w.y + o[1] * e_o.y,
            w.z + o[2] * e_o.z,
        );
        let ff = match (self.feedforward, r.wrench) {
            (true, Some(f)) => {
                let force = rel * Vec3::new(f[0], f[1], f[2]);
                let moment = rel * Vec3::new(f[3], f[4], f[5]);
                Vec6::new(force.x, force.y, force.z, moment.x, moment.y, moment.z)
            }
            _ => Vec6::zeros(),
        };
        (v_r, ff)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::UnitQuaternion;

    #[test]
    fn on_the_reference_the_law_is_its_twist_and_errors_push_back() {
        let g = TrackingGains::default();
        let mut r = Reference::new(0);
        r.base_orientation = UnitQuaternion::from_euler_angles(0.1, -0.2, 0.7);
        r.base_position = Vec3::new(1.0, 2.0, -0.5);
        r.base_twist = Vec6::new(0.4, 0.0, 0.01, 0.0, 0.02, -0.1);
        let on = BasePose {
            orientation: r.base_orientation,
            position: r.base_position,
        };
        let (v_r, ff) = g.base_reference(&on, &r);
        assert!((v_r - r.base_twist).norm() < 1e-12, "{v_r}");
        assert_eq!(ff, Vec6::zeros());
        // Behind the reference along its own x axis: a positive surge correction K_p · 0.2.
        let mut behind = on;
        behind.position -= r.base_orientation * Vec3::new(0.2, 0.0, 0.0);
        let (v_r, _) = g.base_reference(&behind, &r);
        assert!((v_r[0] - 0.4 - 0.5 * 0.2).abs() < 1e-12, "{v_r}");
        // Yawed left of the reference: a negative yaw-rate correction.
        let mut yawed = on;
        yawed.orientation = r.base_orientation * UnitQuaternion::from_euler_angles(0.0, 0.0, 0.1);
        let (v_r, _) = g.base_reference(&yawed, &r);
        assert!(v_r[5] < -0.1 - 0.04, "{v_r}");
    }
}
