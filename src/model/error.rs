//! The model room's error, [`ModelError`]: what is wrong and where (a key path).

use thiserror::Error;

/// An invalid model: what is wrong and where (a key path such as `body[2].mass`).
#[derive(Debug, Error, Clone, PartialEq)]
#[error("{key}: {message}")]
pub struct ModelError {
    /// Key path of the offending value, e.g. `thruster[3].direction`.
    pub key: String,
    /// What is wrong with it.
    pub message: String,
}

impl ModelError {
    /// A new error at `key`.
    pub fn new(key: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            key: key.into(),
            message: message.into(),
        }
    }
}
