//! [`Deadline`]: the one wall-clock budget type of a case, used by the closed loop (checked
//! before every control period), the static analysis (checked after every chunk of samples)
//! and per-case tuning (every tuning run and the scoring run share the case's deadline).
//!
//! Deadlines are cooperative: no thread is ever killed. A case past its deadline ends
//! `failed` with a reason starting [`TIMEOUT`].

use std::time::{Duration, Instant};

use crate::scenario::Stop;

/// The word a timed-out case's reason starts with (`timeout: …`).
pub const TIMEOUT: &str = crate::scenario::TIMEOUT;

/// A wall-clock deadline, or none (unlimited). It holds the closed loop's [`Stop`] (the
/// scenario room's form of the same instant), which [`Deadline::stop`] hands out.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Deadline(Stop);

/// The phase a deadline ran out in (its message names it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Phase {
    /// The static T(q) analysis.
    Static,
    /// The closed-loop run (stopped at simulated time `t` [s]).
    ClosedLoop {
        /// Simulated time reached [s].
        t: f64,
    },
}

/// A case's wall-clock budget ran out.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("{TIMEOUT}: the case's wall-clock budget ran out {}", where_(.phase))]
pub struct TimedOut {
    /// Where it ran out.
    pub phase: Phase,
}

fn where_(p: &Phase) -> String {
    match p {
        Phase::Static => "in the static analysis".into(),
        Phase::ClosedLoop { t } => format!("at t = {t:.3} s"),
    }
}

impl Deadline {
    /// No deadline.
    pub const NONE: Deadline = Deadline(Stop::NEVER);

    /// `budget` from now (`None`: no deadline).
    pub fn after(budget: Option<Duration>) -> Self {
        Deadline(budget.map_or(Stop::NEVER, |b| Stop::at(Instant::now() + b)))
    }

    /// The deadline at `instant`.
    pub fn at(instant: Instant) -> Self {
        Deadline(Stop::at(instant))
    }

    /// The closed loop's [`Stop`] at this deadline (never, without one).
    pub fn stop(self) -> Stop {
        self.0
    }

    /// Whether the deadline has passed (never, without one).
    pub fn passed(self) -> bool {
        self.0.due()
    }

    /// `Err` naming `phase` once the deadline has passed.
    pub fn check(self, phase: Phase) -> Result<(), TimedOut> {
        if self.passed() {
            Err(TimedOut { phase })
        } else {
            Ok(())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_deadline_never_passes_and_a_past_one_has() {
        assert!(!Deadline::NONE.passed());
        assert!(!Deadline::after(None).passed());
        assert_eq!(Deadline::after(None), Deadline::NONE);
        let past = Deadline::at(Instant::now() - Duration::from_millis(1));
        assert!(past.passed());
        // The closed loop's stop is the same instant.
        assert!(past.stop().due());
        assert_eq!(Deadline::NONE.stop(), Stop::NEVER);
        assert!(!Deadline::after(Some(Duration::from_secs(3600)))
            .stop()
            .due());
        assert!(Deadline::after(Some(Duration::from_secs(3600)))
            .check(Phase::Static)
            .is_ok());
    }

    #[test]
    fn messages_are_those_of_the_sweep() {
        let past = Deadline::at(Instant::now() - Duration::from_millis(1));
        let e = past.check(Phase::Static).unwrap_err();
        assert_eq!(
            e.to_string(),
            "timeout: the case's wall-clock budget ran out in the static analysis"
        );
        let e = TimedOut {
            phase: Phase::ClosedLoop { t: 1.5 },
        };
        assert_eq!(
            e.to_string(),
            "timeout: the case's wall-clock budget ran out at t = 1.500 s"
        );
    }
}
