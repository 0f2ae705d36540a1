//! Metrics of a run (docs/model.md §6): thruster power by actuator-disk momentum theory with axial
//! inflow and the effort and energy integrals of the actuators, accumulated at every control
//! step by an [`EnergyIntegrator`] (not from the log); and, as pure functions of a sampled
//! trajectory, singularity exposure and tracking quality (cross-track error, convergence,
//! overshoot, settling).
//!
//! Time series are slices sampled at times `t` [s] (strictly increasing, not necessarily
//! uniform); their integrals use the trapezoidal rule, and fractions of time weight each
//! interval by its length.

use serde::{Deserialize, Serialize};

/// Parameters of the actuator-disk (momentum-theory) thruster power model (docs/model.md §6). Both
/// defaults are inferred (the paper gives no propeller data): a 70 mm propeller, the size of
/// the small ROV thrusters such a vehicle carries, and an overall shaft efficiency η = 0.5.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PowerModel {
    /// Propeller diameter D [m], disk area `A = πD²/4`. Default 0.07 m (inferred).
    pub propeller_diameter: f64,
    /// Overall efficiency η from shaft to ideal (induced + useful) power. Default 0.5
    /// (inferred).
    pub efficiency: f64,
    /// Water density ρ [kg/m³]. Default [`crate::model::RHO_SEAWATER`].
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

/// A [`PowerModel`] parameter that is not a finite number > 0.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("metrics.{key} must be a finite number > 0, got {value}")]
pub struct PowerModelError {
    /// The parameter (`propeller_diameter`, `efficiency`, `rho`).
    pub key: &'static str,
    /// Its value.
    pub value: f64,
}

impl PowerModel {
    /// Check the parameters are physical.
    pub fn validate(&self) -> Result<(), PowerModelError> {
        for (key, value) in [
            ("propeller_diameter", self.propeller_diameter),
            ("efficiency", self.efficiency),
            ("rho", self.rho),
        ] {
            if !value.is_finite() || value <= 0.0 {
                return Err(PowerModelError { key, value });
            }
        }
        Ok(())
    }

    /// Disk area `A = πD²/4` [m²].
    #[inline]
    pub fn disk_area(&self) -> f64 {
        std::f64::consts::PI * self.propeller_diameter.powi(2) / 4.0
    }

    /// `(w, V_a + w)` [m/s] of a disk delivering thrust `u` [N] with axial inflow `v_a`
    /// [m/s]: the induced velocity, the non-negative root of `|u| = 2ρA w (V_a + w)`
    /// (docs/model.md §6), `w = (−V_a + √(V_a² + 4c)) / 2` with `c = |u| / (2ρA)`, and the flow
    /// speed through the disk. Both without cancellation for either sign of `v_a`: where a
    /// printed form subtracts nearly equal numbers it is replaced by the conjugate
    /// `2c / (|V_a| + √(V_a² + 4c))` (for `w` when `V_a > 0`, for `V_a + w` when `V_a < 0`).
    #[inline]
    pub fn disk_velocities(&self, u: f64, v_a: f64) -> (f64, f64) {
        let c = u.abs() / (2.0 * self.rho * self.disk_area());
        let root = (v_a * v_a + 4.0 * c).sqrt();
        // 0/0 at zero thrust and zero inflow, where both velocities are 0.
        let small = if c > 0.0 {
            2.0 * c / (v_a.abs() + root)
        } else {
            0.0
        };
        let large = 0.5 * (root + v_a.abs());
        if v_a > 0.0 {
            (small, v_a + small)
        } else {
            (large, small)
        }
    }

    /// Induced velocity w ≥ 0 [m/s] of [`PowerModel::disk_velocities`].
    #[inline]
    pub fn induced_velocity(&self, u: f64, v_a: f64) -> f64 {
        self.disk_velocities(u, v_a).0
    }

    /// Shaft power [W] of one thruster delivering thrust `u` [N] with axial inflow `v_a`
    /// [m/s]: the ideal power `P = |u| (V_a + w)` of the actuator disk (useful power `|u| V_a`
    /// plus the induced loss `|u| w`) divided by η (docs/model.md §6).
    ///
    /// Sign convention: `v_a` is the speed of the water through the disk in the direction of
    /// the jet, i.e. the thruster's velocity relative to the water projected on the direction
    /// it pushes the vehicle (a thruster pushing the vehicle forward sees an inflow equal to
    /// the forward speed). Where the flow opposes the thrust (`v_a < 0`: braking, or the
    /// vehicle moving against the thrust) momentum theory has no valid slipstream (windmill
    /// brake and vortex-ring states), and the inflow is taken as `max(V_a, 0)`: the static
    /// figure, an upper bound on the slipstream power at that thrust. At `v_a ≤ 0` this is
    /// therefore [`PowerModel::static_power`] (to rounding).
    #[inline]
    pub fn shaft_power(&self, u: f64, v_a: f64) -> f64 {
        u.abs() * self.disk_velocities(u, v_a.max(0.0)).1 / self.efficiency
    }

    /// Shaft power [W] at zero inflow (hover, the bollard figure):
    /// `P = |u|^{3/2} / (η √(2ρA))` (docs/model.md §6).
    #[inline]
    pub fn static_power(&self, u: f64) -> f64 {
        u.abs().powf(1.5) / (self.efficiency * (2.0 * self.rho * self.disk_area()).sqrt())
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
        .fold(0.0, |a, b| a + b)
        / span
}

/// The thrusters at one control tick, as the closed loop reads them.
#[derive(Clone, Copy, Debug)]
pub struct ThrusterSample<'a> {
    /// Thrust of each thruster over the coming control interval [N].
    pub thrust: &'a [f64],
    /// Axial inflow of each thruster along its thrust [m/s] (sign convention of
    /// [`PowerModel::shaft_power`]).
    pub inflow: &'a [f64],
    /// `(u_min, u_max)` of each thruster [N].
    pub limits: &'a [(f64, f64)],
}

/// Thruster effort and power at one control tick: the integrands of [`EnergyMetrics`]'
/// thruster figures, held over the control interval that starts at the tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PowerSample {
    /// `Σ_j P_j / η` with axial inflow [W] ([`PowerModel::shaft_power`]).
    pub thruster_power: f64,
    /// `Σ_j P_j / η` at zero inflow [W] ([`PowerModel::static_power`]).
    pub thruster_power_static: f64,
    /// `‖u‖²` [N²].
    pub thrust_sq: f64,
    /// `Σ_j |u_j|` [N].
    pub thrust_abs: f64,
    /// Largest `|u_j|` [N].
    pub peak_thrust: f64,
    /// Whether at least one thruster is within `sat_tol` of a limit.
    pub saturated: bool,
}

impl PowerSample {
    /// The sample of thrusters `a` under the power model `model`; a thruster counts as
    /// saturated within `sat_tol` [N] of a limit.
    pub fn new(model: &PowerModel, a: &ThrusterSample, sat_tol: f64) -> Self {
        let mut s = Self::default();
        for ((u, v_a), (lo, hi)) in a.thrust.iter().zip(a.inflow).zip(a.limits) {
            s.thruster_power += model.shaft_power(*u, *v_a);
            s.thruster_power_static += model.static_power(*u);
            s.thrust_sq += u * u;
            s.thrust_abs += u.abs();
            s.peak_thrust = s.peak_thrust.max(u.abs());
            s.saturated |= *u <= lo + sat_tol || *u >= hi - sat_tol;
        }
        s
    }
}

/// Effort and energy of a run (docs/model.md §6), integrated over the control intervals.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct EnergyMetrics {
    /// Thruster shaft energy with axial inflow, `∫ Σ_j P_j(u_j, V_a,j) / η dt` [J].
    pub thruster_energy: f64,
    /// Thruster shaft energy at zero inflow, `∫ Σ_j |u_j|^{3/2} / (η √(2ρA)) dt` [J] (the
    /// figure reported before inflow was modelled; a lower bound on `thruster_energy`, which
    /// adds the useful power against the through-flow).
    pub thruster_energy_static: f64,
    /// `∫ ‖u‖² dt` [N²·s].
    pub effort_sq: f64,
    /// `∫ Σ_j |u_j| dt` [N·s].
    pub effort_abs: f64,
    /// Joint mechanical energy `∫ Σ_i |τ_q,i q̇_i| dt` [J].
    pub joint_energy: f64,
    /// Largest |u_j| at a control tick [N].
    pub peak_thrust: f64,
    /// Largest |τ_q,i| at the start of a physics step [N·m].
    pub joint_torque_peak: f64,
    /// Fraction of the integrated time during which at least one thruster is at a limit.
    pub saturation_fraction: f64,
    /// Distance covered along the path [m] (transport; 0 otherwise): the sum over the
    /// control ticks of the along-track advance of the guided point while its segment stays
    /// active (a segment switch starts counting afresh on the new segment).
    pub path_progress: f64,
    /// Largest `|τ_c,k|` of the commanded base wrench at a control tick, per base axis
    /// (surge, sway, heave [N]; roll, pitch, yaw [N·m]; base frame, USM-33): the wrench the
    /// run asked the thrusters for, against which `authority_margin` measures the design.
    pub wrench_peak: [f64; 6],
}

impl EnergyMetrics {
    /// Thruster shaft energy per metre of path covered [J/m]; NaN if no progress was made.
    pub fn energy_per_metre(&self) -> f64 {
        if self.path_progress > 0.0 {
            self.thruster_energy / self.path_progress
        } else {
            f64::NAN
        }
    }
}

/// Integrates the effort and energy of a run: the thrusters' [`PowerSample`]s over the
/// control intervals by the rectangle rule on the zero-order hold (each sample is held over
/// the interval that starts at its tick); the joints' energy and peak torque come from the
/// simulator ([`EnergyIntegrator::set_joints`]).
#[derive(Clone, Debug, Default)]
pub struct EnergyIntegrator {
    sums: EnergyMetrics,
    span: f64,
    saturated: f64,
    /// The active segment and along-track position at the last tracked tick.
    last_on_path: Option<(f64, f64)>,
}

impl EnergyIntegrator {
    /// Add thruster sample `s` held for `dt` [s] (`dt = 0` for a tick that starts no
    /// interval, e.g. the last one: only its peak counts).
    pub fn add(&mut self, s: &PowerSample, dt: f64) {
        let e = &mut self.sums;
        e.thruster_energy += s.thruster_power * dt;
        e.thruster_energy_static += s.thruster_power_static * dt;
        e.effort_sq += s.thrust_sq * dt;
        e.effort_abs += s.thrust_abs * dt;
        e.peak_thrust = e.peak_thrust.max(s.peak_thrust);
        self.span += dt;
        if s.saturated {
            self.saturated += dt;
        }
    }

    /// Set the joints' figures of the run: the joint mechanical energy `∫Σ|τ_q,i q̇_i| dt`
    /// [J], integrated by the simulator with the motion, and the peak |τ_q| [N·m] over its
    /// step boundaries.
    pub fn set_joints(&mut self, joint_energy: f64, joint_torque_peak: f64) {
        self.sums.joint_energy = joint_energy;
        self.sums.joint_torque_peak = joint_torque_peak;
    }

    /// Track the commanded base wrench `tau_c` [N, N·m] (base frame) of a control tick:
    /// [`EnergyMetrics::wrench_peak`].
    pub fn track_wrench(&mut self, tau_c: &[f64; 6]) {
        for (p, t) in self.sums.wrench_peak.iter_mut().zip(tau_c) {
            *p = p.max(t.abs());
        }
    }

    /// Track the guided point at a control tick: `segment` is the active segment's index,
    /// `along_track` [m] the position along it; the advance since the previous tick counts
    /// towards [`EnergyMetrics::path_progress`] if the segment is the same (negative when
    /// moving backwards along it).
    pub fn track_path(&mut self, segment: f64, along_track: f64) {
        if let Some((seg, along)) = self.last_on_path {
            if seg == segment {
                self.sums.path_progress += along_track - along;
            }
        }
        self.last_on_path = Some((segment, along_track));
    }

    /// The time so far with a thruster at a limit [s] (the numerator of
    /// [`EnergyMetrics::saturation_fraction`]; it never decreases).
    pub fn saturated_time(&self) -> f64 {
        self.saturated
    }

    /// The largest |u_j| so far [N] ([`EnergyMetrics::peak_thrust`]).
    pub fn peak_thrust(&self) -> f64 {
        self.sums.peak_thrust
    }

    /// The integrals so far, with the saturated fraction of the integrated time.
    pub fn metrics(&self) -> EnergyMetrics {
        EnergyMetrics {
            saturation_fraction: if self.span > 0.0 {
                self.saturated / self.span
            } else {
                0.0
            },
            ..self.sums.clone()
        }
    }
}

/// Singularity exposure: fraction of time the scaled σ_min of T(q) is below `threshold`
/// (docs/model.md §6, "how often T is singular" over the configurations a scenario visits).
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
    fn static_power_reference_value() {
        // 70 mm propeller, η = 0.5, ρ = 1026: A = 3.848e-3 m², √(2ρA) = 2.8102, so
        // 10 N costs 10^1.5 / (0.5·2.8102) = 22.5060 W.
        let m = PowerModel::default();
        assert!((m.static_power(10.0) - 22.5060).abs() < 1e-4);
        assert_eq!(m.static_power(-10.0), m.static_power(10.0));
    }

    #[test]
    fn zero_inflow_is_the_static_formula() {
        // At V_a = 0, w = √(|u|/2ρA) and P/η = |u|^{3/2}/(η√(2ρA)) exactly; a flow opposing
        // the thrust is clamped to V_a = 0.
        let m = PowerModel::default();
        for u in [1e-6, 0.3, 1.0, 10.0, -17.5, 40.0, 1e4] {
            let p0 = m.static_power(u);
            for v_a in [0.0, -0.2, -5.0] {
                let p = m.shaft_power(u, v_a);
                assert!(
                    (p - p0).abs() <= 1e-14 * p0,
                    "u {u}, v_a {v_a}: {p} vs {p0}"
                );
            }
        }
        assert_eq!(m.shaft_power(0.0, 0.0), 0.0);
        assert_eq!(m.shaft_power(0.0, 1.0), 0.0);
    }

    #[test]
    fn inflow_power_hand_computed() {
        // u = 10 N, V_a = 0.5 m/s, defaults: 2ρA = 7.897021 kg/m, c = u/2ρA = 1.266300 m²/s²,
        // w = (−0.5 + √(0.25 + 4c))/2 = 0.902736 m/s, P/η = 10·(0.5 + w)/0.5 = 28.054719 W
        // (against 22.506001 W static).
        let m = PowerModel::default();
        assert!((m.induced_velocity(10.0, 0.5) - 0.902_735_971).abs() < 1e-8);
        assert!((m.shaft_power(10.0, 0.5) - 28.054_719_43).abs() < 1e-7);
        // The sign of u is the thrust direction; V_a is already measured along it.
        assert_eq!(m.shaft_power(-10.0, 0.5), m.shaft_power(10.0, 0.5));
    }

    #[test]
    fn induced_velocity_solves_the_momentum_balance_for_both_signs() {
        // |u| = 2ρA w (V_a + w) to rounding, including inflows far above the induced velocity
        // (where the printed root would cancel) and strongly negative inflows (where V_a + w
        // would).
        let m = PowerModel::default();
        let k = 2.0 * m.rho * m.disk_area();
        for u in [1e-6, 0.5, 10.0, 40.0] {
            for v_a in [-50.0, -1.0, -1e-3, 0.0, 1e-3, 0.5, 3.0, 1e3] {
                let (w, through) = m.disk_velocities(u, v_a);
                assert!(w >= 0.0 && through >= 0.0);
                assert_eq!(w, m.induced_velocity(u, v_a));
                let back = k * w * through;
                assert!((back - u).abs() <= 1e-11 * u, "u {u}, v_a {v_a}: {back}");
            }
        }
    }

    proptest::proptest! {
        #[test]
        fn power_is_non_negative_and_increases_with_thrust(
            u in -100.0f64..100.0,
            du in 1e-6f64..50.0,
            v_a in -5.0f64..5.0,
        ) {
            let m = PowerModel::default();
            let p = m.shaft_power(u, v_a);
            proptest::prop_assert!(p >= 0.0);
            proptest::prop_assert!(m.shaft_power(u.abs() + du, v_a) > p);
            proptest::prop_assert!(m.shaft_power(-(u.abs() + du), v_a) > p);
        }
    }

    #[test]
    fn energy_of_constant_samples() {
        let m = PowerModel::default();
        let limits = [(-40.0, 40.0), (-5.0, 5.0)];
        let a = ThrusterSample {
            thrust: &[10.0, -5.0],
            inflow: &[0.5, -0.5],
            limits: &limits,
        };
        let s = PowerSample::new(&m, &a, 1e-9);
        let mut e = EnergyIntegrator::default();
        for _ in 0..200 {
            e.add(&s, 0.05);
        }
        e.add(&s, 0.0);
        e.set_joints(10.0, 3.0);
        let e = e.metrics();
        // Exact for constant samples over 10 s (rounding of 200 additions aside).
        let p = m.shaft_power(10.0, 0.5) + m.static_power(5.0);
        assert!((e.thruster_energy - 10.0 * p).abs() < 1e-9);
        let p0 = m.static_power(10.0) + m.static_power(5.0);
        assert!((e.thruster_energy_static - 10.0 * p0).abs() < 1e-9);
        assert!((e.effort_sq - 10.0 * 125.0).abs() < 1e-9);
        assert!((e.effort_abs - 150.0).abs() < 1e-9);
        assert!((e.joint_energy - 10.0).abs() < 1e-9);
        assert_eq!(e.peak_thrust, 10.0);
        assert_eq!(e.joint_torque_peak, 3.0);
        assert!((e.saturation_fraction - 1.0).abs() < 1e-12);
        assert!(e.energy_per_metre().is_nan());
    }

    #[test]
    fn path_progress_counts_advance_within_each_segment() {
        let mut e = EnergyIntegrator::default();
        // 2 m along segment 0, then a switch to segment 1 entered 150 m along it, 3 m more.
        for (seg, along) in [
            (0.0, 1.0),
            (0.0, 2.0),
            (0.0, 3.0),
            (1.0, 150.0),
            (1.0, 153.0),
        ] {
            e.track_path(seg, along);
        }
        e.add(
            &PowerSample {
                thruster_power: 10.0,
                ..PowerSample::default()
            },
            2.5,
        );
        let m = e.metrics();
        assert!((m.path_progress - 5.0).abs() < 1e-12);
        assert!((m.energy_per_metre() - 5.0).abs() < 1e-12);
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
