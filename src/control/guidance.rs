//! Line-of-sight guidance along a path of straight segments (docs/model.md §5 transport mode, USM-39).
//!
//! For the active segment `k` from `a_k` to `b_k` with direction `α_k` (angle of `b_k − a_k`
//! about the inertial +z axis) and a point `p` (the front of the vehicle: the end-effector
//! position projected on the horizontal plane, inertial frame, metres):
//! - along-track distance `s = cos α_k (x − a_x) + sin α_k (y − a_y)` [m] (0 at `a_k`);
//! - cross-track error `e_y = −sin α_k (x − a_x) + cos α_k (y − a_y)` [m], **positive when the
//!   point is to the left of the segment** (counter-clockwise side seen from above, z up);
//! - reference heading `ψ_r = α_k − atan(e_y / Δ)` [rad] (USM-39; the paper's path is along +X,
//!   `α = 0`), wrapped to `(−π, π]`; a point left of the path gets a heading pointing right,
//!   back towards it;
//! - its rate, analytically for the fixed segment: `ė_y = −sin α_k ẋ + cos α_k ẏ` from the point's
//!   horizontal velocity and `ψ̇_r = −Δ ė_y / (Δ² + e_y²)` [rad/s]. A segment switch makes `ψ_r`
//!   jump; `ψ̇_r` does not contain that impulse (it is the rate on the new segment).
//!
//! Segment switching (both rules are always on):
//! - **by time**: a segment with `start_time = t_s` becomes active as soon as `t ≥ t_s`
//!   (the latest such segment after the active one wins), whether or not the previous one was
//!   completed — the paper's "180° turn commanded at t = 95 s";
//! - **by distance**: the next segment becomes active when the along-track position passes the
//!   active segment's end (`s ≥ length`) or the point is within `acceptance_radius` of its end,
//!   provided the next segment has no start time still in the future.
//!
//! The last segment (and any segment still waiting for a timed successor) extends as a line
//! beyond its end.

use super::error::{check_finite, check_nonneg, check_pos, ControlError};
use crate::spatial::wrap_angle;
use crate::spatial::Vec3;
use serde::{Deserialize, Serialize};

/// One straight segment of a path, as written in a scenario file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SegmentSpec {
    /// Start point `(x, y)` in the inertial frame [m].
    pub from: [f64; 2],
    /// End point `(x, y)` in the inertial frame [m]; defines the direction `α_k`.
    pub to: [f64; 2],
    /// Optional time [s] at which this segment becomes active (switching by time).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start_time: Option<f64>,
}

/// A path for [`LosGuidance`], as written in a scenario file: either `waypoints` (consecutive
/// points joined by segments, switched by distance) or explicit `segments` (which may carry
/// start times), not both.
///
/// ```toml
/// [path]
/// segments = [
///   { from = [0.0, 0.0], to = [100.0, 0.0] },
///   { from = [100.0, 5.0], to = [0.0, 5.0], start_time = 95.0 },
/// ]
/// acceptance_radius = 0.0
/// ```
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PathSpec {
    /// Waypoints `(x, y)` in the inertial frame [m]; at least two.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub waypoints: Vec<[f64; 2]>,
    /// Explicit segments.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub segments: Vec<SegmentSpec>,
    /// Distance [m] to a segment's end at which the next segment becomes active (0: switch
    /// only when the along-track position passes the end).
    #[serde(default)]
    pub acceptance_radius: f64,
}

/// A validated segment with precomputed geometry.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Segment {
    a: [f64; 2],
    /// Unit direction `(cos α, sin α)`.
    dir: [f64; 2],
    alpha: f64,
    length: f64,
    start_time: Option<f64>,
}

/// Result of one guidance update (USM-39).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LosOutput {
    /// Reference heading `ψ_r` [rad] about inertial +z, in `(−π, π]`.
    pub psi_r: f64,
    /// Its rate `ψ̇_r` [rad/s] (analytic, for the active segment).
    pub psi_r_dot: f64,
    /// Signed cross-track error `e_y` [m], positive left of the segment.
    pub cross_track: f64,
    /// Along-track distance `s` [m] from the active segment's start.
    pub along_track: f64,
    /// Index of the active segment.
    pub segment: usize,
    /// Direction `α_k` [rad] of the active segment.
    pub alpha: f64,
    /// Whether the active segment changed in this update.
    pub switched: bool,
}

/// LOS guidance state (USM-39): the path, the look-ahead distance `Δ` and the active segment.
#[derive(Clone, Debug, PartialEq)]
pub struct LosGuidance {
    segments: Vec<Segment>,
    look_ahead: f64,
    acceptance_radius: f64,
    active: usize,
}

impl LosGuidance {
    /// Validate a path and build the guidance with look-ahead distance `look_ahead` = Δ [m]
    /// (> 0; USM Table III: 3 m for Method 1, 2 m for Method 2). Errors name the key
    /// (`path.waypoints[3]`, `path.segments[1].to`, …).
    pub fn new(spec: &PathSpec, look_ahead: f64) -> Result<Self, ControlError> {
        check_pos("look_ahead", look_ahead)?;
        check_nonneg("path.acceptance_radius", spec.acceptance_radius)?;
        // (key, from, to, start time) per segment.
        type RawSegment = (String, [f64; 2], [f64; 2], Option<f64>);
        let raw: Vec<RawSegment> = match (spec.waypoints.is_empty(), spec.segments.is_empty()) {
            (false, false) => {
                return Err(ControlError::new(
                    "path",
                    "give either `waypoints` or `segments`, not both",
                ))
            }
            (true, true) => {
                return Err(ControlError::new(
                    "path",
                    "needs `waypoints` (at least two) or `segments` (at least one)",
                ))
            }
            (false, true) => {
                if spec.waypoints.len() < 2 {
                    return Err(ControlError::new(
                        "path.waypoints",
                        "needs at least two waypoints",
                    ));
                }
                spec.waypoints
                    .windows(2)
                    .enumerate()
                    .map(|(i, w)| (format!("path.waypoints[{}]", i + 1), w[0], w[1], None))
                    .collect()
            }
            (true, false) => spec
                .segments
                .iter()
                .enumerate()
                .map(|(i, s)| (format!("path.segments[{i}]"), s.from, s.to, s.start_time))
                .collect(),
        };
        let mut segments = Vec::with_capacity(raw.len());
        let mut last_time = f64::NEG_INFINITY;
        for (key, a, b, t) in raw {
            for x in a.iter().chain(b.iter()) {
                check_finite(&key, *x)?;
            }
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            let length = dx.hypot(dy);
            if length < 1e-9 {
                return Err(ControlError::new(key, "has zero length"));
            }
            if let Some(ts) = t {
                check_finite(&format!("{key}.start_time"), ts)?;
                if ts < last_time {
                    return Err(ControlError::new(
                        format!("{key}.start_time"),
                        format!("start times must not decrease (got {ts} after {last_time})"),
                    ));
                }
                last_time = ts;
            }
            segments.push(Segment {
                a,
                dir: [dx / length, dy / length],
                alpha: dy.atan2(dx),
                length,
                start_time: t,
            });
        }
        Ok(Self {
            segments,
            look_ahead,
            acceptance_radius: spec.acceptance_radius,
            active: 0,
        })
    }

    /// Look-ahead distance Δ [m].
    pub fn look_ahead(&self) -> f64 {
        self.look_ahead
    }

    /// Make segment 0 active again.
    pub fn reset(&mut self) {
        self.active = 0;
    }

    /// Along-track and cross-track coordinates `(s, e_y)` [m] of `(x, y)` for segment `k`.
    fn path_coords(&self, k: usize, x: f64, y: f64) -> (f64, f64) {
        let s = &self.segments[k];
        let (rx, ry) = (x - s.a[0], y - s.a[1]);
        (
            s.dir[0] * rx + s.dir[1] * ry,
            -s.dir[1] * rx + s.dir[0] * ry,
        )
    }

    /// One guidance update at time `t` [s] for the point `p` (the front of the vehicle:
    /// end-effector position in `I`, metres; only x and y are used) moving with inertial velocity
    /// `p_dot` [m/s] (only x and y used): applies the switching rules, then USM-39.
    /// Allocation-free. Non-finite inputs give non-finite outputs (never a panic).
    pub fn update(&mut self, t: f64, p: &Vec3, p_dot: &Vec3) -> LosOutput {
        let before = self.active;
        // Switching by time: the latest segment after the active one whose start has come.
        for j in (self.active + 1)..self.segments.len() {
            if self.segments[j].start_time.is_some_and(|ts| t >= ts) {
                self.active = j;
            }
        }
        // Switching by distance (bounded by the segment count).
        while self.active + 1 < self.segments.len() {
            let next_ready = self.segments[self.active + 1]
                .start_time
                .is_none_or(|ts| t >= ts);
            if !next_ready {
                break;
            }
            let seg = self.segments[self.active];
            let (s, _) = self.path_coords(self.active, p.x, p.y);
            let end = [
                seg.a[0] + seg.dir[0] * seg.length,
                seg.a[1] + seg.dir[1] * seg.length,
            ];
            let d_end = (p.x - end[0]).hypot(p.y - end[1]);
            if s >= seg.length || d_end <= self.acceptance_radius {
                self.active += 1;
            } else {
                break;
            }
        }
        let k = self.active;
        let seg = self.segments[k];
        let (s, e) = self.path_coords(k, p.x, p.y);
        let delta = self.look_ahead;
        let psi_r = wrap_angle(seg.alpha - (e / delta).atan());
        let e_dot = -seg.dir[1] * p_dot.x + seg.dir[0] * p_dot.y;
        let psi_r_dot = -delta * e_dot / (delta * delta + e * e);
        LosOutput {
            psi_r,
            psi_r_dot,
            cross_track: e,
            along_track: s,
            segment: k,
            alpha: seg.alpha,
            switched: k != before,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn x_line() -> LosGuidance {
        let spec = PathSpec {
            waypoints: vec![[0.0, 0.0], [100.0, 0.0]],
            ..Default::default()
        };
        LosGuidance::new(&spec, 2.0).unwrap()
    }

    #[test]
    fn point_left_of_x_path_steers_back() {
        let mut g = x_line();
        let o = g.update(0.0, &Vec3::new(5.0, 2.0, -1.0), &Vec3::zeros());
        // Left of a +X path (y > 0): e_y > 0 and ψ_r = −atan(2/2) = −π/4 (pointing right, back).
        assert!((o.cross_track - 2.0).abs() < 1e-12);
        assert!((o.along_track - 5.0).abs() < 1e-12);
        assert!((o.psi_r + PI / 4.0).abs() < 1e-12);
        let o = g.update(0.0, &Vec3::new(5.0, -2.0, 0.0), &Vec3::zeros());
        assert!(o.cross_track < 0.0 && (o.psi_r - PI / 4.0).abs() < 1e-12);
        // On the path: ψ_r = α = 0.
        let o = g.update(0.0, &Vec3::new(5.0, 0.0, 0.0), &Vec3::zeros());
        assert!(o.psi_r.abs() < 1e-15);
    }

    #[test]
    fn psi_r_dot_matches_difference() {
        let mut g = x_line();
        let p = Vec3::new(3.0, 1.3, 0.0);
        let v = Vec3::new(0.5, -0.2, 0.0);
        let o = g.update(0.0, &p, &v);
        let h = 1e-6;
        let op = g.update(0.0, &(p + v * h), &v);
        let om = g.update(0.0, &(p - v * h), &v);
        // Central difference, error ~h² + 1e-16/h.
        assert!((o.psi_r_dot - (op.psi_r - om.psi_r) / (2.0 * h)).abs() < 1e-8);
        // Moving towards the path (ė < 0 while e > 0) makes ψ_r rise towards α.
        assert!(o.psi_r_dot > 0.0);
    }

    #[test]
    fn switching_by_distance_and_acceptance_radius() {
        let spec = PathSpec {
            waypoints: vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]],
            ..Default::default()
        };
        let mut g = LosGuidance::new(&spec, 2.0).unwrap();
        let o = g.update(0.0, &Vec3::new(9.9, 0.5, 0.0), &Vec3::zeros());
        assert_eq!(o.segment, 0);
        assert!(!o.switched);
        let o = g.update(0.0, &Vec3::new(10.1, 0.5, 0.0), &Vec3::zeros());
        assert_eq!(o.segment, 1);
        assert!(o.switched);
        // Segment 1 points along +Y (α = π/2); the point at x = 10.1 is right of it.
        assert!((o.alpha - PI / 2.0).abs() < 1e-12);
        assert!((o.cross_track + 0.1).abs() < 1e-12);
        assert!((o.along_track - 0.5).abs() < 1e-12);
        // Last segment extends beyond its end.
        let o = g.update(0.0, &Vec3::new(10.0, 50.0, 0.0), &Vec3::zeros());
        assert_eq!(o.segment, 1);
        assert!(!o.switched);

        let spec = PathSpec {
            acceptance_radius: 1.0,
            ..spec
        };
        let mut g = LosGuidance::new(&spec, 2.0).unwrap();
        assert_eq!(
            g.update(0.0, &Vec3::new(9.5, 0.5, 0.0), &Vec3::zeros())
                .segment,
            1
        );
    }

    #[test]
    fn switching_by_time_and_180_turn_wraps() {
        // The paper's scenario: along +X, a 180° turn commanded at t = 95 s onto a line y = 5
        // heading −X.
        let spec: PathSpec = toml::from_str(
            r#"
            segments = [
              { from = [0.0, 0.0], to = [100.0, 0.0] },
              { from = [100.0, 5.0], to = [0.0, 5.0], start_time = 95.0 },
            ]
            "#,
        )
        .unwrap();
        let mut g = LosGuidance::new(&spec, 3.0).unwrap();
        // Far beyond segment 0's end: no distance switch because segment 1 waits for t = 95.
        let o = g.update(94.9, &Vec3::new(150.0, 0.0, 0.0), &Vec3::zeros());
        assert_eq!(o.segment, 0);
        let o = g.update(95.0, &Vec3::new(40.0, 0.0, 0.0), &Vec3::zeros());
        assert_eq!(o.segment, 1);
        assert!(o.switched);
        assert!((o.alpha.abs() - PI).abs() < 1e-12);
        // y = 0 is left of a −X path at y = 5 (e_y = +5): ψ_r = π − atan(5/3), inside (−π, π].
        assert!((o.cross_track - 5.0).abs() < 1e-12);
        assert!((o.psi_r - (PI - (5.0f64 / 3.0).atan())).abs() < 1e-12);
        // Right of it (y = 6, e_y = −1): π + atan(1/3) wraps to −π + atan(1/3).
        let o = g.update(96.0, &Vec3::new(40.0, 6.0, 0.0), &Vec3::zeros());
        assert!((o.cross_track + 1.0).abs() < 1e-12);
        assert!((o.psi_r - (-PI + (1.0f64 / 3.0).atan())).abs() < 1e-12);
        assert!(o.psi_r > -PI && o.psi_r <= PI);
    }

    #[test]
    fn bad_paths_name_the_key() {
        let cases = [
            (r#"waypoints = [[0.0, 0.0]]"#, "path.waypoints"),
            (
                r#"waypoints = [[0.0, 0.0], [0.0, 0.0]]"#,
                "path.waypoints[1]",
            ),
            (
                r#"segments = [{ from = [0.0, 0.0], to = [1.0, 0.0], start_time = 5.0 },
                               { from = [0.0, 0.0], to = [1.0, 0.0], start_time = 1.0 }]"#,
                "path.segments[1].start_time",
            ),
            (r#"acceptance_radius = 1.0"#, "path"),
        ];
        for (text, key) in cases {
            let spec: PathSpec = toml::from_str(text).unwrap();
            assert_eq!(LosGuidance::new(&spec, 2.0).unwrap_err().key, key, "{text}");
        }
        assert!(toml::from_str::<PathSpec>("bogus = 1").is_err());
        let ok: PathSpec = toml::from_str(r#"waypoints = [[0.0, 0.0], [1.0, 0.0]]"#).unwrap();
        assert_eq!(LosGuidance::new(&ok, 0.0).unwrap_err().key, "look_ahead");
    }
}
