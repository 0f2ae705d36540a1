//! The error of a scenario: invalid settings, found before anything runs. A run that stops
//! early is not an error: it is a result with its failure (`RunResult::failure`).

use thiserror::Error;

/// A problem with a scenario's settings or its design; nothing ran.
#[derive(Debug, Error)]
pub enum ScenarioError {
    /// The scenario or its design is invalid (the message names the key).
    #[error("{0}")]
    Invalid(String),
}
