//! How a case ended: [`CaseEnd`] (what it means, with its data) and [`CaseStatus`] (the
//! `status` column it is written as).

use std::fmt;
use std::str::FromStr;

use super::deadline::TIMEOUT;
use crate::outcome::RUN_STOPPED;
use crate::scenario::criteria::Criterion;

/// How a case ended (the `status` column: `ok`, `unsuccessful`, `failed`, `skipped`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum CaseStatus {
    /// Every metric was computed and, for a closed-loop run, every `[success]` criterion met:
    /// the cases a report ranks.
    Ok,
    /// The run completed but missed a `[success]` criterion: the reason is
    /// `criterion: detail`, the criterion id first ([`CaseEnd::Missed`],
    /// [`CaseEnd::Disqualified`]).
    Unsuccessful,
    /// The analysis or the run failed (the reason says why; metrics computed so far are kept).
    Failed,
    /// The case could not be set up (an override that does not apply, an invalid design).
    Skipped,
}

impl CaseStatus {
    /// Every status, in table order.
    pub const ALL: [CaseStatus; 4] = [
        CaseStatus::Ok,
        CaseStatus::Unsuccessful,
        CaseStatus::Failed,
        CaseStatus::Skipped,
    ];

    /// The text in the `status` column.
    pub fn as_str(self) -> &'static str {
        match self {
            CaseStatus::Ok => "ok",
            CaseStatus::Unsuccessful => "unsuccessful",
            CaseStatus::Failed => "failed",
            CaseStatus::Skipped => "skipped",
        }
    }

    /// The status of a `status` cell; `None` for any other text.
    pub fn parse(s: &str) -> Option<Self> {
        CaseStatus::ALL.into_iter().find(|c| c.as_str() == s)
    }
}

/// Why a design is disqualified whatever the world, gains or fault: such a case is neither
/// tuned further, put in worlds nor ranked.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Disqualification {
    /// It cannot reach the mission (`[mission] reach`, criterion `mission.reach`).
    MissionReach,
    /// It cannot command an axis anywhere in joint space: the static analysis's
    /// `under_actuated_axes` bit mask (surge = 1 … yaw = 32).
    UnderActuated {
        /// The axes without authority, as the bit mask.
        axes: u32,
    },
}

/// The id an under-actuated case's reason starts with (`under_actuated: …`).
pub const UNDER_ACTUATED: &str = "under_actuated";

/// The text a panicking case's reason starts with (`panic: …`).
pub const PANIC: &str = "panic: ";

/// How a case ended, with what the ending means: the [`CaseStatus`] of the `status` column
/// is [`CaseEnd::status`]; the `reason` text beside it is for people and never read back for
/// meaning (tables read from disk are decoded once, by [`CaseEnd::read`], beside the
/// writers of those reasons).
#[derive(Clone, Debug, PartialEq)]
pub enum CaseEnd {
    /// Every phase ran and every `[success]` criterion was met.
    Ok,
    /// The run completed but missed this `[success]` criterion (the first in judging order).
    Missed(Criterion),
    /// The design cannot meet the mission whatever its run did (unsuccessful, not ranked).
    Disqualified(Disqualification),
    /// The case's wall-clock budget ran out (failed).
    Timeout,
    /// The closed-loop run stopped early (non-finite state, singular mass matrix, …) at
    /// simulated time `at` [s] (failed).
    Diverged {
        /// Simulated time the run stopped at [s].
        at: f64,
    },
    /// The evaluation panicked (failed); the panic's message.
    Panic {
        /// The panic's message.
        message: String,
    },
    /// Another failure: the static analysis, the trajectory, tuning or the worlds (failed).
    Error,
    /// The case could not be set up (an invalid design, a bad `[static]` table).
    Skipped,
    /// The case's overrides do not apply to its tables (an index beyond an array, a design
    /// the generator cannot build for thruster edits): skipped, never run.
    NotApplicable,
}

impl CaseEnd {
    /// The `status` column of this ending.
    pub fn status(&self) -> CaseStatus {
        match self {
            CaseEnd::Ok => CaseStatus::Ok,
            CaseEnd::Missed(_) | CaseEnd::Disqualified(_) => CaseStatus::Unsuccessful,
            CaseEnd::Timeout
            | CaseEnd::Diverged { .. }
            | CaseEnd::Panic { .. }
            | CaseEnd::Error => CaseStatus::Failed,
            CaseEnd::Skipped | CaseEnd::NotApplicable => CaseStatus::Skipped,
        }
    }

    /// The unsuccessful ending of a missed criterion: `mission.reach` disqualifies.
    pub fn missed(c: Criterion) -> Self {
        match c {
            Criterion::MissionReach => CaseEnd::Disqualified(Disqualification::MissionReach),
            c => CaseEnd::Missed(c),
        }
    }

    /// Whether the design is disqualified whatever the world, gains or fault.
    pub fn disqualified(&self) -> bool {
        matches!(self, CaseEnd::Disqualified(_))
    }

    /// Whether the case's wall-clock budget ran out.
    pub fn timed_out(&self) -> bool {
        matches!(self, CaseEnd::Timeout)
    }

    /// The criterion id the report names: the missed criterion, `mission.reach` or
    /// `under_actuated` for a disqualified case, `no_failure` for a failed case; `None` for
    /// `ok` and `skipped` cases (a skipped case never ran).
    pub fn criterion(&self) -> Option<&'static str> {
        match self {
            CaseEnd::Missed(c) => Some(c.as_str()),
            CaseEnd::Disqualified(Disqualification::MissionReach) => {
                Some(Criterion::MissionReach.as_str())
            }
            CaseEnd::Disqualified(Disqualification::UnderActuated { .. }) => Some(UNDER_ACTUATED),
            CaseEnd::Timeout
            | CaseEnd::Diverged { .. }
            | CaseEnd::Panic { .. }
            | CaseEnd::Error => Some(Criterion::NoFailure.as_str()),
            CaseEnd::Ok | CaseEnd::Skipped | CaseEnd::NotApplicable => None,
        }
    }

    /// The [`Criterion`] of [`CaseEnd::criterion`] (`None` also for `under_actuated`, which
    /// is a static finding, not a `[success]` criterion).
    pub fn missed_criterion(&self) -> Option<Criterion> {
        match self {
            CaseEnd::Missed(c) => Some(*c),
            CaseEnd::Disqualified(Disqualification::MissionReach) => Some(Criterion::MissionReach),
            CaseEnd::Disqualified(Disqualification::UnderActuated { .. }) => None,
            CaseEnd::Timeout
            | CaseEnd::Diverged { .. }
            | CaseEnd::Panic { .. }
            | CaseEnd::Error => Some(Criterion::NoFailure),
            CaseEnd::Ok | CaseEnd::Skipped | CaseEnd::NotApplicable => None,
        }
    }

    /// The ending of a table row read back from disk (`report`, `merge`, re-ranking): the
    /// inverse of the reasons the evaluator, the worlds and the adaptive rounds write, decoded
    /// here once. `None` for an unsuccessful row whose reason names no criterion (a file
    /// written by hand or by another version).
    pub fn read(status: CaseStatus, reason: &str) -> Option<CaseEnd> {
        Some(match status {
            CaseStatus::Ok => CaseEnd::Ok,
            CaseStatus::Skipped => CaseEnd::Skipped,
            CaseStatus::Unsuccessful => {
                let id = reason.split_once(':').map_or(reason, |x| x.0).trim();
                if id == UNDER_ACTUATED {
                    CaseEnd::Disqualified(Disqualification::UnderActuated { axes: 0 })
                } else {
                    CaseEnd::missed(Criterion::parse(id)?)
                }
            }
            CaseStatus::Failed if reason.starts_with(TIMEOUT) => CaseEnd::Timeout,
            CaseStatus::Failed => match reason.strip_prefix(PANIC) {
                Some(m) => CaseEnd::Panic {
                    message: m.to_string(),
                },
                None => match reason.strip_prefix(RUN_STOPPED) {
                    Some(r) => CaseEnd::Diverged {
                        at: r
                            .split(' ')
                            .next()
                            .and_then(|t| t.parse().ok())
                            .unwrap_or(f64::NAN),
                    },
                    None => CaseEnd::Error,
                },
            },
        })
    }
}

/// The reason of a left-out case without the criterion an unsuccessful case's reason starts
/// with (a report shows the criterion in its own column).
pub fn reason_detail(status: CaseStatus, reason: &str) -> &str {
    match (status, reason.split_once(": ")) {
        (CaseStatus::Unsuccessful, Some((_, d))) => d,
        _ => reason,
    }
}

impl fmt::Display for CaseStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A `status` cell that names no [`CaseStatus`].
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown case status `{0}`")]
pub struct UnknownStatus(pub String);

impl FromStr for CaseStatus {
    type Err = UnknownStatus;
    fn from_str(s: &str) -> Result<Self, UnknownStatus> {
        CaseStatus::parse(s).ok_or_else(|| UnknownStatus(s.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statuses_round_trip_and_name_their_criterion() {
        for s in CaseStatus::ALL {
            assert_eq!(s.as_str().parse::<CaseStatus>(), Ok(s));
        }
        assert_eq!(
            "done".parse::<CaseStatus>().unwrap_err().to_string(),
            "unknown case status `done`"
        );
        let r = "cross_track_bound: 2.1 m > 1 m";
        let un = CaseStatus::Unsuccessful;
        let end = CaseEnd::read(un, r).unwrap();
        assert_eq!(end, CaseEnd::Missed(Criterion::CrossTrackBound));
        assert_eq!(end.criterion(), Some("cross_track_bound"));
        assert_eq!(reason_detail(un, r), "2.1 m > 1 m");
        let reach = CaseEnd::read(un, "mission.reach: 1 m < 2 m").unwrap();
        assert!(reach.disqualified() && reach.status() == un);
        let ua = CaseEnd::read(un, "under_actuated: no authority").unwrap();
        assert!(ua.disqualified() && ua.missed_criterion().is_none());
        assert_eq!(ua.criterion(), Some(UNDER_ACTUATED));
        assert_eq!(CaseEnd::read(un, "nonsense: x"), None);
        let f = CaseStatus::Failed;
        assert!(CaseEnd::read(f, "timeout in world 3").unwrap().timed_out());
        assert_eq!(
            CaseEnd::read(f, "run stopped at t = 1.250 s: non-finite state"),
            Some(CaseEnd::Diverged { at: 1.25 })
        );
        assert_eq!(
            CaseEnd::read(f, "panic: boom"),
            Some(CaseEnd::Panic {
                message: "boom".into()
            })
        );
        let other = CaseEnd::read(f, r).unwrap();
        assert_eq!(
            (other.clone(), other.criterion()),
            (CaseEnd::Error, Some("no_failure"))
        );
        assert_eq!(CaseEnd::read(CaseStatus::Ok, "").unwrap().criterion(), None);
    }
}
