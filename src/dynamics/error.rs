//! The dynamics room's errors: [`DynError`] (no simulation time) and [`SimError`] (at a
//! simulation time), and the finiteness check that names the offending entry.

use thiserror::Error;

/// A numerical failure of a dynamics algorithm (no simulation time attached): a singular
/// mass matrix or a non-finite quantity, named by `quantity` (e.g. `mass_matrix`,
/// `bias[3]`), or a slice of the wrong length.
#[derive(Clone, Debug, Error, PartialEq)]
#[error("{quantity} {message}")]
pub struct DynError {
    /// The offending quantity, e.g. `mass_matrix` or `joint_accelerations[2]`.
    pub quantity: String,
    /// What is wrong with it.
    pub message: String,
}

impl DynError {
    /// A new error about `quantity`.
    pub fn new(quantity: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            quantity: quantity.into(),
            message: message.into(),
        }
    }

    /// Attach the simulation time `t` [s].
    pub fn at(self, time: f64) -> SimError {
        SimError {
            time,
            quantity: self.quantity,
            message: self.message,
        }
    }
}

/// A simulation failure: at simulation time `time` [s], `quantity` (e.g. `joint_rates[3]`)
/// is wrong (`message`, e.g. "is NaN"). Configuration errors found before the run starts
/// carry `time = 0`. The simulator never panics and never continues with a NaN.
#[derive(Clone, Debug, Error, PartialEq)]
#[error("{quantity} {message} at t = {time:.6} s")]
pub struct SimError {
    /// Simulation time [s] at which the problem was detected.
    pub time: f64,
    /// The offending quantity, e.g. `joint_rates[3]`, `mass_matrix`, `config.servo.omega_n`.
    pub quantity: String,
    /// What is wrong with it.
    pub message: String,
}

/// `Err` naming the first non-finite entry of `x` as `name[i]`.
pub(crate) fn check_finite(name: &str, x: &[f64]) -> Result<(), DynError> {
    match x.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(DynError::new(
            format!("{name}[{i}]"),
            if x[i].is_nan() {
                "is NaN"
            } else {
                "is infinite"
            },
        )),
    }
}
