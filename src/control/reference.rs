//! The time-parameterised reference the closed loop follows (docs/model.md §5 "References"):
//! one [`Reference`] sample — base pose and twist, joint positions and rates, optionally an
//! end-effector pose and twist, a feed-forward base wrench and joint torques — filled every
//! control period by a [`super::reference_source::ReferenceSource`]:
//!
//! - `ReferenceSource::EndEffector`: the work-mode timed path of [`super::spline`] (natural
//!   spline through via-points, quintic timing; fills only the end-effector part);
//! - `ReferenceSource::Table`: a trajectory read from a file with the time-series column
//!   names ([`super::trajectory_file`]), interpolated in time; fills the base, the joints and,
//!   when the file has them, the end effector and the feed-forward terms.
//!
//! The transport mode's LOS guidance ([`super::guidance`]) is not a time-parameterised
//! source: its reference heading depends on the measured position (USM-38/39), so it stays
//! inside the transport law.
//!
//! Frames and units: positions in the inertial frame `I` [m]; orientations map body vectors to
//! `I`; the base twist is in the reference base frame `F_b,r` [m/s, rad/s]; the end-effector
//! twist in the *measured* end-effector frame (USM-42's `V_e,d`); the wrench in `F_b,r`
//! [N, N·m]; joint angles [rad], rates [rad/s], torques [N·m]. Sampling never allocates: the
//! joint vectors are sized once by [`Reference::new`].

use crate::spatial::{Vec3, Vec6};
use nalgebra::UnitQuaternion;

/// The end-effector part of a reference: desired pose in `I` and twist in the measured `F_e`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EeReference {
    /// Desired end-effector position `p_d` in `I` [m].
    pub position: Vec3,
    /// Desired end-effector orientation `q_d` (maps `F_e,d` vectors to `I`).
    pub orientation: UnitQuaternion<f64>,
    /// Desired end-effector twist `V_e,d` in the measured `F_e` [m/s, rad/s].
    pub twist: Vec6,
}

/// One sample of a time-parameterised reference at time `t`. Which parts a source fills is
/// said by the flags (`has_base`, `has_joints`, `has_torques`) and the options (`ee`,
/// `wrench`); a part a source does not fill keeps its last value.
#[derive(Clone, Debug, PartialEq)]
pub struct Reference {
    /// Sample time [s].
    pub t: f64,
    /// Whether the base pose and twist are set.
    pub has_base: bool,
    /// Reference base position `p_b,r` in `I` [m].
    pub base_position: Vec3,
    /// Reference base orientation `R_Ib,r` (maps `F_b,r` vectors to `I`).
    pub base_orientation: UnitQuaternion<f64>,
    /// Reference base twist `V_b,r` in `F_b,r` [m/s, rad/s].
    pub base_twist: Vec6,
    /// Whether the joint angles and rates are set.
    pub has_joints: bool,
    /// Joint angles `q_r` [rad].
    pub q: Vec<f64>,
    /// Joint rates `q̇_r` [rad/s].
    pub qd: Vec<f64>,
    /// End-effector pose and twist, when the source gives one.
    pub ee: Option<EeReference>,
    /// Feed-forward base wrench `τ_ff` in `F_b,r` [N, N·m], when the source gives one.
    pub wrench: Option<Vec6>,
    /// Whether `torques` holds feed-forward joint torques.
    pub has_torques: bool,
    /// Feed-forward joint torques [N·m].
    pub torques: Vec<f64>,
}

impl Reference {
    /// An empty reference for `n_joints` joints (nothing set; identity pose; zeros).
    pub fn new(n_joints: usize) -> Self {
        Self {
            t: 0.0,
            has_base: false,
            base_position: Vec3::zeros(),
            base_orientation: UnitQuaternion::identity(),
            base_twist: Vec6::zeros(),
            has_joints: false,
            q: vec![0.0; n_joints],
            qd: vec![0.0; n_joints],
            ee: None,
            wrench: None,
            has_torques: false,
            torques: vec![0.0; n_joints],
        }
    }
}
