//! The control room's error, [`ControlError`] (key path and message), and the checks of
//! settings values that produce it.

use thiserror::Error;

/// Invalid control settings or inputs: the key path of the offending value and what is wrong
/// (e.g. `path.segments[2]: zero length`).
#[derive(Debug, Error, Clone, PartialEq)]
#[error("{key}: {message}")]
pub struct ControlError {
    /// Key path, e.g. `transport.k_psi`.
    pub key: String,
    /// What is wrong.
    pub message: String,
}

impl ControlError {
    /// A new error at `key`.
    pub fn new(key: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            key: key.into(),
            message: message.into(),
        }
    }
}

/// Check that `x` is finite; the error names `key`.
pub(crate) fn check_finite(key: &str, x: f64) -> Result<(), ControlError> {
    if x.is_finite() {
        Ok(())
    } else {
        Err(ControlError::new(key, format!("must be finite, got {x}")))
    }
}

/// Check that `x` is finite and `>= 0`.
pub(crate) fn check_nonneg(key: &str, x: f64) -> Result<(), ControlError> {
    check_finite(key, x)?;
    if x < 0.0 {
        return Err(ControlError::new(key, format!("must be >= 0, got {x}")));
    }
    Ok(())
}

/// Check that `x` is finite and `> 0`.
pub(crate) fn check_pos(key: &str, x: f64) -> Result<(), ControlError> {
    check_finite(key, x)?;
    if x <= 0.0 {
        return Err(ControlError::new(key, format!("must be > 0, got {x}")));
    }
    Ok(())
}
