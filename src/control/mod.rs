//! Control laws of the USM motion-control framework (docs/model.md §5, USM section IV–V, Fig. 5):
//! guidance → kinematic control → dynamic control (→ thrust allocation, in [`crate::allocation`]).
//!
//! | module | law | equations |
//! |---|---|---|
//! | [`guidance`] | line-of-sight guidance along straight segments | USM-39 |
//! | [`kinematic`] | damped weighted pseudoinverse, SRMTP task priority, task errors, inertial-frame task variables | USM-28…32, AC-7…13 |
//! | [`reference`] | the time-parameterised reference the loop follows | §5 "References" |
//! | [`reference_source`] | its sources: the timed end-effector path, a trajectory file | §5 "References" |
//! | [`trajectory_file`] | a reference read from a trajectory file (time-series columns), interpolated | §5 "References" |
//! | [`tracking`] | base pose tracking of a full-state reference into `V_r` | §5 "References", USM-33/34 |
//! | [`quintic`] | quintic point-to-point references (zero end rates and accelerations) | AC §5 |
//! | [`spline`] | timed end-effector paths: natural spline through via-points, quintic timing | AC §5, USM-42 |
//! | [`transport`] | transport mode: joint references, surge and yaw accelerations | USM-38, 40, 41 |
//! | [`work`] | work mode: end-effector pose + base position by SRMTP | USM-42 |
//! | [`dynamic`] | feedback-linearising base control | USM-33/34 |
//!
//! Every controller is split like the rest of the crate: settings (serde-deserialisable,
//! `deny_unknown_fields`, defaults = the paper's values), a controller struct that owns all
//! its buffers and state (integrators), and a per-step call that does not allocate.
//!
//! Frames and units (docs/model.md §1): inertial frame `I` with z up; base frame `F_b` at the tail
//! face of body 0; end-effector frame `F_e` at the front face of the last body. Twists are
//! `[v; ω]` (m/s, rad/s) in the frame named by the variable (`v_b` in `F_b`, `v_e` in `F_e`);
//! the generalised velocity is `ζ = [V_b; q̇]`. Angles in radians. The *heading* ψ of a frame is
//! the yaw of its x axis about the inertial +z axis, `ψ = atan2(R₁₀, R₀₀)`.

pub mod dynamic;
mod error;
pub mod guidance;
pub mod kinematic;
pub mod quintic;
pub mod reference;
pub mod reference_source;
pub mod spline;
pub mod tracking;
pub mod trajectory_file;
pub mod transport;
pub mod work;

use crate::spatial::{quat_error_vec, Vec3};
use nalgebra::UnitQuaternion;

pub use dynamic::{DynamicController, DynamicGains, DynamicOutput};
pub(crate) use error::check_nonneg;
pub use error::ControlError;
pub use guidance::{LosGuidance, LosOutput, PathSpec, SegmentSpec};
pub use kinematic::{
    base_position_jacobian, damped_weighted_pinv, ee_pose, ee_pose_error, InertialTask,
    JointLimitSettings, JointLimitTask, PinvWorkspace, Srmtp, TaskInverse, TaskVariable,
};
pub use quintic::Quintic;
pub use reference::{EeReference, Reference};
pub use reference_source::ReferenceSource;
pub use tracking::TrackingGains;
pub use trajectory_file::{ReferenceFileError, TrajectoryTable};
pub use transport::{
    measure_transport, yaw_joint_mask, SurgeLaw, SurgeSource, TransportController, TransportGains,
    TransportMeasurement, TransportMethod, TransportOutput, YawRateSource,
};
pub use work::{WorkController, WorkGains, WorkOutput, WorkTarget};

/// Orientation error `ε̃` of the end-effector task (docs/model.md §5, USM-42): the vector part of the
/// error quaternion `q⁻¹ ⊗ q_d` (sign chosen with a non-negative scalar part), i.e. the rotation
/// that takes the current frame onto the desired one, **expressed in the current frame**
/// (`≈ ½ θ a` for a small rotation `θ` about the unit axis `a`). Both quaternions map
/// frame vectors to the inertial frame.
///
/// With this sign a body-frame angular velocity `ω = k ε̃` (k > 0) decreases the error — the
/// convention USM-42 needs (`V_e = … + k_e ẽ`). It wraps [`crate::spatial::quat_error_vec`],
/// whose *code* computes exactly `q⁻¹ ⊗ q_d` (its doc comment says `q_d⁻¹ ⊗ q`, which is the
/// error in the opposite sense; the behaviour is pinned by a convergence test here).
#[inline]
pub fn orientation_error(q_d: &UnitQuaternion<f64>, q: &UnitQuaternion<f64>) -> Vec3 {
    quat_error_vec(q_d, q)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::quat_integrate;

    #[test]
    fn orientation_error_feedback_converges() {
        // ω = k ε̃ in the body frame, integrated on SO(3), drives q to q_d: pins the sign.
        let q_d = UnitQuaternion::from_euler_angles(0.4, -0.3, 1.2);
        let mut q = UnitQuaternion::from_euler_angles(-0.5, 0.6, -0.4);
        let e0 = orientation_error(&q_d, &q).norm();
        for _ in 0..4000 {
            let w = orientation_error(&q_d, &q) * 2.0;
            q = quat_integrate(&q, &w, 0.005);
        }
        let e1 = orientation_error(&q_d, &q).norm();
        assert!(e0 > 0.3 && e1 < 1e-6, "{e0} -> {e1}");
        assert!(q.angle_to(&q_d) < 1e-5);
    }
}
