//! Sliding-mode vehicle control for Antonelli & Chiaverini's case 3 (docs/model.md §8).
//!
//! What the paper says of it, in full (section 5, third case study): "Two simulations have
//! been performed considering the full-dimensional dynamic model of the NPS AUV II under a
//! sliding mode control law [1]", with "[1] G. Antonelli and S. Chiaverini, *Singularity-Free
//! Regulation of Underwater Vehicle-Manipulator Systems*, Proc. American Control Conference,
//! Philadelphia, PA, 1998". The law of [1] is a **regulation** law (its title); its text is
//! not in the seed and we did not have it. We use the quaternion-based sliding-mode law in the
//! form of Antonelli's later book ("Underwater Robots", after Slotine & Li), from memory of
//! that book — an inference. Its regulation form ([`SlidingLaw::Regulation`], the paper's
//! case 3 as written) is
//!
//! ```text
//! s = Λ [R_Ibᵀ (p_d − p); ε̃] − [v; ω],   τ = K_D s + K_S sat(s/φ) + ĝ
//! ```
//!
//! with no feed-forward of the reference's velocity or acceleration: a moving set-point
//! `(p_d(t), R_d(t))` is regulated to as if it were constant at each instant. The tracking form
//! ([`SlidingLaw::Tracking`], the project's earlier reading) adds the reference's velocity to
//! the sliding variable:
//!
//! ```text
//! s = [R_Ibᵀ ṗ_d − v; R_Ibᵀ ω_d − ω] + Λ [R_Ibᵀ (p_d − p); ε̃]
//! ```
//!
//! Neither form feeds the reference acceleration forward. `V_b = [v; ω]` is the base twist in
//! `F_b`, `(p_d, R_d)` the desired base pose in the inertial frame, `ṗ_d, ω_d` its rates
//! (inertial), `ε̃` the vector part of `R_Ibᵀ R_d` as a quaternion with non-negative scalar
//! part (the orientation error in `F_b`, ≈ ½θ axis), and `ĝ = −(restoring wrench)` the
//! compensation of weight and buoyancy. `τ` is the base wrench `[f; m]` in `F_b` [N, N·m].
//!
//! Inferred (stated, overridable in [`SlidingModeGains`]): the boundary layer `φ` replacing
//! `sign(s)` by a saturation (no chattering: a chattering switch term would add its own
//! amplitude to the force integrals of Table I), and every gain (the paper gives none).

use crate::control::{check_nonneg, ControlError};
use crate::kinematics::BasePose;
use crate::spatial::{quat_error_vec, Vec3, Vec6};
use nalgebra::UnitQuaternion;

/// Gains of the sliding-mode law, per base axis `[x, y, z, roll, pitch, yaw]` of `F_b`.
/// Defaults (inferred for the NPS AUV II): `K_D` twice the diagonal of its mass matrix per
/// second (the sliding variable decays at about 2 rad/s), `Λ` = 0.5 1/s, a switching gain of
/// 10 N / 50 N·m and a boundary layer of 0.01 m/s / 0.01 rad/s.
#[derive(Clone, Debug, PartialEq)]
pub struct SlidingModeGains {
    /// `Λ` [1/s]: the sliding surface's position (orientation) gain. Default 0.5.
    pub lambda: [f64; 6],
    /// `K_D` [N·s/m, N·m·s/rad]. Default about `2 · diag(M_RB + M_A)` of the NPS AUV II
    /// (legacy constants, diagonal ≈ [6 020, 9 550, 23 300, 4 130, 49 100, 20 700]):
    /// `[12 060, 19 300, 47 500, 8 360, 100 000, 41 750]`.
    pub k_d: [f64; 6],
    /// `K_S` [N, N·m]: the switching (robustness) gain. Default `[10, 10, 10, 50, 50, 50]`.
    pub k_s: [f64; 6],
    /// `φ` [m/s, rad/s]: boundary-layer width of `sat(s/φ)`. Default 0.01.
    pub boundary: [f64; 6],
}

impl Default for SlidingModeGains {
    fn default() -> Self {
        Self {
            lambda: [0.5; 6],
            k_d: [12_060.0, 19_300.0, 47_500.0, 8_360.0, 100_000.0, 41_750.0],
            k_s: [10.0, 10.0, 10.0, 50.0, 50.0, 50.0],
            boundary: [0.01; 6],
        }
    }
}

impl SlidingModeGains {
    /// Every entry finite and `>= 0`, boundary layers `> 0`.
    pub fn validate(&self) -> Result<(), ControlError> {
        for (name, g) in [
            ("lambda", &self.lambda),
            ("k_d", &self.k_d),
            ("k_s", &self.k_s),
            ("boundary", &self.boundary),
        ] {
            for (i, x) in g.iter().enumerate() {
                check_nonneg(&format!("sliding.{name}[{i}]"), *x)?;
            }
        }
        if let Some(i) = self.boundary.iter().position(|b| *b <= 0.0) {
            return Err(ControlError::new(
                format!("sliding.boundary[{i}]"),
                "must be > 0",
            ));
        }
        Ok(())
    }
}

/// A desired base motion: pose and rates in the inertial frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoseReference {
    /// Desired base position `p_d` [m].
    pub position: Vec3,
    /// Desired base orientation `R_d`.
    pub orientation: UnitQuaternion<f64>,
    /// Desired linear velocity `ṗ_d` [m/s] (inertial).
    pub velocity: Vec3,
    /// Desired angular velocity `ω_d` [rad/s] (inertial).
    pub angular_velocity: Vec3,
}

/// Which form of the sliding variable (module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SlidingLaw {
    /// `s = Λ ỹ − ν`: the regulation law of the paper's reference [1]; the reference's
    /// velocity never enters.
    Regulation,
    /// `s = ν_d + Λ ỹ − ν`: the reference's velocity fed forward (tracking).
    Tracking,
}

/// The sliding variable `s` (in `F_b`) of the law in the module doc, in the form `law`.
pub fn sliding_variable(
    gains: &SlidingModeGains,
    law: SlidingLaw,
    pose: &BasePose,
    twist: &Vec6,
    reference: &PoseReference,
) -> Vec6 {
    let rt = pose.orientation.inverse();
    let e_p = rt * (reference.position - pose.position);
    let e_o = quat_error_vec(&reference.orientation, &pose.orientation);
    let err = [e_p.x, e_p.y, e_p.z, e_o.x, e_o.y, e_o.z];
    let vel = match law {
        SlidingLaw::Regulation => [0.0; 6],
        SlidingLaw::Tracking => {
            let v_d = rt * reference.velocity;
            let w_d = rt * reference.angular_velocity;
            [v_d.x, v_d.y, v_d.z, w_d.x, w_d.y, w_d.z]
        }
    };
    Vec6::from_fn(|i, _| vel[i] - twist[i] + gains.lambda[i] * err[i])
}

/// The control wrench `τ = K_D s + K_S sat(s/φ) − restoring` [N, N·m] in `F_b`, with
/// `restoring` the wrench weight and buoyancy apply to the base (`F_b`, e.g. the base rows of
/// [`crate::dynamics::restoring_generalized`]).
pub fn sliding_mode_wrench(gains: &SlidingModeGains, s: &Vec6, restoring: &Vec6) -> Vec6 {
    Vec6::from_fn(|i, _| {
        let sat = (s[i] / gains.boundary[i]).clamp(-1.0, 1.0);
        gains.k_d[i] * s[i] + gains.k_s[i] * sat - restoring[i]
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_error_gives_only_the_restoring_compensation() {
        let g = SlidingModeGains::default();
        g.validate().unwrap();
        let pose = BasePose::default();
        let r = PoseReference {
            position: pose.position,
            orientation: pose.orientation,
            velocity: Vec3::zeros(),
            angular_velocity: Vec3::zeros(),
        };
        let s = sliding_variable(&g, SlidingLaw::Regulation, &pose, &Vec6::zeros(), &r);
        assert_eq!(s, Vec6::zeros());
        let rest = Vec6::new(0.0, 0.0, 3.0, 1.0, 0.0, 0.0);
        assert_eq!(sliding_mode_wrench(&g, &s, &rest), -rest);
    }

    #[test]
    fn errors_push_towards_the_reference() {
        // Desired 1 m along inertial x with the vehicle yawed 90°: inertial +x is body −y,
        // so the force is along body −y; a desired yaw 0.2 rad further gives a positive yaw
        // moment.
        let g = SlidingModeGains::default();
        let yaw = std::f64::consts::FRAC_PI_2;
        let pose = BasePose {
            orientation: UnitQuaternion::from_axis_angle(&Vec3::z_axis(), yaw),
            position: Vec3::zeros(),
        };
        let r = PoseReference {
            position: Vec3::new(1.0, 0.0, 0.0),
            orientation: UnitQuaternion::from_axis_angle(&Vec3::z_axis(), yaw + 0.2),
            velocity: Vec3::zeros(),
            angular_velocity: Vec3::zeros(),
        };
        let s = sliding_variable(&g, SlidingLaw::Regulation, &pose, &Vec6::zeros(), &r);
        let tau = sliding_mode_wrench(&g, &s, &Vec6::zeros());
        assert!(
            tau[1] < 0.0 && tau[0].abs() < 1e-9 * tau[1].abs(),
            "{tau:?}"
        );
        assert!(tau[5] > 0.0, "{tau:?}");
    }

    #[test]
    fn regulation_ignores_the_reference_velocity_and_tracking_feeds_it_forward() {
        // Regulation (the paper's reference [1]): s = Λ ỹ − ν whatever the reference's rates;
        // tracking adds R_Ibᵀ ṗ_d and R_Ibᵀ ω_d.
        let g = SlidingModeGains::default();
        let pose = BasePose {
            orientation: UnitQuaternion::from_axis_angle(&Vec3::z_axis(), 0.4),
            position: Vec3::new(0.1, -0.2, 0.0),
        };
        let twist = Vec6::new(0.05, -0.02, 0.0, 0.0, 0.0, 0.03);
        let still = PoseReference {
            position: Vec3::new(0.3, 0.1, 0.0),
            orientation: UnitQuaternion::from_axis_angle(&Vec3::z_axis(), 0.6),
            velocity: Vec3::zeros(),
            angular_velocity: Vec3::zeros(),
        };
        let moving = PoseReference {
            velocity: Vec3::new(0.7, -0.4, 0.0),
            angular_velocity: Vec3::new(0.0, 0.0, 0.25),
            ..still
        };
        let reg =
            |r: &PoseReference| sliding_variable(&g, SlidingLaw::Regulation, &pose, &twist, r);
        let trk = |r: &PoseReference| sliding_variable(&g, SlidingLaw::Tracking, &pose, &twist, r);
        assert_eq!(reg(&still), reg(&moving));
        assert_eq!(reg(&still), trk(&still));
        let ff = trk(&moving) - trk(&still);
        let body_v = pose.orientation.inverse() * moving.velocity;
        assert!((ff[0] - body_v.x).abs() < 1e-15 && (ff[1] - body_v.y).abs() < 1e-15);
        assert!((ff[5] - 0.25).abs() < 1e-15, "{ff:?}");
    }
}
