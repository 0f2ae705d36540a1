//! How a run that followed a trajectory file (`[reference] file`, work mode) compares with
//! that reference: the base path error along the run and at its end, and the control effort
//! the closed loop spent beside the effort the reference's own controls cost (for an `ocp`
//! optimum: the open-loop optimum's objective, so the difference is the controller's price).
//!
//! Effort `J = Σ_k Δt_k (‖u_k‖² + ‖τ_k‖²)`: thrusts `u` [N] and joint torques `τ` [N·m], the
//! `effort` objective of `usm-study ocp` (weight 1; with base-wrench actuation the reference's
//! wrench takes the thrusts' place). For the run it is the rectangle rule over the logged rows
//! (exact when `scenario.log_dt = scenario.control_dt`, the zero-order hold of the thrusts).
//! Thruster energy, both sides, is the static actuator-disk figure `Σ Δt Σ_j P_0(u_j)`
//! (docs/model.md §6; no inflow, which the reference does not know); the run's own
//! `thruster_energy` metric, with inflow, is in its summary.

use super::channels::{Channel, Pose, Trajectory};
use crate::control::reference::Reference;
use crate::control::trajectory_file::TrajectoryTable;
use crate::metrics::trajectory::PowerModel;
use crate::spatial::Vec3;
use serde::Serialize;

/// A tracked run beside its reference (module docs).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TrackingComparison {
    /// Largest distance of the run's base origin from the reference's at the same time [m].
    pub base_error_max: f64,
    /// RMS of that distance over the logged rows [m].
    pub base_error_rms: f64,
    /// That distance at the last logged row [m].
    pub base_error_final: f64,
    /// The run's effort `Σ Δt (‖u‖² + ‖τ‖²)` over the logged rows [N² s + (N·m)² s].
    pub tracked_effort: f64,
    /// The reference's own effort (its control columns), `None` without any.
    pub reference_effort: Option<f64>,
    /// `tracked_effort − reference_effort`: what closing the loop costs; `None` without
    /// reference controls.
    pub price: Option<f64>,
    /// The run's static thruster energy over the logged rows [J].
    pub tracked_thruster_energy_static: f64,
    /// The reference's static thruster energy from its thrust columns [J]; `None` without.
    pub reference_thruster_energy_static: Option<f64>,
}

/// Compare the logged `trajectory` of a run with the reference `table` it followed.
pub fn compare_with_reference(
    table: &TrajectoryTable,
    trajectory: &Trajectory,
    power: &PowerModel,
) -> TrackingComparison {
    let col = |c: Channel| trajectory.get(c).unwrap_or(&[]);
    let t = col(Channel::T);
    let (x, y, z) = (
        col(Channel::BasePose(Pose::X)),
        col(Channel::BasePose(Pose::Y)),
        col(Channel::BasePose(Pose::Z)),
    );
    let mut r = Reference::new(table.n_joints());
    let (mut max, mut sq, mut last) = (0.0f64, 0.0, f64::NAN);
    for k in 0..t.len() {
        table.sample_into(t[k], &mut r);
        let d = (Vec3::new(x[k], y[k], z[k]) - r.base_position).norm();
        max = max.max(d);
        sq += d * d;
        last = d;
    }
    let u = trajectory.indexed(Channel::U);
    let tau = trajectory.indexed(Channel::Tau);
    let (mut effort, mut energy) = (0.0, 0.0);
    for k in 0..t.len().saturating_sub(1) {
        let s: f64 = (u.iter().chain(&tau)).map(|c| c[k] * c[k]).sum();
        effort += (t[k + 1] - t[k]) * s;
        let p: f64 = u.iter().map(|c| power.static_power(c[k])).sum();
        energy += (t[k + 1] - t[k]) * p;
    }
    let reference_effort = table.effort();
    TrackingComparison {
        base_error_max: max,
        base_error_rms: (sq / t.len().max(1) as f64).sqrt(),
        base_error_final: last,
        tracked_effort: effort,
        reference_effort,
        price: reference_effort.map(|j| effort - j),
        tracked_thruster_energy_static: energy,
        reference_thruster_energy_static: table.thrust_integral(|u| power.static_power(u)),
    }
}
