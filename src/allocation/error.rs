//! Bad input to the allocation functions ([`AllocError`]) and the checks that produce it.

use nalgebra::{Matrix6xX, Vector6};

/// Bad input to the allocation functions. Each message names the argument (as the case-file key:
/// `T`, `tau`, `u_min`, `u_max`, `weights`, `u_prev`, `rate_weights`, `rate_limit`, `lambda`, `q`,
/// `eps`, `slack_tol`) and, where relevant, the index.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AllocError {
    /// A vector or matrix has the wrong size.
    #[error("`{arg}` has {found} entries, expected {expected}")]
    Dimension {
        /// Argument name.
        arg: &'static str,
        /// Expected length (number of thrusters `n_thrusters`, or 6).
        expected: usize,
        /// Length found.
        found: usize,
    },
    /// No thrusters (T has zero columns).
    #[error("`T` has no columns: at least one thruster is needed")]
    NoThrusters,
    /// A vector entry is NaN or infinite.
    #[error("`{arg}[{index}]` is not finite ({value})")]
    NonFinite {
        /// Argument name.
        arg: &'static str,
        /// Index of the entry.
        index: usize,
        /// The offending value.
        value: f64,
    },
    /// A matrix entry is NaN or infinite.
    #[error("`{arg}[{row}][{col}]` is not finite ({value})")]
    NonFiniteMatrix {
        /// Argument name.
        arg: &'static str,
        /// Row index.
        row: usize,
        /// Column index.
        col: usize,
        /// The offending value.
        value: f64,
    },
    /// A matrix entry beyond [`MAX_T_ENTRY`] in magnitude: `T W⁻¹ Tᵀ` would overflow.
    #[error(
        "`{arg}[{row}][{col}]` = {value:e} exceeds 1e150 in magnitude (T W⁻¹ Tᵀ would overflow)"
    )]
    HugeMatrix {
        /// Argument name.
        arg: &'static str,
        /// Row index.
        row: usize,
        /// Column index.
        col: usize,
        /// The offending value.
        value: f64,
    },
    /// `u_min[i] > u_max[i]`.
    #[error("`u_min[{index}]` = {min} exceeds `u_max[{index}]` = {max}")]
    BoundsOrder {
        /// Thruster index.
        index: usize,
        /// Lower bound (N).
        min: f64,
        /// Upper bound (N).
        max: f64,
    },
    /// A weight that must be positive (or non-negative) is not.
    #[error("`{arg}[{index}]` = {value} must be {requirement}")]
    BadWeight {
        /// Argument name.
        arg: &'static str,
        /// Index of the entry.
        index: usize,
        /// The offending value.
        value: f64,
        /// What is required, e.g. "> 0".
        requirement: &'static str,
    },
    /// A scalar setting is out of range.
    #[error("setting `{name}` = {value:?} must be {requirement}")]
    BadSetting {
        /// Setting name.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// What is required.
        requirement: &'static str,
    },
}

/// `v` has length `len` and finite entries, else the error naming `arg`.
pub(crate) fn check_vec(arg: &'static str, v: &[f64], len: usize) -> Result<(), AllocError> {
    if v.len() != len {
        return Err(AllocError::Dimension {
            arg,
            expected: len,
            found: v.len(),
        });
    }
    if let Some((index, &value)) = v.iter().enumerate().find(|(_, x)| !x.is_finite()) {
        return Err(AllocError::NonFinite { arg, index, value });
    }
    Ok(())
}

/// `u_min`, `u_max` (N) have length `n_thrusters`, finite entries, and `u_min ≤ u_max`.
pub(crate) fn check_bounds(
    u_min: &[f64],
    u_max: &[f64],
    n_thrusters: usize,
) -> Result<(), AllocError> {
    check_vec("u_min", u_min, n_thrusters)?;
    check_vec("u_max", u_max, n_thrusters)?;
    for (index, (&min, &max)) in u_min.iter().zip(u_max).enumerate() {
        if min > max {
            return Err(AllocError::BoundsOrder { index, min, max });
        }
    }
    Ok(())
}

/// `T` has at least one column (exactly `n_thrusters` if given) and finite entries.
pub(crate) fn check_t(t: &Matrix6xX<f64>, n_thrusters: Option<usize>) -> Result<(), AllocError> {
    if t.ncols() == 0 {
        return Err(AllocError::NoThrusters);
    }
    if let Some(n_thrusters) = n_thrusters {
        if t.ncols() != n_thrusters {
            return Err(AllocError::Dimension {
                arg: "T",
                expected: n_thrusters,
                found: t.ncols(),
            });
        }
    }
    for col in 0..t.ncols() {
        for row in 0..6 {
            let value = t[(row, col)];
            if !value.is_finite() {
                return Err(AllocError::NonFiniteMatrix {
                    arg: "T",
                    row,
                    col,
                    value,
                });
            }
            if value.abs() > MAX_T_ENTRY {
                return Err(AllocError::HugeMatrix {
                    arg: "T",
                    row,
                    col,
                    value,
                });
            }
        }
    }
    Ok(())
}

/// `τ` is finite.
pub(super) fn check_tau(tau: &Vector6<f64>) -> Result<(), AllocError> {
    check_vec("tau", tau.as_slice(), 6)
}

/// `value` is finite and `ok` (the range check described by `requirement`).
pub(super) fn check_setting(
    name: &'static str,
    value: f64,
    ok: bool,
    requirement: &'static str,
) -> Result<(), AllocError> {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(AllocError::BadSetting {
            name,
            value,
            requirement,
        })
    }
}

/// Largest magnitude of an entry of `T` accepted (N/N, N·m/N): products of two entries stay
/// finite. Real thruster matrices hold directions and lever arms of a few metres.
pub const MAX_T_ENTRY: f64 = 1e150;

/// Largest damping λ accepted (USM-37 uses λ²; beyond 1e150 it overflows to infinity and the
/// damped pseudoinverse has no meaningful value).
pub const MAX_LAMBDA: f64 = 1e150;

/// Check the damping λ of the pseudoinverse: finite, ≥ 0 and ≤ [`MAX_LAMBDA`].
pub(super) fn check_lambda(lambda: f64) -> Result<(), AllocError> {
    check_setting(
        "lambda",
        lambda,
        (0.0..=MAX_LAMBDA).contains(&lambda),
        ">= 0 and <= 1e150 (λ² must be finite)",
    )
}
