//! The trajectory figures of the transport readings runs that are not scenario metrics
//! ([`super::readings`], judged in [`super::transport_claims`]):
//! - `tail_deviation_rms` [m]: how closely the back end follows the *track of the front end*
//!   (the paper's Fig. 8a/b remark): on the first segment, the RMS of the base's lateral offset
//!   minus the front's lateral offset when the front was at the same along-track position
//!   (samples before the base reaches the front's starting position are skipped);
//! - `cruise_peak_thrust` [N]: the largest `|u_j|` outside the two commanded transients, i.e.
//!   over `2 s ≤ t < t_turn` and `t ≥ t_turn + 30 s` (`t_turn` the first segment switch);
//! - `ee_sway_peak` [m/s]: the largest end-effector sideways velocity `|v_e,y|` (in `F_e`,
//!   the paper's `V_e,2` of Fig. 8c/d) over `2 s ≤ t < t_turn`, the approach to the first
//!   segment after the joints' start transient.

use crate::control::guidance::PathSpec;
use crate::outcome::RunResult;
use crate::scenario::channels::{Pose, Twist};
use crate::scenario::Channel;

/// The first segment of a path: start point and unit direction.
fn first_segment(path: &PathSpec) -> Option<([f64; 2], [f64; 2])> {
    let (a, b) = match (path.segments.first(), path.waypoints.get(..2)) {
        (Some(s), _) => (s.from, s.to),
        (None, Some(w)) => (w[0], w[1]),
        _ => return None,
    };
    let l = (b[0] - a[0]).hypot(b[1] - a[1]);
    (l > 0.0).then(|| (a, [(b[0] - a[0]) / l, (b[1] - a[1]) / l]))
}

/// `tail_deviation_rms` of the module docs; NaN when no sample qualifies.
pub fn tail_deviation_rms(r: &RunResult, path: &PathSpec) -> f64 {
    let tr = &r.trajectory;
    let (Some(seg), Some(s_e), Some(l_e), Some(xb), Some(yb), Some((a, d))) = (
        tr.get(Channel::Segment),
        tr.get(Channel::AlongTrack),
        tr.get(Channel::CrossTrack),
        tr.get(Channel::BasePose(Pose::X)),
        tr.get(Channel::BasePose(Pose::Y)),
        first_segment(path),
    ) else {
        return f64::NAN;
    };
    let n = seg.iter().take_while(|s| **s == 0.0).count();
    let (mut sum, mut count) = (0.0, 0usize);
    for i in 0..n {
        let (rx, ry) = (xb[i] - a[0], yb[i] - a[1]);
        let s_b = d[0] * rx + d[1] * ry;
        let l_b = -d[1] * rx + d[0] * ry;
        // The front's lateral offset where it passed s_b, from its track so far.
        let hit = (0..i).find(|&j| s_e[j] <= s_b && s_b < s_e[j + 1]);
        if let Some(j) = hit {
            let f = (s_b - s_e[j]) / (s_e[j + 1] - s_e[j]);
            let gap = l_b - (l_e[j] + f * (l_e[j + 1] - l_e[j]));
            sum += gap * gap;
            count += 1;
        }
    }
    if count == 0 {
        f64::NAN
    } else {
        (sum / count as f64).sqrt()
    }
}

/// The time of the first segment switch (the turn command) [s]; infinite if none.
fn turn_time(t: &[f64], seg: &[f64]) -> f64 {
    seg.iter()
        .position(|s| *s != seg[0])
        .map_or(f64::INFINITY, |i| t[i])
}

/// `cruise_peak_thrust` of the module docs.
pub fn cruise_peak_thrust(r: &RunResult) -> f64 {
    let tr = &r.trajectory;
    let (Some(t), Some(seg)) = (tr.get(Channel::T), tr.get(Channel::Segment)) else {
        return f64::NAN;
    };
    let t_turn = turn_time(t, seg);
    let u = tr.indexed(Channel::U);
    (0..t.len())
        .filter(|&i| (t[i] >= 2.0 && t[i] < t_turn) || t[i] >= t_turn + 30.0)
        .flat_map(|i| u.iter().map(move |c| c[i].abs()))
        .fold(0.0, f64::max)
}

/// `ee_sway_peak` of the module docs; NaN without the channels.
pub fn ee_sway_peak(r: &RunResult) -> f64 {
    let tr = &r.trajectory;
    let (Some(t), Some(seg), Some(v)) = (
        tr.get(Channel::T),
        tr.get(Channel::Segment),
        tr.get(Channel::EeTwist(Twist::V)),
    ) else {
        return f64::NAN;
    };
    let t_turn = turn_time(t, seg);
    (0..t.len())
        .filter(|&i| t[i] >= 2.0 && t[i] < t_turn)
        .map(|i| v[i].abs())
        .fold(0.0, f64::max)
}
