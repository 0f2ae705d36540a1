//! Quintic point-to-point references (Antonelli & Chiaverini, section 5: "a quintic polynomial
//! interpolating law with null initial and final velocities and accelerations"; docs/model.md §8).
//!
//! The timing law `s(τ) = 10τ³ − 15τ⁴ + 6τ⁵`, `τ = t/T ∈ [0, 1]`, is the unique quintic with
//! `s(0) = 0`, `s(1) = 1` and zero first and second derivatives at both ends. A scalar reference
//! from `a` to `b` over `T` seconds is `x(t) = a + (b − a) s(t/T)`; it holds `a` before `t = 0`
//! and `b` after `t = T`. Several scalars sharing one `T` move along the straight line between
//! their end points (the paper's straight-line end-effector path), so a vector reference is one
//! [`Quintic`] per component.

use super::error::{check_finite, check_pos, ControlError};

/// A scalar quintic reference from `from` to `to` over `duration` seconds, starting at `t = 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quintic {
    /// Value at and before `t = 0` (task units: m, rad, …).
    pub from: f64,
    /// Value at and after `t = duration`.
    pub to: f64,
    /// Transition time `T` [s], > 0.
    pub duration: f64,
}

/// A reference sample: value, first and second time derivatives (units, units/s, units/s²).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Value `x(t)`.
    pub value: f64,
    /// Rate `ẋ(t)`.
    pub rate: f64,
    /// Acceleration `ẍ(t)`.
    pub accel: f64,
}

impl Quintic {
    /// A checked reference: finite end points, `duration > 0`.
    pub fn new(from: f64, to: f64, duration: f64) -> Result<Self, ControlError> {
        check_finite("quintic.from", from)?;
        check_finite("quintic.to", to)?;
        check_pos("quintic.duration", duration)?;
        Ok(Self { from, to, duration })
    }

    /// A constant reference (`from = to`) — the "hold the initial value" task of the paper.
    pub fn hold(value: f64) -> Self {
        Self {
            from: value,
            to: value,
            duration: 1.0,
        }
    }

    /// Value, rate and acceleration at time `t` [s] (clamped outside `[0, T]`).
    pub fn sample(&self, t: f64) -> Sample {
        let big_t = self.duration;
        let tau = (t / big_t).clamp(0.0, 1.0);
        let (t2, t3) = (tau * tau, tau * tau * tau);
        let s = t3 * (10.0 - 15.0 * tau + 6.0 * t2);
        let (ds, dds) = if t <= 0.0 || t >= big_t {
            (0.0, 0.0)
        } else {
            (
                30.0 * t2 * (1.0 - tau) * (1.0 - tau) / big_t,
                60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau) / (big_t * big_t),
            )
        };
        let d = self.to - self.from;
        Sample {
            value: self.from + d * s,
            rate: d * ds,
            accel: d * dds,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn end_conditions_and_midpoint() {
        let q = Quintic::new(-1.0, -0.78, 10.0).unwrap();
        let a = q.sample(0.0);
        let b = q.sample(10.0);
        assert_eq!((a.value, a.rate, a.accel), (-1.0, 0.0, 0.0));
        assert!((b.value + 0.78).abs() < 1e-15 && b.rate == 0.0 && b.accel == 0.0);
        // Symmetric law: half way at T/2, peak rate 15/8 · Δ/T there, zero acceleration.
        let m = q.sample(5.0);
        assert!((m.value + 0.89).abs() < 1e-12);
        assert!((m.rate - 1.875 * 0.22 / 10.0).abs() < 1e-12);
        assert!(m.accel.abs() < 1e-15);
        assert_eq!(q.sample(-3.0).value, -1.0);
        assert_eq!(q.sample(42.0).value, -0.78);
        assert!(Quintic::new(0.0, 1.0, 0.0).is_err());
    }

    #[test]
    fn derivatives_match_differences() {
        let q = Quintic::new(0.3, 2.1, 7.0).unwrap();
        let h = 1e-5;
        for t in [0.4, 2.0, 3.5, 6.1] {
            let (p, m, c) = (q.sample(t + h), q.sample(t - h), q.sample(t));
            assert!(((p.value - m.value) / (2.0 * h) - c.rate).abs() < 1e-8);
            assert!(((p.rate - m.rate) / (2.0 * h) - c.accel).abs() < 1e-8);
        }
    }
}
