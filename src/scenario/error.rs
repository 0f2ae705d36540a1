//! The error of a scenario: invalid settings (nothing ran) or a run that stopped early.

use thiserror::Error;

/// A problem with a scenario: bad settings (before running) or a failed run.
#[derive(Debug, Error)]
pub enum ScenarioError {
    /// The scenario or its design is invalid; nothing ran.
    #[error("{0}")]
    Invalid(String),
    /// The run stopped early; what was simulated up to then is in the partial result.
    #[error("run stopped at t = {time:.3} s: {cause}")]
    Stopped {
        /// Simulation time of the failure [s].
        time: f64,
        /// What went wrong (the offending quantity).
        cause: String,
    },
}
