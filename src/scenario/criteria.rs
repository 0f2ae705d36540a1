//! `[success]`: what a closed-loop run must achieve to count as a success (docs/model.md §6
//! "Success"), the criteria and the verdict on a run ([`Missed`]: the first criterion it
//! missed), as judged by `outcome::judge::judge`.
//!
//! ```toml
//! [success]
//! # both modes (a run that stopped early always misses `no_failure`)
//! max_peak_thrust = 0.0          # N; 0 = the thrusters' own limits
//! max_saturation_fraction = 0.05 # of the run with a thruster at a limit
//! # transport
//! cross_track_bound = 0.1        # m, |cross-track error| at the end of the run
//! convergence_window = 60.0      # s after a segment becomes active
//! max_roll_deg = 30.0            # deg, |base roll| over the whole run (0 = not judged)
//! max_pitch_deg = 30.0           # deg, |base pitch| over the whole run (0 = not judged)
//! max_vertical_error = 1.0       # m, |depth deviation| of base or head from the path (0 = not judged)
//! # work
//! position_tolerance = 0.02      # m, final end-effector position error
//! orientation_tolerance_deg = 2.0 # deg, final pointing error (roll excluded)
//! # both modes
//! stop_on_failure = true         # end a run once it certainly misses (see below)
//! ```
//!
//! Criteria are checked in the order of [`Criterion::ALL`], except that the mission's reach
//! comes first and the transport attitude and depth bounds come right after `no_failure` (a
//! capsize saturates the thrusters and leaves the path: the verdict names the cause, the roll,
//! not its symptoms), and a transport run's forward progress (`forward_progress`:
//! `path_progress` > 0) and finite objective (`finite_objective`: `mission_cost`) come last
//! (issue 39); a verdict names the first one missed by its id, which is the `[success]`
//! key that bounds it (`no_failure` has none).
//! Studies rank and compare only successful runs (`study::summary`).
//!
//! With `stop_on_failure` (the default) a run ends as soon as the criterion its verdict would
//! name is certain to be missed whatever the rest of the run does (`super::watch`): the
//! mission's reach, or the first judged criterion of the run itself among the attitude and
//! depth bounds, the peak thrust and the saturation fraction. The stopped run reports that
//! criterion, `stopped_at` and its metrics up to the stop; a successful run is unaffected.

use std::fmt;

use serde::{Deserialize, Serialize};

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
    /// Transport: the largest |roll| of the base frame from level (the transport reference:
    /// the path is horizontal and every joint reference keeps the body level) over the whole
    /// run, ZYX roll wrapped into (−180°, 180°] (metric `max_abs_roll_deg`) [deg]. Judged over
    /// the whole run, not after convergence: the start is level, so a nominal transient does
    /// not roll, and a capsize at any time ends the mission. 0 = not judged. Default 30°
    /// (**inferred**: a capsize detector, not a ride-quality bound; a study may tighten it).
    pub max_roll_deg: f64,
    /// Transport: the largest |pitch| of the base frame from level over the whole run (metric
    /// `max_abs_pitch_deg`) [deg]. 0 = not judged. Default 30° (**inferred**, as the roll).
    pub max_pitch_deg: f64,
    /// Transport: the largest vertical deviation from the path over the whole run, of the base
    /// origin or the end effector (the "front" the cross-track error is measured at), from
    /// the depth each started at (transport paths are horizontal, at the depth the vehicle
    /// starts; metric `max_vertical_error`) [m]. The 3-D complement of
    /// [`SuccessSpec::cross_track_bound`]. 0 = not judged. Default 1 m (**inferred**: ten
    /// times the cross-track bound).
    pub max_vertical_error: f64,
    /// End a run at the first control period after which the criterion its verdict would name
    /// is certainly missed (`super::watch`, docs/study-format.md "Stopping a failed run"):
    /// the verdict (status and criterion) is the whole run's, the metrics go as far as the
    /// run did (metric `stopped_at` [s]). A run that meets its criteria is bit-identical
    /// either way. Default true; false keeps the whole trajectory of every failure.
    pub stop_on_failure: bool,
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
            max_roll_deg: 30.0,
            max_pitch_deg: 30.0,
            max_vertical_error: 1.0,
            stop_on_failure: true,
        }
    }
}

impl SuccessSpec {
    /// Check the bounds; errors name `success.<key>`.
    pub fn validate(&self) -> Result<(), KeyError> {
        let bad = |k: &str, what: &str, v: f64| {
            Err(KeyError::new(
                format!("success.{k}"),
                format!(
                    "must be {what}, got {}",
                    crate::input::located::fmt_exact(v)
                ),
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
        for (k, v) in [
            ("max_roll_deg", self.max_roll_deg),
            ("max_pitch_deg", self.max_pitch_deg),
        ] {
            if !(0.0..=180.0).contains(&v) {
                return bad(k, "in [0, 180] (0 = not judged)", v);
            }
        }
        if !self.max_vertical_error.is_finite() || self.max_vertical_error < 0.0 {
            return bad(
                "max_vertical_error",
                "finite and >= 0 (0 = not judged)",
                self.max_vertical_error,
            );
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

/// One success criterion; its id ([`Criterion::as_str`]) is the `[success]` key bounding it
/// (`mission.<key>` for a `[mission]` requirement).
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
    /// `[mission] reach` (`super::config::MissionSpec::reach`): the design's reach.
    MissionReach,
    /// `[mission] deadline` (transport): every reached segment converged this soon.
    MissionDeadline,
    /// [`SuccessSpec::max_roll_deg`] (transport): the base rolled too far (a capsize).
    MaxRoll,
    /// [`SuccessSpec::max_pitch_deg`] (transport).
    MaxPitch,
    /// [`SuccessSpec::max_vertical_error`] (transport): left the path's depth.
    MaxVerticalError,
    /// Transport: the run advanced along the path (`path_progress` > 0); judged last.
    ForwardProgress,
    /// Transport: the objective `mission_cost` is finite; judged last, after
    /// [`Criterion::ForwardProgress`].
    FiniteObjective,
}

impl Criterion {
    /// Every criterion. A run is judged in this order, except that the mission's design
    /// requirement [`Criterion::MissionReach`] comes first (a design that cannot reach fails
    /// the mission whatever its run did) and the attitude and depth bounds
    /// ([`Criterion::MaxRoll`], [`Criterion::MaxPitch`], [`Criterion::MaxVerticalError`]) right
    /// after [`Criterion::NoFailure`], and the transport run's forward progress and finite
    /// objective ([`Criterion::ForwardProgress`], [`Criterion::FiniteObjective`]) come last,
    /// after `mission.deadline`; new criteria are appended, so an index into this list stays
    /// valid across versions.
    pub const ALL: [Criterion; 14] = [
        Criterion::NoFailure,
        Criterion::MaxPeakThrust,
        Criterion::MaxSaturationFraction,
        Criterion::CrossTrackBound,
        Criterion::ConvergenceWindow,
        Criterion::PositionTolerance,
        Criterion::OrientationTolerance,
        Criterion::MissionReach,
        Criterion::MissionDeadline,
        Criterion::MaxRoll,
        Criterion::MaxPitch,
        Criterion::MaxVerticalError,
        Criterion::ForwardProgress,
        Criterion::FiniteObjective,
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
            Criterion::MissionReach => "mission.reach",
            Criterion::MissionDeadline => "mission.deadline",
            Criterion::MaxRoll => "max_roll_deg",
            Criterion::MaxPitch => "max_pitch_deg",
            Criterion::MaxVerticalError => "max_vertical_error",
            Criterion::ForwardProgress => "forward_progress",
            Criterion::FiniteObjective => "finite_objective",
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

#[cfg(test)]
mod tests {
    use crate::scenario::criteria::{Criterion, SuccessSpec};

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
