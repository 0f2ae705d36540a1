//! Metrics as pure functions of a sampled trajectory (SPEC §6): thruster energy by momentum
//! theory, effort integrals, joint mechanical energy, peak thrust, saturation and singularity
//! exposure, and tracking quality (cross-track error, convergence, overshoot, settling).
//!
//! Time series are slices sampled at times `t` [s] (strictly increasing, not necessarily
//! uniform); integrals use the trapezoidal rule, and fractions of time weight each interval
//! by its length.

use serde::{Deserialize, Serialize};

/// Parameters of the momentum-theory thruster power model (SPEC §6; inferred defaults).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PowerModel {
    /// Propeller diameter [m] (default 0.07 m).
    pub propeller_diameter: f64,
    /// Overall efficiency η (default 0.5).
    pub efficiency: f64,
    /// Water density ρ [kg/m³].
    pub rho: f64,
}

impl Default for PowerModel {
    fn default() -> Self {
        Self {
            propeller_diameter: 0.07,
            efficiency: 0.5,
            rho: crate::model::RHO_SEAWATER,
        }
    }
}

impl PowerModel {
    /// Check the parameters are physical.
    pub fn validate(&self) -> Result<(), String> {
        for (k, v) in [
            ("propeller_diameter", self.propeller_diameter),
            ("efficiency", self.efficiency),
            ("rho", self.rho),
        ] {
            if !v.is_finite() || v <= 0.0 {
                return Err(format!("metrics.{k} must be a finite number > 0, got {v}"));
            }
        }
        Ok(())
    }

    /// Electrical power [W] of one thruster delivering thrust `u` [N]:
    /// `P = |u|^{3/2} / (η √(2ρA))`, `A = πD²/4` (SPEC §6).
    #[inline]
    pub fn power(&self, u: f64) -> f64 {
        let a = std::f64::consts::PI * self.propeller_diameter.powi(2) / 4.0;
        u.abs().powf(1.5) / (self.efficiency * (2.0 * self.rho * a).sqrt())
    }
}

/// Trapezoidal integral of `y(t)`.
pub fn integrate(t: &[f64], y: &[f64]) -> f64 {
    t.windows(2)
        .zip(y.windows(2))
        .map(|(tw, yw)| 0.5 * (tw[1] - tw[0]) * (yw[0] + yw[1]))
        .sum()
}

/// Trapezoidal integral of `f(k)` evaluated at every sample `k`.
fn integrate_fn(t: &[f64], f: impl Fn(usize) -> f64) -> f64 {
    (1..t.len())
        .map(|k| 0.5 * (t[k] - t[k - 1]) * (f(k - 1) + f(k)))
        .sum()
}

/// Fraction of the time span during which `flag(k)` holds; each interval counts when the
/// flag holds at its start sample.
pub fn time_fraction(t: &[f64], flag: impl Fn(usize) -> bool) -> f64 {
    let span = match (t.first(), t.last()) {
        (Some(a), Some(b)) if b > a => b - a,
        _ => return 0.0,
    };
    (1..t.len())
        .filter(|&k| flag(k - 1))
        .map(|k| t[k] - t[k - 1])
        .sum::<f64>()
        / span
}

/// Effort and energy of a run.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct EnergyMetrics {
    /// Thruster energy by momentum theory, `∫ Σ_j P_j dt` [J].
    pub thruster_energy: f64,
    /// `∫ ‖u‖² dt` [N²·s].
    pub effort_sq: f64,
    /// `∫ Σ_j |u_j| dt` [N·s].
    pub effort_abs: f64,
    /// Joint mechanical energy `∫ Σ_i |τ_i q̇_i| dt` [J].
    pub joint_energy: f64,
    /// Largest |u_j| over the run [N].
    pub peak_thrust: f64,
    /// Fraction of time at least one thruster is at a limit (within `sat_tol` N).
    pub saturation_fraction: f64,
}

/// Energy and effort (SPEC §6). `thrust[j]` is thruster j's actual thrust series [N],
/// `limits[j] = (u_min, u_max)`, `torque[i]`/`rate[i]` joint i's torque [N·m] and rate
/// [rad/s]. A thruster counts as saturated within `sat_tol` [N] of a limit.
pub fn energy_metrics(
    t: &[f64],
    thrust: &[&[f64]],
    limits: &[(f64, f64)],
    torque: &[&[f64]],
    rate: &[&[f64]],
    model: &PowerModel,
    sat_tol: f64,
) -> EnergyMetrics {
    let thruster_energy = thrust
        .iter()
        .map(|u| integrate_fn(t, |k| model.power(u[k])))
        .sum();
    let effort_sq = thrust
        .iter()
        .map(|u| integrate_fn(t, |k| u[k] * u[k]))
        .sum();
    let effort_abs = thrust.iter().map(|u| integrate_fn(t, |k| u[k].abs())).sum();
    let joint_energy = torque
        .iter()
        .zip(rate)
        .map(|(tau, qd)| integrate_fn(t, |k| (tau[k] * qd[k]).abs()))
        .sum();
    let peak_thrust = thrust
        .iter()
        .flat_map(|u| u.iter())
        .fold(0.0f64, |peak, x| peak.max(x.abs()));
    let saturation_fraction = time_fraction(t, |k| {
        thrust
            .iter()
            .zip(limits)
            .any(|(u, (lo, hi))| u[k] <= lo + sat_tol || u[k] >= hi - sat_tol)
    });
    EnergyMetrics {
        thruster_energy,
        effort_sq,
        effort_abs,
        joint_energy,
        peak_thrust,
        saturation_fraction,
    }
}

/// Singularity exposure: fraction of time the scaled σ_min of T(q) is below `threshold`
/// (SPEC §6, "how often T is singular" over the configurations a scenario visits).
pub fn singularity_exposure(t: &[f64], sigma_min: &[f64], threshold: f64) -> f64 {
    time_fraction(t, |k| sigma_min[k] < threshold)
}

/// Path-following quality over one segment of a transport run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SegmentTracking {
    /// Time the segment became active [s].
    pub start: f64,
    /// Time after which |e_y| stays below the band until the segment ends [s after start];
    /// NaN if it never converges.
    pub convergence_time: f64,
    /// Largest excursion past the path on the far side after the first crossing [m] (0 if
    /// it never crosses).
    pub overshoot: f64,
    /// RMS cross-track error after convergence [m]; NaN if it never converges.
    pub rms_after: f64,
    /// Largest |e_y| after convergence [m]; NaN if it never converges.
    pub max_after: f64,
}

/// Tracking of one segment: `t`, `e_y` restricted to the samples where the segment is
/// active; `band` [m] is the convergence band.
pub fn segment_tracking(t: &[f64], e_y: &[f64], band: f64) -> SegmentTracking {
    let nan = f64::NAN;
    if t.is_empty() {
        return SegmentTracking {
            start: nan,
            convergence_time: nan,
            overshoot: 0.0,
            rms_after: nan,
            max_after: nan,
        };
    }
    let start = t[0];
    // Last sample outside the band: convergence is the sample after it.
    let conv_idx = match e_y.iter().rposition(|e| e.abs() >= band) {
        None => Some(0),
        Some(k) if k + 1 < e_y.len() => Some(k + 1),
        Some(_) => None,
    };
    let side = e_y[0].signum();
    let crossing = e_y.iter().position(|e| e.signum() != side && *e != 0.0);
    let overshoot = match crossing {
        Some(c) if side != 0.0 => e_y[c..].iter().map(|e| -side * e).fold(0.0f64, f64::max),
        _ => 0.0,
    };
    let (convergence_time, rms_after, max_after) = match conv_idx {
        Some(c) => {
            let tt = &t[c..];
            let ee = &e_y[c..];
            let rms = if tt.len() > 1 {
                (integrate_fn(tt, |k| ee[k] * ee[k]) / (tt[tt.len() - 1] - tt[0])).sqrt()
            } else {
                ee[0].abs()
            };
            let mx = ee.iter().fold(0.0f64, |peak, e| peak.max(e.abs()));
            (t[c] - start, rms, mx)
        }
        None => (nan, nan, nan),
    };
    SegmentTracking {
        start,
        convergence_time,
        overshoot,
        rms_after,
        max_after,
    }
}

/// Settling time of an error norm: the first time after which `err` stays below `tol`
/// until the end [s from `t[0]`]; NaN if the final sample is not below `tol`.
pub fn settling_time(t: &[f64], err: &[f64], tol: f64) -> f64 {
    match err.iter().rposition(|e| e.is_nan() || e.abs() >= tol) {
        None => t.first().map(|_| 0.0).unwrap_or(f64::NAN),
        Some(k) if k + 1 < err.len() => t[k + 1] - t[0],
        Some(_) => f64::NAN,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_model_reference_value() {
        // 70 mm propeller, η = 0.5, ρ = 1026: A = 3.848e-3 m², √(2ρA) = 2.8102, so
        // 10 N costs 10^1.5 / (0.5·2.8102) = 22.5060 W.
        let m = PowerModel::default();
        assert!((m.power(10.0) - 22.5060).abs() < 1e-4);
        assert_eq!(m.power(-10.0), m.power(10.0));
    }

    #[test]
    fn energy_of_constant_thrust() {
        let t: Vec<f64> = (0..=100).map(|k| k as f64 * 0.1).collect();
        let (u0, u1) = (vec![10.0; 101], vec![-5.0; 101]);
        let u = [u0.as_slice(), u1.as_slice()];
        let lim = [(-40.0, 40.0), (-5.0, 5.0)];
        let tau = vec![2.0; 101];
        let qd = vec![-0.5; 101];
        let m = PowerModel::default();
        let e = energy_metrics(&t, &u, &lim, &[&tau], &[&qd], &m, 1e-9);
        // Exact for constant signals over 10 s.
        assert!((e.thruster_energy - 10.0 * (m.power(10.0) + m.power(5.0))).abs() < 1e-9);
        assert!((e.effort_sq - 10.0 * 125.0).abs() < 1e-9);
        assert!((e.effort_abs - 150.0).abs() < 1e-9);
        assert!((e.joint_energy - 10.0).abs() < 1e-9);
        assert_eq!(e.peak_thrust, 10.0);
        assert!((e.saturation_fraction - 1.0).abs() < 1e-12);
    }

    #[test]
    fn tracking_of_a_damped_approach() {
        // e_y = 3 e^{-t} cos(t): crosses at t = π/2, overshoot 3 e^{-5π/4}·… computed from
        // samples; converges into 0.1 m.
        let t: Vec<f64> = (0..=20000).map(|k| k as f64 * 1e-3).collect();
        let e: Vec<f64> = t.iter().map(|x| 3.0 * (-x).exp() * x.cos()).collect();
        let s = segment_tracking(&t, &e, 0.1);
        // Largest negative excursion of 3e^{-t}cos t is at t = 3π/4: 3e^{-3π/4}·(√2/2).
        let expect = 3.0 * (-3.0 * std::f64::consts::PI / 4.0).exp() * 0.5f64.sqrt();
        assert!((s.overshoot - expect).abs() < 1e-5);
        assert!(s.convergence_time > 1.0 && s.convergence_time < 4.0);
        assert!(s.max_after < 0.1);
        assert!(settling_time(&t, &e, 0.1) == s.convergence_time);
        assert!(settling_time(&t, &[1.0, 1.0], 0.5).is_nan());
    }

    #[test]
    fn exposure_and_fraction() {
        let t = [0.0, 1.0, 2.0, 4.0];
        let s = [0.0, 1.0, 0.0, 1.0];
        // Below 0.5 on [0,1) and [2,4): 3 of 4 seconds.
        assert!((singularity_exposure(&t, &s, 0.5) - 0.75).abs() < 1e-12);
        assert_eq!(time_fraction(&[], |_| true), 0.0);
    }
}
