//! The failure watch of a closed-loop run (`[success] stop_on_failure`, docs/study-format.md
//! "Stopping a failed run"): after every control period, whether the criterion the run's
//! verdict (`outcome::judge::judge`) would name is already certain to be missed, whatever the
//! rest of the run does.
//!
//! The verdict names the first criterion missed in a fixed order (the mission's reach,
//! `no_failure`, in transport the attitude and depth bounds, the peak thrust, the saturation
//! fraction, then the criteria judged at the end). Every criterion of the run itself can still
//! be missed until the end, so only the first one that is judged and can be missed at all is
//! watched: once it is missed, no later event can make the verdict name another one, except a
//! numerical failure after the stop (`no_failure`), which the stopped run never meets. The
//! watched criterion, each certain the moment its test holds:
//!
//! - `mission.reach`: the design's reach is short of `[mission] reach` (known before the run);
//! - `max_roll_deg`, `max_pitch_deg`: one logged sample's |roll| or |pitch| of the base
//!   (wrapped, in degrees) above the bound — the metric is the largest over the log;
//! - `max_vertical_error`: one logged sample's `|z − z(0)|` of the base or the end effector
//!   above the bound;
//! - `max_peak_thrust` (when set below the largest thruster limit): the peak so far above it;
//! - `max_saturation_fraction` (when below 1): the saturated time so far divided by the
//!   integrated time of the whole run — the same sum of `control_dt` the integrator will reach —
//!   above the bound (the saturated time can only grow).
//!
//! Each test uses the very floating-point values the run's metric is made of, compared as the
//! verdict compares them (`value > bound`), so a stop is never a guess. Reads only; the run
//! itself is untouched (a successful run is bit-identical with or without the watch).

use super::channels::{Channel, Pose, Trajectory};
use super::config::{Mode, ScenarioFile};
use super::criteria::Criterion;
use crate::kinematics::straight_reach;
use crate::metrics::trajectory::EnergyIntegrator;
use crate::model::Vehicle;
use crate::spatial::wrap_angle;

/// The one criterion a run may be stopped on, with its bound.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Watched {
    /// The design's reach is short of the mission's: certain before the run.
    Reach,
    /// |roll| of the base [deg] at a logged sample above the bound.
    Roll(f64),
    /// |pitch| of the base [deg] at a logged sample above the bound.
    Pitch(f64),
    /// `|z − z(0)|` of the base origin or the end effector [m] at a logged sample above the
    /// bound.
    Vertical(f64),
    /// The largest thrust so far [N] above the bound.
    PeakThrust(f64),
    /// The saturated time so far over `span`, the whole run's integrated time [s], above
    /// `bound`.
    Saturation {
        /// `max_saturation_fraction`.
        bound: f64,
        /// `n_control · control_dt` summed as the energy integrator sums it.
        span: f64,
    },
}

impl Watched {
    fn criterion(self) -> Criterion {
        match self {
            Watched::Reach => Criterion::MissionReach,
            Watched::Roll(_) => Criterion::MaxRoll,
            Watched::Pitch(_) => Criterion::MaxPitch,
            Watched::Vertical(_) => Criterion::MaxVerticalError,
            Watched::PeakThrust(_) => Criterion::MaxPeakThrust,
            Watched::Saturation { .. } => Criterion::MaxSaturationFraction,
        }
    }
}

/// Watches a run for the certain miss of the criterion its verdict would name (module docs).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct FailureWatch {
    watched: Option<Watched>,
    /// Logged rows already looked at.
    rows_seen: usize,
}

impl FailureWatch {
    /// The watch of a run of `file` on `v` (the run's own vehicle, world scales applied) with
    /// `n_control` control periods after the first tick; `design` is the vehicle as given
    /// (its reach, `kinematics::straight_reach`, is the run's metric `reach`). It watches
    /// nothing when `[success] stop_on_failure` is off or no criterion qualifies.
    pub fn new(design: &Vehicle, v: &Vehicle, file: &ScenarioFile, n_control: usize) -> Self {
        let s = &file.success;
        let reach = straight_reach(design);
        let short = file.mission.reach > 0.0 && (reach.is_nan() || reach < file.mission.reach);
        let largest_limit = v
            .thrusters
            .iter()
            .fold(0.0f64, |m, t| m.max(t.u_min.abs()).max(t.u_max.abs()));
        let dt = file.scenario.control_dt;
        let span = (0..n_control).fold(0.0f64, |a, _| a + dt);
        let transport = file.scenario.mode == Mode::Transport;
        let candidates = [
            (short, Watched::Reach),
            (
                transport && s.max_roll_deg > 0.0,
                Watched::Roll(s.max_roll_deg),
            ),
            (
                transport && s.max_pitch_deg > 0.0,
                Watched::Pitch(s.max_pitch_deg),
            ),
            (
                transport && s.max_vertical_error > 0.0,
                Watched::Vertical(s.max_vertical_error),
            ),
            // A bound at or above every thruster's limit can never be missed (the delivered
            // thrust is clamped to the limits): it does not hide the criteria after it.
            (
                s.max_peak_thrust > 0.0 && s.max_peak_thrust < largest_limit,
                Watched::PeakThrust(s.max_peak_thrust),
            ),
            // Nor can a saturation bound of 1.
            (
                s.max_saturation_fraction < 1.0 && span > 0.0,
                Watched::Saturation {
                    bound: s.max_saturation_fraction,
                    span,
                },
            ),
        ];
        let watched = candidates
            .into_iter()
            .find(|(judged, _)| *judged)
            .map(|(_, w)| w)
            .filter(|_| s.stop_on_failure);
        FailureWatch {
            watched,
            rows_seen: 0,
        }
    }

    /// The criterion now certainly missed, if it is: after a control period, with the log
    /// `traj` and the thruster integrals `energy` so far.
    pub fn check(&mut self, traj: &Trajectory, energy: &EnergyIntegrator) -> Option<Criterion> {
        let w = self.watched?;
        let rows = traj.len();
        let new_row = rows > self.rows_seen;
        self.rows_seen = rows;
        let missed = match w {
            Watched::Reach => true,
            Watched::PeakThrust(b) => energy.peak_thrust() > b,
            Watched::Saturation { bound, span } => energy.saturated_time() / span > bound,
            _ if !new_row => false,
            Watched::Roll(b) => last_angle_deg(traj, Channel::BasePose(Pose::Roll)) > b,
            Watched::Pitch(b) => last_angle_deg(traj, Channel::BasePose(Pose::Pitch)) > b,
            Watched::Vertical(b) => {
                depth_change(traj, Channel::BasePose(Pose::Z)) > b
                    || depth_change(traj, Channel::EePose(Pose::Z)) > b
            }
        };
        missed.then(|| w.criterion())
    }
}

/// `|wrap(x)|` in degrees of the last logged sample of an angle channel (NaN when none).
fn last_angle_deg(traj: &Trajectory, c: Channel) -> f64 {
    traj.get(c)
        .and_then(|x| x.last())
        .map_or(f64::NAN, |a| wrap_angle(*a).abs().to_degrees())
}

/// `|z − z(0)|` of the last logged sample of a depth channel (NaN when none).
fn depth_change(traj: &Trajectory, c: Channel) -> f64 {
    match traj.get(c) {
        Some([z0, .., z]) => (z - z0).abs(),
        _ => f64::NAN,
    }
}
