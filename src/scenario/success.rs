//! `[success]`: what a closed-loop run must achieve to count as a success (SPEC §6
//! "Success"), and the verdict on a run ([`judge`]): the first criterion it missed, or none.
//!
//! ```toml
//! [success]
//! # both modes (a run that stopped early always misses `no_failure`)
//! max_peak_thrust = 0.0          # N; 0 = the thrusters' own limits
//! max_saturation_fraction = 0.05 # of the run with a thruster at a limit
//! # transport
//! cross_track_bound = 0.1        # m, |cross-track error| at the end of the run
//! convergence_window = 60.0      # s after a segment becomes active
//! # work
//! position_tolerance = 0.02      # m, final end-effector position error
//! orientation_tolerance_deg = 2.0 # deg, final pointing error (roll excluded)
//! ```
//!
//! Criteria are checked in the order of [`Criterion::ALL`]; a verdict names the first one
//! missed by its id, which is the `[success]` key that bounds it (`no_failure` has none).
//! Studies rank and compare only successful runs (`study::summary`).

use std::fmt;

use serde::{Deserialize, Serialize};

use super::config::Mode;
use crate::input::located::KeyError;

/// `[success]`: the bounds a run must keep to count as a success. Defaults beside each field.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SuccessSpec {
    /// Largest thrust of any thruster at any control tick [N] (metric `peak_thrust`); 0 (the
    /// default) = the thrusters' own limits, which the delivered thrust never exceeds (the
    /// thrusters saturate): set it below them to demand headroom.
    pub max_peak_thrust: f64,
    /// Largest fraction of the run during which a thruster sits at a limit (metric
    /// `saturation_fraction`, within `metrics.saturation_tolerance`). Default 0.05.
    pub max_saturation_fraction: f64,
    /// Transport: the run ends within this distance of the path, `|final_cross_track|` [m].
    /// Default 0.1 m (the `metrics.band` default).
    pub cross_track_bound: f64,
    /// Transport: every segment the run reaches converges — `|e_y|` enters `metrics.band`
    /// and stays there until the segment ends — within this time after it becomes active
    /// [s] (metrics `seg<k>_convergence_time`). Default 60 s.
    pub convergence_window: f64,
    /// Work: final end-effector position error (metric `final_position_error`) [m]. Default
    /// 0.02 m.
    pub position_tolerance: f64,
    /// Work: final end-effector pointing error, roll excluded (metric
    /// `final_orientation_error_deg`) [deg]. Default 2°.
    pub orientation_tolerance_deg: f64,
}

impl Default for SuccessSpec {
    fn default() -> Self {
        Self {
            max_peak_thrust: 0.0,
            max_saturation_fraction: 0.05,
            cross_track_bound: 0.1,
            convergence_window: 60.0,
            position_tolerance: 0.02,
            orientation_tolerance_deg: 2.0,
        }
    }
}

impl SuccessSpec {
    /// Check the bounds; errors name `success.<key>`.
    pub fn validate(&self) -> Result<(), KeyError> {
        let bad = |k: &str, what: &str, v: f64| {
            Err(KeyError::new(
                format!("success.{k}"),
                format!("must be {what}, got {v}"),
            ))
        };
        for (k, v) in [
            ("cross_track_bound", self.cross_track_bound),
            ("convergence_window", self.convergence_window),
            ("position_tolerance", self.position_tolerance),
            ("orientation_tolerance_deg", self.orientation_tolerance_deg),
        ] {
            if !v.is_finite() || v <= 0.0 {
                return bad(k, "a finite number > 0", v);
            }
        }
        if !self.max_peak_thrust.is_finite() || self.max_peak_thrust < 0.0 {
            return bad(
                "max_peak_thrust",
                "finite and >= 0 (0 = the thrusters' limits)",
                self.max_peak_thrust,
            );
        }
        if !(0.0..=1.0).contains(&self.max_saturation_fraction) {
            return bad(
                "max_saturation_fraction",
                "in [0, 1]",
                self.max_saturation_fraction,
            );
        }
        Ok(())
    }
}

/// One success criterion; its id ([`Criterion::as_str`]) is the `[success]` key bounding it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Criterion {
    /// The run completed (did not diverge or fail numerically).
    NoFailure,
    /// [`SuccessSpec::max_peak_thrust`].
    MaxPeakThrust,
    /// [`SuccessSpec::max_saturation_fraction`].
    MaxSaturationFraction,
    /// [`SuccessSpec::cross_track_bound`] (transport).
    CrossTrackBound,
    /// [`SuccessSpec::convergence_window`] (transport).
    ConvergenceWindow,
    /// [`SuccessSpec::position_tolerance`] (work).
    PositionTolerance,
    /// [`SuccessSpec::orientation_tolerance_deg`] (work).
    OrientationTolerance,
}

impl Criterion {
    /// Every criterion, in the order a run is judged.
    pub const ALL: [Criterion; 7] = [
        Criterion::NoFailure,
        Criterion::MaxPeakThrust,
        Criterion::MaxSaturationFraction,
        Criterion::CrossTrackBound,
        Criterion::ConvergenceWindow,
        Criterion::PositionTolerance,
        Criterion::OrientationTolerance,
    ];

    /// The machine-readable id.
    pub fn as_str(self) -> &'static str {
        match self {
            Criterion::NoFailure => "no_failure",
            Criterion::MaxPeakThrust => "max_peak_thrust",
            Criterion::MaxSaturationFraction => "max_saturation_fraction",
            Criterion::CrossTrackBound => "cross_track_bound",
            Criterion::ConvergenceWindow => "convergence_window",
            Criterion::PositionTolerance => "position_tolerance",
            Criterion::OrientationTolerance => "orientation_tolerance_deg",
        }
    }

    /// The criterion of an id; `None` for any other text.
    pub fn parse(s: &str) -> Option<Self> {
        Criterion::ALL.into_iter().find(|c| c.as_str() == s)
    }
}

impl fmt::Display for Criterion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The first criterion a run missed, and by how much.
#[derive(Clone, Debug, PartialEq)]
pub struct Missed {
    /// Which criterion.
    pub criterion: Criterion,
    /// The value against its bound, one line (`|final_cross_track| = 1.243 m > 0.1 m`).
    pub detail: String,
}

impl fmt::Display for Missed {
    /// `criterion: detail` — the form of a sweep's `reason` cell for an unsuccessful case.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.criterion, self.detail)
    }
}

/// Judge a run of `mode` by its summary `metrics` (see `metrics::run_summary`) against
/// `spec`: `None` when it met every criterion, else the first one missed. `metrics` must
/// hold `completed`, `peak_thrust`, `saturation_fraction` and the mode's metrics; a
/// missing or NaN value misses its criterion.
pub fn judge(spec: &SuccessSpec, mode: Mode, metrics: &[(String, f64)]) -> Option<Missed> {
    let get = |k: &str| {
        metrics
            .iter()
            .find(|(n, _)| n == k)
            .map_or(f64::NAN, |x| x.1)
    };
    let missed = |criterion, detail: String| Some(Missed { criterion, detail });
    // NaN misses.
    let above = |x: f64, bound: f64| x.is_nan() || x > bound;
    if get("completed") != 1.0 {
        return missed(Criterion::NoFailure, "the run stopped early".into());
    }
    let peak = get("peak_thrust");
    if spec.max_peak_thrust > 0.0 && above(peak, spec.max_peak_thrust) {
        let d = format!("peak_thrust = {peak:.4} N > {} N", spec.max_peak_thrust);
        return missed(Criterion::MaxPeakThrust, d);
    }
    let sat = get("saturation_fraction");
    if above(sat, spec.max_saturation_fraction) {
        let d = format!(
            "saturation_fraction = {sat:.4} > {}",
            spec.max_saturation_fraction
        );
        return missed(Criterion::MaxSaturationFraction, d);
    }
    match mode {
        Mode::Transport => judge_transport(spec, &get),
        Mode::Work => {
            let p = get("final_position_error");
            if above(p, spec.position_tolerance) {
                let d = format!(
                    "final_position_error = {p:.4} m > {} m",
                    spec.position_tolerance
                );
                return missed(Criterion::PositionTolerance, d);
            }
            let a = get("final_orientation_error_deg");
            if above(a, spec.orientation_tolerance_deg) {
                let d = format!(
                    "final_orientation_error_deg = {a:.4} > {}",
                    spec.orientation_tolerance_deg
                );
                return missed(Criterion::OrientationTolerance, d);
            }
            None
        }
    }
}

/// The transport criteria: the final cross-track bound, then each reached segment's
/// convergence window in the order the segments became active.
fn judge_transport(spec: &SuccessSpec, get: &dyn Fn(&str) -> f64) -> Option<Missed> {
    let e = get("final_cross_track");
    if e.is_nan() || e.abs() > spec.cross_track_bound {
        return Some(Missed {
            criterion: Criterion::CrossTrackBound,
            detail: format!(
                "|final_cross_track| = {:.4} m > {} m",
                e.abs(),
                spec.cross_track_bound
            ),
        });
    }
    let reached = get("segments_reached");
    let n = if reached.is_finite() && reached > 0.0 {
        reached as usize
    } else {
        0
    };
    for k in 0..n {
        let c = get(&format!("seg{k}_convergence_time"));
        let detail = if c.is_nan() {
            format!("segment {k} never stayed within metrics.band before it ended")
        } else if c > spec.convergence_window {
            format!(
                "segment {k} converged after {c:.1} s > {} s",
                spec.convergence_window
            )
        } else {
            continue;
        };
        return Some(Missed {
            criterion: Criterion::ConvergenceWindow,
            detail,
        });
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn metrics(kv: &[(&str, f64)]) -> Vec<(String, f64)> {
        kv.iter().map(|(k, v)| (k.to_string(), *v)).collect()
    }

    const COMMON: [(&str, f64); 3] = [
        ("completed", 1.0),
        ("peak_thrust", 40.0),
        ("saturation_fraction", 0.01),
    ];

    fn transport(final_ct: f64, seg: &[f64]) -> Vec<(String, f64)> {
        let mut m = metrics(&COMMON);
        m.extend(
            seg.iter()
                .enumerate()
                .map(|(k, c)| (format!("seg{k}_convergence_time"), *c)),
        );
        m.extend(metrics(&[
            ("segments_reached", seg.len() as f64),
            ("final_cross_track", final_ct),
        ]));
        m
    }

    #[test]
    fn transport_criteria_in_order() {
        let s = SuccessSpec::default();
        let id = |m: &[(String, f64)]| judge(&s, Mode::Transport, m).map(|x| x.criterion);
        assert_eq!(id(&transport(-0.05, &[30.0, 44.0])), None);
        // Signed cross-track: judged by magnitude.
        assert_eq!(
            id(&transport(-1.24, &[f64::NAN, f64::NAN])),
            Some(Criterion::CrossTrackBound)
        );
        assert_eq!(
            id(&transport(0.05, &[71.5, 40.0])),
            Some(Criterion::ConvergenceWindow)
        );
        let m = judge(&s, Mode::Transport, &transport(0.05, &[30.0, f64::NAN])).unwrap();
        assert!(m.detail.starts_with("segment 1 never"), "{}", m.detail);
        assert!(m.to_string().starts_with("convergence_window: segment 1"));
        // Earlier criteria come first: a run that stopped early misses `no_failure` only.
        let mut stopped = transport(-1.24, &[f64::NAN]);
        stopped[0].1 = 0.0;
        assert_eq!(id(&stopped), Some(Criterion::NoFailure));
        let mut sat = transport(0.0, &[1.0]);
        sat[2].1 = 0.2;
        assert_eq!(id(&sat), Some(Criterion::MaxSaturationFraction));
        // The peak bound only binds when set.
        let tight = SuccessSpec {
            max_peak_thrust: 30.0,
            ..SuccessSpec::default()
        };
        let m = judge(&tight, Mode::Transport, &transport(0.0, &[1.0]));
        assert_eq!(m.map(|x| x.criterion), Some(Criterion::MaxPeakThrust));
    }

    #[test]
    fn work_criteria_and_missing_metrics() {
        let s = SuccessSpec::default();
        let mut m = metrics(&COMMON);
        m.extend(metrics(&[
            ("final_position_error", 0.01),
            ("final_orientation_error_deg", 0.1),
        ]));
        assert_eq!(judge(&s, Mode::Work, &m), None);
        m[3].1 = 0.5;
        let x = judge(&s, Mode::Work, &m).unwrap();
        assert_eq!(x.criterion, Criterion::PositionTolerance);
        m[3].1 = 0.01;
        m[4].1 = f64::NAN;
        let x = judge(&s, Mode::Work, &m).unwrap();
        assert_eq!(x.criterion, Criterion::OrientationTolerance);
        // A missing metric misses its criterion.
        assert_eq!(
            judge(&s, Mode::Work, &metrics(&COMMON)).map(|x| x.criterion),
            Some(Criterion::PositionTolerance)
        );
    }

    #[test]
    fn ids_round_trip_and_validation_names_the_key() {
        for c in Criterion::ALL {
            assert_eq!(Criterion::parse(c.as_str()), Some(c));
        }
        assert_eq!(Criterion::parse("nope"), None);
        assert!(SuccessSpec::default().validate().is_ok());
        let bad = SuccessSpec {
            convergence_window: -1.0,
            ..SuccessSpec::default()
        };
        assert_eq!(
            bad.validate().unwrap_err().key,
            "success.convergence_window"
        );
        let bad = SuccessSpec {
            max_saturation_fraction: 1.5,
            ..SuccessSpec::default()
        };
        assert_eq!(
            bad.validate().unwrap_err().key,
            "success.max_saturation_fraction"
        );
    }
}
