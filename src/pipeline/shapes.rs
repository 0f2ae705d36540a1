//! The body along a run: `shapes.svg` (the body at regular times over the path, coloured by
//! time, with the base and end-effector traces) and `animation.svg` (the body moving along
//! the run, SMIL, self-contained), drawn by [`crate::report::drawing::run_drawing`] from the logged
//! base pose (inertial frame, ZYX Euler angles) and joint angles.

use std::path::Path;

use nalgebra::UnitQuaternion;

use super::draw::{arrow_scale, vehicle_scene};
use super::error::PipelineError;
use crate::kinematics::BasePose;
use crate::model::Vehicle;
use crate::outcome::RunResult;
use crate::report::atomic_write;
use crate::report::drawing::run_drawing::{
    render_animation_svg, render_shapes_svg, RunDrawing, Snapshot,
};
use crate::report::drawing::Arrow;
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

/// Metres of arrow per newton for a run: the largest logged |thrust| drawn about a quarter of
/// the vehicle length (a 1–2–5 value), so that the thrusts a run actually uses are visible;
/// the design's limit-based [`arrow_scale`] when no thrust was logged.
pub(super) fn thrust_scale(v: &Vehicle, thrust: &[&[f64]]) -> f64 {
    let peak = thrust
        .iter()
        .flat_map(|c| c.iter())
        .filter(|x| x.is_finite())
        .fold(0.0_f64, |a, x| a.max(x.abs()));
    let m = 0.25 * v.total_length() / peak;
    if peak > 0.0 && m.is_finite() && m > 0.0 {
        crate::report::drawing::nice_length(m)
    } else {
        arrow_scale(v)
    }
}

/// Sets each thrust arrow to the thrust `u[j]` [N] logged for it: length `|u| · m_per_n`,
/// pointing along the thrust direction for `u > 0` and against it for `u < 0` (a thruster
/// without a logged finite thrust gets no arrow: length 0).
pub(super) fn set_thrust(arrows: &mut [Arrow], u: &[f64], m_per_n: f64) {
    for (j, a) in arrows.iter_mut().enumerate() {
        let f = u.get(j).copied().filter(|x| x.is_finite()).unwrap_or(0.0);
        a.length = f.abs() * m_per_n;
        if f < 0.0 {
            a.direction = -a.direction;
        }
    }
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

/// `count` (clamped to 1…n) evenly spaced indices of `n ≥ 1` samples, first and last included,
/// without repeats.
pub(super) fn even_picks(n: usize, count: usize) -> Vec<usize> {
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
    picks
}

/// The drawing of run `r` of `v` with `count` snapshots at evenly spaced samples (first and
/// last included); `None` when the run logged no samples.
pub fn run_drawing(r: &RunResult, v: &Vehicle, count: usize) -> Option<RunDrawing> {
    let t = r.trajectory.get(Channel::T)?;
    let n = t.len();
    if n == 0 {
        return None;
    }
    let picks = even_picks(n, count);
    let thrust = r.trajectory.indexed(Channel::U);
    let m_per_n = thrust_scale(v, &thrust);
    let snapshots = picks
        .into_iter()
        .filter_map(|k| {
            state_at(r, v, k).map(|s| {
                let mut scene = vehicle_scene(v, &s);
                let u: Vec<f64> = thrust.iter().map(|c| c[k]).collect();
                set_thrust(&mut scene.arrows, &u, m_per_n);
                Snapshot { t: t[k], scene }
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
            format!(
                "arrows: each thruster's thrust at that time, signed, {} m per N",
                crate::report::fmt_short(m_per_n)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thrust_arrows_scale_with_the_thrust_and_flip_with_its_sign() {
        let arrow = |name: &str| Arrow {
            name: name.into(),
            start: Vec3::zeros(),
            direction: Vec3::new(1.0, 0.0, 0.0),
            length: 9.0,
        };
        let mut arrows = vec![arrow("T1"), arrow("T2"), arrow("T3")];
        set_thrust(&mut arrows, &[20.0, -10.0], 0.01);
        assert_eq!(arrows[0].length, 0.2);
        assert_eq!(arrows[0].direction, Vec3::new(1.0, 0.0, 0.0));
        assert_eq!(arrows[1].length, 0.1);
        assert_eq!(arrows[1].direction, Vec3::new(-1.0, 0.0, 0.0));
        // No logged thrust: no arrow.
        assert_eq!(arrows[2].length, 0.0);
    }
}
