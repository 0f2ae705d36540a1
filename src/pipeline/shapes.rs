//! The body along a run: `shapes.svg` (the body at regular times over the path, coloured by
//! time, with the base and end-effector traces) and `animation.svg` (the body moving along
//! the run, SMIL, self-contained), drawn by [`crate::report::drawing::run`] from the logged
//! base pose (inertial frame, ZYX Euler angles) and joint angles.

use std::path::Path;

use nalgebra::UnitQuaternion;

use super::draw::vehicle_scene;
use super::error::PipelineError;
use crate::kinematics::BasePose;
use crate::model::Vehicle;
use crate::outcome::RunResult;
use crate::report::atomic_write;
use crate::report::drawing::run::{render_animation_svg, render_shapes_svg, RunDrawing, Snapshot};
use crate::scenario::channels::{Channel, Pose};
use crate::spatial::Vec3;
use crate::state::VehicleState;

/// Bodies drawn in `shapes.svg` (first and last sample included).
pub const SHAPE_SNAPSHOTS: usize = 8;
/// Frames of `animation.svg`.
pub const ANIMATION_FRAMES: usize = 60;
/// Length of one cycle of the animation [s] (wall-clock, whatever the run's duration).
pub const ANIMATION_SECONDS: f64 = 12.0;

/// The logged state of `v` at sample `k`: base pose from `base_x…base_yaw` (USM-1, ZYX
/// Euler angles, inertial frame) and joint angles `q_*`; velocities zero (they are not drawn).
fn state_at(r: &RunResult, v: &Vehicle, k: usize) -> Option<VehicleState> {
    let tr = &r.trajectory;
    let pose: Vec<f64> = Pose::ALL
        .iter()
        .map(|&p| tr.get(Channel::BasePose(p)).map(|c| c[k]))
        .collect::<Option<_>>()?;
    let q: Vec<f64> = tr.indexed(Channel::Q).iter().map(|c| c[k]).collect();
    if q.len() != v.n_joints() || pose.iter().chain(&q).any(|x| !x.is_finite()) {
        return None;
    }
    let mut s = VehicleState::rest(v);
    s.base = BasePose {
        orientation: UnitQuaternion::from_euler_angles(pose[3], pose[4], pose[5]),
        position: Vec3::new(pose[0], pose[1], pose[2]),
    };
    s.q = q;
    Some(s)
}

/// A channel triple as points, e.g. the base or end-effector position.
fn trace(r: &RunResult, ch: fn(Pose) -> Channel) -> Vec<Vec3> {
    let tr = &r.trajectory;
    match (
        tr.get(ch(Pose::X)),
        tr.get(ch(Pose::Y)),
        tr.get(ch(Pose::Z)),
    ) {
        (Some(x), Some(y), Some(z)) => (0..x.len())
            .map(|k| Vec3::new(x[k], y[k], z[k]))
            .filter(|p| p.iter().all(|c| c.is_finite()))
            .collect(),
        _ => Vec::new(),
    }
}

/// The drawing of run `r` of `v` with `count` snapshots at evenly spaced samples (first and
/// last included); `None` when the run logged no samples.
pub fn run_drawing(r: &RunResult, v: &Vehicle, count: usize) -> Option<RunDrawing> {
    let t = r.trajectory.get(Channel::T)?;
    let n = t.len();
    if n == 0 {
        return None;
    }
    let count = count.clamp(1, n);
    let mut picks: Vec<usize> = (0..count)
        .map(|i| {
            if count == 1 {
                0
            } else {
                i * (n - 1) / (count - 1)
            }
        })
        .collect();
    picks.dedup();
    let snapshots = picks
        .into_iter()
        .filter_map(|k| {
            state_at(r, v, k).map(|s| Snapshot {
                t: t[k],
                scene: vehicle_scene(v, &s),
            })
        })
        .collect();
    let outcome = match &r.failure {
        Some((at, cause)) => format!("failed at t = {at:.2} s: {cause}"),
        None => "completed".into(),
    };
    Some(RunDrawing {
        caption: vec![
            format!("{} — {} ({} mode)", v.name, r.name, r.mode),
            format!(
                "{} s simulated, {outcome}; base and end-effector traces over every logged sample",
                t[n - 1]
            ),
        ],
        snapshots,
        base_trace: trace(r, Channel::BasePose),
        ee_trace: trace(r, Channel::EePose),
    })
}

/// Writes `shapes.svg` and `animation.svg` of run `r` of `v` into `out` (which must exist);
/// nothing when the run logged no samples.
pub fn write_shapes(r: &RunResult, v: &Vehicle, out: &Path) -> Result<(), PipelineError> {
    if let Some(d) = run_drawing(r, v, SHAPE_SNAPSHOTS) {
        atomic_write(&out.join("shapes.svg"), render_shapes_svg(&d).as_bytes())?;
    }
    if let Some(d) = run_drawing(r, v, ANIMATION_FRAMES) {
        let svg = render_animation_svg(&d, ANIMATION_SECONDS);
        atomic_write(&out.join("animation.svg"), svg.as_bytes())?;
    }
    Ok(())
}
