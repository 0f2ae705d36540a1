//! Time-parametrised end-effector references for work mode: a natural cubic spline path
//! through via-points, traversed with the quintic timing law of [`super::quintic`].
//!
//! The reference pose is six scalars `x = [p; φ θ ψ]` (position in `I` [m], then the ZYX
//! roll, pitch, yaw of `F_e,d` [rad]). With `s(t)` the quintic timing law over the duration
//! `T` (`s(0) = 0`, `s(T) = 1`, zero rate and acceleration at both ends) and `P(σ)` the natural
//! cubic spline (zero second derivative at both ends) through the knots `(σ_k, x_k)` — the
//! start pose at `σ = 0`, the via-points at `σ_k = s(t_k)`, the final pose at `σ = 1` —
//!
//! `x(t) = P(s(t))`, `ẋ(t) = P'(s) ṡ`, `ẍ(t) = P''(s) ṡ² + P'(s) s̈`.
//!
//! So the reference passes through via-point `k` at its time `t_k`, starts and stops at rest,
//! and has continuous velocity and acceleration. Without via-points `P` is the straight line
//! and `x(t)` the quintic point-to-point reference of AC §5 (the paper's straight-line
//! end-effector path); via-points on that line at the line's own times (`x_k = x_0 + (x_T −
//! x_0) s(t_k)`) reproduce it exactly, because a natural cubic spline reproduces linear data.
//! Orientation is interpolated in ZYX angles (not along the geodesic); the desired twist is
//! `V_e,d = [R_Ie^T ṗ; R_Ie^T E(φ, θ, ψ) [φ̇; θ̇; ψ̇]]` in the measured `F_e` (USM-42), with
//! `E` the ZYX angle-rate matrix ([`zyx_rate_matrix`]).

use super::error::{check_finite, ControlError};
use super::quintic::Quintic;
use crate::spatial::{Mat3, Vec3, Vec6};
use nalgebra::UnitQuaternion;
use std::f64::consts::TAU;

/// A scalar natural cubic spline `P(σ)` through knots `(σ_k, y_k)`, `σ` strictly increasing
/// (the second derivatives `M_k` solve the usual tridiagonal system with `M_0 = M_m = 0`).
#[derive(Clone, Debug, PartialEq)]
pub struct NaturalSpline {
    sigma: Vec<f64>,
    y: Vec<f64>,
    m: Vec<f64>,
}

/// Value, first and second derivative of a spline at one abscissa.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SplineSample {
    /// `P(σ)`.
    pub value: f64,
    /// `P'(σ)`.
    pub slope: f64,
    /// `P''(σ)`.
    pub curvature: f64,
}

impl NaturalSpline {
    /// The spline through `(sigma[k], y[k])`; needs at least two knots with strictly
    /// increasing finite `sigma` and finite `y`.
    pub fn new(sigma: &[f64], y: &[f64]) -> Result<Self, ControlError> {
        let n = sigma.len();
        if n < 2 || y.len() != n {
            return Err(ControlError::new(
                "spline",
                format!(
                    "needs >= 2 knots with one value each, got {n} and {}",
                    y.len()
                ),
            ));
        }
        for (i, (s, v)) in sigma.iter().zip(y).enumerate() {
            check_finite(&format!("spline.sigma[{i}]"), *s)?;
            check_finite(&format!("spline.y[{i}]"), *v)?;
        }
        if sigma.windows(2).any(|w| w[1] <= w[0]) {
            return Err(ControlError::new(
                "spline.sigma",
                "knots must be strictly increasing",
            ));
        }
        // Thomas algorithm on rows 1..n-1: h_{i-1} M_{i-1} + 2(h_{i-1}+h_i) M_i + h_i M_{i+1}
        // = 6 (Δ_i − Δ_{i-1}), Δ_i the chord slope of interval i.
        let h: Vec<f64> = sigma.windows(2).map(|w| w[1] - w[0]).collect();
        let slope = |i: usize| (y[i + 1] - y[i]) / h[i];
        let mut m = vec![0.0; n];
        let (mut c, mut d) = (vec![0.0; n], vec![0.0; n]);
        for i in 1..n - 1 {
            let b = 2.0 * (h[i - 1] + h[i]) - h[i - 1] * c[i - 1];
            c[i] = h[i] / b;
            d[i] = (6.0 * (slope(i) - slope(i - 1)) - h[i - 1] * d[i - 1]) / b;
        }
        for i in (1..n - 1).rev() {
            m[i] = d[i] - c[i] * m[i + 1];
        }
        Ok(Self {
            sigma: sigma.to_vec(),
            y: y.to_vec(),
            m,
        })
    }

    /// `P`, `P'`, `P''` at `s` (clamped to the knot range).
    pub fn sample(&self, s: f64) -> SplineSample {
        let last = self.sigma.len() - 1;
        let s = s.clamp(self.sigma[0], self.sigma[last]);
        let i = self.sigma[1..last].partition_point(|&k| k <= s);
        let h = self.sigma[i + 1] - self.sigma[i];
        let (a, b) = ((self.sigma[i + 1] - s) / h, (s - self.sigma[i]) / h);
        let (mi, mj) = (self.m[i], self.m[i + 1]);
        SplineSample {
            value: a * self.y[i]
                + b * self.y[i + 1]
                + ((a * a * a - a) * mi + (b * b * b - b) * mj) * h * h / 6.0,
            slope: (self.y[i + 1] - self.y[i]) / h - (3.0 * a * a - 1.0) * h * mi / 6.0
                + (3.0 * b * b - 1.0) * h * mj / 6.0,
            curvature: a * mi + b * mj,
        }
    }
}

/// One via-point of a [`PoseReference`]: its time [s] in `(0, T)`, position in `I` [m] and,
/// optionally, ZYX angles [rad] (`None`: the straight-line angles at that time).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Via {
    /// Time of passage [s], `0 < t < T`, increasing along the list.
    pub time: f64,
    /// End-effector position [m], inertial frame.
    pub position: [f64; 3],
    /// Roll, pitch, yaw (ZYX) [rad]; `None` keeps the straight-line angles.
    pub rpy: Option<[f64; 3]>,
}

/// A reference sample: pose `x = [p; φ θ ψ]` and its first two time derivatives (inertial
/// position [m, m/s, m/s²], ZYX angles [rad, rad/s, rad/s²]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoseSample {
    /// `x(t)`.
    pub pose: [f64; 6],
    /// `ẋ(t)`.
    pub rate: [f64; 6],
    /// `ẍ(t)`.
    pub accel: [f64; 6],
}

/// The end-effector reference `x(t) = P(s(t))` of the module docs, from a start pose to a
/// final pose over `T` seconds through optional via-points.
#[derive(Clone, Debug, PartialEq)]
pub struct PoseReference {
    timing: Quintic,
    axes: [NaturalSpline; 6],
}

/// `a + 2π k` nearest to `near` (so interpolated angles take the short way round).
fn unwrap_near(a: f64, near: f64) -> f64 {
    a + TAU * ((near - a) / TAU).round()
}

impl PoseReference {
    /// The reference from `start` to `end` (each `[x, y, z, φ, θ, ψ]`, m and rad) over
    /// `duration` [s] through `via` (times strictly increasing inside `(0, duration)`).
    /// Target angles are unwrapped to within π of the previous knot's.
    pub fn new(
        start: [f64; 6],
        end: [f64; 6],
        duration: f64,
        via: &[Via],
    ) -> Result<Self, ControlError> {
        let timing = Quintic::new(0.0, 1.0, duration)?;
        let mut sigma = vec![0.0];
        let mut prev_t = 0.0;
        for (k, v) in via.iter().enumerate() {
            if !(v.time > prev_t && v.time < duration) {
                return Err(ControlError::new(
                    format!("reference.via[{k}].time"),
                    format!(
                        "{} must lie after the previous via-point (or 0) at {prev_t} and before \
                         the duration {duration}",
                        v.time
                    ),
                ));
            }
            prev_t = v.time;
            sigma.push(timing.sample(v.time).value);
        }
        sigma.push(1.0);
        let mut end = end;
        for j in 3..6 {
            end[j] = unwrap_near(end[j], start[j]);
        }
        let mut rows = vec![start];
        for (k, v) in via.iter().enumerate() {
            let s = sigma[k + 1];
            let mut x = [0.0; 6];
            for j in 0..6 {
                x[j] = start[j] + (end[j] - start[j]) * s;
            }
            x[..3].copy_from_slice(&v.position);
            if let Some(r) = v.rpy {
                for j in 0..3 {
                    x[3 + j] = unwrap_near(r[j], rows[k][3 + j]);
                }
            }
            rows.push(x);
        }
        rows.push(end);
        let axis = |j: usize| {
            let y: Vec<f64> = rows.iter().map(|r| r[j]).collect();
            NaturalSpline::new(&sigma, &y)
                .map_err(|e| ControlError::new(format!("reference.via (axis {j})"), e.message))
        };
        Ok(Self {
            timing,
            axes: [axis(0)?, axis(1)?, axis(2)?, axis(3)?, axis(4)?, axis(5)?],
        })
    }

    /// The duration `T` [s].
    pub fn duration(&self) -> f64 {
        self.timing.duration
    }

    /// Pose, rate and acceleration at `t` [s] (held at the end points outside `[0, T]`).
    pub fn sample(&self, t: f64) -> PoseSample {
        let s = self.timing.sample(t);
        let mut out = PoseSample {
            pose: [0.0; 6],
            rate: [0.0; 6],
            accel: [0.0; 6],
        };
        for (j, a) in self.axes.iter().enumerate() {
            let p = a.sample(s.value);
            out.pose[j] = p.value;
            out.rate[j] = p.slope * s.rate;
            out.accel[j] = p.curvature * s.rate * s.rate + p.slope * s.accel;
        }
        out
    }
}

/// The ZYX angle-rate matrix `E`: `ω_I = E(φ, θ, ψ) [φ̇; θ̇; ψ̇]` for `R = R_z(ψ) R_y(θ) R_x(φ)`
/// (columns: `R_z R_y e_x`, `R_z e_y`, `e_z`).
pub fn zyx_rate_matrix(theta: f64, psi: f64) -> Mat3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = psi.sin_cos();
    Mat3::new(cp * ct, -sp, 0.0, sp * ct, cp, 0.0, -st, 0.0, 1.0)
}

/// The desired pose of a sample as `(p_d, q_d)` (position in `I`, orientation mapping `F_e,d`
/// to `I`), and its twist `V_e,d` expressed in the measured end-effector frame whose
/// orientation in `I` is `r_ie` (USM-42's feed-forward term).
pub fn pose_and_twist(x: &PoseSample, r_ie: &Mat3) -> (Vec3, UnitQuaternion<f64>, Vec6) {
    let [px, py, pz, roll, pitch, yaw] = x.pose;
    let q = UnitQuaternion::from_euler_angles(roll, pitch, yaw);
    let v = r_ie.transpose() * Vec3::new(x.rate[0], x.rate[1], x.rate[2]);
    let w_i = zyx_rate_matrix(pitch, yaw) * Vec3::new(x.rate[3], x.rate[4], x.rate[5]);
    let w = r_ie.transpose() * w_i;
    (
        Vec3::new(px, py, pz),
        q,
        Vec6::new(v.x, v.y, v.z, w.x, w.y, w.z),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    const A: [f64; 6] = [3.3, 0.0, 0.0, 0.0, 0.0, 0.0];
    const B: [f64; 6] = [3.0, 0.5, -0.3, 0.0, 0.17, 0.44];

    #[test]
    fn natural_spline_interpolates_and_is_c2() {
        let sp = NaturalSpline::new(&[0.0, 0.2, 0.7, 1.0], &[1.0, -0.5, 2.0, 0.3]).unwrap();
        for (s, y) in [(0.0, 1.0), (0.2, -0.5), (0.7, 2.0), (1.0, 0.3)] {
            assert!((sp.sample(s).value - y).abs() < 1e-14);
        }
        // Natural ends, continuous slope and curvature across the knots.
        assert!(sp.sample(0.0).curvature.abs() < 1e-12 && sp.sample(1.0).curvature.abs() < 1e-12);
        for k in [0.2, 0.7] {
            let (l, r) = (sp.sample(k - 1e-9), sp.sample(k + 1e-9));
            assert!((l.slope - r.slope).abs() < 1e-6);
            assert!((l.curvature - r.curvature).abs() < 1e-6);
        }
        assert!(NaturalSpline::new(&[0.0, 0.0], &[1.0, 2.0]).is_err());
    }

    #[test]
    fn no_via_points_is_the_quintic_straight_line() {
        let r = PoseReference::new(A, B, 20.0, &[]).unwrap();
        for t in [0.0, 3.0, 10.0, 17.5, 20.0, 30.0] {
            let x = r.sample(t);
            for j in 0..6 {
                let q = Quintic::new(A[j], B[j], 20.0).unwrap().sample(t);
                assert!((x.pose[j] - q.value).abs() < 1e-14);
                assert!((x.rate[j] - q.rate).abs() < 1e-14);
                assert!((x.accel[j] - q.accel).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn derivatives_match_differences_through_via_points() {
        let via = [
            Via {
                time: 6.0,
                position: [3.4, 0.3, 0.2],
                rpy: Some([0.1, 0.0, 0.2]),
            },
            Via {
                time: 13.0,
                position: [3.1, 0.6, -0.1],
                rpy: None,
            },
        ];
        let r = PoseReference::new(A, B, 20.0, &via).unwrap();
        let h = 1e-5;
        for t in [0.5, 5.0, 6.0, 9.0, 13.0, 19.0] {
            let (p, m, c) = (r.sample(t + h), r.sample(t - h), r.sample(t));
            for j in 0..6 {
                assert!(((p.pose[j] - m.pose[j]) / (2.0 * h) - c.rate[j]).abs() < 1e-7);
                assert!(((p.rate[j] - m.rate[j]) / (2.0 * h) - c.accel[j]).abs() < 1e-6);
            }
        }
    }

    #[test]
    fn angle_rate_matrix_matches_finite_rotation() {
        let (r0, p0, y0) = (0.3, -0.4, 1.1);
        let (dr, dp, dy) = (0.2, -0.7, 0.5);
        let h = 1e-6;
        let rot = |t: f64| {
            UnitQuaternion::from_euler_angles(r0 + dr * t, p0 + dp * t, y0 + dy * t)
                .to_rotation_matrix()
                .into_inner()
        };
        // Ṙ Rᵀ = [ω]×, inertial ω.
        let w = (rot(h) - rot(-h)) / (2.0 * h) * rot(0.0).transpose();
        let expect = zyx_rate_matrix(p0, y0) * Vec3::new(dr, dp, dy);
        let got = Vec3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
        assert!((got - expect).norm() < 1e-8);
    }
}
