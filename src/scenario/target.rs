//! What work mode asks of the end effector: the `[setpoint]` pose and the optional
//! `[reference]`, a time-parametrised path to it (docs/model.md §5, USM-42; the path law is
//! [`crate::control::spline`]).
//!
//! ```toml
//! [setpoint]                 # final pose, inertial frame
//! position = [3.0, 0.5, -0.3]
//! rpy_deg = [0.0, 10.0, 25.0]
//!
//! [reference]                # optional: reach the setpoint along a timed path
//! duration = 30.0            # s, T: arrival at the setpoint (<= scenario.duration)
//! [[reference.via]]          # optional via-points, times increasing inside (0, T)
//! time = 15.0                # s
//! position = [3.4, 0.4, 0.1] # m, inertial
//! rpy_deg = [0.0, 5.0, 12.0] # optional; default: the straight-line angles at that time
//! ```
//!
//! Without `[reference]` the setpoint is a step at `t = 0` (the paper's regulation). With it,
//! the desired pose starts at the end effector's initial pose and follows the quintic
//! straight line (no via-points) or the natural spline through the via-points, arriving at
//! the setpoint at `T` and holding it; the desired twist is fed forward (USM-42's `V_e,d`).
//! Sweep axes and `[[param]]` reach every number: `reference.duration`,
//! `reference.via[0].time`, `reference.via[0].position[1]`.
//!
//! Or the reference is a trajectory file (`simulate --reference FILE` sets this):
//!
//! ```toml
//! [reference]
//! file = "timeseries.csv"        # time-series column names (control::trajectory_file)
//! k_position = [0.5, 0.5, 0.5]   # optional tracking gains, 1/s (control::tracking)
//! k_attitude = [1.0, 1.0, 1.0]
//! feedforward = false            # add the file's wrench_* columns to tau_c
//! ```
//!
//! The whole state is then followed — base pose and twist by the tracking law of
//! [`crate::control::tracking`] into the dynamic control, the joints by their servos — and
//! `[setpoint]` may be left out (the work-mode channels compare the end effector with the
//! reference's). The file's path is relative to the scenario file.

use crate::control::spline::Via;
use crate::control::tracking::TrackingGains;
use crate::input::document::deserialize_table;
use crate::input::located::KeyError;
use serde::{Deserialize, Serialize};

/// Most via-points of a `[reference]`.
pub const MAX_VIA: usize = 64;

/// `[setpoint]`: a time-invariant end-effector pose (work mode), inertial frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SetpointSpec {
    /// End-effector position [m].
    pub position: [f64; 3],
    /// End-effector orientation as roll, pitch, yaw (ZYX) [deg].
    #[serde(default)]
    pub rpy_deg: [f64; 3],
    /// Base position target of the secondary task [m]; default: the initial base position.
    #[serde(default)]
    pub base_position: Option<[f64; 3]>,
}

/// `[reference]`: a timed end-effector path from the initial pose to the setpoint (module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSpec {
    /// Arrival time `T` at the setpoint [s], `0 < T <= scenario.duration` (unused, and may be
    /// left out, with `file`).
    #[serde(default)]
    pub duration: f64,
    /// A trajectory file to follow instead of the timed path (module docs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// With `file`: the base position gain of the tracking law [1/s].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k_position: Option<[f64; 3]>,
    /// With `file`: the base attitude gain of the tracking law [1/s].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k_attitude: Option<[f64; 3]>,
    /// With `file`: whether the file's base wrench is fed forward.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feedforward: Option<bool>,
    /// Via-points, times strictly increasing inside `(0, T)`; empty: the quintic straight line.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub via: Vec<ViaSpec>,
}

/// One `[[reference.via]]` entry.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ViaSpec {
    /// Time of passage [s].
    pub time: f64,
    /// End-effector position [m], inertial frame.
    pub position: [f64; 3],
    /// Roll, pitch, yaw (ZYX) [deg]; default: the straight-line angles at `time`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rpy_deg: Option<[f64; 3]>,
}

impl ReferenceSpec {
    /// Check the reference of a run in work mode (`work`) lasting `run_duration` [s]; errors
    /// name the file key (`reference.via[1].time`).
    pub fn validate(&self, work: bool, run_duration: f64) -> Result<(), KeyError> {
        if !work {
            return Err(KeyError::new(
                "reference",
                "only work mode takes a [reference]",
            ));
        }
        if self.file.is_some() {
            if !self.via.is_empty() {
                return Err(KeyError::new(
                    "reference.via",
                    "a reference file takes no via-points",
                ));
            }
            return (self.tracking_gains().validate()).map_err(|e| KeyError::new(e.key, e.message));
        }
        for (key, set) in [
            ("reference.k_position", self.k_position.is_some()),
            ("reference.k_attitude", self.k_attitude.is_some()),
            ("reference.feedforward", self.feedforward.is_some()),
        ] {
            if set {
                return Err(KeyError::new(key, "applies only with reference.file"));
            }
        }
        let t = self.duration;
        if !t.is_finite() || t <= 0.0 || t > run_duration {
            return Err(KeyError::new(
                "reference.duration",
                format!("must be > 0 and at most scenario.duration ({run_duration}), got {t}"),
            ));
        }
        if self.via.len() > MAX_VIA {
            return Err(KeyError::new(
                "reference.via",
                format!("at most {MAX_VIA} via-points, got {}", self.via.len()),
            ));
        }
        let mut prev = 0.0;
        for (k, v) in self.via.iter().enumerate() {
            let key = |f: &str| format!("reference.via[{k}].{f}");
            if !(v.time > prev && v.time < t) {
                return Err(KeyError::new(
                    key("time"),
                    format!(
                        "{} must lie after the previous via-point's time (or 0), {prev}, and \
                         before reference.duration, {t}",
                        v.time
                    ),
                ));
            }
            prev = v.time;
            if let Some(x) = v.position.iter().find(|x| !x.is_finite()) {
                return Err(KeyError::new(
                    key("position"),
                    format!("must be finite, got {x}"),
                ));
            }
            if let Some(x) = v.rpy_deg.iter().flatten().find(|x| !x.is_finite()) {
                return Err(KeyError::new(
                    key("rpy_deg"),
                    format!("must be finite, got {x}"),
                ));
            }
        }
        Ok(())
    }

    /// The tracking gains of a file reference: the file's keys over the defaults.
    pub fn tracking_gains(&self) -> TrackingGains {
        let d = TrackingGains::default();
        TrackingGains {
            k_position: self.k_position.unwrap_or(d.k_position),
            k_attitude: self.k_attitude.unwrap_or(d.k_attitude),
            feedforward: self.feedforward.unwrap_or(d.feedforward),
        }
    }

    /// The via-points in the units of [`crate::control::spline::PoseReference`] (rad).
    pub fn via_points(&self) -> Vec<Via> {
        self.via
            .iter()
            .map(|v| Via {
                time: v.time,
                position: v.position,
                rpy: v.rpy_deg.map(|r| r.map(f64::to_radians)),
            })
            .collect()
    }
}

/// Check the `[reference]` of a resolved scenario-side table (a study's base scenario), if
/// any: known keys, work mode, times within `scenario.duration`; errors name the file key.
pub fn check_reference(scenario: &toml::Table) -> Result<(), KeyError> {
    let Some(v) = scenario.get("reference") else {
        return Ok(());
    };
    let toml::Value::Table(t) = v else {
        return Err(KeyError::new("reference", "must be a table"));
    };
    let spec: ReferenceSpec = deserialize_table(t, "reference")?;
    let section = scenario.get("scenario");
    let get = |k: &str| section.and_then(|s| s.get(k));
    let work = get("mode").and_then(|m| m.as_str()) == Some("work");
    let duration = get("duration")
        .and_then(|d| d.as_float())
        .unwrap_or(f64::INFINITY);
    spec.validate(work, duration)
}

#[cfg(test)]
mod tests {
    use crate::scenario::target::ReferenceSpec;

    fn spec(text: &str) -> ReferenceSpec {
        toml::from_str(text).unwrap()
    }

    #[test]
    fn bad_via_points_name_their_key() {
        let ok = "duration = 20.0\n[[via]]\ntime = 5.0\nposition = [1.0, 2.0, 3.0]\n";
        assert!(spec(ok).validate(true, 80.0).is_ok());
        let cases = [
            ("duration = 90.0", "reference.duration"),
            (
                "duration = 20.0\n[[via]]\ntime = 25.0\nposition = [1.0, 2.0, 3.0]",
                "reference.via[0].time",
            ),
            (
                "duration = 20.0\n[[via]]\ntime = 8.0\nposition = [1.0, 2.0, 3.0]\n\
                 [[via]]\ntime = 8.0\nposition = [1.0, 2.0, 3.0]",
                "reference.via[1].time",
            ),
            (
                "duration = 20.0\n[[via]]\ntime = 8.0\nposition = [1.0, nan, 3.0]",
                "reference.via[0].position",
            ),
        ];
        for (text, key) in cases {
            assert_eq!(
                spec(text).validate(true, 80.0).unwrap_err().key,
                key,
                "{text}"
            );
        }
    }
}
