//! How a case ended ([`CaseStatus`]) and the criterion an unsuccessful case missed.

use std::fmt;
use std::str::FromStr;

/// How a case ended (the `status` column: `ok`, `unsuccessful`, `failed`, `skipped`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum CaseStatus {
    /// Every metric was computed and, for a closed-loop run, every `[success]` criterion met:
    /// the cases a report ranks.
    Ok,
    /// The run completed but missed a `[success]` criterion: the reason is
    /// `criterion: detail`, the criterion id first ([`missed_criterion`]).
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

/// The criterion a case with `status` and `reason` missed, for the report: the id before
/// the first `:` of an `unsuccessful` case's reason; `no_failure` for a `failed` case; `None`
/// for `ok` and `skipped` cases (a skipped case never ran).
pub fn missed_criterion(status: CaseStatus, reason: &str) -> Option<&str> {
    match status {
        CaseStatus::Unsuccessful => Some(reason.split_once(':').map_or(reason, |x| x.0).trim()),
        CaseStatus::Failed => Some("no_failure"),
        CaseStatus::Ok | CaseStatus::Skipped => None,
    }
}

/// Reasons that disqualify a design whatever the world, gains or fault: it cannot reach the
/// mission (`mission.reach`), or cannot command an axis anywhere in joint space
/// (`under_actuated`). Such a case is neither tuned further, put in worlds nor ranked.
pub const DISQUALIFYING: [&str; 2] = ["mission.reach:", "under_actuated:"];

/// Whether an unsuccessful case's `reason` is one of [`DISQUALIFYING`].
pub fn disqualified(reason: &str) -> bool {
    DISQUALIFYING.iter().any(|p| reason.starts_with(p))
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
        assert_eq!(
            missed_criterion(CaseStatus::Unsuccessful, r),
            Some("cross_track_bound")
        );
        assert_eq!(missed_criterion(CaseStatus::Failed, r), Some("no_failure"));
        assert_eq!(missed_criterion(CaseStatus::Ok, ""), None);
    }
}
